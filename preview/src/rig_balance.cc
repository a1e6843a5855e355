#include "preview/rig_balance.h"

#include <algorithm>

namespace studio::preview {

offline::ColourBalanceOptions rig_balance_defaults() {
  offline::ColourBalanceOptions o;
  // A pair shares a few hundred samples per frame of a 96-cell live hull at 352x288 (in process
  // 2 618 vertices seen by two cameras over 10 frames): the window holds the last few dozen
  // frames that pair was textured in (a 1.5 dB gain change half taken up 1.5-4 s after it,
  // preview_studio_test).
  o.max_pair_samples = 8192;
  // The live estimate strays further from 1 on cameras that agree than the offline one (fewer
  // frames, the coarse live hull, which poses the run sees): 0.2-1.8 % in 10 runs of 30 meshes
  // of preview_studio_test's identical rig, 0.5 % in process, but up to 3.8-4.1 % as the window
  // fills over longer runs (every mesh pooled for 8 s: 2 of 6 runs drifted there and a 3 %
  // tolerance applied gains on cameras that agree; at 5 %, 0 of 8, largest 2.8 %). A difference
  // within the estimate's own error is not one to correct.
  o.tolerance = 0.05;
  return o;
}

float largest_gain_offset(const std::vector<Eigen::Vector3f>& estimated) {
  float off = 0;
  for (const Eigen::Vector3f& g : estimated) off = std::max(off, (g.array() - 1).abs().maxCoeff());
  return off;
}

int linked_cameras(const offline::ColourBalance& balance) {
  return int(std::count_if(balance.linked_set.begin(), balance.linked_set.end(),
                           [](int set) { return set >= 0; }));
}

bool balance_applies(const std::vector<Eigen::Vector3f>& estimated, double tolerance,
                     bool applied_before) {
  return largest_gain_offset(estimated) > (applied_before ? 0.5 : 1.0) * tolerance;
}

RigBalance::RigBalance(const offline::ColourBalanceOptions& options, int min_frames)
    : options_(options), min_frames_(min_frames) {}

Expected<void> RigBalance::add(const std::map<std::string, Camera>& rig,
                               const scene::ActorMesh& mesh,
                               const std::vector<BalanceView>& views) {
  if (auto ok = options_.validate(); !ok) return ok;
  std::vector<std::string> ids;
  for (const auto& [id, c] : rig) ids.push_back(id);
  if (ids != ids_ || !estimator_) {
    ids_ = std::move(ids);
    estimator_.emplace(ids_.size(), options_);
    balance_ = {};
    balance_.gains.assign(ids_.size(), Eigen::Vector3f::Ones());
    balance_.estimated = balance_.gains;
  }
  rig_.clear();
  for (const auto& [id, c] : rig) rig_.push_back(c);
  std::vector<offline::ColourView> cv(ids_.size());  // absent: all empty
  for (const BalanceView& v : views) {
    const auto at = std::lower_bound(ids_.begin(), ids_.end(), v.camera);
    if (at == ids_.end() || *at != v.camera)
      return fail("colour balance: camera " + v.camera + " is not calibrated");
    const std::size_t i = std::size_t(at - ids_.begin());
    if (!v.mask) return fail("colour balance: camera " + v.camera + " without a mask");
    cv[i] = {&rig_[i], v.image, v.mask};
  }
  hull::Mesh m;
  m.vertices = mesh.vertices;
  m.triangles = mesh.triangles;  // normals: the estimate computes its own
  if (auto ok = estimator_->add(m, cv); !ok) return ok;
  const bool was_applied = balance_.applied;
  balance_ = estimator_->solve();
  balance_.applied = balance_.frames >= min_frames_ &&  // not before: see the constructor
                     balance_applies(balance_.estimated, options_.tolerance, was_applied);
  balance_.gains = balance_.applied
                       ? balance_.estimated
                       : std::vector<Eigen::Vector3f>(ids_.size(), Eigen::Vector3f::Ones());
  return {};
}

namespace {

// The entry of `id` among `ids` (sorted) in `per_camera`, 1 when absent.
Eigen::Vector3f gains_of(const std::vector<std::string>& ids,
                         const std::vector<Eigen::Vector3f>& per_camera, const std::string& id) {
  const auto at = std::lower_bound(ids.begin(), ids.end(), id);
  if (at == ids.end() || *at != id) return Eigen::Vector3f::Ones();
  const std::size_t i = std::size_t(at - ids.begin());
  return i < per_camera.size() ? per_camera[i] : Eigen::Vector3f::Ones();
}

}  // namespace

Eigen::Vector3f RigBalance::gains(const std::string& id) const {
  return gains_of(ids_, balance_.gains, id);
}

Eigen::Vector3f BalanceSnapshot::gains(const std::string& id) const {
  return gains_of(cameras, balance.gains, id);
}

Eigen::Vector3f BalanceSnapshot::estimated(const std::string& id) const {
  return gains_of(cameras, balance.estimated, id);
}

}  // namespace studio::preview
