#pragma once
// Per-service metrics that the status publisher reports in studio/service/status: named
// counters (monotonic), rates (events per second over the last report period) and latency
// (capture → publish, milliseconds; mean and max over the period).
//
// Hot paths touch only atomics; snapshot() is called by the status publisher about once per
// second. Names are registered once at start-up and live as long as the Metrics object.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace studio::runtime {

class Counter {
 public:
  void add(uint64_t n = 1) { value_.fetch_add(n, std::memory_order_relaxed); }
  uint64_t value() const { return value_.load(std::memory_order_relaxed); }

 private:
  std::atomic<uint64_t> value_{0};
};

// Latency samples in nanoseconds; keeps the sum, count and max since the last snapshot.
// A value that goes up and down (e.g. a projector's margin in use, mm): reported in
// ServiceStatus among the counters by its name, with no "_hz" rate. Thread-safe.
class Gauge {
 public:
  void set(double v) { value_.store(v, std::memory_order_relaxed); }
  double value() const { return value_.load(std::memory_order_relaxed); }

 private:
  std::atomic<double> value_{0};
};

class LatencyMeter {
 public:
  void record(int64_t ns);
  struct Stats {
    uint64_t count = 0;
    double mean_ms = 0;
    double max_ms = 0;
  };
  Stats take();  // returns and resets

 private:
  std::atomic<uint64_t> count_{0};
  std::atomic<int64_t> sum_ns_{0};
  std::atomic<int64_t> max_ns_{0};
};

struct MetricsSnapshot {
  struct Named {
    std::string name;
    double value;
  };
  std::vector<Named> counters;  // totals since start, then the gauges' current values
  std::vector<Named> rates;     // per second over the period since the previous snapshot
  double latency_mean_ms = 0;
  double latency_max_ms = 0;
  uint64_t latency_count = 0;
};

class Metrics {
 public:
  // A counter that is also reported as a rate (e.g. "masks_published").
  Counter& counter(const std::string& name);
  Gauge& gauge(const std::string& name);
  LatencyMeter& latency() { return latency_; }
  MetricsSnapshot snapshot(std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());

 private:
  struct Entry {
    std::string name;
    Counter counter;
    uint64_t last_value = 0;
  };
  std::mutex mutex_;
  std::deque<Entry> entries_;  // deque: stable addresses for handed-out references
  std::deque<std::pair<std::string, Gauge>> gauges_;
  LatencyMeter latency_;
  std::chrono::steady_clock::time_point last_snapshot_ = std::chrono::steady_clock::now();
};

}  // namespace studio::runtime
