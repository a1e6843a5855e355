#pragma once
// One preview view (issue 16): the scene mirror drawn by the project's renderer
// (scene_render::Renderer), then the live actor textured frame-exactly (gl/actor_texturer.h).
//
// Frame-exact rule: a mesh built from the masks of frame F is drawn textured only with the
// images of frame F of the cameras chosen for it (preview/camera_select.h: nearest, or the blend
// of up to three). When a new mesh arrives the pipeline requests those images and keeps drawing
// the previous (mesh, images) pair until they are all here; if they do not arrive within `wait`
// (late, evicted from the capture ring) the new mesh is drawn untextured and counted. A mesh is
// never drawn with another frame's image.
// Over the scene and the actor: the overlays (preview/overlays.h; head marker, camera and
// projector frusta, projector screens showing the projectors' latest thumbnails), each switched
// by PipelineOptions::overlays.
// Needs a current OpenGL 3.3 context (EGL headless or the GLFW window's).

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "preview/camera_select.h"
#include "preview/overlays.h"
#include "preview/rig_balance.h"
#include "preview/viewpoint.h"
#include "preview_node.h"
#include "runtime/metrics.h"

namespace studio::preview {

struct PipelineOptions {
  bool blend = true;           // false: the paper's nearest camera
  BlendOptions blend_options;  // cameras: how many the blend uses (at most 3 here)
  std::chrono::milliseconds wait{200};
  std::string asset_root;  // relative asset paths of scene nodes resolve here
  OverlayOptions overlays;
  // Request a new mesh's images when it arrives (on the node's loop thread), so that they are
  // here when it is drawn; false: only when render() takes the mesh (a preview that draws few of
  // the meshes it receives, and must not make the capture servers answer for the others).
  bool prefetch = true;
  // Blend: carve the hull against every camera's actor mask of the mesh's frame
  // (studio/camera/mask), not only the three texturing cameras' keys.
  bool carve_all_masks = true;
  // The cameras' colour balance (preview/rig_balance.h): every textured mesh is drawn with each
  // texturing camera's gains; one textured mesh in every `balance_every` (of those with two or
  // more texturing cameras) is pooled into the estimate on a thread of its own (its texturing
  // cameras' images and masks of the mesh's frame: 4-10 ms of CPU at 352x288 to 704x576,
  // BENCHMARKS.md; node/balance_worker.h). A rig whose cameras agree keeps gains 1.
  bool colour_balance = true;
  int balance_every = 4;
  // Rig samples: once per this period, one mesh's images of every calibrated camera are asked
  // for and pooled (those that come within `wait`, on a worker thread of their own, so that the
  // live estimate's pooling never waits for them) into an estimate of their own that links the
  // whole rig, not only the cameras near this view: Match cameras (node/camera_matching.h) sends
  // it. The view is drawn with the live estimate of its own cameras only: over every camera the
  // estimate's view-dependent error (the overhead camera 2.6-4 % off on agreeing cameras)
  // crossed the live tolerance (5 %) and balanced agreeing rigs.
  // 0: off. A sample of 9 cameras costs the worker 12.6 ms of CPU at 352x288, 36.7 ms at
  // 704x576 (preview_bench BM_PreviewRigSample; the view's three: 4.6 / 10.6 ms): 2.5-7 % of a
  // core at the default 0.5 s. Every camera is linked from the first sample
  // (preview_quality_test TheColourBalancePooledFromEveryCameraLinksTheRig).
  std::chrono::milliseconds balance_rig_every{500};
};

struct FrameReport {
  bool new_mesh = false;             // this frame drew a mesh not drawn before
  bool textured = false;             // the drawn mesh is textured
  uint64_t source_frame = 0;         // frame of the masks that built the drawn mesh
  std::vector<std::string> cameras;  // texturing cameras (ids), with their weights
  std::vector<float> weights;
  int carving_masks = 0;  // blend: the cameras' masks of the mesh's frame carving it
  // Per texturing camera: the colour gains (R, G, B) its image was drawn with (all 1 when the
  // balance is off, the rig is within its tolerance or the camera is not yet linked).
  std::vector<Eigen::Vector3f> gains;
  std::vector<Eigen::Vector3f> estimated;  // ... and the balance's estimate for it then
  bool balance_pooled = false;  // this mesh's images were handed to the colour balance
};

// meshes = drawn meshes = textured + untextured; untextured = late (no reply within `wait`) +
// refused (a capture server no longer or not yet had the frame); skipped: meshes superseded by
// a newer one while their images were on the way (never drawn).
struct PipelineCounts {
  uint64_t meshes = 0, textured = 0, untextured = 0, late = 0, refused = 0, skipped = 0;
  // Meshes handed to the colour balance's worker, and those due but refused (the worker still
  // pooling the previous one).
  uint64_t balance_frames = 0, balance_busy = 0;
  // Rig samples handed to the worker, and those given up (fewer than two images came, or the
  // worker stayed busy for a second).
  uint64_t balance_rig_frames = 0, balance_rig_dropped = 0;
};

class ViewPipeline {
 public:
  static Expected<std::unique_ptr<ViewPipeline>> create(PreviewNode& node,
                                                        const PipelineOptions& options);
  ~ViewPipeline();

  // Draws into the bound framebuffer (width x height). block: wait up to options.wait for the
  // images of a new mesh here (headless); else return at once and look again next frame (GUI).
  FrameReport render(const Viewpoint& view, int width, int height, bool block);
  const PipelineCounts& counts() const;
  // A mesh is waiting for its images or a newer one has arrived (render() has work).
  bool has_work() const;
  // Assets the scene names that could not be loaded, one line each.
  std::vector<std::string> asset_problems() const;
  // The newest mesh's centre (for orbiting), or the origin.
  Eigen::Vector3d actor_centre() const;
  void set_blend(bool blend);
  bool blend() const;
  // The cameras' colour balance so far (its latest estimate), and switching it;
  // finish_colour_balance() waits until the mesh the worker holds is pooled.
  BalanceSnapshot colour_balance() const;
  // The rig samples' estimate (every camera; PipelineOptions::balance_rig_every), and whether
  // the rig is sampled (the colour balance on, a period set).
  BalanceSnapshot rig_colour_balance() const;
  bool rig_sampling() const;
  void finish_colour_balance();
  // The colour balance on the service's status (studioctl, the Services panels): gauges
  // colour_balance_applied (0 / 1), colour_balance_frames (pooled) and colour_balance_off_pct
  // (the estimate's largest |gain - 1| over the cameras, percent); the whole rig's estimate:
  // colour_balance_rig_frames (rig samples since the last match) and colour_balance_rig_linked
  // (cameras it links).
  void report(runtime::Metrics& metrics) const;
  void set_colour_balance(bool on);
  bool colour_balance_on() const;
  // Forgets both estimates (the cameras' colours were changed at the cameras:
  // node/camera_matching.h) and pools again only meshes captured at or after
  // `pool_from_capture_ns` (frames on the way still show the old colours).
  void restart_colour_balance(int64_t pool_from_capture_ns);
  OverlayOptions& overlays();
  // GL texture name and size of a projector's latest thumbnail (0: none yet), for the
  // Projectors panel.
  struct Thumbnail {
    unsigned texture = 0;
    int width = 0, height = 0;
  };
  Thumbnail thumbnail(const std::string& projector_id) const;

 private:
  struct Impl;
  explicit ViewPipeline(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::preview
