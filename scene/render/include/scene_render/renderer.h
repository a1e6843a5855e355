#pragma once
// The one OpenGL renderer of the project (the projector and the director's preview both use it):
// OpenGL 3.3 core, context-agnostic (a HeadlessContext, a GLFW window, anything current).
//
// draw() renders the scene graph from a given view (cam_from_world) and projection
// (clip_from_cam, taken as given: the projector passes an off-axis frustum): every visible model
// node's meshes with its asset material (base colour x texture x node colour), every actor node's
// latest ActorMesh, lit by the scene's light nodes (up to 8; Blinn-Phong with inverse-square
// fall-off for point and spot lights) plus an ambient term, evaluated per vertex by default
// (RendererOptions::Shading::fast, a textured 1080p frame costs ~4x less on llvmpipe) or per
// fragment (reference); high-contrast nodes (paper §V-F) and
// emissive materials are drawn unlit at full intensity. Back faces of asset meshes are culled
// unless their material is double-sided (glTF's rule); actor meshes are drawn two-sided.
//
// Assets are uploaded once (upload(), cached by path; re-uploaded when the content hash differs)
// and actor meshes into buffers that only grow; a steady-state draw() allocates nothing.
// A node naming an asset the renderer lacks, or one with a different hash, is skipped and listed
// by check_assets() (what a renderer reports in its status).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/actor_mesh.h"
#include "scene/scene.h"
#include "scene_assets/asset.h"

namespace studio::scene_render {

struct RendererOptions {
  // reference: Blinn-Phong per fragment (the exact path, for quality tests);
  // fast: the same lighting per vertex, the fragment stage is texture x light (shaders.h).
  enum class Shading { reference, fast };
  Shading shading = Shading::fast;
  Eigen::Vector4f clear_colour{0.05f, 0.05f, 0.07f, 1.0f};
  Eigen::Vector3f ambient{0.22f, 0.22f, 0.24f};
  // Scale from light units (candela, lux) to the shader's unit radiance.
  float exposure = 0.3f;
  // Skip meshes whose bounding sphere lies outside the view (its frustum, the clip plane and
  // View::cull_clip_from_world) and draw the rest nearest first (by the far side of their
  // bounding sphere), so llvmpipe's early depth test rejects hidden fragments before shading
  // them. The same image as false (every mesh in scene order) up to ties in depth; false is the
  // baseline of the renderer bench and its tests.
  bool cull_and_sort = true;
  // Levels of detail: asset meshes of >= 2048 triangles get coarser versions at upload
  // (mesh_lod.h); draw() takes the coarsest whose geometric error, projected at the mesh's
  // nearest point, stays within this many pixels. 0: always the full mesh (set before upload).
  double lod_pixel_error = 0.5;
  // How textures are sampled. bilinear: fast shading reads the nearest mip level bilinearly
  // (GL_LINEAR_MIPMAP_NEAREST), the reference shading trilinearly. nearest: the nearest texel of
  // the nearest mip level (GL_NEAREST_MIPMAP_NEAREST / GL_NEAREST), both shadings: on llvmpipe
  // the filter is most of a textured fragment's cost (docs/renderer.md), a 1080p frame of the
  // default scene costs about a sixth less CPU; texels show as small squares close up.
  enum class TextureFilter { bilinear, nearest };
  TextureFilter texture_filter = TextureFilter::bilinear;
  Expected<void> validate() const;
};

struct View {
  Eigen::Matrix4d cam_from_world = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d clip_from_cam = Eigen::Matrix4d::Identity();
  // The eye for specular light; absent: the origin of cam_from_world (a projector passes its
  // combined clip_from_world as clip_from_cam with an identity cam_from_world, and the eye here).
  std::optional<Eigen::Vector3d> eye_in_world;
  // World plane (a, b, c, d): only points with a x + b y + c z + d >= 0 are drawn
  // (gl_ClipDistance[0]); the projector's single-pass form clips behind the eye with it.
  std::optional<Eigen::Vector4d> clip_plane_world;
  // A frustum the caller cares about (only its side planes: left, right, bottom, top): what is
  // drawn outside it will be overwritten, so meshes entirely outside it may be skipped. The
  // projector's single pass passes the eye's frustum through the screen rectangle.
  std::optional<Eigen::Matrix4d> cull_clip_from_world;
  // false: draw() keeps the bound framebuffer's colour and depth (the caller cleared it, e.g. to
  // lay an occluder at depth 0 first).
  bool clear = true;
};

struct AssetStatus {
  enum class State { missing, different };
  std::string path;
  std::string wanted_sha256;
  std::string have_sha256;  // empty when missing
  State state = State::missing;
};

class Renderer {
 public:
  // Compiles the shaders; needs a current OpenGL 3.3 core context.
  static Expected<Renderer> create(const RendererOptions& options = {});
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  ~Renderer();

  // Uploads meshes and textures of an asset (no-op when the same path and hash are loaded).
  Expected<void> upload(const scene_assets::Asset& asset);
  // The latest mesh of an actor (replaces the previous one; buffers grow, never shrink).
  Expected<void> set_actor_mesh(const scene::ActorMesh& mesh);

  // Assets the scene's model nodes name that are not uploaded or differ, one per path.
  std::vector<AssetStatus> check_assets(const scene::Scene& scene) const;

  // Clears colour and depth of the bound framebuffer and draws the scene.
  void draw(const scene::Scene& scene, const View& view);
  // The actor mask of the projector: the actor's mesh in one flat colour (black) over whatever
  // is drawn (the image of depth test off, each pixel shaded once however often the mesh
  // overlaps itself: the depth buffer is cleared and left 0 where the mesh covers), every vertex
  // moved `inflate_m` metres along its normal (the security margin). The colour's alpha is
  // written too (draw() writes alpha 1): a mask drawn with alpha 0 can be told from black scene
  // pixels in the read-back. `disjoint`: the caller knows the mesh's triangles do not overlap
  // in the view beyond seams (the projector's outline mask: runs of pixels as quads), so each
  // pixel is shaded about once without the depth pass, and with one flat colour and no
  // blending a seam shaded twice looks the same: depth is neither cleared, tested nor written
  // (the clear alone, ~1 ms of a 1280x720 frame on llvmpipe, cost more than the ~57k px of a
  // mask; projector_bench SceneImageFrame_720p).
  void draw_actor_flat(const std::string& actor_id, const View& view, float inflate_m = 0.0f,
                       const Eigen::Vector4f& colour = Eigen::Vector4f(0, 0, 0, 1),
                       bool disjoint = false);
  // The same mesh as an occluder: flat `colour`, written at depth 0 (the near plane) whatever
  // its distance, so a later draw(view with clear = false) shades nothing behind it.
  // first_layer: only where nothing is at the near plane yet (GL_LESS): a mesh folding over
  // itself is shaded once per pixel, and an earlier occluder's pixels are kept; false: every
  // fragment written (GL_ALWAYS).
  void draw_actor_occluder(const std::string& actor_id, const View& view,
                           const Eigen::Vector4f& colour = Eigen::Vector4f(0, 0, 0, 1),
                           bool first_layer = false);
  // Draws a texture (e.g. a RenderTarget's colour texture) over the whole bound framebuffer;
  // the output pixel at normalised coordinates p in [0,1]^2 (x right, y up) samples the texture
  // at dehomogenised tex_from_screen * (p, 1) (identity: a plain copy; the projector passes its
  // homography), black where that falls outside [0,1]^2. `region`: only the pixels inside this
  // convex quad (4 corners in order, normalised coordinates) are drawn, the rest of the
  // framebuffer is kept (the projector's warp covers only the screen's image). Depth test off.
  void draw_texture(unsigned texture,
                    const Eigen::Matrix3f& tex_from_screen = Eigen::Matrix3f::Identity(),
                    const std::optional<std::array<Eigen::Vector2f, 4>>& region = std::nullopt);

  int draw_calls_last_frame() const;
  // Triangles submitted since the last draw() began (its levels of detail, culling).
  std::int64_t triangles_last_frame() const;

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::scene_render
