#pragma once
// What the preview's overlays draw (preview/overlays.h), mirrored from the wire on the node's
// loop thread:
//   studio/actor/head             → the tracked heads (one per actor_id); a head not updated for
//                                   `head_timeout` is no longer drawn (the tracker keeps a live
//                                   head alive every frame), a disposed one at once
//   studio/projector/calibration  → each projector's K, pose, size and screen corners
//   studio/projector/frame        → each projector's latest thumbnail (what it shows), frame
//                                   counters, latency and margin, for the screens and the
//                                   Projectors panel
// Declared on the preview node's ServiceLoop (before start); every accessor is thread-safe.
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/rig.h"
#include "preview/overlays.h"
#include "runtime/service_loop.h"

namespace studio::preview {

struct ProjectorView {
  Projector projector;  // valid when calibrated
  bool calibrated = false;
  uint64_t render_frame = 0;  // of the latest ProjectorFrame (0: none yet)
  uint64_t mesh_frame = 0;    // studio frame of the newest actor mesh in its mask
  double latency_ms = 0, margin_m = 0;
  int thumb_width = 0, thumb_height = 0;
  std::vector<uint8_t> thumbnail;  // RGB8, top row first
  uint64_t thumbnail_version = 0;  // increases with every thumbnail received
};

struct OverlayCounts {
  std::size_t heads = 0, projectors = 0, thumbnails = 0;
};

class OverlayInputs {
 public:
  OverlayInputs(runtime::ServiceLoop& loop,
                std::chrono::milliseconds head_timeout = std::chrono::milliseconds(2000));

  std::vector<HeadMarker> heads() const;  // the live ones
  std::map<std::string, ProjectorView> projectors() const;
  // Calibrated projectors only, as rig projectors.
  std::vector<Projector> calibrated() const;
  OverlayCounts counts() const;

 private:
  struct Head {
    HeadMarker marker;
    std::chrono::steady_clock::time_point seen;
  };
  std::chrono::milliseconds head_timeout_;
  mutable std::mutex mutex_;
  std::map<std::string, Head> heads_;
  std::map<std::string, ProjectorView> projectors_;
};

}  // namespace studio::preview
