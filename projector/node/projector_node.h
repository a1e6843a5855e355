#pragma once
// The projector service (issue 15 item 3; TCSVT 2004 §V-C/D): one data projector's visualisation
// server. Renders the virtual scene from the actor's eye through the projector's screen rectangle
// (single pass: the homography folded into the projection, or two pass: eye texture + warp) at
// once per new actor mesh (drawn at once; stale undrawn meshes dropped and counted) and at least
// at the projector's rate, headless (EGL surfaceless) or in a full-screen window on a named
// monitor (GLFW, the same renderer; node/window_output.h), and blacks out every actor: their
// latest meshes, moved forward by the predicted motion and grown by the computed margin, drawn
// black from the projector with no depth test (projector/mask_planner.h).
//
// Topics in: studio/scene/node (the scene, mirrored; assets loaded from the paths the nodes
// name, checked by hash), studio/actor/mesh (every actor's mesh; a disposed instance removes the
// actor), studio/actor/head (the followed actor's head = the eye; others give head speeds).
// Topics out: studio/projector/calibration (from the rig file, once, transient-local),
// studio/projector/frame (per rendered frame: frame numbers, capture_ns -> render_done_ns,
// margin, the blackout mask at full resolution as runs, a thumbnail), studio/service/status
// (latency = motion to photon of the newest mesh; gauges margin_mm, latency_p_ms; the scene
// cache's frames_from_cache and scene_rerendered).
//
// Bad input never stops the projection: a degenerate or unseen screen fails at start (one line);
// an eye behind or too close to the screen, a malformed or empty mesh, a scene node that does not
// fit (unknown parent, unreadable asset) are counted rejections and the last good state is kept.

#include <Eigen/Core>
#include <memory>
#include <string>

#include "core/rig.h"
#include "projector/mask_planner.h"
#include "projector_render/frame_renderer.h"
#include "runtime/service.h"

namespace studio::projector {

struct LatencyOptions {
  int window = 100;        // frames measured
  double quantile = 0.95;  // the latency the margin covers
  double initial = 0.04;   // seconds, before the first measurement
  Expected<void> validate() const { return {}; }
};

enum class OutputKind { headless, window };

struct ProjectorNodeOptions {
  std::string rig;              // rig.yaml holding the projector (relative to the config file)
  std::string projector;        // its id
  std::string actor = "actor";  // the head (studio/actor/head key) that is the eye
  std::string mesh_actor = "actor0";  // that actor's mesh id: the head's speed joins its margin
  double rate = 25;                   // frames per second without meshes (a mesh: a frame at once)
  projector_render::Form form = projector_render::Form::single_pass;
  OutputKind output = OutputKind::headless;  // window: full screen on `monitor` (window_output.h)
  std::string monitor = "primary";
  std::vector<int> eye_texture{0, 0};  // two pass: eye texture size, 0 0 = suggested
  double eye_texture_scale = 1.0;      // two pass, eye_texture 0 0: the suggested size x this
  std::vector<double> default_eye{0, 1.7, 2.0};  // eye until a head pose arrives, studio frame
  // Render done -> the frame on the cloth (the projector's input lag and scan-out): the mask is
  // predicted to, and the margin covers, the display instant, not the render's end.
  double display_lag_s = 0.016;
  double head_timeout_s = 2.0;  // an older head pose falls back to the last good eye (counted)
  int frame_every = 1;          // publish studio/projector/frame every N rendered frames (0: never)
  std::vector<int> thumbnail{160, 90};
  // Late latching (issues 15/20): after each frame the next frame's scene is drawn ahead from the
  // eye expected at its display, and the frame's new meshes' motion is fitted; a new mesh then
  // needs only its simplification, the previous fit's velocities per vertex
  // (MaskPlanner::latch_mesh), its mask over the prepared scene, the finish and read-back.
  // false: the whole frame (motion fit, scene, masks) after the mesh arrives.
  bool late_latch = true;
  // Late latching: the motion fits on a thread of their own (projector/fit_worker.h) instead of
  // the render thread after each frame; the render thread installs each finished fit at its next
  // frame. The thread runs fit_nice below the process (0..19). false: fitted on the render thread.
  bool fit_thread = true;
  int fit_nice = 3;
  bool fit_realtime = false;  // under a real-time process: the fit at real-time priority 1
  // The scene drawn on a thread of its own, into a renderer on a display of its own
  // (scene_render::EglScreen::own: its own llvmpipe rasteriser threads), from the eye expected
  // when its image is shown; the render thread puts each frame's masks over the newest image
  // (projector/scene_handoff.h), so a new mesh never waits for the scene to be drawn — not for
  // its draw calls, nor behind its rasterisation. Replaces late latching's scene drawn ahead.
  // The thread (and its rasteriser threads) runs scene_nice below the process (0..19); under a
  // real-time process, time-sharing at nice scene_nice (its llvmpipe load stays out of the
  // real-time budget). false: the scene drawn on the render thread (ahead with late_latch).
  bool scene_thread = true;
  int scene_nice = 3;
  // A mesh's simplification on a second thread beside its motion fit (MaskPlannerOptions; the
  // path without late latching).
  bool parallel_mesh_work = true;
  // Hull meshes clustered before the edge collapse (GrowOptions::presimplify).
  bool mask_presimplify = true;
  // How the mask grows by the margin: true = by its outline as this projector sees it (the mesh
  // plus a band of the margin's angular radius round its silhouette: mask_geometry.h
  // grow_outline); false = every vertex pushed out along its normal (margin / cosine, up to
  // 3.3 x the margin: spikes where a hull mesh's normals spread).
  bool mask_outline = true;
  MarginOptions margin;
  LatencyOptions latency;
  // The static scene rendered once and reused while it is unchanged and the eye stays within
  // the displacement bound (projector/static_shift.h); the nodes changed within settle_s drawn
  // every frame (node/scene_mirror.h).
  SceneCacheOptions scene_cache;

  Expected<void> validate() const;
  MaskPlannerOptions mask_options() const;
};

runtime::ServiceDefinition projector_service_definition();

// Builds the node (projector already read from the rig) — exposed for in-process tests.
Expected<std::unique_ptr<runtime::Node>> make_projector_node(const ProjectorNodeOptions& options,
                                                             const Projector& projector,
                                                             runtime::NodeContext& context);

}  // namespace studio::projector
