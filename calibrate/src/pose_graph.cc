#include "calibrate/pose_graph.h"

namespace studio::calibrate {

std::vector<int> ChainedPoses::unreached_sensors() const {
  std::vector<int> out;
  for (size_t i = 0; i < sensor_from_world.size(); ++i)
    if (!sensor_from_world[i]) out.push_back(static_cast<int>(i));
  return out;
}

std::vector<int> ChainedPoses::unreached_frames() const {
  std::vector<int> out;
  for (size_t i = 0; i < world_from_frame.size(); ++i)
    if (!world_from_frame[i]) out.push_back(static_cast<int>(i));
  return out;
}

ChainedPoses chain_poses(int sensors, int frames, const std::vector<PoseEdge>& edges,
                         const PoseGauge& gauge) {
  ChainedPoses out;
  out.sensor_from_world.assign(sensors, std::nullopt);
  out.world_from_frame.assign(frames, std::nullopt);
  if (gauge.is_frame) {
    if (gauge.index >= 0 && gauge.index < frames) out.world_from_frame[gauge.index] = gauge.pose;
  } else if (gauge.index >= 0 && gauge.index < sensors) {
    out.sensor_from_world[gauge.index] = gauge.pose;
  }
  // Grow the tree one node at a time through the heaviest edge joining a known and an unknown
  // node (Prim-like), so poorer measurements are used only where nothing better connects.
  while (true) {
    const PoseEdge* best = nullptr;
    for (const PoseEdge& e : edges) {
      if (e.sensor < 0 || e.sensor >= sensors || e.frame < 0 || e.frame >= frames) continue;
      const bool s = out.sensor_from_world[e.sensor].has_value();
      const bool f = out.world_from_frame[e.frame].has_value();
      if (s == f) continue;
      if (best == nullptr || e.weight > best->weight) best = &e;
    }
    if (best == nullptr) break;
    if (out.sensor_from_world[best->sensor]) {
      out.world_from_frame[best->frame] =
          out.sensor_from_world[best->sensor]->inverse() * best->sensor_from_frame;
    } else {
      out.sensor_from_world[best->sensor] =
          best->sensor_from_frame * out.world_from_frame[best->frame]->inverse();
    }
  }
  return out;
}

}  // namespace studio::calibrate
