#pragma once
// The demo probe's measurement (`studio-demo-probe watch`): it joins the studio's DDS domain as
// one more subscriber and, for a bounded time, records per frame number
//   - when each camera's AlphaMask arrived (studio/camera/mask),
//   - when the hull's first SegmentSet and its actor meshes arrived (studio/actor/segments, mesh),
//   - when the tracker's head update of that frame arrived (studio/actor/head, key `actor`;
//     keep-alive samples, whose capture_ns is not a frame's capture instant, are not updates),
// every service's studio/service/status, and each service process's CPU and RSS from /proc.
// Against the simulator's truth of the same frame number (truth.h) it scores the live meshes
// (re-projection IoU, a few frames per second) and every head update (distance to the true head).
//
// Timeline: wait (at most `ready_timeout_s`) until every camera's calibration and a first mesh
// arrived, then `warmup_s`, then the measurement window of `seconds`; frames whose capture_ns
// lies in the window are the ones reported. One progress line per second on stderr.
//
// Latency is measured from a frame's capture_ns (the instant the camera delivers it, DESIGN §5)
// to the probe's receive time (CLOCK_REALTIME, same host): per stage
//   capture→mask      the frame's last mask (the hull can only start then)
//   mask→segments     first SegmentSet of the frame after its last mask
//   segments→mesh     last actor mesh of the frame after its first SegmentSet
//   segments→head     head update after the first SegmentSet
// and end to end capture→mesh, capture→head, capture→mesh+head (both delivered: what the
// projector needs to draw that frame).
//
// Projectors (studio/projector/frame, one sample per rendered frame with its full-resolution
// blackout mask as runs): every frame rendered in the window is scored against the simulator's
// true actor at its display time (render_done_ns on the studio clock + display_lag_s,
// sim/projector_light.h): lit_actor_px = projector pixels on the true actor the mask leaves lit.
// When projector frames arrive, the headline latency is the projector's motion to photon
// (a mesh's capture_ns → the first projector frame rendered with it) and fps counts the meshes
// that reached a projector.

#include <string>
#include <vector>

#include "core/error.h"
#include "studio_config.h"

namespace studio::demo {

struct ProbeOptions {
  StudioConfig studio;
  std::string rig;              // optional: the hull's rig.yaml, checked against the published
                                // calibrations
  double ready_timeout_s = 60;  // for every calibration and a first mesh
  double warmup_s = 3;
  double seconds = 10;
  double score_rate_hz = 2;  // live meshes scored against the truth per second
  std::string head_id = "actor";
  std::string histogram_png;         // latency histogram (OpenCV), optional
  std::string projector_png;         // a scored projector frame (thumbnail, blackout, true actor)
  std::string actor_view_png;        // that frame on the cloth from the true eye (optional)
  double display_lag_s = 0.016;      // projector frame rendered → on the cloth (sim's default)
  // Frames waiting for scoring (scored when the CPU is otherwise idle, the rest after the window:
  // probe.cc); beyond: counted unscored. 10 000: ~7 min of a 25 Hz projector, ~50 KB each.
  std::size_t projector_queue = 10000;
  bool progress = true;

  Expected<void> validate() const;
};

// Runs the measurement; returns the JSON report (an object). Fails only on setup errors (DDS,
// options); a pipeline that delivers nothing is reported (fps 0, figures null) with
// `complete: false`.
Expected<std::string> run_probe(const ProbeOptions& options);

}  // namespace studio::demo
