#pragma once
// Per-camera colour balance for the photo-consistency test and the texture blend (beyond the
// paper). A real rig's cameras differ in exposure, aperture and white balance by a few percent
// per channel even after white balancing; the carve's colour test allows a spread of 6 grey
// levels (CarveOptions::threshold), so a camera 5 % brighter than its neighbours disagrees with
// them on every bright surface point and the carve removes the true surface. The texture blend
// shows the same difference as seams where the most frontal camera changes.
//
// Estimated from the frame itself, no chart needed: every surface point of a mesh (the visual
// hull) seen by two cameras under the carve's spill rules (in front, facing at cos >= min_cos,
// not hidden by the mesh, sampled edge_margin_px inside the silhouette) at similar angles gives,
// per camera pair and channel, the log ratio of their colours. Per pair the median of those ratios
// (phantom points of the hull see different surfaces in the two cameras, albedo edges and the
// cameras' own ring-light tint differ both ways: the median keeps the common factor); the gains are
// the least-squares solution of the pairwise medians over the camera graph, weighted by the pairs'
// sample counts, per connected set of cameras with a geometric mean of 1 per channel (the rig's
// average response). A linear gain in the sensor is a factor in display values too (the power
// law of the display transfer keeps products), so the gains apply to the 8-bit colours directly.
// Cameras that share no surface with another (fewer than min_samples points) keep gain 1. The
// gains are applied only when some camera's estimate lies beyond the tolerance (below): a rig
// whose cameras agree is left as it is.

#include <Eigen/Core>
#include <array>
#include <span>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "offline/photo_carve.h"

namespace studio::offline {

struct ColourBalanceOptions {
  double min_cos = 0.5;           // the carve's facing test (grazing views carry spill)
  int edge_margin_px = 2;         // samples this far inside the silhouette (spill, edge)
  double depth_tolerance = 0.02;  // metres: visibility slack against the mesh's depth buffers
  // A point is compared between two cameras only where they see it at similar angles
  // (|cos_i - cos_j| <= this): each camera's own LED ring lights what faces it, and the spill
  // grows towards grazing views, so points seen frontally by one camera and obliquely by the
  // other are brighter (bluer) in the first by the viewing geometry, not by the camera.
  double max_cos_difference = 0.25;
  int min_samples = 30;    // per camera pair: fewer shared points, the pair is not used
  double min_level = 16;   // channel values below (noise dominates) or above (clipping)
  double max_level = 250;  // are not compared
  double max_gain = 2;     // estimated gains are clamped to [1 / max_gain, max_gain]
  // When every camera's estimated gains lie within 1 +- tolerance the rig is left as it is (all
  // gains 1): the estimate's own error on a rig whose cameras agree (the view-dependent light
  // above) is 0.8-1.5 % on most poses, and applying it cost the carve; otherwise every camera is
  // corrected (leaving the cameras within the tolerance alone left their few percent against the
  // corrected ones). 4 % (chosen on one drawn rig) left another mild rig's 3 % cameras
  // uncorrected and its carve 8 points worse; 2 % keeps every rig measured at its best
  // (docs/offline.md, "Colour balance between cameras").
  double tolerance = 0.02;
  // ColourBalanceEstimator: per camera pair and channel at most this many samples are pooled,
  // the newest (0: all). A frame's samples are always kept whole; older frames' are dropped
  // first. A live estimate (the preview's, pooled over the frames it draws) follows a camera
  // whose exposure or white balance is changed during the session, in bounded memory.
  std::size_t max_pair_samples = 0;
  int threads = 1;
  Expected<void> validate() const;
};

struct ColourBalance {
  // Per view (in the order given): multiply its colours by these (R, G, B) factors: the
  // estimate, or all 1 when the whole rig lies within the tolerance.
  std::vector<Eigen::Vector3f> gains;
  std::vector<Eigen::Vector3f> estimated;  // per view, before the tolerance
  bool applied = false;    // some camera beyond the tolerance: `gains` are the estimate
  std::size_t points = 0;  // mesh vertices seen by two or more cameras (over all frames)
  int frames = 0;          // frames pooled (ColourBalanceEstimator)
  int pairs = 0;           // camera pairs with >= min_samples shared points (the graph's edges)
  // Per view: the set of cameras it is linked with through those pairs, named by the smallest
  // view index in it; -1 for a camera linked to none (its estimate is 1). Gains of cameras in
  // different sets are not comparable (each set's geometric mean is 1 on its own).
  std::vector<int> linked_set;
  // Median over the used pairs and channels of |log ratio| after the gains: what is left
  // between cameras (0 for a consistent rig; the spread of the data otherwise).
  double residual = 0;
};

// The estimate pooled over several frames of a take (the cameras' responses are a property of
// the rig, not of a frame: one set of gains for the take leaves no frame-to-frame flicker, and
// the poses' view-dependent errors average): add() frames, then solve(). The views of every
// frame are the same cameras in the same order.
class ColourBalanceEstimator {
 public:
  explicit ColourBalanceEstimator(std::size_t cameras, const ColourBalanceOptions& options = {});
  // One frame's shared points. A view without a camera, image or mask (all of them null or
  // empty) takes no part in this frame (a camera whose image of the frame is not at hand: the
  // live preview has only the texturing cameras'). Fails (nothing added) on invalid options, a
  // view count other than `cameras`, or a view whose image or mask size differs from its camera.
  Expected<void> add(const hull::Mesh& mesh, std::span<const ColourView> views);
  // The same from the views' own hull over `grid` at no more than `columns` columns per axis.
  Expected<void> add(const hull::GridSpec& grid, std::span<const ColourView> views,
                     const hull::CutOptions& cut = {}, int columns = 128);
  // The gains from every frame added so far (all 1 before any).
  ColourBalance solve();

 private:
  std::size_t cameras_;
  ColourBalanceOptions options_;
  std::vector<std::array<std::vector<float>, 3>> ratios_;  // per camera pair and channel
  std::size_t points_ = 0;
  int frames_ = 0;
};

// One frame: ColourBalanceEstimator with that frame alone.
// Fails on invalid options, no views or a view whose image or mask size differs from its camera.
// `mesh` needs no normals (computed here). Independent of options.threads.
Expected<ColourBalance> estimate_colour_balance(const hull::Mesh& mesh,
                                                std::span<const ColourView> views,
                                                const ColourBalanceOptions& options = {});

// The same from the views' own visual hull over `grid`, cut at no more than `columns` columns
// per axis (the gains need surface points, not detail: 128 columns estimate them as well as 256
// at a quarter of the mesh; BENCHMARKS.md) with `cut`'s visibility policy and exact crossings.
Expected<ColourBalance> estimate_colour_balance(const hull::GridSpec& grid,
                                                std::span<const ColourView> views,
                                                const hull::CutOptions& cut = {}, int columns = 128,
                                                const ColourBalanceOptions& options = {});

// The views with their images multiplied by the gains (rounded, clamped to 0..255). `images`
// holds the new pixels (the returned views point into it: keep it alive and unmoved); a view
// whose gains are all exactly 1 keeps its own image.
std::vector<ColourView> apply_colour_balance(std::span<const ColourView> views,
                                             const ColourBalance& balance,
                                             std::vector<Image<Rgb8>>* images);

}  // namespace studio::offline
