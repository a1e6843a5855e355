#pragma once
// Camera placements that tests and benchmarks repeat (one copy; tests/support, linked only by
// tests and benchmarks). The pose comes from core/look_at.h, which sim/ and calibrate/ use too.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"

namespace studio::support {

// A pinhole camera `id` of width x height pixels at `centre` looking at `target`, `up` appearing
// up; focal length focal_px on both axes, principal point at the image centre ((w-1)/2, (h-1)/2).
Camera look_at_camera(const std::string& id, const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& target, const Eigen::Vector3d& up, int width,
                      int height, double focal_px,
                      const Distortion& distortion = Distortion::none());

// n cameras "cam0".."cam<n-1>" evenly spaced on a horizontal ring of `radius` around `target`
// (azimuth of camera k: 2π (k + 1/4) / n from +x towards +z) at height height_m, looking at
// `target` with y up.
std::vector<Camera> camera_ring(int n, int width, int height, double radius, double height_m,
                                const Eigen::Vector3d& target, double focal_px,
                                const Distortion& distortion = Distortion::none());

// Writes `cameras` as a rig.yaml (yaml_io/rig_yaml.h) at `path`: what every test that starts a
// service or a CLI with --rig does first.
Expected<void> write_rig_yaml(const std::vector<Camera>& cameras, const std::filesystem::path& path);

}  // namespace studio::support
