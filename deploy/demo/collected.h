#pragma once
// What the probe recorded (probe.cc) and what the report is computed from (report.cc).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "proc_stats.h"
#include "truth.h"

namespace studio::demo {

// Receive times (CLOCK_REALTIME ns at the probe) of one frame number's samples; 0 = not seen.
struct FrameTimes {
  int64_t capture_ns = 0;
  int masks = 0;           // distinct cameras whose mask of this frame arrived
  uint64_t mask_bits = 0;  // which cameras (index in StudioConfig::camera_ids)
  int64_t last_mask_ns = 0;
  int64_t segments_ns = 0;  // first SegmentSet
  int64_t mesh_ns = 0;      // last actor mesh
  int64_t head_ns = 0;      // the primary head's update
};

struct HeadSample {
  uint64_t frame = 0;
  double error_m = 0;
  double confidence = 0;
};

struct ServiceSeen {
  std::string service, instance, host;
  int pid = 0;
  std::string state;
  double input_hz = 0, output_hz = 0, latency_ms = 0;  // the last status
  double output_hz_sum = 0, input_hz_sum = 0;          // over statuses in the window
  int statuses_in_window = 0;
  std::map<std::string, double> counters;           // the last status
  std::map<std::string, double> counters_at_start;  // first status in the window
  bool have_start = false;
  std::optional<ProcSample> proc_start, proc_end;  // this host only
};

struct Collected {
  int64_t window_start_ns = 0, window_end_ns = 0;
  double load_start[3] = {0, 0, 0}, load_end[3] = {0, 0, 0};
  std::map<uint64_t, FrameTimes> frames;
  std::vector<MeshScore> mesh_scores;  // frames in the window
  std::vector<HeadSample> heads;       // head updates of frames in the window
  std::vector<ServiceSeen> services;
  bool ready = false;  // calibrations + first mesh arrived in time
  std::string not_ready_reason;
  int calibrations = 0;
  std::optional<double> rig_max_diff;  // max |difference| published calibration vs rig.yaml
  std::string rig_detail;
  uint64_t masks_rejected = 0, meshes_rejected = 0;  // failed the wire validators at the probe
  std::optional<ProcSample> probe_start, probe_end;
};

}  // namespace studio::demo
