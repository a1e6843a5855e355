#pragma once
// The studio cameras' colour balance as the live preview learns it (issue 16, beyond the paper):
// a real rig's cameras differ by a few percent per channel even after white balancing, and the
// blend of two or three of them (gl/actor_texturer.h) shows the difference as seams where the
// weights change and as a colour that shifts as the director's viewpoint moves. The estimate is
// offline/colour_balance.h's (the median log ratio of the colours two cameras see at the same
// surface points of the mesh, least squares over the camera graph, a geometric mean of 1 per
// channel), pooled over the frames the preview textures: each frame gives the pairs of its
// texturing cameras; as the viewpoint moves the graph fills in. Every pair keeps its newest
// `max_pair_samples` samples, so a camera whose exposure is changed during the session is
// followed within a few frames. The rig-level tolerance (ColourBalanceOptions::tolerance) leaves
// a rig whose cameras agree exactly as it is (all gains 1); balance_applies() below.
//
// Pure library: the node hands over the mesh and the images and masks of exactly the mesh's frame
// (the frame-exact rule, preview/node/view_pipeline.h).
#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "core/run_mask.h"
#include "offline/colour_balance.h"
#include "scene/actor_mesh.h"

namespace studio::preview {

// The preview's defaults: the offline estimate's rules, each pair's window bounded.
offline::ColourBalanceOptions rig_balance_defaults();

// One texturing camera's image (RGB8, top row first) and actor mask of the mesh's frame.
struct BalanceView {
  std::string camera;  // id, one of the rig's
  ImageView<const Rgb8> image;
  const RunMask* mask = nullptr;
};

// Whether the gains are applied: some camera's estimate beyond `tolerance` of 1 (any channel);
// once applied, until every camera is back within half of it. The live estimate moves from
// frame to frame: a rig near the tolerance would otherwise switch between balanced and not, a
// flicker of the tolerance's size; within half of it, it swaps for the drift of a balanced one.
bool balance_applies(const std::vector<Eigen::Vector3f>& estimated, double tolerance,
                     bool applied_before);
// The largest |gain - 1| over the cameras and channels of `estimated` (0 when empty).
float largest_gain_offset(const std::vector<Eigen::Vector3f>& estimated);
// The cameras the estimate links to some other camera (ColourBalance::linked_set >= 0).
int linked_cameras(const offline::ColourBalance& balance);

// What a RigBalance has estimated, copied out (for a thread other than the pooling one).
struct BalanceSnapshot {
  std::vector<std::string> cameras;  // the rig's ids, in the order of balance.gains
  offline::ColourBalance balance;
  double tolerance = 0;  // ColourBalanceOptions::tolerance of the estimate
  int min_frames = 0;    // frames pooled before the gains are applied (RigBalance's)
  // As RigBalance::gains.
  Eigen::Vector3f gains(const std::string& id) const;
  // The estimate for camera `id` (before the tolerance), 1 when not linked.
  Eigen::Vector3f estimated(const std::string& id) const;
};

class RigBalance {
 public:
  // The gains are applied only once `min_frames` frames are pooled: the first frames' estimate
  // strays (on agreeing cameras 3.7 % after 3 frames, within 0.5 % after 8 in
  // preview_quality_test), and a balance switched on and off again in the first second is a
  // flicker the director sees.
  explicit RigBalance(const offline::ColourBalanceOptions& options = rig_balance_defaults(),
                      int min_frames = 8);

  // Pools one frame: `rig` the calibrated cameras (a change of the set of ids restarts the
  // pooling; new calibrations of the same cameras do not),
  // `mesh` the actor of the frame, `views` the cameras whose image and mask of that frame are at
  // hand (two or more give samples). Then re-solves. Fails (nothing pooled) on a view of a camera
  // outside `rig` or whose image or mask size differs from its calibration.
  Expected<void> add(const std::map<std::string, Camera>& rig, const scene::ActorMesh& mesh,
                     const std::vector<BalanceView>& views);
  // Factors (R, G, B) for camera `id`'s 8-bit colours: 1 for a camera not yet linked to another,
  // while fewer than min_frames are pooled or while the rig is within the tolerance.
  Eigen::Vector3f gains(const std::string& id) const;
  // The latest solution (per camera id of the rig, in the rig's order) and its statistics.
  const std::vector<std::string>& cameras() const { return ids_; }
  const offline::ColourBalance& balance() const { return balance_; }
  const offline::ColourBalanceOptions& options() const { return options_; }
  BalanceSnapshot snapshot() const { return {ids_, balance_, options_.tolerance, min_frames_}; }

 private:
  offline::ColourBalanceOptions options_;
  int min_frames_;
  std::vector<std::string> ids_;
  std::vector<Camera> rig_;  // calibrations of ids_ (the latest given)
  std::optional<offline::ColourBalanceEstimator> estimator_;
  offline::ColourBalance balance_;
};

}  // namespace studio::preview
