#pragma once
// The live actor textured from the studio cameras (issue 16), drawn after the scene renderer
// into the same framebuffer (depth test against the scene's depth).
//
// Three modes (TextureMode):
//   flat:    the whole mesh flat-shaded in `untextured` (no images of the mesh's frame);
//   nearest: the paper's: every surface point x coloured from one camera (slot 0, times its
//            gains) where it sees x (visible_0 below) and not the backing there, else `unseen`;
//            a point that camera sees as backing is not drawn;
//   blend:   beyond the paper, image-based refinement of the hull and view-dependent blending of
//            up to kMaxCameras cameras (unstructured lumigraph rendering, Buehler et al. 2001):
//     1. carving (the image-based visual hull of Matusik et al. 2000, per pixel): the mesh is
//        drawn pushed out along its normals by `inflate_m`; from each fragment the novel view's
//        ray is marched inwards in steps of `carve_step_m` (at most `carve_steps`) to the first
//        point x that no selected camera sees as backing (the point is inside every selected
//        camera's silhouette, at the cameras' pixel resolution instead of the hull's voxel
//        grid). No such point: the fragment is discarded (the hull's excess over the actor).
//     2. per camera i: visible_i(x): x projects inside camera i's image, in front of it, and no
//        other part of the mesh is nearer to camera i along that ray (a depth map of the mesh
//        rendered from camera i, shadow-map style, tolerance `depth_tolerance_m` plus the
//        carved depth); backing_i(x): camera i sees the blue backing at x: the bilinear
//        interpolation of its key (1 on pixels that are not backing by the chroma key's rule,
//        blue above red and green by `key_margin`; 0 on backing) is below `key_threshold`;
//     3. colour(x) = sum_i w_i v_i g_i image_i(proj_i(x)) / sum_i w_i v_i, g_i camera i's colour
//        gains (set_camera; 1 unless balanced), v_i = visible_i and not backing_i, with
//        per-point ULR weights w_i = cos_i (1 - a_i / a_thr) / a_i, a_i the angle at x between
//        the novel view's ray and camera i's ray, a_thr the blend's threshold angle
//        (camera_select.h), cos_i = |normal . ray to camera i| (ULR's resolution penalty: a
//        grazing view is foreshortened and spilled). A camera that cannot see x does not
//        colour it.
// A point no camera sees is drawn in `unseen` (flat). Cameras are pinholes (K, cam_from_world,
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
  // A camera sees the backing at a point when the share of actor pixels (by the key) in its
  // bilinear footprint there is below this. 0.5 puts the silhouette half a pixel inside the
  // camera's true one (its edge pixels mix actor and backing and key as backing about half the
  // time), which discards surface points at every camera's rim: measured with the true
  // surface (preview_error_sources_test), 0.5 gives 116 px of actor undrawn and blend
  // 26.7 dB, 0.25 17 px and 28.2 dB, lower thresholds no better and more hull excess.
  float key_threshold = 0.25f;
  // Blend mode's carving (above): push-out, march step and steps. The push-out recovers the
  // hull's flat facets cutting inside a round body (the march takes it back where a camera
  // sees the backing); 0 for a mesh that is the true surface.
  float inflate_m = 0.005f;
  float carve_step_m = 0.004f;
  int carve_steps = 32;
  Eigen::Vector3f unseen{0.35f, 0.35f, 0.35f};
  Eigen::Vector3f untextured{0.75f, 0.72f, 0.68f};
};

enum class TextureMode { flat, nearest, blend };

// The novel (virtual) camera: clip_from_world and its centre, and the target's size.
struct DrawView {
  Eigen::Matrix4d clip_from_world = Eigen::Matrix4d::Identity();
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();
  int width = 0, height = 0;
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
  // row first), and the factors its colours are multiplied by where it colours the actor (its
  // colour balance, preview/rig_balance.h; the key is the image's own). Renders the slot's
  // visibility depth map of the current mesh: call after set_mesh().
  Expected<void> set_camera(int slot, const Camera& camera, const uint8_t* rgb,
                            const Eigen::Vector3f& gains = Eigen::Vector3f::Ones());
  // Blend mode's carving also against these silhouettes (up to kMaxMasks cameras, one size;
  // mask: width*height bytes, top row first, 0 backing, else actor): the march stops at the
  // first point inside every selected camera's key and every mask here, the image-based visual
  // hull of all of them. An empty list: the selected cameras' keys only.
  static constexpr int kMaxMasks = 16;
  struct CarvingMask {
    const Camera* camera = nullptr;
    const uint8_t* mask = nullptr;
  };
  Expected<void> set_carving_masks(const std::vector<CarvingMask>& masks);
  // Draws the mesh into the bound framebuffer (viewport set to width x height). weights[slot] > 0
  // selects a slot (nearest: slot 0 only); blend: per-point ULR weights with threshold angle
  // `angle_threshold` (radians) replace the weights' values.
  void draw(const DrawView& view, TextureMode mode, const std::array<float, kMaxCameras>& weights,
            double angle_threshold = 0);

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
