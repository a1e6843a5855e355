#pragma once
// Texture for the offline mesh: one colour per vertex, blended from the cameras that see the
// vertex (the fallback the issue allows for an atlas: at the offline grid's resolution a mesh
// vertex is ~1 image pixel apart, so per-vertex colour carries the cameras' detail).
//
// Camera c contributes to surface point x (outward normal n) iff x is in front of c, faces it
// (cos = n . to_camera >= min_cos), is not hidden (its depth is within depth_tolerance of c's
// z-buffer of the occluding surface: the mesh itself) and projects into the silhouette's
// interior, edge_margin_px away from its border (the blue spill and the anti-aliased edge mix the
// cloth in there). Weight cos^sharpness: the most frontal views dominate (they carry the least
// spill and the sharpest detail). A vertex no camera sees takes the mean of its mesh neighbours
// (repeated until every vertex connected to a seen one has a colour; the rest are mid grey).

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/error.h"
#include "hull/segment_mesh.h"
#include "offline/photo_carve.h"

namespace studio::offline {

struct TextureOptions {
  double min_cos = 0.15;
  int edge_margin_px = 2;
  double depth_tolerance = 0.02;  // metres
  double sharpness = 4;           // weight = cos^sharpness
  int threads = 1;
  Expected<void> validate() const;
};

// The blend as a function of a surface point, for one frame: each camera's z-buffer of the
// `occluder` mesh (the reconstructed mesh; in a test, any surface, e.g. the true one) decides
// visibility. Not copyable (holds the buffers); thread-safe to query.
class TextureBlend {
 public:
  // Fails on invalid options or views (sizes). Independent of options.threads.
  static Expected<TextureBlend> create(const hull::Mesh& occluder,
                                       std::span<const ColourView> views,
                                       const TextureOptions& options = {});
  TextureBlend(TextureBlend&&) noexcept;
  TextureBlend& operator=(TextureBlend&&) noexcept;
  ~TextureBlend();
  // Display RGB (0..255) at x with outward unit normal n: the weighted mean of the cameras that
  // see x (see above); nullopt when none does.
  std::optional<Eigen::Vector3f> colour(const Eigen::Vector3d& x, const Eigen::Vector3d& n) const;

  struct Impl;

 private:
  explicit TextureBlend(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Display RGB (0..255, the cameras' encoding) per vertex of `mesh` (the blend with the mesh as its
// own occluder; unseen vertices filled from their neighbours). Fails on invalid options or views
// (sizes). Independent of options.threads.
Expected<std::vector<Eigen::Vector3f>> vertex_colours(const hull::Mesh& mesh,
                                                      std::span<const ColourView> views,
                                                      const TextureOptions& options = {});

}  // namespace studio::offline
