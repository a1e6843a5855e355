#pragma once
// One projector frame on the GPU (TCSVT 2004 §V-C/D), shared by the projector node, the
// `studio-projector render` CLI and the benchmark: the virtual scene seen from the actor's eye
// through the projector's screen rectangle, then every actor's mask mesh drawn black from the
// projector's viewpoint with no depth test. Needs a current OpenGL 3.3 context (a
// HeadlessContext, or a GLFW window's) on the calling thread.
//
// Forms (projector/projector_view.h):
// - single pass: the scene drawn once with ProjectorView::single_pass's clip_from_world (the
//   homography folded into the off-axis projection) and its eye clip plane; what lies outside
//   the screen rectangle in the projector's image is black (no cloth there: the same frame as
//   the two-pass warp's). That black is laid first, at depth 0, and the scene is drawn inside
//   the rectangle's bounding box only, culled to the eye's frustum through the rectangle: no
//   fragment outside the cloth is shaded;
// - two pass: the eye's off-axis view rendered into a texture covering the screen rectangle
//   (ProjectorView::suggested_texture_size, or the configured size), then warped onto the
//   projector frame by one full-screen quad sampling it through the 3x3 texture_from_ndc.
//   A projector with lens distortion is refused here (the exact warp map is not wired up).
// Mask: drawn with colour (0, 0, 0, 0) after the scene, so the read-back tells a blacked-out
// pixel (alpha 0) from a black scene pixel (alpha 1): `Readback::blackout` is exactly the set of
// projector pixels the mask covered.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/run_mask.h"
#include "projector/actor_mesh.h"
#include "projector/projector_view.h"
#include "projector/static_shift.h"
#include "scene/scene.h"
#include "scene_render/renderer.h"

namespace studio::projector_render {

enum class Form { single_pass, two_pass };

struct FrameRendererOptions {
  Form form = Form::single_pass;
  // Two-pass eye texture size; 0 x 0: ProjectorView::suggested_texture_size() x
  // eye_texture_scale (each side; 1: one texel per projector pixel on the screen). The scene is
  // shaded per texel: 0.5 shades a quarter of the fragments, the warp then magnifies 2x.
  Eigen::Vector2i eye_texture_size = Eigen::Vector2i::Zero();
  double eye_texture_scale = 1.0;  // (0.1 .. 1]
  projector::OffAxisOptions off_axis;
  // The scene renderer's options; the projector samples textures at the nearest texel (within
  // 42 dB PSNR of bilinear on the default scene, a sixth less CPU per frame on llvmpipe).
  scene_render::RendererOptions renderer = [] {
    scene_render::RendererOptions r;
    r.texture_filter = scene_render::RendererOptions::TextureFilter::nearest;
    return r;
  }();
  // Two pass: the warp is drawn only over the screen rectangle's image (its corners in the
  // projector, 2 px out), the rest cleared black; false: over the whole frame (the baseline,
  // black outside the screen by the warp's own test). The same frame either way.
  bool warp_screen_only = true;
  // Single pass, a frame drawn whole (render() with masks, its static scene not kept for the
  // cache): the actor masks are laid first, at depth 0 like the black around the screen, so the
  // scene is not shaded under them and the frame needs no pass after the scene (an outline
  // mask's rectangle clears make llvmpipe finish the scene first, which stops the next frame's
  // binning from overlapping it). The same frame either way (frame_renderer_test). false: the
  // masks over the finished scene, as draw_masks() lays them after prepare().
  bool masks_first = true;
  // The static scene layer cached between frames (render(const LayeredScene&, ...);
  // render/static_layer.h); enabled = false: every frame draws the whole scene.
  projector::SceneCacheOptions scene_cache;
  int thumb_width = 160;  // 0: no thumbnail
  int thumb_height = 90;
  Expected<void> validate() const;
};

struct Readback {
  std::vector<std::uint8_t> rgba;       // full frame, top row first (kept when asked)
  RunMask blackout;                     // projector pixels the mask covered, top row first
  std::vector<std::uint8_t> thumbnail;  // RGB8, thumb_width x thumb_height, top row first
  int thumb_width = 0, thumb_height = 0;
};

// The scene split in two (the projector node's SceneMirror): `still` is drawn into the cached
// static layer, which is reused while `still_version` stays the same and the eye has moved less
// than the displacement bound allows (projector/static_shift.h); `moving` (may be null) is drawn
// over it, with the depth test, every frame. Both hold the same lights.
struct LayeredScene {
  const scene::Scene& still;
  std::uint64_t still_version = 0;
  const scene::Scene* moving = nullptr;
};

struct FrameInfo {
  int masks = 0;            // mask meshes drawn
  bool from_cache = false;  // the static layer was restored, not drawn
  // Restored beyond the bound, by SceneCacheOptions::hold_frames (shift_px is then the static
  // scene's error bound in this frame).
  bool held = false;
  // The displacement bound (projector px) of the cached layer at this frame's eye; +inf when
  // nothing was cached for this static version (a full render follows either way when it
  // exceeds SceneCacheOptions::max_error_px).
  double shift_px = 0;
  // A re-rendered static layer was kept for later frames (not when the eye moved more than the
  // bound since the previous frame and nothing is held: it would not serve the next one).
  bool stored = false;
};

// The black outside the cloth: the screen's plane around the rectangle, out to 50 m from its
// centre, as an actor mesh (normals the screen's) that the single pass lays first.
scene::ActorMesh screen_surround(const projector::Screen& screen, const std::string& actor_id);

class FrameRenderer {
 public:
  // Errors: invalid options, a two-pass projector with lens distortion, GL resources that cannot
  // be created.
  static Expected<FrameRenderer> create(const projector::ProjectorView& view,
                                        const FrameRendererOptions& options = {});
  FrameRenderer(FrameRenderer&&) noexcept;
  FrameRenderer& operator=(FrameRenderer&&) noexcept;
  ~FrameRenderer();

  // The scene renderer (upload assets, actor meshes of the scene's actor nodes).
  scene_render::Renderer& renderer();
  const projector::ProjectorView& view() const;

  // Draws one frame into the projector target: the scene from `eye`, then every mask mesh
  // (already grown and predicted, studio frame) black. Errors: those of the projection (eye
  // behind or too close to the screen) — nothing is drawn then; an invalid mask mesh is skipped
  // and counted in the result. Returns the number of masks drawn.
  Expected<int> render(const scene::Scene& scene, const Eigen::Vector3d& eye,
                       std::span<const projector::ActorMesh> masks);
  // The same frame from a layered scene: the static layer restored from the cache when it is
  // usable at `eye` (else drawn, and cached when the cache is enabled), then the moving nodes,
  // then the masks. Errors: those of render().
  Expected<FrameInfo> render(const LayeredScene& scene, const Eigen::Vector3d& eye,
                             std::span<const projector::ActorMesh> masks);
  // Late latching (the projector node's default, ProjectorNodeOptions::late_latch): the frame's
  // scene drawn AHEAD, before its masks are known — render() without masks, flushed so that
  // llvmpipe rasterises it while the caller waits for the next mesh — then draw_masks() puts the
  // masks over it (no depth test: the scene's depth plays no part) and finish() completes the
  // frame: prepare + draw_masks + finish gives the very frame render + finish gives. Errors:
  // those of render() (nothing is drawn then).
  Expected<FrameInfo> prepare(const LayeredScene& scene, const Eigen::Vector3d& eye);
  Expected<FrameInfo> prepare(const scene::Scene& scene, const Eigen::Vector3d& eye);
  // Every mask mesh black over the frame prepared (or rendered) last; returns the masks drawn
  // (an invalid mask is skipped).
  int draw_masks(std::span<const projector::ActorMesh> masks);
  // A scene drawn by another renderer (the projector node's scene thread, on a display of its
  // own: scene_render::EglScreen::own) goes between them as memory: read_image() copies this
  // renderer's frame out (RGBA, GL's row order: bottom row first; waits for its rasterisation),
  // load_image() makes such an image this renderer's frame — the scene of a frame whose masks
  // draw_masks() then puts over it. Together: the frame the other renderer prepared, masked
  // here. load_image() is false (nothing loaded) unless `rgba` holds width() x height() x 4.
  void read_image(std::vector<std::uint8_t>& rgba);
  bool load_image(std::span<const std::uint8_t> rgba);
  // The largest eye move (metres, any direction, first order) from `eye` under which the cached
  // static layer stays usable (StaticShiftBound::allowed_move_m over the heights it shows); 0
  // when nothing is cached or the cache is disabled.
  double cache_allowed_move_m(const Eigen::Vector3d& eye) const;
  // Finishes the frame (glFinish): after this the frame is rendered.
  void finish();
  // Reads the frame back: blackout mask and thumbnail (and the full RGBA when keep_rgba).
  void read(Readback& out, bool keep_rgba = false);
  // The projector target's colour texture and framebuffer (to show it in a window).
  unsigned colour_texture() const;
  unsigned framebuffer() const;
  int width() const;
  int height() const;

 private:
  struct Impl;
  explicit FrameRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// RGBA (top row first) → the run mask of pixels whose alpha is 0.
RunMask blackout_of(std::span<const std::uint8_t> rgba, int width, int height);

// The thumbnail (RGB, top row first) of a frame read back bottom row first (RGBA, w x h) whose
// size is a whole multiple of it (1280x720 or 1920x1080 -> 160x90): each pixel the rounded mean
// of its block, what an area resize gives there. False (nothing written) when the sizes do not
// divide or a block is taller than 257 rows; FrameRenderer::read then resizes with OpenCV.
bool box_thumbnail(std::span<const std::uint8_t> rgba_bottom_up, int w, int h, int tw, int th,
                   std::vector<std::uint8_t>& out);

}  // namespace studio::projector_render
