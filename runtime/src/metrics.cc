#include "runtime/metrics.h"

namespace studio::runtime {

void LatencyMeter::record(int64_t ns) {
  count_.fetch_add(1, std::memory_order_relaxed);
  sum_ns_.fetch_add(ns, std::memory_order_relaxed);
  int64_t prev = max_ns_.load(std::memory_order_relaxed);
  while (ns > prev && !max_ns_.compare_exchange_weak(prev, ns, std::memory_order_relaxed)) {
  }
}

LatencyMeter::Stats LatencyMeter::take() {
  Stats s;
  s.count = count_.exchange(0, std::memory_order_relaxed);
  const int64_t sum = sum_ns_.exchange(0, std::memory_order_relaxed);
  const int64_t max = max_ns_.exchange(0, std::memory_order_relaxed);
  if (s.count > 0) {
    s.mean_ms = double(sum) / double(s.count) * 1e-6;
    s.max_ms = double(max) * 1e-6;
  }
  return s;
}

Counter& Metrics::counter(const std::string& name) {
  std::lock_guard lock(mutex_);
  for (Entry& e : entries_)
    if (e.name == name) return e.counter;
  entries_.emplace_back();
  entries_.back().name = name;
  return entries_.back().counter;
}

Gauge& Metrics::gauge(const std::string& name) {
  std::lock_guard lock(mutex_);
  for (auto& [n, g] : gauges_)
    if (n == name) return g;
  gauges_.emplace_back(std::piecewise_construct, std::forward_as_tuple(name), std::forward_as_tuple());
  return gauges_.back().second;
}

MetricsSnapshot Metrics::snapshot(std::chrono::steady_clock::time_point now) {
  std::lock_guard lock(mutex_);
  MetricsSnapshot out;
  const double seconds = std::chrono::duration<double>(now - last_snapshot_).count();
  last_snapshot_ = now;
  for (Entry& e : entries_) {
    const uint64_t v = e.counter.value();
    out.counters.push_back({e.name, double(v)});
    out.rates.push_back({e.name, seconds > 0 ? double(v - e.last_value) / seconds : 0.0});
    e.last_value = v;
  }
  for (const auto& [n, g] : gauges_) out.counters.push_back({n, g.value()});
  const LatencyMeter::Stats l = latency_.take();
  out.latency_mean_ms = l.mean_ms;
  out.latency_max_ms = l.max_ms;
  out.latency_count = l.count;
  return out;
}

}  // namespace studio::runtime
