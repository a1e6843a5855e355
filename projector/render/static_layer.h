#pragma once
// The projector's cached static scene layer (issue 15: render the scene only when it changes):
// the static part of the scene as the projector frame shows it (single pass: the projector
// target; two pass: the eye texture), colour + depth, kept in a render target of its own with
// the eye it was drawn from, the static scene's version and the heights above the screen plane
// of the static points it shows (from its depth buffer, projector/static_shift.h). A later frame
// restores it (one framebuffer blit of colour and depth) instead of drawing the static scene
// again while the version is the same and StaticShiftBound::shift_px(heights, cached eye, eye)
// stays within SceneCacheOptions::max_error_px. Needs the GL context the targets were made in.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/error.h"
#include "projector/static_shift.h"
#include "scene_render/render_target.h"

namespace studio::projector_render {

class StaticLayer {
 public:
  // `width` x `height`: the layer's target (the projector's, or the eye texture's).
  static Expected<StaticLayer> create(const projector::ProjectorView& view,
                                      const projector::OffAxisOptions& off_axis,
                                      const projector::SceneCacheOptions& options, int width,
                                      int height);

  // The displacement bound (px) of the cached layer at `eye` for this static version; +inf when
  // nothing is cached or the version differs.
  double shift_px(std::uint64_t version, const Eigen::Vector3d& eye) const;
  bool usable(std::uint64_t version, const Eigen::Vector3d& eye) const {
    return shift_px(version, eye) <= options_.max_error_px;
  }
  // Whether the layer may serve the next frame whatever the eye's move (the version is the
  // same and fewer than SceneCacheOptions::hold_frames frames have restored it since it was
  // drawn).
  bool holds(std::uint64_t version) const {
    return valid_ && version == version_ && served_ < options_.hold_frames;
  }
  // Copies the cached colour and depth into `into` (same size), which is left bound; counts one
  // frame served.
  void restore(const scene_render::RenderTarget& into);

  // How the depth of the layer maps to the eye's view distance: `eye_clip_from_world` is the
  // eye's off-axis projection; `projector_clip_from_world` the single pass's (its depth is the
  // eye's NDC z divided by k = w'/w, projector/projector_view.h), none for the eye texture.
  struct DepthModel {
    Eigen::Matrix4d eye_clip_from_world;
    std::optional<Eigen::Matrix4d> projector_clip_from_world;
    double near = 0.05, far = 100;
    // GL window box read (x, y from the bottom left, width, height).
    std::array<int, 4> box{0, 0, 0, 0};
  };
  // Keeps `from`'s colour and depth (the static scene just drawn from `eye`) as the layer and
  // reads the heights of the points it shows from its depth (a new layer: no frame served).
  // `from` is left bound.
  void store(const scene_render::RenderTarget& from, std::uint64_t version,
             const Eigen::Vector3d& eye, const DepthModel& model);
  void invalidate() { valid_ = false; }
  bool valid() const { return valid_; }
  std::uint64_t version() const { return version_; }

  const projector::HeightRange& heights() const { return heights_; }
  const projector::StaticShiftBound& bound() const { return bound_; }
  const projector::SceneCacheOptions& options() const { return options_; }

 private:
  StaticLayer(projector::StaticShiftBound bound, projector::SceneCacheOptions options,
              scene_render::RenderTarget target, const projector::ProjectorView& view);
  projector::StaticShiftBound bound_;
  projector::SceneCacheOptions options_;
  scene_render::RenderTarget target_;
  projector::Screen screen_;
  Eigen::Matrix3d screen_from_pixel_;
  int projector_height_ = 0;
  bool valid_ = false;
  std::uint64_t version_ = 0;
  int served_ = 0;  // frames restored from this layer since it was drawn
  Eigen::Vector3d eye_ = Eigen::Vector3d::Zero();
  projector::HeightRange heights_;
  std::vector<float> depth_;
};

}  // namespace studio::projector_render
