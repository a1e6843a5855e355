#pragma once
// Pose chaining through shared frames: sensors (cameras, projectors) and frames (target poses)
// form a bipartite graph whose edges are measured sensor_from_frame poses. Starting from one
// gauge node, poses spread edge by edge (the edge with the largest weight first), so any
// connected graph gets a pose for every node; unreached nodes are reported by index.

#include <optional>
#include <vector>

#include "core/transform.h"

namespace studio::calibrate {

struct PoseEdge {
  int sensor = 0;
  int frame = 0;
  Rigid3 sensor_from_frame;
  double weight = 1;  // e.g. the number of points behind the measurement
};

struct PoseGauge {
  bool is_frame = true;  // the gauge node is a frame (else a sensor)
  int index = 0;
  Rigid3 pose;  // world_from_frame or sensor_from_world
};

struct ChainedPoses {
  std::vector<std::optional<Rigid3>> sensor_from_world;
  std::vector<std::optional<Rigid3>> world_from_frame;
  std::vector<int> unreached_sensors() const;
  std::vector<int> unreached_frames() const;
};

ChainedPoses chain_poses(int sensors, int frames, const std::vector<PoseEdge>& edges,
                         const PoseGauge& gauge);

}  // namespace studio::calibrate
