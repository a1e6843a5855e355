#include "cpu_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace studio::demo {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// CPU ms per frame period between two samples of one process; NaN without both.
double ms_per_frame(const std::optional<ProcSample>& a, const std::optional<ProcSample>& b,
                    double fps, double* dt_s) {
  if (!a || !b || fps <= 0) return kNaN;
  *dt_s = double(b->taken_ns - a->taken_ns) * 1e-9;
  if (*dt_s <= 0) return kNaN;
  return 1000.0 * (b->cpu_s - a->cpu_s) / (*dt_s * fps);
}

}  // namespace

CpuBudget cpu_budget(const Collected& c, double fps, int cores,
                     const std::map<std::string, double>& delivered_hz) {
  CpuBudget b;
  b.fps = fps;
  b.cores = cores;
  b.available_ms_per_frame = fps > 0 ? cores * 1000.0 / fps : kNaN;
  double dt = 0;
  for (const ServiceSeen& s : c.services) {
    const double ms = ms_per_frame(s.proc_start, s.proc_end, fps, &dt);
    if (!std::isfinite(ms)) continue;  // another host, or no samples
    const std::string key = s.service + ":" + s.instance;
    ServiceCpu sc;
    sc.ms_per_frame = ms;
    const auto d = delivered_hz.find(key);
    // Outputs per frame period = delivered_hz / fps; CPU per output = ms / that.
    sc.ms_per_output = d != delivered_hz.end() && std::isfinite(d->second) && d->second > 0
                           ? ms * fps / d->second
                           : kNaN;
    b.per_service[key] = sc;
    b.stage_ms_per_frame[s.service] += ms;
    b.used_ms_per_frame += ms;
  }
  b.probe_ms_per_frame = ms_per_frame(c.probe_start, c.probe_end, fps, &dt);
  if (std::isfinite(b.probe_ms_per_frame)) b.used_ms_per_frame += b.probe_ms_per_frame;
  double heaviest = -1;
  for (const auto& [stage, ms] : b.stage_ms_per_frame)
    if (ms > heaviest) {
      heaviest = ms;
      b.heaviest_stage = stage;
    }
  return b;
}

void write_cpu_budget(JsonWriter& j, const CpuBudget& b) {
  j.key("cpu_budget").begin_object();
  j.field("note",
          "CPU ms (user + system, /proc) per camera frame period in the window: load-robust, "
          "unlike CPU % and rates");
  j.field("fps", b.fps).field("cores", b.cores);
  j.field("available_ms_per_frame", b.available_ms_per_frame);
  j.field("used_ms_per_frame", b.used_ms_per_frame);
  j.field("probe_ms_per_frame", b.probe_ms_per_frame);
  j.key("stages_ms_per_frame").begin_object();
  for (const auto& [stage, ms] : b.stage_ms_per_frame) j.field(stage, ms);
  j.end_object();
  j.key("per_service").begin_object();
  for (const auto& [key, s] : b.per_service) {
    j.key(key).begin_object();
    j.field("ms_per_frame", s.ms_per_frame).field("ms_per_output", s.ms_per_output);
    j.end_object();
  }
  j.end_object();
  j.field("heaviest_stage", b.heaviest_stage);
  j.end_object();
}

std::string cpu_budget_line(const CpuBudget& b) {
  if (b.per_service.empty()) return "";
  std::string line;
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.1f of %.1f CPU ms per %.0f ms frame (%d cores)",
                b.used_ms_per_frame, b.available_ms_per_frame, 1000.0 / b.fps, b.cores);
  line = buf;
  // Stages, heaviest first.
  std::vector<std::pair<double, std::string>> order;
  for (const auto& [stage, ms] : b.stage_ms_per_frame) order.emplace_back(ms, stage);
  std::sort(order.rbegin(), order.rend());
  line += ":";
  for (const auto& [ms, stage] : order) {
    std::snprintf(buf, sizeof buf, " %s %.1f,", stage.c_str(), ms);
    line += buf;
  }
  if (std::isfinite(b.probe_ms_per_frame)) {
    std::snprintf(buf, sizeof buf, " probe %.1f", b.probe_ms_per_frame);
    line += buf;
  } else {
    line.pop_back();
  }
  return line;
}

}  // namespace studio::demo
