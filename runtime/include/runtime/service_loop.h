#pragma once
// The loop every service node runs on (issue 13 item 1). A node DECLARES what it reads and
// writes and supplies the per-sample work; the loop owns everything the nodes have in common:
// the WaitSet and its wake-up on stop, the sample dispatch, counted rejections by reason, the
// input/output rates and frame/latency bookkeeping of NodeHealth, timers, and the node's own
// threads (camera grab threads, worker pools).
//
//   class TrackerNode : public runtime::Node {
//    public:
//     explicit TrackerNode(runtime::NodeContext& context) : loop_(context, "tracker") {
//       heads_ = &loop_.output<studio_HeadPose>({.counter = "heads_out"});
//       loop_.input<studio_SegmentSet>(
//           {.received = "segment_sets_in", .rejected = "rejected"},
//           [this](const studio_SegmentSet& s, const wire::SampleMeta&) -> runtime::Outcome {
//             auto set = wire::to_core(s);
//             if (!set) return runtime::reject("to_core", set.error().message);
//             ...;                                   // heads_->write(pose); loop_.completed(...)
//             return {};
//           });
//       loop_.deadline([this] { return next_keepalive(); }, [this](auto now) { keep_alive(now); });
//     }
//     Expected<void> start() override { return loop_.start(); }
//     void stop() override { loop_.stop(); }
//     runtime::NodeHealth health() override { return loop_.health(); }
//    private:
//     ...                      // the node's state
//     runtime::ServiceLoop loop_;   // LAST member: destroyed (stopped) before the state it uses
//   };
//
// Contract
// - Declaration: input(), output(), every(), deadline(), after_inputs(), at_stop() and thread()
//   are called once, before start() (from the node's constructor); they create nothing yet and
//   cannot fail. start() creates every DDS entity (readers with the topic table's QoS, or the declared
//   history depth; writers; a WaitSet; a guard condition) and starts the loop thread and the
//   declared threads; its error is the node's start error. The returned Output/Input references
//   stay valid as long as the loop.
// - The loop thread: waits on the WaitSet (every input's reader + the stop guard + the wake
//   guard) until data arrives, wake() is called, stop() is called, or the earliest timer is due.
//   Per wake, in declaration order: each input's reader is drained once (up to `batch` samples,
//   loaned, zero-copy) and every sample with data is handed to its handler; then the reader's
//   validator rejections since the last wake are counted (reason "malformed"); then every
//   after_inputs() hook runs; then every timer whose next() is due fires, once. All handlers,
//   hooks and timers run on this one thread, so a node's loop-side state needs no lock.
// - Rejections: a handler returns {} (accepted) or reject(reason, detail). A rejected sample
//   adds 1 to the input's `rejected` counter (the total) and to `<reason_prefix><reason>`; the
//   first rejection of each reason is logged at warn with its detail, later ones at debug. Work
//   done elsewhere (another thread) reports through Input::reject(). Nothing a sample contains
//   ends the loop: an exception a handler throws is logged and the sample counted as reason
//   "exception".
// - Counters: every name given here is a counter of the service's Metrics (one name, one
//   counter, shared by whoever names it), registered at declaration (so the status shows it at
//   0), reported in studio/service/status as a total and as "<name>_hz".
// - NodeHealth (health()): input_hz / output_hz = events per second since the previous call of
//   the inputs' `received` and outputs' `counter` declared with `rate = true`, plus counters
//   added with count_as_input()/count_as_output() (e.g. a grab thread's frames). frame and
//   capture_ns = those of the newest completed() call. degraded is left to the node.
// - completed(frame, capture_ns): the output of a frame is out; records the latency
//   realtime_ns() - capture_ns (the service's latency in ServiceStatus) and the frame for
//   NodeHealth. Thread-safe.
// - Timers: every(period, fire) fires at most once per period; deadline(next, fire) asks next()
//   after each wake and fires when the time it returns has come (nullopt: not armed). fire gets
//   the current steady time. A timer cannot fire before the inputs of its wake were handled.
// - Liveness (the systemd watchdog, runtime/liveness.h): when the context has a Liveness, the
//   loop attaches a Beat (named after `log`) from start() to stop() and stamps it every turn;
//   when idle it comes round at least every turn_period() to stamp it (such a heartbeat turn runs
//   no hooks and no timer that is not due). A turn that never ends stops the watchdog pings.
// - Threads: thread(name, body, interrupt) runs body() on its own thread from start() until it
//   returns; body loops while running() is true. stop() calls interrupt() (e.g. stop a camera
//   source, notify a condition variable) so a blocked body returns promptly.
// - stop(): idempotent; clears running(), triggers the stop guard (the WaitSet returns at once),
//   interrupts and joins every thread, runs the at_stop() hooks (no other thread of the loop
//   runs then; the outputs still write: a last state, finishing recordings), then releases the
//   DDS entities. start() after stop() runs the same declarations again on new entities. The
//   destructor stops.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "core/error.h"
#include "runtime/liveness.h"
#include "runtime/metrics.h"
#include "runtime/service.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"

namespace studio::runtime {

// Why a handler refused a sample: `reason` names the counter (short, snake_case: "to_core",
// "size", "format"), `detail` is logged.
struct Rejection {
  std::string reason;
  std::string detail{};
};
// A handler's verdict on one sample: {} = accepted.
using Outcome = std::expected<void, Rejection>;
inline std::unexpected<Rejection> reject(std::string reason, std::string detail = {}) {
  return std::unexpected(Rejection{std::move(reason), std::move(detail)});
}

// Designated initializers name the fields in this order: {.received = "masks_in", ...}.
struct InputSpec {
  std::string received{};             // counter of samples handed to the handler (e.g. "masks_in")
  std::string rejected = "rejected";  // counter of all rejected samples of this input
  std::string reason_prefix = "rejected_";  // per-reason counters: prefix + reason
  bool rate = true;                         // `received` counts towards NodeHealth::input_hz
  bool instance_changes = false;  // also hand over dispose/unregister notices (meta.valid_data
                                  // false, key fields only); they are never rejected or counted
  std::size_t batch = 64;         // samples taken per wake at most
  std::string topic{};            // "" = the wire table's name for the type
  int32_t history_depth = 0;      // > 0: keep this many samples per instance (wire::Reader::create)
};

struct OutputSpec {
  std::string counter{};  // samples written (e.g. "heads_out"); required
  bool rate = true;       // counts towards NodeHealth::output_hz
  std::string topic{};    // "" = the wire table's name for the type
};

class ServiceLoop;

// The rejection counters of one input (shared by the loop thread and any thread that rejects).
class RejectionCounters {
 public:
  RejectionCounters(Metrics& metrics, std::string total, std::string prefix, std::string log);
  void add(const Rejection& rejection, uint64_t n = 1);
  Counter& total() { return total_; }

 private:
  struct Reason {
    std::string name;
    Counter* counter;
    bool logged = false;
  };
  Metrics& metrics_;
  Counter& total_;
  std::string prefix_, log_;
  std::mutex mutex_;
  std::deque<Reason> reasons_;
};

class InputBase {
 public:
  virtual ~InputBase() = default;
  // Counts a rejection made outside the handler (e.g. by a worker thread). Thread-safe.
  void reject(const Rejection& rejection) { rejections_.add(rejection); }
  Counter& received() { return received_; }
  const InputSpec& spec() const { return spec_; }

 protected:
  friend class ServiceLoop;
  InputBase(InputSpec spec, Metrics& metrics, std::string log)
      : spec_(std::move(spec)),
        received_(metrics.counter(spec_.received)),
        rejections_(metrics, spec_.rejected, spec_.reason_prefix, std::move(log)) {}
  virtual Expected<void> create(const wire::Participant& p) = 0;
  virtual const wire::ReaderBase& reader() const = 0;
  virtual void drain() = 0;  // one wake's samples to the handler
  virtual void release() = 0;
  void sync_validator();  // counts the reader's new validator rejections as "malformed"

  InputSpec spec_;
  Counter& received_;
  RejectionCounters rejections_;
  uint64_t validator_seen_ = 0;
};

template <wire::WireType T>
class Input : public InputBase {
 public:
  using Handler = std::function<Outcome(const T&, const wire::SampleMeta&)>;
  Input(InputSpec spec, Metrics& metrics, std::string log, Handler handler)
      : InputBase(std::move(spec), metrics, std::move(log)), handler_(std::move(handler)) {}

 private:
  Expected<void> create(const wire::Participant& p) override {
    auto s = wire::Subscription<T>::create(p, spec_.topic, spec_.history_depth);
    if (!s) return std::unexpected(s.error());
    sub_.emplace(std::move(*s));
    return {};
  }
  const wire::ReaderBase& reader() const override { return sub_->reader; }
  void release() override { sub_.reset(); }
  void drain() override {
    sub_->reader.visit(
        [&](const T& sample, const wire::SampleMeta& meta) {
          if (!meta.valid_data) {
            if (spec_.instance_changes) (void)call(sample, meta);
            return;
          }
          received_.add();
          if (Outcome r = call(sample, meta); !r) rejections_.add(r.error());
        },
        spec_.batch);
  }
  Outcome call(const T& sample, const wire::SampleMeta& meta) {
    try {
      return handler_(sample, meta);
    } catch (const std::exception& e) {
      return runtime::reject("exception", e.what());
    }
  }
  Handler handler_;
  std::optional<wire::Subscription<T>> sub_;
};

class OutputBase {
 public:
  virtual ~OutputBase() = default;
  Counter& written() { return counter_; }
  const OutputSpec& spec() const { return spec_; }

 protected:
  friend class ServiceLoop;
  OutputBase(OutputSpec spec, Metrics& metrics, std::string log)
      : spec_(std::move(spec)), counter_(metrics.counter(spec_.counter)), log_(std::move(log)) {}
  virtual Expected<void> create(const wire::Participant& p) = 0;
  virtual void release() = 0;
  // Counts a successful write; logs a failed one (first at warn, then debug).
  Expected<void> account(Expected<void> result);

  OutputSpec spec_;
  Counter& counter_;
  std::string log_;
  std::atomic<bool> warned_{false};
};

// A declared publication. write() and dispose() are thread-safe (DDS writers are); before
// start() and after stop() they fail with a one-line error. Threads the loop does not own must
// stop writing before stop() (the loop's own threads and at_stop() hooks may write throughout).
template <wire::WireType T>
class Output : public OutputBase {
 public:
  Output(OutputSpec spec, Metrics& metrics, std::string log)
      : OutputBase(std::move(spec), metrics, std::move(log)) {}
  Expected<void> write(const T& sample) {
    if (!pub_) return fail(spec_.counter + ": not started");
    return account(pub_->writer.write(sample));
  }
  Expected<void> dispose(const T& key) {
    if (!pub_) return fail(spec_.counter + ": not started");
    return pub_->writer.dispose(key);
  }
  // The writer, e.g. to wait for readers; valid between start() and stop().
  const wire::Writer<T>& writer() const { return pub_->writer; }

 private:
  Expected<void> create(const wire::Participant& p) override {
    auto pub = wire::Publication<T>::create(p, spec_.topic);
    if (!pub) return std::unexpected(pub.error());
    pub_.emplace(std::move(*pub));
    return {};
  }
  void release() override { pub_.reset(); }
  std::optional<wire::Publication<T>> pub_;
};

class ServiceLoop {
 public:
  // `log` is the log category of the node ("hull"); rejections and write failures log under it.
  ServiceLoop(NodeContext& context, std::string log);
  ~ServiceLoop();
  ServiceLoop(const ServiceLoop&) = delete;
  ServiceLoop& operator=(const ServiceLoop&) = delete;

  // --- declaration (before start) ---
  template <wire::WireType T>
  Input<T>& input(InputSpec spec, typename Input<T>::Handler handler) {
    auto in =
        std::make_unique<Input<T>>(std::move(spec), context_.metrics, log_, std::move(handler));
    Input<T>& ref = *in;
    if (ref.spec().rate) rate_in_.push_back({&ref.received(), 0});
    inputs_.push_back(std::move(in));
    return ref;
  }
  template <wire::WireType T>
  Output<T>& output(OutputSpec spec) {
    auto out = std::make_unique<Output<T>>(std::move(spec), context_.metrics, log_);
    Output<T>& ref = *out;
    if (ref.spec().rate) rate_out_.push_back({&ref.written(), 0});
    outputs_.push_back(std::move(out));
    return ref;
  }
  using Fire = std::function<void(SteadyClock::time_point now)>;
  void every(SteadyClock::duration period, Fire fire);
  void deadline(std::function<std::optional<SteadyClock::time_point>()> next, Fire fire);
  void after_inputs(Fire hook);
  void at_stop(std::function<void()> hook);
  void thread(std::string name, std::function<void()> body, std::function<void()> interrupt = {});
  // A counter (registered now) whose rate counts as NodeHealth input / output.
  void count_as_input(Counter& counter) { rate_in_.push_back({&counter, 0}); }
  void count_as_output(Counter& counter) { rate_out_.push_back({&counter, 0}); }

  // --- running ---
  Expected<void> start();
  void stop();
  bool running() const { return running_.load(std::memory_order_acquire); }
  // Wakes the loop thread (runs after_inputs hooks and due timers). Thread-safe.
  void wake();
  void completed(uint64_t frame, int64_t capture_ns);
  NodeHealth health();

  Metrics& metrics() { return context_.metrics; }
  Counter& counter(const std::string& name) { return context_.metrics.counter(name); }
  const wire::Participant& participant() const { return context_.participant; }
  const std::string& instance() const { return context_.instance; }

 private:
  struct Timer {
    std::function<std::optional<SteadyClock::time_point>()> next;
    Fire fire;
  };
  struct Rate {
    Counter* counter;
    uint64_t last;
  };
  struct Thread {
    std::string name;
    std::function<void()> body, interrupt;
    std::thread thread;
  };
  struct Entities;
  void run();
  SteadyClock::duration wait_time() const;
  void fire_timers(SteadyClock::time_point now);
  static double rate(std::vector<Rate>& rates, double seconds);

  NodeContext& context_;
  std::string log_;
  std::vector<std::unique_ptr<InputBase>> inputs_;
  std::vector<std::unique_ptr<OutputBase>> outputs_;
  std::vector<Timer> timers_;
  std::vector<Fire> hooks_;
  std::vector<std::function<void()>> stop_hooks_;
  std::deque<Thread> threads_;
  std::vector<Rate> rate_in_, rate_out_;
  std::unique_ptr<Entities> entities_;
  std::shared_ptr<Liveness::Beat> beat_;  // attached to context_.liveness while running
  std::thread loop_thread_;
  std::atomic<bool> running_{false};
  std::atomic<uint64_t> frame_{0};
  std::atomic<int64_t> capture_ns_{0};
  std::mutex health_mutex_;
  SteadyClock::time_point last_health_ = SteadyClock::now();
};

}  // namespace studio::runtime
