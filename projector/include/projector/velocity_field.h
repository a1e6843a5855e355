#pragma once
// The last motion fit's velocities as a field over space, for late latching (issues 15 and 20:
// a new actor mesh is drawn before its own motion is fitted, moved forward by the velocities of
// the previous fit; projector/mask_planner.h latch_mesh()).
//
// Built once per fit (off the critical path) from the fitted mesh and its MeshMotion
// (projector/motion.h): voxel cells of `cell_m` (the fit's region size) over the fitted mesh's
// bounding box, 1 cell of border; each cell holds the region that most of the fitted mesh's
// vertices in it belong to (MeshMotion::vertex_region). A cell with no vertex takes, among its 26
// neighbours, the one holding most vertices (the border cells included), else it stays empty.
//
// Lookup of a point p of a NEWER mesh, captured `since_s` after the fitted one: the field
// describes the surface where it was at the fitted capture, so p is looked up where it was then,
// p - v since_s, with v from a first lookup at p (one fixed-point step). Outside the box or in an
// empty cell: the whole mesh's velocity (MeshMotion::global_velocity). O(1) per point: two
// array lookups.
//
// What this cannot see (the margin's job, projector/mask_margin.h velocity_age_s): the velocity
// is the mean over the fit's two captures, so for a point at the newer capture it is
// (since_s + dt/2) old; a part that changed speed in that time is off by a * age.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "core/error.h"
#include "projector/actor_mesh.h"
#include "projector/motion.h"

namespace studio::projector {

class VelocityField {
 public:
  // Errors: a motion that is not this mesh's (vertex counts differ), a cell size not in
  // [1 mm, 10 m], an empty mesh.
  static Expected<VelocityField> create(const ActorMesh& fitted, const MeshMotion& motion,
                                        double cell_m);

  // The velocity (m/s) at p of a mesh captured since_s after the fitted mesh.
  Eigen::Vector3f at(const Eigen::Vector3f& p, double since_s) const;
  // The velocity of every vertex of `mesh` that a triangle uses (others: zero), since_s from the
  // capture times. Errors: mesh captured before the fitted one.
  Expected<std::vector<Eigen::Vector3f>> at(const ActorMesh& mesh) const;

  std::int64_t capture_ns() const { return capture_ns_; }

 private:
  VelocityField() = default;
  int cell_of(const Eigen::Vector3f& p) const;  // -1 outside the box
  float inv_cell_ = 1;
  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  Eigen::Vector3i size_ = Eigen::Vector3i::Zero();
  std::vector<int> cell_region_;           // per cell: region index, -1 empty
  std::vector<Eigen::Vector3f> velocity_;  // per region
  Eigen::Vector3f global_ = Eigen::Vector3f::Zero();
  std::int64_t capture_ns_ = 0;
};

// The mesh moved forward by per-vertex velocities over horizon_s (same triangles). Errors: a
// velocity count that is not the mesh's vertex count, a negative or non-finite horizon.
Expected<ActorMesh> predict_by_velocities(const ActorMesh& mesh,
                                          std::span<const Eigen::Vector3f> velocities,
                                          double horizon_s);

}  // namespace studio::projector
