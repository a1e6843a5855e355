#pragma once
// Test and benchmark support: rasterised primitives and a stick-figure actor (head ball on a
// neck, torso, shoulders, arms, legs) with its true head centre, for exercising the head tracker
// without the visual hull. Not part of the tracker library.

#include <Eigen/Core>

#include "tracker/occupancy.h"

namespace studio::tracker::testing {

// Adds the shape to the grid: each voxel takes max(current, covered fraction), the fraction
// estimated with 4x4x4 samples.
void add_sphere(OccupancyGrid& grid, const Eigen::Vector3d& centre, double radius);
void add_capsule(OccupancyGrid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 double radius);
void add_box(OccupancyGrid& grid, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

struct SyntheticActor {
  Eigen::Vector2d floor_xz = Eigen::Vector2d::Zero();  // where the actor stands
  double height = 1.75;                                // top of the head, standing
  double head_radius = 0.10;
  double crouch = 0;         // 0 standing .. 1 deep crouch (head at ~60 % height)
  bool hand_raised = false;  // right hand straight up, well above the head
  double yaw = 0;            // radians about +y

  Eigen::Vector3d head_centre() const;
  Eigen::Vector3d raised_hand_centre() const;
};

void add_actor(OccupancyGrid& grid, const SyntheticActor& actor);

}  // namespace studio::tracker::testing
