#pragma once
// What the probe recorded (probe.cc) and what the report is computed from (report.cc).

#include <Eigen/Core>
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

// One studio/projector/frame sample rendered in the window, scored against the simulator's true
// actor at its display time (truth.h projector_lit).
struct ProjectorSample {
  std::string projector_id;
  uint64_t render_frame = 0;
  uint64_t mesh_frame = 0;     // studio frame of the newest mesh in the mask (0: none)
  int64_t capture_ns = 0;      // of that mesh
  int64_t render_done_ns = 0;  // CLOCK_REALTIME
  double latency_ms = 0;       // as the projector published it
  double margin_m = 0;
  bool predicted = false;
  bool scored = false;  // false: the scorer fell behind (or the calibration was missing)
  // Rendered after the window, with a mesh captured in it: counts for that mesh's rate and
  // motion to photon only (not a frame of the window: not rendered, scored or lit).
  bool after_window = false;
  uint64_t actor_px = 0, lit_actor_px = 0, blackout_px = 0, wasted_px = 0;
  // The eye the frame's scene was drawn from, and its distance to the true head centre at the
  // frame's display (scored frames): what the actor sees is off by this much parallax.
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();
  double eye_error_m = -1;
};

// The picture of one scored projector frame (OUT/projector.png): the thumbnail it published,
// the blackout mask and the true actor at display time, at full resolution.
struct ProjectorPicture {
  std::string projector_id;
  uint64_t render_frame = 0, lit_actor_px = 0, actor_px = 0;
  double studio_frame = 0;  // its render time on the simulator's clock (fractional frame)
  int thumb_width = 0, thumb_height = 0;
  std::vector<uint8_t> thumbnail;  // RGB8
  Mask actor;
  RunMask blackout;
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
  std::vector<ProjectorSample> projector;  // frames rendered in the window, every projector
  std::map<std::string, int> projector_calibrations;  // id -> width*height seen (0: none)
  uint64_t projector_frames_rejected = 0, projector_score_errors = 0;
  std::string projector_score_error;                  // the first one
  std::optional<ProjectorPicture> projector_picture;  // the worst scored frame (most lit px)
  double display_lag_s = 0;
};

}  // namespace studio::demo
