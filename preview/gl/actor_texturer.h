#pragma once
// The live actor textured from the studio cameras (issue 16), drawn after the scene renderer
// into the same framebuffer (depth test against the scene's depth).
//
// Per surface point x of the actor mesh and per selected camera i (up to kMaxCameras):
//   visible_i(x): x projects inside camera i's image, in front of it, and no other part of the
//                 mesh is nearer to camera i along that ray (a depth map of the mesh rendered
//                 from camera i, tolerance `depth_tolerance_m`);
//   backing_i(x): camera i's pixel at x is the blue backing (blue above red and green by
//                 `key_margin`, the chroma key's rule): camera i sees past the actor there;
//   colour(x)   = sum_i w_i v_i(x) image_i(proj_i(x)) / sum_i w_i v_i(x), v_i = visible_i and
//                 not backing_i,
// with the weights of camera_select.h (nearest: one camera of weight 1). A point every camera
// that sees it sees as backing is not drawn (the visual hull's excess over the actor); a point
// no selected camera sees is drawn in `unseen` (flat); an untextured draw (no images of the mesh's
// frame) draws the whole mesh flat-shaded in `untextured`. Cameras are pinholes (K, cam_from_world,
// image size; the paper's radial distortion is ignored here: below a pixel for the studio's lenses
// at the preview's scale). Needs a current OpenGL 3.3 core context; GL names are plain unsigned
// ints.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "scene/actor_mesh.h"

namespace studio::preview {

struct TexturerOptions {
  float depth_tolerance_m = 0.03f;
  float key_margin = 0.2f;  // of full scale: the backing is blue above red and green by this
  Eigen::Vector3f unseen{0.35f, 0.35f, 0.35f};
  Eigen::Vector3f untextured{0.75f, 0.72f, 0.68f};
};

class ActorTexturer {
 public:
  static constexpr int kMaxCameras = 3;
  static Expected<ActorTexturer> create(const TexturerOptions& options = {});
  ActorTexturer(ActorTexturer&&) noexcept;
  ActorTexturer& operator=(ActorTexturer&&) noexcept;
  ~ActorTexturer();

  // The mesh to draw (uploaded once per call).
  Expected<void> set_mesh(const scene::ActorMesh& mesh);
  // Camera slot (0..kMaxCameras-1): calibration and its RGB8 image (width*height*3 bytes, top
  // row first). Renders the slot's visibility depth map of the current mesh: call after
  // set_mesh().
  Expected<void> set_camera(int slot, const Camera& camera, const uint8_t* rgb);
  // Draws the mesh into the bound framebuffer. weights[slot] > 0 selects a slot; textured false:
  // flat, untextured. Restores the viewport to (width, height).
  void draw(const Eigen::Matrix4d& clip_from_world, const std::array<float, kMaxCameras>& weights,
            bool textured, int width, int height);

 private:
  struct Impl;
  explicit ActorTexturer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// OpenGL clip_from_cam of a pinhole camera (OpenCV convention: x right, y down, z forward;
// pixel (0,0) is the centre of the top-left pixel): NDC x, y in [-1, 1] cover the image, NDC y
// up = image up, depth [near, far] → [-1, 1].
Eigen::Matrix4d clip_from_camera(const Camera& camera, double near_m = 0.05, double far_m = 100);

}  // namespace studio::preview
