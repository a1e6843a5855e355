#pragma once
// A synthetic studio for tests and benchmarks: N cameras on a ring looking at the acting area,
// a planar target at known poses (one origin frame, some floor frames, the rest in the air,
// plus held-out frames), exact projections with the paper's radial model, Gaussian pixel noise
// and optional gross outliers. A view is kept when the camera sees the target's face at less
// than 75° from its normal and every point lands inside the image; poses are redrawn until >= 3 cameras see the target.

#include <cstdint>
#include <vector>

#include "calibrate/observations.h"
#include "calibrate/target.h"
#include "core/camera.h"

namespace studio::calibrate {

struct SyntheticStudioOptions {
  int cameras = 8;
  int frames = 12;          // solved frames: 1 origin + floor_frames + the rest free
  int floor_frames = 4;
  int heldout_frames = 3;   // extra frames flagged held-out (the first on the floor, see below)
  bool heldout_floor_frame = true;  // the first held-out frame lies on the floor
  double noise_rms_px = 0.2;  // RMS length of the 2-D pixel noise (σ per axis = this / √2)
  int outliers = 0;         // observations moved by 5-20 px
  int width = 704, height = 576;
  double ring_radius_m = 2.5;  // horizontal distance of the cameras from the acting area
  std::uint32_t seed = 1;
  TargetSpec target;        // default: grid 10x10, 0.1 m (100 points, ~1 m)
};

struct SyntheticStudio {
  std::vector<Camera> cameras;                  // the truth
  std::vector<Rigid3> world_from_target;        // per frame, the truth
  std::vector<Eigen::Vector3d> target_points;
  Observations observations;
};

SyntheticStudio make_synthetic_studio(const SyntheticStudioOptions& options);

}  // namespace studio::calibrate
