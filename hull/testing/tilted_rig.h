#pragma once
// The "real rig" of issue 18 for tests and benchmarks: many cameras at several heights, tilted
// down 10-40 degrees, some rolled, around an acting position, and a loose reconstruction box
// three times the actor's size with the actor far from its centre. Not part of the library.

#include <Eigen/Core>
#include <vector>

#include "core/camera.h"
#include "hull/segment_set.h"

namespace studio::hull::testing {

struct TiltedRigOptions {
  int count = 20;
  int width = 1024, height = 768;
  double focal_px = 820;  // ~64 degrees across 1024 px
};

// `count` pinhole cameras cam0.. around the vertical axis through `centre` (x, z of the actor;
// its y is ignored): azimuth 360/count apart (jittered), heights 0.9 / 1.7 / 2.5 / 3.3 m in turn,
// horizontal distance 3.3-4.35 m, tilted down 10-40 degrees (higher cameras more), every third
// camera rolled +6 degrees and every fifth -9.
std::vector<Camera> tilted_rig(const Eigen::Vector3d& centre, const TiltedRigOptions& options = {});

// A loose box `factor` times the actor's bounds [lo, hi] along every axis, the actor in its
// lower (x, y, z)-min corner (a margin of 5 % of its size), columns along y, n x n.
GridSpec loose_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double factor, int n);

// The tight box: the actor's bounds with a margin of `margin` metres on every side.
GridSpec tight_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double margin, int n);

}  // namespace studio::hull::testing
