#include "runtime/metrics.h"

#include <gtest/gtest.h>

#include <thread>

namespace studio::runtime {
namespace {

TEST(Metrics, CountersAndRatesOverThePeriod) {
  Metrics m;
  const auto t0 = std::chrono::steady_clock::now();
  m.snapshot(t0);
  Counter& frames = m.counter("frames");
  EXPECT_EQ(&frames, &m.counter("frames"));  // same name, same counter
  frames.add(50);
  m.counter("drops").add(2);
  MetricsSnapshot s = m.snapshot(t0 + std::chrono::seconds(2));
  ASSERT_EQ(s.counters.size(), 2u);
  EXPECT_EQ(s.counters[0].name, "frames");
  EXPECT_DOUBLE_EQ(s.counters[0].value, 50);
  EXPECT_DOUBLE_EQ(s.rates[0].value, 25);  // 50 in 2 s
  EXPECT_DOUBLE_EQ(s.rates[1].value, 1);
  frames.add(10);
  s = m.snapshot(t0 + std::chrono::seconds(3));
  EXPECT_DOUBLE_EQ(s.counters[0].value, 60);
  EXPECT_DOUBLE_EQ(s.rates[0].value, 10);
  EXPECT_DOUBLE_EQ(s.rates[1].value, 0);
}

TEST(Metrics, LatencyMeanAndMaxResetEachSnapshot) {
  Metrics m;
  m.latency().record(2'000'000);
  m.latency().record(4'000'000);
  MetricsSnapshot s = m.snapshot();
  EXPECT_EQ(s.latency_count, 2u);
  EXPECT_DOUBLE_EQ(s.latency_mean_ms, 3.0);
  EXPECT_DOUBLE_EQ(s.latency_max_ms, 4.0);
  s = m.snapshot();
  EXPECT_EQ(s.latency_count, 0u);
  EXPECT_DOUBLE_EQ(s.latency_max_ms, 0.0);
}

TEST(Metrics, ConcurrentIncrementsAreNotLost) {
  Metrics m;
  Counter& c = m.counter("n");
  std::thread a([&] { for (int i = 0; i < 100000; ++i) c.add(); });
  std::thread b([&] { for (int i = 0; i < 100000; ++i) { c.add(); m.latency().record(i); } });
  a.join();
  b.join();
  EXPECT_EQ(c.value(), 200000u);
  EXPECT_EQ(m.snapshot().latency_max_ms, 99999 * 1e-6);
}

}  // namespace
}  // namespace studio::runtime
