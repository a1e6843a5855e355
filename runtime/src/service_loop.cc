#include "runtime/service_loop.h"

#include <algorithm>

#include "core/clock.h"
#include "core/log.h"

namespace studio::runtime {

namespace {
constexpr dds_attach_t kStop = 0;  // inputs are attached as 1 + their index
constexpr dds_attach_t kWake = ~dds_attach_t(0);
// Upper bound of one wait (stop and wake() end a wait at once through their guards).
constexpr auto kMaxWait = std::chrono::seconds(60);
}  // namespace

RejectionCounters::RejectionCounters(Metrics& metrics, std::string total, std::string prefix,
                                     std::string log)
    : metrics_(metrics),
      total_(metrics.counter(total)),
      prefix_(std::move(prefix)),
      log_(std::move(log)) {}

void RejectionCounters::add(const Rejection& rejection, uint64_t n) {
  bool first = false;
  Counter* counter = nullptr;
  {
    std::lock_guard lock(mutex_);
    auto it = std::find_if(reasons_.begin(), reasons_.end(),
                           [&](const Reason& r) { return r.name == rejection.reason; });
    if (it == reasons_.end()) {
      reasons_.push_back({rejection.reason, &metrics_.counter(prefix_ + rejection.reason)});
      it = std::prev(reasons_.end());
    }
    counter = it->counter;
    first = !std::exchange(it->logged, true);
  }
  counter->add(n);
  total_.add(n);
  if (rejection.detail.empty()) return;
  if (first)
    STUDIO_LOG(warn, log_) << prefix_ << rejection.reason << ": " << rejection.detail
                           << " (further ones at debug level)";
  else
    STUDIO_LOG(debug, log_) << prefix_ << rejection.reason << ": " << rejection.detail;
}

void InputBase::sync_validator() {
  const uint64_t total = reader().rejected().total();
  if (total > validator_seen_) {
    rejections_.add({"malformed", {}}, total - validator_seen_);  // the reader logged them
    validator_seen_ = total;
  }
}

Expected<void> OutputBase::account(Expected<void> result) {
  if (result) {
    counter_.add();
  } else if (!warned_.exchange(true)) {
    STUDIO_LOG(warn, log_) << spec_.counter << ": " << result.error().message;
  } else {
    STUDIO_LOG(debug, log_) << spec_.counter << ": " << result.error().message;
  }
  return result;
}

struct ServiceLoop::Entities {
  wire::WaitSet waitset;
  wire::GuardCondition stop;
  wire::GuardCondition wake;
};

ServiceLoop::ServiceLoop(NodeContext& context, std::string log)
    : context_(context), log_(std::move(log)) {}

ServiceLoop::~ServiceLoop() { stop(); }

void ServiceLoop::every(SteadyClock::duration period, Fire fire) {
  auto last = std::make_shared<SteadyClock::time_point>(SteadyClock::now());
  timers_.push_back({[last, period] { return std::optional(*last + period); },
                     [last, fire = std::move(fire)](SteadyClock::time_point now) {
                       *last = now;
                       fire(now);
                     }});
}

void ServiceLoop::deadline(std::function<std::optional<SteadyClock::time_point>()> next,
                           Fire fire) {
  timers_.push_back({std::move(next), std::move(fire)});
}

void ServiceLoop::after_inputs(Fire hook) { hooks_.push_back(std::move(hook)); }

void ServiceLoop::at_stop(std::function<void()> hook) { stop_hooks_.push_back(std::move(hook)); }

void ServiceLoop::thread(std::string name, std::function<void()> body,
                         std::function<void()> interrupt) {
  threads_.push_back({std::move(name), std::move(body), std::move(interrupt), {}});
}

Expected<void> ServiceLoop::start() {
  if (entities_) return {};
  const wire::Participant& p = context_.participant;
  auto e =
      wire::gather([](auto&&... x) { return Entities{std::move(x)...}; }, wire::WaitSet::create(p),
                   wire::GuardCondition::create(p), wire::GuardCondition::create(p));
  if (!e) return std::unexpected(e.error());
  auto entities = std::make_unique<Entities>(std::move(*e));
  auto undo = [&](const Error& error) {
    for (auto& in : inputs_) in->release();
    for (auto& out : outputs_) out->release();
    return std::unexpected(error);
  };
  for (auto& out : outputs_)
    if (auto r = out->create(p); !r) return undo(r.error());
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    if (auto r = inputs_[i]->create(p); !r) return undo(r.error());
    inputs_[i]->validator_seen_ = 0;  // a new reader counts from 0
    if (auto r = entities->waitset.attach(inputs_[i]->reader(), dds_attach_t(i + 1)); !r)
      return undo(r.error());
  }
  if (auto r = entities->waitset.attach(entities->stop, kStop); !r) return undo(r.error());
  if (auto r = entities->waitset.attach(entities->wake, kWake); !r) return undo(r.error());
  entities_ = std::move(entities);
  if (context_.liveness) beat_ = context_.liveness->attach(log_);
  running_.store(true, std::memory_order_release);
  loop_thread_ = std::thread([this] { run(); });
  for (Thread& t : threads_) t.thread = std::thread(t.body);
  return {};
}

void ServiceLoop::stop() {
  if (!running_.exchange(false, std::memory_order_acq_rel)) return;
  entities_->stop.trigger();
  for (Thread& t : threads_)
    if (t.interrupt) t.interrupt();
  if (loop_thread_.joinable()) loop_thread_.join();
  for (Thread& t : threads_)
    if (t.thread.joinable()) t.thread.join();
  if (beat_) context_.liveness->detach(std::exchange(beat_, nullptr));
  for (auto& hook : stop_hooks_) hook();
  for (auto& in : inputs_) in->release();
  for (auto& out : outputs_) out->release();
  entities_.reset();
}

void ServiceLoop::wake() {
  if (running() && entities_) entities_->wake.trigger();
}

SteadyClock::duration ServiceLoop::wait_time() const {
  const auto now = SteadyClock::now();
  SteadyClock::duration wait = kMaxWait;
  for (const Timer& t : timers_)
    if (auto at = t.next()) wait = std::min(wait, *at - now);
  return std::max(wait, SteadyClock::duration::zero());
}

void ServiceLoop::fire_timers(SteadyClock::time_point now) {
  for (Timer& t : timers_)
    if (auto at = t.next(); at && now >= *at) t.fire(now);
}

void ServiceLoop::run() {
  const auto heartbeat = beat_ ? context_.liveness->turn_period() : kMaxWait;
  while (running()) {
    const auto timers = wait_time();
    const auto woke = entities_->waitset.wait(std::min<SteadyClock::duration>(timers, heartbeat));
    if (beat_) beat_->turn(SteadyClock::now());
    if (std::find(woke.begin(), woke.end(), kStop) != woke.end() || !running()) break;
    // Came round only to stamp the beat: nothing arrived and no timer is due yet.
    if (woke.empty() && timers > heartbeat && wait_time() > SteadyClock::duration::zero()) continue;
    if (std::find(woke.begin(), woke.end(), kWake) != woke.end()) entities_->wake.take();
    for (auto& in : inputs_) {
      in->drain();
      in->sync_validator();
    }
    const auto now = SteadyClock::now();
    for (Fire& hook : hooks_) hook(now);
    fire_timers(SteadyClock::now());
  }
}

void ServiceLoop::completed(uint64_t frame, int64_t capture_ns) {
  context_.metrics.latency().record(realtime_ns() - capture_ns);
  frame_.store(frame, std::memory_order_relaxed);
  capture_ns_.store(capture_ns, std::memory_order_relaxed);
}

double ServiceLoop::rate(std::vector<Rate>& rates, double seconds) {
  uint64_t events = 0;
  for (Rate& r : rates) {
    const uint64_t v = r.counter->value();
    events += v - r.last;
    r.last = v;
  }
  return seconds > 0 ? double(events) / seconds : 0.0;
}

NodeHealth ServiceLoop::health() {
  std::lock_guard lock(health_mutex_);
  NodeHealth h;
  h.frame = frame_.load(std::memory_order_relaxed);
  h.capture_ns = capture_ns_.load(std::memory_order_relaxed);
  const auto now = SteadyClock::now();
  const double seconds = std::chrono::duration<double>(now - last_health_).count();
  last_health_ = now;
  h.input_hz = rate(rate_in_, seconds);
  h.output_hz = rate(rate_out_, seconds);
  return h;
}

}  // namespace studio::runtime
