#include "truth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "capture/sim_source.h"
#include "core/look_at.h"
#include "sim/projector_light.h"
#include "sim/studio.h"
#include "support/masks.h"
#include "testing/raster.h"

namespace studio::demo {

struct TruthScorer::Impl {
  sim::SimulatedStudio studio;
};

TruthScorer::TruthScorer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TruthScorer::TruthScorer(TruthScorer&&) noexcept = default;
TruthScorer& TruthScorer::operator=(TruthScorer&&) noexcept = default;
TruthScorer::~TruthScorer() = default;

Expected<TruthScorer> TruthScorer::create(std::vector<Camera> cameras) {
  // The scene every `source: {type: sim}` camera renders (capture_config.cc sets no studio
  // options, so SimSourceOptions's defaults are the scene).
  const sim::StudioOptions scene = capture::SimSourceOptions{}.studio;
  auto studio = sim::SimulatedStudio::create(std::move(cameras), scene);
  if (!studio) return std::unexpected(studio.error());
  return TruthScorer(std::make_unique<Impl>(Impl{std::move(*studio)}));
}

MeshScore TruthScorer::score_meshes(uint64_t frame, const std::vector<hull::Mesh>& meshes) const {
  MeshScore score;
  score.frame = frame;
  score.min_iou = std::numeric_limits<double>::infinity();
  const auto& cams = impl_->studio.cameras();
  // The geometric silhouette cast from the true body: the same pixels as the true mask that
  // render() makes beside the camera's image (truth_test.cc), without rendering the image.
  const sim::ActorBody body = impl_->studio.truth(int64_t(frame)).body;
  double sum = 0;
  for (int i = 0; i < int(cams.size()); ++i) {
    const Mask truth = sim::actor_in_projector(cams[i], body);
    Mask drawn(cams[i].width, cams[i].height, 0);
    for (const hull::Mesh& m : meshes) {
      const Mask one = hull::testing::rasterise(m, cams[i]);
      auto& d = drawn.pixels();
      const auto& o = one.pixels();
      for (std::size_t k = 0; k < d.size(); ++k) d[k] |= o[k];
    }
    const double iou = support::iou(drawn, truth);
    sum += iou;
    if (iou < score.min_iou) {
      score.min_iou = iou;
      score.worst_camera = cams[i].id;
    }
  }
  score.mean_iou = cams.empty() ? 0 : sum / double(cams.size());
  return score;
}

Eigen::Vector3d TruthScorer::true_head(uint64_t frame) const {
  return impl_->studio.truth(int64_t(frame)).head_centre();
}

Eigen::Vector3d TruthScorer::true_head_at(double studio_frame) const {
  const double f = std::max(studio_frame, 0.0);
  const auto f0 = uint64_t(std::floor(f));
  const double t = f - double(f0);
  const Eigen::Vector3d a = true_head(f0);
  return t > 0 ? Eigen::Vector3d(a + t * (true_head(f0 + 1) - a)) : a;
}

double TruthScorer::head_error(uint64_t frame, const Eigen::Vector3d& position) const {
  return (position - true_head(frame)).norm();
}

Expected<TruthScorer::Lit> TruthScorer::projector_lit(const Camera& projector, double studio_frame,
                                                      double display_lag_s, const RunMask& blackout,
                                                      Mask* actor_out) const {
  if (blackout.width() != projector.width || blackout.height() != projector.height)
    return fail("projector frame " + std::to_string(blackout.width()) + "x" +
                std::to_string(blackout.height()) + " is not the projector's " +
                std::to_string(projector.width) + "x" + std::to_string(projector.height));
  sim::DisplayOptions display;
  display.display_lag_s = display_lag_s;
  if (auto ok = display.validate(); !ok) return std::unexpected(ok.error());
  const double t = studio_frame / impl_->studio.options().fps;
  Mask actor = sim::actor_at_display(impl_->studio.actor(), projector, t, display);
  const sim::LitCount n = sim::count_lit(actor, blackout);
  if (actor_out) *actor_out = std::move(actor);
  return Lit{n.actor, n.lit_actor, n.blackout, n.wasted};
}

Expected<Image<Rgb8>> TruthScorer::actor_view(const Projector& projector, double studio_frame,
                                              double display_lag_s, Image<Rgb8> frame, int width,
                                              int height) const {
  if (frame.width() != projector.camera.width || frame.height() != projector.camera.height)
    return fail("actor view: the frame is not of the projector's size");
  if (width < 16 || height < 16) return fail("actor view: image too small");
  const double t = studio_frame / impl_->studio.options().fps + display_lag_s;
  const sim::ActorBody body = impl_->studio.actor().body_at(t);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double back = 0;
  for (const Eigen::Vector3d& c : projector.screen) {
    centre += c / 4;
    back = std::max(back, std::abs(c.z()));
  }
  Camera eye;
  eye.id = "actor_eye";
  eye.width = width;
  eye.height = height;
  const double f = 0.5 * width / std::tan(0.5 * 100.0 * M_PI / 180);
  eye.intrinsics = {f, f, 0.5 * (width - 1), 0.5 * (height - 1), 0};
  eye.cam_from_world = look_at(body.head_centre(), centre);
  sim::ProjectorLight light;
  light.projectors.push_back({projector, std::move(frame)});
  if (auto ok = light.validate(); !ok) return std::unexpected(ok.error());
  sim::Cyclorama cyc;
  if (back > 0.5) cyc.half_width = back;
  return sim::eye_view(light, cyc, eye, &body).image;
}

}  // namespace studio::demo
