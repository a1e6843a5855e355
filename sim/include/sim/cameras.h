#pragma once
// Virtual camera rigs for the simulated studio.

#include <vector>

#include "core/camera.h"

namespace studio::sim {

struct RingOptions {
  int count = 6;            // total cameras; the last one is overhead when overhead == true
  int width = 704;          // the paper's PAL frame
  int height = 576;
  bool overhead = true;
  double radius = 3.6;      // metres from the studio centre (outside the 3 m acting area)
  double height_m = 2.3;    // camera centre height
  double look_at_y = 1.1;   // the ring looks at (0, look_at_y, 0)
  double focal_px = 560;    // horizontal field of view about 64 degrees at 704 px
  double overhead_height = 5.0;
  double first_azimuth_deg = 0;  // azimuth of cam0, measured from +z towards +x
  Expected<void> validate() const;
};

// A camera at `centre` looking at `target`, image y pointing as close to world -y (down) as
// possible (for a camera looking straight down, image y points to world +z).
Rigid3 look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target);

// Pinhole cameras (no distortion) with ids cam0..cam<N-1>: count-1 (or count) on a ring around
// the acting area, evenly spaced in azimuth and looking at its centre, plus one overhead camera
// looking straight down (the paper's layout). Principal point at the image centre.
std::vector<Camera> ring_cameras(const RingOptions& options = {});

}  // namespace studio::sim
