#include "testing/sim_rig.h"

#include <cmath>

#include "sim/studio.h"

namespace studio::hull::testing {

sim::ActorBody sim_actor_body(const sim::Actor::Options& actor, int64_t frame) {
  sim::StudioOptions defaults;
  return sim::Actor(actor).body_at(double(frame) / defaults.fps);
}

void bounds(const sim::ActorBody& body, Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  body.bounds(lo, hi);
}

std::vector<View> SimFrame::views() const {
  std::vector<View> v;
  for (std::size_t k = 0; k < cameras.size(); ++k) v.push_back({&cameras[k], &masks[k]});
  return v;
}

SimFrame render_sim(const sim::Actor::Options& actor, int64_t frame, std::vector<Camera> cameras) {
  SimFrame out;
  sim::StudioOptions so;
  so.actor = actor;
  auto studio = sim::SimulatedStudio::create(cameras, so);
  if (!studio) return out;
  out.cameras = std::move(cameras);
  studio->render_all(frame, nullptr, &out.truth);
  for (const Mask& m : out.truth) out.masks.push_back(RunMask::from_mask(m.view()));
  return out;
}

VoxelCarve::VoxelCarve(const std::vector<Camera>& cameras, const std::vector<Mask>& masks,
                       int min_views) {
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    P_.push_back(cameras[k].projection_matrix());
    masks_.push_back(&masks[k]);
  }
  need_ = min_views == kAllViews ? int(cameras.size()) : min_views;
}

bool VoxelCarve::keeps(const Eigen::Vector3d& x) const {
  int seen = 0;
  for (std::size_t c = 0; c < P_.size(); ++c) {
    const Eigen::Matrix<double, 3, 4>& P = P_[c];
    const double w = P(2, 0) * x[0] + P(2, 1) * x[1] + P(2, 2) * x[2] + P(2, 3);
    if (!(w > 0)) continue;
    const double u = (P(0, 0) * x[0] + P(0, 1) * x[1] + P(0, 2) * x[2] + P(0, 3)) / w;
    const double v = (P(1, 0) * x[0] + P(1, 1) * x[1] + P(1, 2) * x[2] + P(1, 3)) / w;
    const Mask& m = *masks_[c];
    const double iu = std::floor(u + 0.5), iv = std::floor(v + 0.5);
    if (!(iu >= 0 && iv >= 0 && iu < m.width() && iv < m.height())) continue;
    ++seen;
    if (m(int(iu), int(iv)) == 0) return false;  // the first camera that can reject does
  }
  return seen >= need_;
}

std::size_t VoxelCarve::carve(const GridSpec& box, int n) const {
  const Eigen::Vector3d step = (box.box_max - box.box_min) / n;
  std::size_t occupied = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d x(box.box_min.x() + (i + 0.5) * step.x(),
                                box.box_min.y() + (j + 0.5) * step.y(),
                                box.box_min.z() + (k + 0.5) * step.z());
        occupied += keeps(x);
      }
  return occupied;
}

}  // namespace studio::hull::testing
