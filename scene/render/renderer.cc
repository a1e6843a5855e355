#include "scene_render/renderer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <unordered_map>

#include "gl.h"
#include "gl_program.h"
#include "mesh_lod.h"
#include "scene_programs.h"
#include "shaders.h"

namespace studio::scene_render {
namespace {

constexpr int kMaxLights = 8;

struct GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei index_count = 0;
  int material = -1;
  std::size_t vbo_bytes = 0, ebo_bytes = 0;          // capacity (actor meshes grow)
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();  // bounding sphere, model frame
  float radius = 0;
  std::vector<LodLevel> lods;  // finest first (empty: index_count indices from 0)
};

// A bounding sphere of the points (centre of their box, radius to the farthest point).
void set_bounds(GpuMesh& mesh, const std::vector<Eigen::Vector3f>& points) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  mesh.centre =
      box.isEmpty() ? Eigen::Vector3f(Eigen::Vector3f::Zero()) : Eigen::Vector3f(box.center());
  float r2 = 0;
  for (const Eigen::Vector3f& p : points) r2 = std::max(r2, (p - mesh.centre).squaredNorm());
  mesh.radius = std::sqrt(r2);
}

// Half-spaces of a view (world planes a x + b y + c z + d >= 0, (a, b, c) unit): a sphere wholly
// on the negative side of one of them draws nothing.
class CullPlanes {
 public:
  // The clip volume of clip_from_world, -w <= x, y, z <= w (Gribb and Hartmann's extraction);
  // sides_only: left, right, bottom, top.
  void add_frustum(const Eigen::Matrix4d& clip_from_world, bool sides_only) {
    const Eigen::RowVector4d w = clip_from_world.row(3);
    for (int axis = 0; axis < (sides_only ? 2 : 3); ++axis) {
      add((w + clip_from_world.row(axis)).transpose());
      add((w - clip_from_world.row(axis)).transpose());
    }
  }
  void add(const Eigen::Vector4d& plane) {
    const double n = plane.head<3>().norm();
    if (!(n > 1e-12) || count_ == static_cast<int>(planes_.size())) return;
    planes_[static_cast<std::size_t>(count_++)] = plane / n;
  }
  bool outside(const Eigen::Vector3d& centre, double radius) const {
    for (int i = 0; i < count_; ++i)
      if (planes_[static_cast<std::size_t>(i)].dot(centre.homogeneous()) < -radius) return true;
    return false;
  }

 private:
  std::array<Eigen::Vector4d, 12> planes_;
  int count_ = 0;
};

struct GpuAsset {
  std::string sha256;
  std::vector<GpuMesh> meshes;
  std::vector<GLuint> textures;
  std::vector<scene_assets::MaterialData> materials;
};

void release(GpuMesh& m) {
  if (m.vao) glDeleteVertexArrays(1, &m.vao);
  if (m.vbo) glDeleteBuffers(1, &m.vbo);
  if (m.ebo) glDeleteBuffers(1, &m.ebo);
  m = GpuMesh{};
}

void release(GpuAsset& a) {
  for (GpuMesh& m : a.meshes) release(m);
  if (!a.textures.empty())
    glDeleteTextures(static_cast<GLsizei>(a.textures.size()), a.textures.data());
  a = GpuAsset{};
}

GLuint upload_texture(int width, int height, const std::uint8_t* rgba_bottom_first) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               rgba_bottom_first);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  return t;
}

// Interleaved vertex layout: position, normal, uv, colour (11 floats).
constexpr int kFloats = 11;

void set_layout() {
  const GLsizei stride = kFloats * sizeof(float);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(0));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(3 * sizeof(float)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(6 * sizeof(float)));
  glEnableVertexAttribArray(3);
  glVertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(8 * sizeof(float)));
}

// Writes vertices into `mesh`'s buffers, growing them when needed (never shrinking).
void fill(GpuMesh& mesh, const std::vector<float>& vertices,
          const std::vector<std::uint32_t>& indices) {
  if (!mesh.vao) {
    glGenVertexArrays(1, &mesh.vao);
    glGenBuffers(1, &mesh.vbo);
    glGenBuffers(1, &mesh.ebo);
    glBindVertexArray(mesh.vao);
    glBindBuffer(GL_ARRAY_BUFFER, mesh.vbo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.ebo);
    set_layout();
  }
  glBindVertexArray(mesh.vao);
  const std::size_t vb = vertices.size() * sizeof(float),
                    ib = indices.size() * sizeof(std::uint32_t);
  glBindBuffer(GL_ARRAY_BUFFER, mesh.vbo);
  if (vb > mesh.vbo_bytes) {
    mesh.vbo_bytes = std::max(vb, mesh.vbo_bytes * 3 / 2);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vbo_bytes), nullptr,
                 GL_DYNAMIC_DRAW);
  }
  glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(vb), vertices.data());
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.ebo);
  if (ib > mesh.ebo_bytes) {
    mesh.ebo_bytes = std::max(ib, mesh.ebo_bytes * 3 / 2);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.ebo_bytes), nullptr,
                 GL_DYNAMIC_DRAW);
  }
  glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(ib), indices.data());
  mesh.index_count = static_cast<GLsizei>(indices.size());
  glBindVertexArray(0);
}

// Sets the clip plane (gl_ClipDistance[0] >= 0 is kept); none: everything is kept.
void set_clip_plane(GLint location, const std::optional<Eigen::Vector4d>& plane) {
  const Eigen::Vector4f p = plane ? plane->cast<float>() : Eigen::Vector4f(0, 0, 0, 1);
  glUniform4fv(location, 1, p.data());
}

}  // namespace

Expected<void> RendererOptions::validate() const {
  if (!clear_colour.allFinite() || !ambient.allFinite() || !std::isfinite(exposure) || exposure < 0)
    return fail("renderer options: colours and exposure must be finite, exposure >= 0");
  if (!std::isfinite(lod_pixel_error) || lod_pixel_error < 0)
    return fail("renderer options: lod_pixel_error must be finite and >= 0");
  return {};
}

struct Renderer::Impl {
  RendererOptions options;
  std::array<LitProgram, 2> lit;  // [0] untextured, [1] textured (scene_programs.h)
  FlatProgram flat;
  GLuint quad_program = 0, quad_vao = 0;
  GLint quad_texture = -1, quad_tex_from_screen = -1, quad_corners = -1, quad_viewport = -1;
  GLuint sampler = 0;  // fast shading: one mip level, bilinear (0: the textures' own filter)
  std::unordered_map<std::string, GpuAsset> assets;
  std::unordered_map<std::string, GpuMesh> actors;
  std::map<std::string, GLuint> override_textures;  // Material::texture paths
  // Per-frame scratch, reused.
  std::vector<Eigen::Matrix4d> world;
  std::vector<char> visible;
  std::vector<float> vertex_scratch;
  std::vector<std::uint32_t> index_scratch;
  // One mesh to draw: node index in scene order, mesh index in its asset (-1: the actor's mesh).
  struct Item {
    double key;
    std::uint32_t node;
    std::int32_t mesh;
    std::uint32_t first, count;  // index range (a level of detail)
  };
  std::vector<Item> items;
  int draw_calls = 0;
  std::int64_t triangles = 0;
  bool culling = false;

  ~Impl() {
    for (auto& [p, a] : assets) release(a);
    for (auto& [id, m] : actors) release(m);
    for (auto& [p, t] : override_textures) glDeleteTextures(1, &t);
    for (const LitProgram& p : lit)
      if (p.id) glDeleteProgram(p.id);
    if (flat.id) glDeleteProgram(flat.id);
    if (quad_program) glDeleteProgram(quad_program);
    if (quad_vao) glDeleteVertexArrays(1, &quad_vao);
    if (sampler) glDeleteSamplers(1, &sampler);
  }

  GLuint texture_for_path(const std::string& path) {
    if (auto it = override_textures.find(path); it != override_textures.end()) return it->second;
    cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
    GLuint t = 0;
    if (!image.empty()) {  // an unreadable texture draws untextured (and is tried only once)
      cv::cvtColor(image, image, cv::COLOR_BGR2RGBA);
      cv::flip(image, image, 0);
      t = upload_texture(image.cols, image.rows, image.data);
    }
    override_textures.emplace(path, t);
    return t;
  }

  // On the program in use (p).
  static void set_matrices(const LitProgram& p, const Eigen::Matrix4d& world_from_model) {
    const LitUniforms& u = p.u;
    const Eigen::Matrix4f m = world_from_model.cast<float>();
    const Eigen::Matrix3f n = m.topLeftCorner<3, 3>().inverse().transpose();
    glUniformMatrix4fv(u.world_from_model, 1, GL_FALSE, m.data());
    glUniformMatrix3fv(u.normal_matrix, 1, GL_FALSE, n.data());
  }

  // On both lit programs (leaves lit[1] in use).
  void set_lights(const scene::Scene& scene) {
    GLfloat position[kMaxLights * 4], radiance[kMaxLights * 3], spot[kMaxLights * 4],
        inner[kMaxLights], range[kMaxLights];
    int count = 0;
    const auto& order = scene.order();
    for (std::size_t i = 0; i < order.size() && count < kMaxLights; ++i) {
      const scene::Node& n = *order[i];
      if (n.kind != scene::NodeKind::light || !visible[i]) continue;
      const Eigen::Matrix4d& w = world[i];
      const Eigen::Vector3d origin = w.col(3).head<3>();
      const Eigen::Vector3d axis = (-w.col(2).head<3>()).normalized();  // the light shines along -z
      const scene::Light& l = n.light;
      if (l.type == scene::LightType::directional) {
        position[4 * count + 0] = static_cast<float>(-axis.x());
        position[4 * count + 1] = static_cast<float>(-axis.y());
        position[4 * count + 2] = static_cast<float>(-axis.z());
        position[4 * count + 3] = 0;
      } else {
        for (int k = 0; k < 3; ++k) position[4 * count + k] = static_cast<float>(origin[k]);
        position[4 * count + 3] = 1;
      }
      for (int k = 0; k < 3; ++k)
        radiance[3 * count + k] = l.colour[k] * l.intensity * options.exposure;
      for (int k = 0; k < 3; ++k) spot[4 * count + k] = static_cast<float>(axis[k]);
      spot[4 * count + 3] = l.type == scene::LightType::spot ? std::cos(l.outer_cone) : -2.0f;
      inner[count] = std::cos(l.inner_cone);
      range[count] = l.range;
      ++count;
    }
    for (const LitProgram& p : lit) {
      const LitUniforms& u = p.u;
      glUseProgram(p.id);
      glUniform1i(u.light_count, count);
      if (count == 0) continue;
      glUniform4fv(u.light_position, count, position);
      glUniform3fv(u.light_radiance, count, radiance);
      glUniform4fv(u.light_spot, count, spot);
      glUniform1fv(u.light_spot_inner, count, inner);
      glUniform1fv(u.light_range, count, range);
    }
  }

  // An actor mesh (studio frame) in one colour (its vertex colours ignored), alpha written, every
  // vertex moved inflate_m along its normal, by the flat program; the caller sets the depth state.
  void draw_flat(const GpuMesh& m, const View& view, float inflate_m,
                 const Eigen::Vector4f& colour) {
    glUseProgram(flat.id);
    glDisable(GL_CLIP_DISTANCE0);  // the flat vertex shader writes no clip distance
    const Eigen::Matrix4f clip_from_world =
        (view.clip_from_cam * view.cam_from_world).cast<float>();
    glUniformMatrix4fv(flat.clip_from_world, 1, GL_FALSE, clip_from_world.data());
    glUniform1f(flat.inflate, inflate_m);
    const Eigen::Vector4f c = colour.cwiseMax(0.0f).cwiseMin(1.0f);
    glUniform4fv(flat.colour, 1, c.data());
    draw_mesh(m);
    glBindVertexArray(0);
  }

  void draw_mesh(const GpuMesh& m) { draw_range(m, 0, static_cast<std::uint32_t>(m.index_count)); }
  void draw_range(const GpuMesh& m, std::uint32_t first, std::uint32_t count) {
    glBindVertexArray(m.vao);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(std::uintptr_t(first) * sizeof(std::uint32_t)));
    ++draw_calls;
    triangles += count / 3;
  }
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
Renderer::~Renderer() = default;

Expected<Renderer> Renderer::create(const RendererOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  if (!version) return fail("renderer: no current OpenGL context");
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  const bool fast = options.shading == RendererOptions::Shading::fast;
  for (int textured = 0; textured < 2; ++textured) {
    auto p = build_lit_program(fast, textured == 1);
    if (!p) return std::unexpected(p.error());
    impl->lit[static_cast<std::size_t>(textured)] = *p;
  }
  auto flat = build_flat_program();
  if (!flat) return std::unexpected(flat.error());
  impl->flat = *flat;
  auto quad = build_program(shaders::kQuadVertex, shaders::kQuadFragment, "texture quad");
  if (!quad) return std::unexpected(quad.error());
  impl->quad_program = *quad;
  impl->quad_texture = glGetUniformLocation(impl->quad_program, "u_texture");
  impl->quad_tex_from_screen = glGetUniformLocation(impl->quad_program, "u_tex_from_screen");
  impl->quad_corners = glGetUniformLocation(impl->quad_program, "u_corners[0]");
  impl->quad_viewport = glGetUniformLocation(impl->quad_program, "u_viewport");
  glGenVertexArrays(1, &impl->quad_vao);
  const bool nearest = options.texture_filter == RendererOptions::TextureFilter::nearest;
  if (fast || nearest) {  // the nearest mip level, sampled bilinearly (or its nearest texel)
    glGenSamplers(1, &impl->sampler);
    glSamplerParameteri(impl->sampler, GL_TEXTURE_MIN_FILTER,
                        nearest ? GL_NEAREST_MIPMAP_NEAREST : GL_LINEAR_MIPMAP_NEAREST);
    glSamplerParameteri(impl->sampler, GL_TEXTURE_MAG_FILTER, nearest ? GL_NEAREST : GL_LINEAR);
    glSamplerParameteri(impl->sampler, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glSamplerParameteri(impl->sampler, GL_TEXTURE_WRAP_T, GL_REPEAT);
  }
  return Renderer(std::move(impl));
}

Expected<void> Renderer::upload(const scene_assets::Asset& asset) {
  auto& slot = impl_->assets[asset.path];
  if (!slot.sha256.empty() && slot.sha256 == asset.sha256) return {};
  release(slot);
  GpuAsset g;
  g.sha256 = asset.sha256;
  g.materials = asset.materials;
  for (const scene_assets::Texture& t : asset.textures) {
    if (t.width < 1 || t.height < 1 ||
        t.rgba.size() != static_cast<std::size_t>(t.width) * t.height * 4)
      return fail(asset.path + ": texture '" + t.name + "' has a bad size");
    g.textures.push_back(upload_texture(t.width, t.height, t.rgba.data()));
  }
  std::vector<float> v;
  for (const scene_assets::MeshData& m : asset.meshes) {
    v.clear();
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      const Eigen::Vector2f uv = m.uvs.empty() ? Eigen::Vector2f::Zero() : m.uvs[i];
      const Eigen::Vector3f c = m.colours.empty() ? Eigen::Vector3f::Ones() : m.colours[i];
      v.insert(v.end(),
               {m.positions[i].x(), m.positions[i].y(), m.positions[i].z(), m.normals[i].x(),
                m.normals[i].y(), m.normals[i].z(), uv.x(), uv.y(), c.x(), c.y(), c.z()});
    }
    GpuMesh gm;
    if (impl_->options.lod_pixel_error > 0) {
      MeshLods lods = build_lods(m.positions, m.indices);
      fill(gm, v, lods.indices);
      gm.index_count = static_cast<GLsizei>(lods.levels.front().count);
      if (lods.levels.size() > 1) gm.lods = std::move(lods.levels);
    } else {
      fill(gm, v, m.indices);
    }
    set_bounds(gm, m.positions);
    gm.material = m.material;
    g.meshes.push_back(gm);
  }
  slot = std::move(g);
  return {};
}

Expected<void> Renderer::set_actor_mesh(const scene::ActorMesh& mesh) {
  if (auto ok = mesh.validate(); !ok) return ok;
  if (mesh.actor_id.empty()) return fail("actor mesh: empty actor id");
  auto& v = impl_->vertex_scratch;
  auto& idx = impl_->index_scratch;
  v.clear();
  idx.clear();
  scene::ActorMesh with_normals;
  const std::vector<Eigen::Vector3f>* normals = &mesh.normals;
  if (mesh.normals.empty()) {
    with_normals.vertices = mesh.vertices;
    with_normals.triangles = mesh.triangles;
    with_normals.compute_normals();
    normals = &with_normals.normals;
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& p = mesh.vertices[i];
    const Eigen::Vector3f& n = (*normals)[i];
    const Eigen::Vector3f c = mesh.colours.empty() ? Eigen::Vector3f::Ones() : mesh.colours[i];
    v.insert(v.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), 0.0f, 0.0f, c.x(), c.y(), c.z()});
  }
  for (const auto& t : mesh.triangles) idx.insert(idx.end(), {t[0], t[1], t[2]});
  GpuMesh& gm = impl_->actors[mesh.actor_id];
  fill(gm, v, idx);
  set_bounds(gm, mesh.vertices);
  return {};
}

std::vector<AssetStatus> Renderer::check_assets(const scene::Scene& scene) const {
  std::map<std::string, AssetStatus> out;
  for (const auto& [id, n] : scene.nodes()) {
    if (n.kind != scene::NodeKind::model || out.contains(n.asset.path)) continue;
    auto it = impl_->assets.find(n.asset.path);
    if (it == impl_->assets.end())
      out[n.asset.path] = {n.asset.path, n.asset.sha256, "", AssetStatus::State::missing};
    else if (it->second.sha256 != n.asset.sha256)
      out[n.asset.path] = {n.asset.path, n.asset.sha256, it->second.sha256,
                           AssetStatus::State::different};
  }
  std::vector<AssetStatus> v;
  for (auto& [p, s] : out) v.push_back(std::move(s));
  return v;
}

void Renderer::draw(const scene::Scene& scene, const View& view) {
  Impl& r = *impl_;
  r.draw_calls = 0;
  r.triangles = 0;
  if (view.clear) {
    const Eigen::Vector4f& cc = r.options.clear_colour;
    glClearColor(cc[0], cc[1], cc[2], cc[3]);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  r.culling = false;
  glDisable(GL_BLEND);

  scene.world_from_nodes(r.world);
  const auto& order = scene.order();
  const auto& parent = scene.parent_index();
  r.visible.resize(order.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    r.visible[i] =
        order[i]->visible && (parent[i] < 0 || r.visible[static_cast<std::size_t>(parent[i])]);

  const Eigen::Matrix4d clip_from_world_d = view.clip_from_cam * view.cam_from_world;
  const Eigen::Matrix4f clip_from_world = clip_from_world_d.cast<float>();
  const Eigen::Vector3d eye_d =
      view.eye_in_world ? *view.eye_in_world
                        : Eigen::Vector3d(view.cam_from_world.inverse().col(3).head<3>());
  const Eigen::Vector3f eye = eye_d.cast<float>();
  glEnable(GL_CLIP_DISTANCE0);
  for (const LitProgram& p : r.lit) {
    glUseProgram(p.id);
    glUniformMatrix4fv(p.u.clip_from_world, 1, GL_FALSE, clip_from_world.data());
    set_clip_plane(p.u.clip_plane, view.clip_plane_world);
    glUniform1f(p.u.alpha, 1.0f);
    glUniform3fv(p.u.eye, 1, eye.data());
    glUniform3fv(p.u.ambient, 1, r.options.ambient.data());
    glUniform1f(p.u.inflate, 0.0f);
    glUniform1i(p.u.texture, 0);
  }
  glActiveTexture(GL_TEXTURE0);
  glBindSampler(0, r.sampler);
  r.set_lights(scene);

  // What to draw: every mesh of the visible model and actor nodes, culled and sorted nearest
  // first (RendererOptions::cull_and_sort), else in scene order.
  const bool cull_and_sort = r.options.cull_and_sort;
  CullPlanes planes;
  if (cull_and_sort) {
    planes.add_frustum(clip_from_world_d, false);
    if (view.clip_plane_world) planes.add(*view.clip_plane_world);
    if (view.cull_clip_from_world) planes.add_frustum(*view.cull_clip_from_world, true);
  }
  r.items.clear();
  GLint viewport[4] = {0, 0, 1, 1};
  glGetIntegerv(GL_VIEWPORT, viewport);
  const double half_w = 0.5 * viewport[2], half_h = 0.5 * viewport[3];
  // Pixels per world unit at world point c (an upper bound over directions: the Frobenius norm
  // of the 2x3 Jacobian of the pixel position).
  auto pixels_per_unit = [&](const Eigen::Vector3d& c) {
    const Eigen::Vector4d p = clip_from_world_d * c.homogeneous();
    if (!(p.w() > 1e-9)) return std::numeric_limits<double>::infinity();
    double sum = 0;
    for (int j = 0; j < 3; ++j) {
      const double dx = (clip_from_world_d(0, j) * p.w() - p.x() * clip_from_world_d(3, j)) *
                        half_w / (p.w() * p.w());
      const double dy = (clip_from_world_d(1, j) * p.w() - p.y() * clip_from_world_d(3, j)) *
                        half_h / (p.w() * p.w());
      sum += dx * dx + dy * dy;
    }
    return std::sqrt(sum);
  };
  const double lod_pixels = r.options.lod_pixel_error;
  auto consider = [&](std::size_t i, std::int32_t m, const GpuMesh& mesh) {
    double key = 0;
    std::uint32_t first = 0, count = static_cast<std::uint32_t>(mesh.index_count);
    if (cull_and_sort || (lod_pixels > 0 && !mesh.lods.empty())) {
      const Eigen::Matrix4d& w = r.world[i];
      const Eigen::Vector3d centre = (w * mesh.centre.cast<double>().homogeneous()).head<3>();
      const double scale = std::max(
          {w.col(0).head<3>().norm(), w.col(1).head<3>().norm(), w.col(2).head<3>().norm()});
      const double radius = mesh.radius * scale * 1.0001 + 1e-6;
      if (cull_and_sort && planes.outside(centre, radius)) return;
      const double distance = (centre - eye_d).norm();
      key = distance + radius;
      // Level of detail: the error measured at the nearest point of the bounding sphere
      // (projected size grows as 1 / distance); inside the sphere, full detail.
      if (lod_pixels > 0 && !mesh.lods.empty() && distance > 1.25 * radius) {
        const double px = pixels_per_unit(centre) * distance / (distance - radius) * scale;
        for (const LodLevel& level : mesh.lods)
          if (level.error * px <= lod_pixels) {
            first = level.first;
            count = level.count;
          }
      }
    }
    r.items.push_back({key, static_cast<std::uint32_t>(i), m, first, count});
  };
  for (std::size_t i = 0; i < order.size(); ++i) {
    const scene::Node& n = *order[i];
    if (!r.visible[i]) continue;
    if (n.kind == scene::NodeKind::model) {
      auto it = r.assets.find(n.asset.path);
      if (it == r.assets.end() || it->second.sha256 != n.asset.sha256) continue;  // check_assets()
      const GpuAsset& a = it->second;
      if (n.asset.meshes.empty()) {
        for (std::size_t m = 0; m < a.meshes.size(); ++m)
          consider(i, static_cast<std::int32_t>(m), a.meshes[m]);
      } else {
        for (std::uint32_t m : n.asset.meshes)
          if (m < a.meshes.size()) consider(i, static_cast<std::int32_t>(m), a.meshes[m]);
      }
    } else if (n.kind == scene::NodeKind::actor) {
      auto it = r.actors.find(n.actor_id);
      if (it == r.actors.end() || it->second.index_count == 0) continue;
      consider(i, -1, it->second);
    }
  }
  if (cull_and_sort)
    std::stable_sort(r.items.begin(), r.items.end(),
                     [](const Impl::Item& a, const Impl::Item& b) { return a.key < b.key; });

  // The program in use (untextured or textured variant) and, per program, the node whose
  // matrices it holds.
  int in_use = -1;
  std::array<std::size_t, 2> matrices_of{order.size(), order.size()};
  auto use = [&](int textured, std::size_t node) {
    const LitProgram& p = r.lit[static_cast<std::size_t>(textured)];
    if (in_use != textured) {
      glUseProgram(p.id);
      in_use = textured;
    }
    if (matrices_of[static_cast<std::size_t>(textured)] != node) {
      Impl::set_matrices(p, r.world[node]);
      matrices_of[static_cast<std::size_t>(textured)] = node;
    }
    return p.u;
  };
  for (const Impl::Item& item : r.items) {
    const std::size_t i = item.node;
    const scene::Node& n = *order[i];
    if (item.mesh < 0) {  // an actor's mesh
      const LitUniforms u = use(0, i);
      if (r.culling) glDisable(GL_CULL_FACE);  // actor meshes are drawn two-sided
      r.culling = false;
      glUniform4fv(u.base, 1, n.material.colour.data());
      const Eigen::Vector3f zero = Eigen::Vector3f::Zero();
      glUniform3fv(u.emissive, 1, zero.data());
      glUniform1i(u.unlit, n.material.high_contrast ? 1 : 0);
      r.draw_mesh(r.actors.find(n.actor_id)->second);
      continue;
    }
    const GpuAsset& a = r.assets.find(n.asset.path)->second;
    const GpuMesh& mesh = a.meshes[static_cast<std::size_t>(item.mesh)];
    GLuint texture = n.material.texture.empty() ? 0 : r.texture_for_path(n.material.texture);
    Eigen::Vector4f base = n.material.colour;
    Eigen::Vector3f emissive = Eigen::Vector3f::Zero();
    bool cull = false;
    if (mesh.material >= 0) {
      const scene_assets::MaterialData& md = a.materials[static_cast<std::size_t>(mesh.material)];
      base = base.cwiseProduct(md.base_colour);
      emissive = md.emissive;
      if (!texture && md.texture >= 0) texture = a.textures[static_cast<std::size_t>(md.texture)];
      cull = !md.double_sided;
    }
    if (cull != r.culling) {
      cull ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
      r.culling = cull;
    }
    const LitUniforms u = use(texture ? 1 : 0, i);
    glUniform4fv(u.base, 1, base.data());
    if (n.material.high_contrast) emissive.setZero();  // unlit: base colour only
    glUniform3fv(u.emissive, 1, emissive.data());
    glUniform1i(u.unlit, n.material.high_contrast ? 1 : 0);
    if (texture) glBindTexture(GL_TEXTURE_2D, texture);
    r.draw_range(mesh, item.first, item.count);
  }
  glBindVertexArray(0);
  glDisable(GL_CULL_FACE);
  glDisable(GL_CLIP_DISTANCE0);
  glBindSampler(0, 0);
  r.culling = false;
}

void Renderer::draw_actor_flat(const std::string& actor_id, const View& view, float inflate_m,
                               const Eigen::Vector4f& colour, bool disjoint) {
  Impl& r = *impl_;
  auto it = r.actors.find(actor_id);
  if (it == r.actors.end() || it->second.index_count == 0) return;
  if (disjoint) {  // no fold to shade twice: no depth pass (see renderer.h)
    glDisable(GL_DEPTH_TEST);
    r.draw_flat(it->second, view, inflate_m, colour);
    glEnable(GL_DEPTH_TEST);
    return;
  }
  // Each covered pixel is shaded once, however often the mesh overlaps itself there: a grown
  // mask folds over itself many times (vertices pushed out along their normals), and with the
  // depth test off llvmpipe shades and writes every layer (a 0.3 m margin on a hull mesh: ~40x
  // the frame's time). The depth buffer is cleared, every fragment lands on the near plane and
  // GL_LESS lets only the first through (early depth test). Blending is off and the colour is
  // one flat value, so the image is the one "depth test off" gives; afterwards depth is 0 where
  // the mesh covers and 1 elsewhere.
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDepthRange(0.0, 0.0);
  r.draw_flat(it->second, view, inflate_m, colour);
  glDepthRange(0.0, 1.0);
}

void Renderer::draw_actor_occluder(const std::string& actor_id, const View& view,
                                   const Eigen::Vector4f& colour, bool first_layer) {
  Impl& r = *impl_;
  auto it = r.actors.find(actor_id);
  if (it == r.actors.end() || it->second.index_count == 0) return;
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(first_layer ? GL_LESS : GL_ALWAYS);
  glDepthRange(0.0, 0.0);  // every fragment at the near plane: nothing drawn later passes GL_LESS
  r.draw_flat(it->second, view, 0.0f, colour);
  glDepthRange(0.0, 1.0);
  glDepthFunc(GL_LESS);
}

void Renderer::draw_texture(unsigned texture, const Eigen::Matrix3f& tex_from_screen,
                            const std::optional<std::array<Eigen::Vector2f, 4>>& region) {
  Impl& r = *impl_;
  glDisable(GL_DEPTH_TEST);
  glUseProgram(r.quad_program);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture);
  glUniform1i(r.quad_texture, 0);
  glUniformMatrix3fv(r.quad_tex_from_screen, 1, GL_FALSE, tex_from_screen.data());
  GLfloat corners[8] = {0, 0, 1, 0, 1, 1, 0, 1};
  if (region)
    for (int i = 0; i < 4; ++i) {
      corners[2 * i] = (*region)[static_cast<std::size_t>(i)].x();
      corners[2 * i + 1] = (*region)[static_cast<std::size_t>(i)].y();
    }
  glUniform2fv(r.quad_corners, 4, corners);
  GLint viewport[4] = {0, 0, 1, 1};
  glGetIntegerv(GL_VIEWPORT, viewport);
  glUniform4f(r.quad_viewport, float(viewport[0]), float(viewport[1]), float(viewport[2]),
              float(viewport[3]));
  glBindVertexArray(r.quad_vao);
  glDrawArrays(GL_TRIANGLES, 0, 6);
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
}

int Renderer::draw_calls_last_frame() const { return impl_->draw_calls; }
std::int64_t Renderer::triangles_last_frame() const { return impl_->triangles; }

}  // namespace studio::scene_render
