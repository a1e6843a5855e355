#pragma once
// The demo's CPU budget per studio frame (report.json "cpu_budget", report.md "CPU per frame"):
// what each service's process spent in the measurement window, as CPU milliseconds per camera
// frame period (1 / fps) and per output it delivered, against what the host's cores give in one
// period. CPU time (utime + stime from /proc) counts work done, not waiting, so these figures
// hold on a loaded machine where % of wall time and rates do not: a stage "holds the rate back"
// when the whole studio's CPU per frame exceeds the cores' budget, by the stages that spend it.
//
//   per service  cpu_ms_per_frame  = 1000 * dCPU_s / (dt_s * fps)        (dt: its /proc samples)
//                cpu_ms_per_output = 1000 * dCPU_s / outputs delivered in dt (masks, meshes,
//                                    head updates, projector frames rendered; NaN when none)
//   per stage    the sum of its services' cpu_ms_per_frame (the 6 capture servers are one stage)
//   budget       available_ms_per_frame = cores * 1000 / fps; used = sum over stages + probe

#include <map>
#include <string>

#include "collected.h"
#include "json_writer.h"

namespace studio::demo {

struct ServiceCpu {
  double ms_per_frame = 0;   // CPU ms per camera frame period
  double ms_per_output = 0;  // CPU ms per output delivered (NaN: none delivered)
};

struct CpuBudget {
  double fps = 0;
  int cores = 0;
  double available_ms_per_frame = 0;  // cores * 1000 / fps
  double used_ms_per_frame = 0;       // services + probe
  double probe_ms_per_frame = 0;
  std::map<std::string, double> stage_ms_per_frame;  // service kind -> sum over its instances
  std::map<std::string, ServiceCpu> per_service;     // "kind:instance" -> figures (this host)
  std::string heaviest_stage;
};

// `delivered_hz`: "kind:instance" -> outputs per second reaching the probe (masks, meshes, ...).
CpuBudget cpu_budget(const Collected& c, double fps, int cores,
                     const std::map<std::string, double>& delivered_hz);
void write_cpu_budget(JsonWriter& j, const CpuBudget& b);
// One line for held_back_by.cpu: the budget and the stages that spend it.
std::string cpu_budget_line(const CpuBudget& b);

}  // namespace studio::demo
