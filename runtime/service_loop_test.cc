// The service loop (runtime/service_loop.h) against real Cyclone DDS in one process (a private
// domain per test): declared inputs dispatch, rejections are counted by reason, output and input
// rates reach NodeHealth, timers fire, threads run and stop, and stop() ends a blocked wait at
// once.

#include "runtime/service_loop.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>

#include "core/clock.h"
#include "harness/fixture.h"
#include "wire/sample.h"

namespace studio::runtime {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

class ServiceLoopTest : public testing::ProcessTest {
 protected:
  void SetUp() override {
    ProcessTest::SetUp();
    participant_.emplace(wire::Participant::create().value());
    context_.emplace(NodeContext{*participant_, metrics_, "test"});
    topic_.emplace(wire::Topic<studio_CameraControl>::create(*participant_).value());
    writer_.emplace(wire::Writer<studio_CameraControl>::create(*participant_, *topic_).value());
  }
  void TearDown() override {
    writer_.reset();
    topic_.reset();
    context_.reset();
    participant_.reset();
    ProcessTest::TearDown();
  }

  void send(const std::string& feature, double value) {
    wire::Owned<studio_CameraControl> c;
    wire::set(c->camera_id, "cam0");
    wire::set(c->feature, feature);
    c->value = value;
    ASSERT_TRUE(writer_->write(*c).has_value());
  }
  uint64_t count(const std::string& name) { return metrics_.counter(name).value(); }
  // Polls `done` for up to 10 s.
  template <class F>
  static bool eventually(F done) {
    for (auto until = Clock::now() + 10s; Clock::now() < until; std::this_thread::sleep_for(5ms))
      if (done()) return true;
    return done();
  }

  Metrics metrics_;
  std::optional<wire::Participant> participant_;
  std::optional<NodeContext> context_;
  std::optional<wire::Topic<studio_CameraControl>> topic_;
  std::optional<wire::Writer<studio_CameraControl>> writer_;
};

TEST_F(ServiceLoopTest, DeclaredInputsDispatchAndOutputsAreCounted) {
  ServiceLoop loop(*context_, "test");
  auto& out = loop.output<studio_CameraControl>({.counter = "echoed", .topic = "test/loop/echo"});
  std::mutex mutex;
  std::vector<double> seen;
  std::thread::id handler_thread;
  loop.input<studio_CameraControl>(
      {.received = "controls_in"},
      [&](const studio_CameraControl& c, const wire::SampleMeta&) -> Outcome {
        {
          std::lock_guard lock(mutex);
          seen.push_back(c.value);
          handler_thread = std::this_thread::get_id();
        }
        wire::Owned<studio_CameraControl> echo;
        std::memcpy(echo.get(), &c, sizeof c);
        echo->value = c.value * 10;
        (void)out.write(*echo);
        return {};
      });
  // Writes before start fail with a line, and are not counted.
  EXPECT_FALSE(out.write(studio_CameraControl{}).has_value());
  auto echo_topic =
      wire::Topic<studio_CameraControl>::create(*participant_, "test/loop/echo").value();
  auto echoes = wire::Reader<studio_CameraControl>::create(*participant_, echo_topic).value();
  ASSERT_TRUE(loop.start().has_value());
  ASSERT_TRUE(out.writer().wait_for_readers(1, 10s)) << "the echo reader never matched";
  for (int k = 0; k < 5; ++k) send("f" + std::to_string(k), k);
  ASSERT_TRUE(eventually([&] { return count("echoed") == 5; })) << count("echoed");
  EXPECT_EQ(count("controls_in"), 5u);
  EXPECT_EQ(count("rejected"), 0u);
  {
    std::lock_guard lock(mutex);
    EXPECT_EQ(seen.size(), 5u);
    EXPECT_NE(handler_thread, std::this_thread::get_id());  // the loop's own thread
  }
  std::vector<double> echoed;
  ASSERT_TRUE(eventually([&] {
    for (auto& s : echoes.take()) echoed.push_back(s.data->value);
    return echoed.size() == 5;
  }));
  std::sort(echoed.begin(), echoed.end());
  EXPECT_EQ(echoed, (std::vector<double>{0, 10, 20, 30, 40}));
  loop.stop();
  EXPECT_FALSE(out.write(studio_CameraControl{}).has_value());  // released at stop
}

TEST_F(ServiceLoopTest, RejectionsAreCountedByReason) {
  ServiceLoop loop(*context_, "test");
  auto& in = loop.input<studio_CameraControl>(
      {.received = "controls_in", .rejected = "controls_rejected", .reason_prefix = "controls_"},
      [&](const studio_CameraControl& c, const wire::SampleMeta&) -> Outcome {
        if (c.value < 0) return reject("negative", "value " + std::to_string(c.value));
        if (c.value > 100) throw std::runtime_error("handler failed");
        return {};
      });
  ASSERT_TRUE(loop.start().has_value());
  send("a", 1);               // accepted
  send("b", -1);              // refused by the handler
  send("c", -2);              // refused by the handler
  send("d", std::nan(""));    // refused by the reader's validator: never reaches the handler
  send("e", 1000);            // the handler throws
  in.reject({"worker", ""});  // refused elsewhere (e.g. a worker thread)
  ASSERT_TRUE(eventually([&] { return count("controls_rejected") == 5; }))
      << count("controls_rejected");
  EXPECT_EQ(count("controls_negative"), 2u);
  EXPECT_EQ(count("controls_malformed"), 1u);
  EXPECT_EQ(count("controls_exception"), 1u);
  EXPECT_EQ(count("controls_worker"), 1u);
  EXPECT_EQ(count("controls_in"), 4u);  // every sample with valid data the validator passed
  // The loop carries on after all of that.
  send("f", 2);
  EXPECT_TRUE(eventually([&] { return count("controls_in") == 5; }));
  EXPECT_EQ(count("controls_rejected"), 5u);
}

TEST_F(ServiceLoopTest, HealthReportsRatesFrameAndLatency) {
  ServiceLoop loop(*context_, "test");
  auto& out = loop.output<studio_CameraControl>({.counter = "out", .topic = "test/loop/out"});
  loop.output<studio_CameraControl>({.counter = "side", .rate = false, .topic = "test/loop/side"});
  loop.input<studio_CameraControl>(
      {.received = "in"}, [&](const studio_CameraControl& c, const wire::SampleMeta&) -> Outcome {
        (void)out.write(c);
        (void)out.write(c);                                            // two out per sample in
        loop.completed(uint64_t(c.value), realtime_ns() - 5'000'000);  // captured 5 ms ago
        return {};
      });
  ASSERT_TRUE(loop.start().has_value());
  metrics_.snapshot();  // latency since here
  const auto a = Clock::now();
  (void)loop.health();
  const auto b = Clock::now();
  for (int k = 1; k <= 10; ++k) send("f" + std::to_string(k), k);
  ASSERT_TRUE(eventually([&] { return count("in") == 10; }));
  const auto c = Clock::now();
  const NodeHealth h = loop.health();
  const auto d = Clock::now();
  // The health period lies between [b, c] and [a, d].
  const double inner = std::chrono::duration<double>(c - b).count();
  const double outer = std::chrono::duration<double>(d - a).count();
  EXPECT_GE(h.input_hz, 10 / outer);
  EXPECT_LE(h.input_hz, 10 / inner);
  EXPECT_DOUBLE_EQ(h.output_hz, 2 * h.input_hz);  // `side` is not a rate output
  EXPECT_GE(h.frame, 1u);
  EXPECT_LE(h.frame, 10u);
  EXPECT_GT(h.capture_ns, 0);
  const MetricsSnapshot s = metrics_.snapshot();
  EXPECT_EQ(s.latency_count, 10u);
  EXPECT_GE(s.latency_mean_ms, 5.0);
  // Nothing since: rates fall to 0.
  std::this_thread::sleep_for(20ms);
  const NodeHealth idle = loop.health();
  EXPECT_EQ(idle.input_hz, 0);
  EXPECT_EQ(idle.output_hz, 0);
}

TEST_F(ServiceLoopTest, TimersFireAndHooksRunOnWake) {
  ServiceLoop loop(*context_, "test");
  std::atomic<int> ticks{0}, deadlines{0}, hooks{0};
  std::optional<Clock::time_point> armed;  // loop thread only, after start
  Clock::time_point fired_at{};
  loop.every(20ms, [&](Clock::time_point) { ++ticks; });
  const auto started = Clock::now();
  armed = started + 150ms;
  loop.deadline([&] { return armed; },
                [&](Clock::time_point now) {
                  fired_at = now;
                  armed.reset();  // one shot
                  ++deadlines;
                });
  loop.after_inputs([&](Clock::time_point) { ++hooks; });
  ASSERT_TRUE(loop.start().has_value());
  ASSERT_TRUE(eventually([&] { return deadlines == 1 && ticks >= 10; }));
  std::this_thread::sleep_for(100ms);
  loop.stop();
  EXPECT_EQ(deadlines, 1);  // disarmed: fired once
  EXPECT_GE(fired_at - started, 150ms);
  // 20 ms ticks: at most one per period since start.
  EXPECT_LE(ticks, 1 + (Clock::now() - started) / 20ms);
  const int hooks_before = hooks;
  EXPECT_GE(hooks_before, ticks);  // every wake runs the hooks

  // wake() runs the hooks without any timer or data.
  ServiceLoop quiet(*context_, "test");
  std::atomic<int> woken{0};
  quiet.after_inputs([&](Clock::time_point) { ++woken; });
  ASSERT_TRUE(quiet.start().has_value());
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(woken, 0);  // nothing to do: the loop sleeps
  quiet.wake();
  EXPECT_TRUE(eventually([&] { return woken == 1; }));
}

TEST_F(ServiceLoopTest, StopEndsABlockedWaitAndInterruptsThreads) {
  ServiceLoop loop(*context_, "test");
  loop.input<studio_CameraControl>(
      {.received = "in"},
      [](const studio_CameraControl&, const wire::SampleMeta&) -> Outcome { return {}; });
  // A timer a minute away: the loop thread blocks in its WaitSet.
  loop.deadline([] { return std::optional(Clock::now() + 60s); }, [](Clock::time_point) {});
  std::mutex mutex;
  std::condition_variable cv;
  std::atomic<int> rounds{0};
  std::atomic<bool> interrupted{false};
  std::atomic<bool> worker_ended{false}, hook_ran{false}, hook_wrote{false}, hook_saw_worker{false};
  loop.thread(
      "worker",
      [&] {
        std::unique_lock lock(mutex);
        while (loop.running()) {
          ++rounds;
          cv.wait(lock);  // blocks until interrupted
        }
        worker_ended = true;
      },
      [&] {
        interrupted = true;
        std::lock_guard lock(mutex);
        cv.notify_all();
      });
  // at_stop: after every thread ended, while the outputs still write (a last state).
  auto& last = loop.output<studio_CameraControl>({.counter = "last", .topic = "test/loop/last"});
  loop.at_stop([&] {
    hook_ran = true;
    hook_saw_worker = !worker_ended;
    wire::Owned<studio_CameraControl> c;
    wire::set(c->camera_id, "cam0");
    wire::set(c->feature, "last");
    hook_wrote = last.write(*c).has_value();
  });
  ASSERT_TRUE(loop.start().has_value());
  EXPECT_TRUE(loop.running());
  ASSERT_TRUE(eventually([&] { return rounds >= 1; }));
  std::this_thread::sleep_for(100ms);
  const auto t0 = Clock::now();
  loop.stop();
  // Far below the minute the wait would otherwise last (generous for a loaded machine).
  EXPECT_LT(Clock::now() - t0, 5s);
  EXPECT_TRUE(interrupted);
  EXPECT_FALSE(loop.running());
  EXPECT_TRUE(hook_ran);
  EXPECT_FALSE(hook_saw_worker);  // the worker had ended
  EXPECT_TRUE(hook_wrote);
  EXPECT_EQ(count("last"), 1u);
  loop.stop();  // idempotent
  // A stopped loop can be destroyed; its DDS entities are gone (a new loop starts cleanly).
  ServiceLoop again(*context_, "test");
  again.input<studio_CameraControl>(
      {.received = "in2"},
      [](const studio_CameraControl&, const wire::SampleMeta&) -> Outcome { return {}; });
  ASSERT_TRUE(again.start().has_value());
  send("x", 1);
  EXPECT_TRUE(eventually([&] { return count("in2") == 1; }));
}

// Liveness (the watchdog's view, runtime/liveness.h): an idle loop comes round often enough to
// stay alive without running its hooks; a handler that does not return makes the loop stalled,
// named; it recovers when the handler returns, and stop() detaches it.
TEST_F(ServiceLoopTest, AnIdleLoopStaysAliveAWedgedHandlerStallsIt) {
  Liveness liveness(200ms);
  NodeContext context{*participant_, metrics_, "test", &liveness};
  ServiceLoop loop(context, "wedgeable");
  std::mutex mutex;
  std::condition_variable cv;
  bool wedged = false;
  std::atomic<int> hooks{0}, handled{0};
  loop.input<studio_CameraControl>(
      {.received = "in"}, [&](const studio_CameraControl& c, const wire::SampleMeta&) -> Outcome {
        std::unique_lock lock(mutex);
        if (c.value > 0) {
          wedged = true;
          cv.wait(lock, [&] { return !wedged; });
        }
        ++handled;
        return {};
      });
  loop.after_inputs([&](Clock::time_point) { ++hooks; });
  ASSERT_TRUE(loop.start().has_value());
  // Idle for 5 bounds: alive (heartbeat turns every 50 ms), and no hook ran.
  for (int i = 0; i < 10; ++i) {
    std::this_thread::sleep_for(100ms);
    EXPECT_FALSE(liveness.stalled(Clock::now())) << "an idle loop must not count as stalled";
  }
  EXPECT_EQ(hooks, 0) << "a heartbeat turn runs no hooks";
  // Positive control: a sample is handled, the hooks run, still alive.
  send("gain", 0);
  ASSERT_TRUE(eventually([&] { return handled == 1 && hooks >= 1; }));
  EXPECT_FALSE(liveness.stalled(Clock::now()));
  // A handler that does not return: stalled past the bound, the loop named.
  send("gain", 1);
  ASSERT_TRUE(eventually([&] {
    std::lock_guard lock(mutex);
    return wedged;
  }));
  std::this_thread::sleep_for(300ms);
  auto stall = liveness.stalled(Clock::now());
  ASSERT_TRUE(stall) << "a wedged handler must count as stalled";
  EXPECT_EQ(stall->name, "wedgeable");
  EXPECT_GT(stall->silent, 200ms);
  {
    std::lock_guard lock(mutex);
    wedged = false;
  }
  cv.notify_all();
  ASSERT_TRUE(eventually([&] { return handled == 2 && !liveness.stalled(Clock::now()); }));
  loop.stop();
  std::this_thread::sleep_for(300ms);
  EXPECT_FALSE(liveness.stalled(Clock::now())) << "a stopped loop is detached";
}

}  // namespace
}  // namespace studio::runtime
