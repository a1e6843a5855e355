#pragma once
// The simulator's truth for the demo, frame by frame (the simulated studio is deterministic per
// frame: sim/studio.h; the capture service's sim source renders frame f of its camera as
// SimulatedStudio::render(camera, f) — capture/sim_source.h — with the scene of
// capture::SimSourceOptions's defaults, which is what a `source: {type: sim}` config gets).
//
//   - mesh score: each live actor mesh of frame f rasterised into every camera (pixel centres,
//     hull/testing/raster.h) against that camera's TRUE mask of frame f (the geometric
//     silhouette); IoU per camera, mean over cameras;
//   - head error: distance between a published head position and the true head centre of f.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "hull/segment_mesh.h"

namespace studio::demo {

struct MeshScore {
  uint64_t frame = 0;
  double mean_iou = 0;
  double min_iou = 0;
  std::string worst_camera;
};

class TruthScorer {
 public:
  // cameras: as the capture services publish them on studio/camera/calibration.
  static Expected<TruthScorer> create(std::vector<Camera> cameras);
  TruthScorer(TruthScorer&&) noexcept;
  TruthScorer& operator=(TruthScorer&&) noexcept;
  ~TruthScorer();

  // The union of `meshes` (every actor of the frame) against the true masks of `frame`.
  MeshScore score_meshes(uint64_t frame, const std::vector<hull::Mesh>& meshes) const;
  // |position - true head centre of frame|, metres.
  double head_error(uint64_t frame, const Eigen::Vector3d& position) const;
  Eigen::Vector3d true_head(uint64_t frame) const;

 private:
  struct Impl;
  explicit TruthScorer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::demo
