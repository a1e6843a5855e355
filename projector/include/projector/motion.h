#pragma once
// How the actor mesh moves between two consecutive hull meshes, and the mesh moved forward to the
// moment the projector frame is shown ("beyond the paper": TCSVT 2004 §V-D only enlarges the mask
// by a security margin; predicting the motion lets that margin stay small).
//
// Choice of motion model. Hull meshes (segment marching cubes) share no vertices from frame to
// frame, so there is no correspondence to difference. Plain nearest-neighbour matching of vertices
// only sees the motion along the surface normal and under-estimates it once the displacement per
// frame approaches the local radius of curvature (a forearm of 4-5 cm radius moving 6 cm per
// frame at 1.5 m/s and 25 fps), so it is not used. A rigid or affine fit per body part needs the
// parts, which the hull does not give. Instead:
// 1. The current mesh is cut into regions (cells of a voxel grid of region_size_m), small enough
//    for an articulated body (a hand, a forearm, the head each get their own) and large enough to
//    hold the dozens of vertices that make a 3x3 fit well posed.
// 2. Each region gets one translation by point-to-plane ICP against the previous mesh
//    (correspondence: the closest point on the previous triangles around the nearest previous
//    vertex, with that triangle's normal: no bias from tessellations that differ between
//    frames), started from and damped towards the whole mesh's ICP translation.
// 3. Point-to-plane only sees a region's motion along its normals. Along the directions it sees
//    (eigenvectors of sum n n^T with >= weak_direction of the largest eigenvalue) the region keeps
//    its own estimate; the others come from the smallest enclosing cell (2, 4, 8 ... region sizes,
//    then the whole mesh) whose regions together see every direction and agree on one translation
//    (information-weighted, disagreement <= consistency_m): the faces of a moving box move with
//    its edges and corners, and the predicted mesh does not fold. A cell that holds a moving hand
//    and a still torso disagrees and lends nothing: those directions then stay still, which moves
//    no part of the silhouette (sliding over a surface does not change it).
// 4. A region too small to fit takes the nearest fitted region's velocity (within 1.5 region
//    sizes), else the whole mesh's. No blending across regions, so a moving hand does not drag a
//    still torso along (limitation: parts closer than one region size share a cell and get one
//    mixed velocity).
//
// Cost (the projector renders every 25 Hz mesh): each fit runs on a fixed budget of vertices,
// not on all of them: the whole-mesh fit on global_fit_vertices, each region's on fit_vertices,
// both a stratified sample (every k-th vertex in mesh order: the hull's marching cubes emit
// vertices slice by slice, so a stride spreads the sample over the region). A fit's information
// (sum n n^T) is scaled by members / sample so regions keep the weights of their full size when
// cells combine them. The previous mesh's correspondence structure (vertex grid, triangles per
// vertex, face normals) is built once, when that mesh arrives, and kept by MotionTracker.
//
// Velocity of a region = its translation / dt (the mean velocity over the two captures); its
// acceleration = the change since the previous estimate of the velocity of the region that,
// moved by its velocity, lands nearest, divided by the time between the two mean velocities.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/error.h"
#include "projector/actor_mesh.h"

namespace studio::projector {

struct MotionOptions {
  double region_size_m = 0.15;
  int iterations = 15;            // ICP iterations per region (and for the whole mesh), at most
  double converged_m = 1e-5;      // an ICP step shorter than this ends the fit
  int fit_vertices = 24;          // vertices per region fit (stratified sample); 0: all
  int global_fit_vertices = 300;  // vertices of the whole-mesh fit; 0: all
  double max_correspondence_m = 0.25;  // no previous vertex nearer than this: vertex ignored
  // Damping of each region's fit towards no motion, relative to the region's
  // information (trace of sum n n^T / 3): small, it only steers directions the region cannot see.
  double damping = 1e-3;
  // A direction a region (or coarser cell) sees with less than this fraction of its strongest
  // direction's information is taken from the coarser cell around it.
  double weak_direction = 0.05;
  // Regions of one cell "agree" when their translations differ by less than this RMS (metres
  // per mesh interval, weighted by what each sees).
  double consistency_m = 0.005;
  int min_region_vertices = 12;  // smaller regions take the whole-mesh translation
  double max_dt_s = 0.5;         // meshes further apart are not compared (motion unknown)
  // MotionTracker: the acceleration the margin uses is the median of the last this many
  // estimates' max_acceleration_mps2 (1: the latest alone). The largest region acceleration is a
  // second difference of noisy fits, maximised over ~50 regions: on hull meshes with a few mm
  // of surface noise it jumps to 15-35 m/s^2 from frame to frame where the simulated arm swing's
  // true peak is ~5 m/s^2 (projector/margin_noise_test.cc). A true acceleration lasts: an arm
  // swing's acceleration phase spans 5-10 frames at 25 Hz, so the median of 5 keeps it while
  // a spike in one frame is dropped; two consecutive estimates above the median are taken at
  // once (a projector that keeps up with only a few meshes a second sees an onset in 2-3).
  int acceleration_window = 5;
  Expected<void> validate() const;
};

struct RegionMotion {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();    // centroid of its vertices, current mesh
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s
  int vertices = 0;
  double rms_m = 0;     // point-to-plane residual RMS after the fit
  bool fitted = false;  // false: too few vertices, velocity taken from the nearest fitted region
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // mean unit vertex normal (not normalised)
  std::optional<Eigen::Vector3d> acceleration;  // m/s^2, when the previous estimate had a match
};

struct MeshMotion {
  double dt_s = 0;  // time between the two meshes
  std::vector<RegionMotion> regions;
  std::vector<int> vertex_region;  // per vertex of the current mesh
  Eigen::Vector3d global_velocity = Eigen::Vector3d::Zero();
  double max_speed_mps = 0;  // over regions
  // Over regions with an acceleration, the component along the region's mean normal (the full
  // vector where the region has no dominant normal, |mean normal| < 0.5).
  std::optional<double> max_acceleration_mps2;
  // MotionTracker only: the median of the last acceleration_window max_acceleration_mps2, or the
  // smaller of the last two when that is larger (an onset both agree on is not waited for; a
  // one-estimate spike is dropped): the margin's acceleration, projector/mask_margin.h; unset
  // from estimate_motion.
  std::optional<double> robust_acceleration_mps2;
  // What the fit cost: closest-point queries against the previous mesh, ICP fits (the whole
  // mesh's and the regions') and their iterations.
  int64_t closest_queries = 0;
  int fits = 0, iterations = 0;
  Eigen::Vector3f velocity(size_t vertex) const {
    return regions[vertex_region[vertex]].velocity.cast<float>();
  }
};

// The motion from `previous` to `current` (velocities at current's vertices). Errors: invalid
// options or meshes, capture times not increasing or further apart than max_dt_s.
Expected<MeshMotion> estimate_motion(const ActorMesh& previous, const ActorMesh& current,
                                     const MotionOptions& options = {});

// Keeps the last mesh and motion of one actor; every new mesh yields its motion (with
// accelerations from the previous estimate). The first mesh, or one after a gap longer than
// max_dt_s or a rejected mesh, yields no motion (std::nullopt): the margin then falls back to
// the no-prediction term.
// The previous mesh as ICP's target (grid, triangles per vertex, face normals), built once.
class MotionTarget;

class MotionTracker {
 public:
  explicit MotionTracker(MotionOptions options = {});
  ~MotionTracker();
  MotionTracker(MotionTracker&&) noexcept;
  MotionTracker& operator=(MotionTracker&&) noexcept;
  Expected<std::optional<MeshMotion>> update(const ActorMesh& mesh);
  void reset();

 private:
  MotionOptions options_;
  std::unique_ptr<MotionTarget> last_;  // the last mesh and its target structure
  std::optional<MeshMotion> last_motion_;
  std::vector<double> accelerations_;  // the last acceleration_window estimates, oldest first
};

// The mesh moved forward by its velocity field over horizon_s (constant velocity; the
// acceleration is left to the margin, projector/mask_margin.h). Same triangles. Fails when the
// motion is not this mesh's (vertex count differs) or the horizon is negative or not finite.
Expected<ActorMesh> predict(const ActorMesh& mesh, const MeshMotion& motion, double horizon_s);

}  // namespace studio::projector
