// OverlayRenderer (overlay_renderer.h): one coloured program for lines and spheres, one
// projective-texturing program for the projector screens.
#include "overlay_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <vector>

#include "gl_program.h"

namespace studio::preview {
namespace {

constexpr const char* kColourVs = R"(#version 330 core
layout(location = 0) in vec3 world;
layout(location = 1) in vec3 colour;
uniform mat4 clip_from_world;
out vec3 c;
void main() {
  c = colour;
  gl_Position = clip_from_world * vec4(world, 1);
})";
constexpr const char* kColourFs = R"(#version 330 core
in vec3 c;
out vec4 frag;
void main() { frag = vec4(c, 1); })";

constexpr const char* kScreenVs = R"(#version 330 core
layout(location = 0) in vec3 world;
uniform mat4 clip_from_world;
out vec3 p;
void main() {
  p = world;
  gl_Position = clip_from_world * vec4(world, 1);
})";
// pixel_from_world: the projector's K [R | t] as the first three rows (fourth row unused).
constexpr const char* kScreenFs = R"(#version 330 core
in vec3 p;
uniform mat4 pixel_from_world;
uniform vec2 size;
uniform int has_thumbnail;
uniform vec3 unlit;
uniform sampler2D thumbnail;
out vec4 frag;
void main() {
  vec4 q = pixel_from_world * vec4(p, 1);
  if (has_thumbnail == 0 || q.z <= 0.0) { frag = vec4(unlit, 1); return; }
  vec2 uv = (q.xy / q.z + 0.5) / size;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
    frag = vec4(unlit, 1);
    return;
  }
  frag = vec4(texture(thumbnail, uv).rgb, 1);
})";

constexpr int kSphereRings = 12, kSphereSectors = 20;

struct Thumbnail {
  GLuint texture = 0;
  int width = 0, height = 0;
};

void push(std::vector<float>& v, const Eigen::Vector3f& p, const Eigen::Vector3f& c) {
  v.insert(v.end(), {p.x(), p.y(), p.z(), c.x(), c.y(), c.z()});
}

// A UV sphere as triangles, lit by a fixed light from above-front (0.6 .. 1 of its colour).
void push_sphere(std::vector<float>& v, const OverlaySphere& s) {
  const Eigen::Vector3f light = Eigen::Vector3f(0.4f, 1.0f, 0.5f).normalized();
  auto point = [&](int ring, int sector, Eigen::Vector3f& n) {
    const double th = std::numbers::pi * ring / kSphereRings;
    const double ph = 2 * std::numbers::pi * sector / kSphereSectors;
    n = Eigen::Vector3f(float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                        float(std::sin(th) * std::sin(ph)));
    return Eigen::Vector3f(s.centre + s.radius * n);
  };
  auto vertex = [&](int ring, int sector) {
    Eigen::Vector3f n;
    const Eigen::Vector3f p = point(ring, sector, n);
    push(v, p, s.colour * (0.6f + 0.4f * std::max(0.0f, n.dot(light))));
  };
  for (int r = 0; r < kSphereRings; ++r)
    for (int k = 0; k < kSphereSectors; ++k) {
      const std::array<std::pair<int, int>, 6> quad = {
          {{r, k}, {r + 1, k}, {r + 1, k + 1}, {r, k}, {r + 1, k + 1}, {r, k + 1}}};
      for (const auto& [ring, sector] : quad) vertex(ring, sector);
    }
}

}  // namespace

struct OverlayRenderer::Impl {
  GLuint colour_program = 0, screen_program = 0;
  GLuint vao = 0, vbo = 0;
  std::map<std::string, Thumbnail> thumbnails;
  std::vector<float> scratch;

  ~Impl() {
    for (auto& [id, t] : thumbnails) glDeleteTextures(1, &t.texture);
    glDeleteBuffers(1, &vbo);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(colour_program);
    glDeleteProgram(screen_program);
  }
};

OverlayRenderer::OverlayRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OverlayRenderer::OverlayRenderer(OverlayRenderer&&) noexcept = default;
OverlayRenderer& OverlayRenderer::operator=(OverlayRenderer&&) noexcept = default;
OverlayRenderer::~OverlayRenderer() = default;

Expected<OverlayRenderer> OverlayRenderer::create() {
  auto impl = std::make_unique<Impl>();
  auto c = gl::program(kColourVs, kColourFs, "overlay lines");
  if (!c) return std::unexpected(c.error());
  impl->colour_program = *c;
  auto s = gl::program(kScreenVs, kScreenFs, "projector screen");
  if (!s) return std::unexpected(s.error());
  impl->screen_program = *s;
  glGenVertexArrays(1, &impl->vao);
  glGenBuffers(1, &impl->vbo);
  glBindVertexArray(impl->vao);
  glBindBuffer(GL_ARRAY_BUFFER, impl->vbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<void*>(3 * sizeof(float)));
  glBindVertexArray(0);
  return OverlayRenderer(std::move(impl));
}

Expected<void> OverlayRenderer::set_thumbnail(const std::string& id, int width, int height,
                                              const uint8_t* rgb) {
  if (width <= 0 || height <= 0 || width > 4096 || height > 4096 || !rgb)
    return fail("thumbnail of " + id + ": bad size " + std::to_string(width) + "x" +
                std::to_string(height));
  Thumbnail& t = impl_->thumbnails[id];
  if (!t.texture) {
    glGenTextures(1, &t.texture);
    glBindTexture(GL_TEXTURE_2D, t.texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  glBindTexture(GL_TEXTURE_2D, t.texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (t.width != width || t.height != height)
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, width, height, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb);
  else
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb);
  glBindTexture(GL_TEXTURE_2D, 0);
  t.width = width;
  t.height = height;
  return {};
}

std::optional<OverlayRenderer::Texture> OverlayRenderer::thumbnail(const std::string& id) const {
  const auto it = impl_->thumbnails.find(id);
  if (it == impl_->thumbnails.end()) return std::nullopt;
  return Texture{it->second.texture, it->second.width, it->second.height};
}

void OverlayRenderer::draw(const OverlayGeometry& g, const Eigen::Matrix4d& clip_from_world,
                           int width, int height) {
  Impl& r = *impl_;
  glViewport(0, 0, width, height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBindVertexArray(r.vao);
  glBindBuffer(GL_ARRAY_BUFFER, r.vbo);

  // Screens first (coplanar with a set wall they would fight it: pulled towards the eye).
  if (!g.screens.empty()) {
    glUseProgram(r.screen_program);
    gl::set_matrix(r.screen_program, "clip_from_world", clip_from_world);
    glUniform3f(glGetUniformLocation(r.screen_program, "unlit"), overlay_colour::screen_unlit.x(),
                overlay_colour::screen_unlit.y(), overlay_colour::screen_unlit.z());
    glUniform1i(glGetUniformLocation(r.screen_program, "thumbnail"), 0);
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-1.0f, -4.0f);
    for (const OverlayScreen& s : g.screens) {
      Eigen::Matrix4d pixel_from_world = Eigen::Matrix4d::Zero();
      pixel_from_world.topRows<3>() = s.projector.projection_matrix();
      gl::set_matrix(r.screen_program, "pixel_from_world", pixel_from_world);
      glUniform2f(glGetUniformLocation(r.screen_program, "size"), float(s.projector.width),
                  float(s.projector.height));
      const auto t = r.thumbnails.find(s.projector_id);
      glUniform1i(glGetUniformLocation(r.screen_program, "has_thumbnail"),
                  t != r.thumbnails.end() ? 1 : 0);
      glBindTexture(GL_TEXTURE_2D, t != r.thumbnails.end() ? t->second.texture : 0);
      r.scratch.clear();
      for (int k : {0, 1, 2, 0, 2, 3})
        push(r.scratch, s.corners[std::size_t(k)].cast<float>(), Eigen::Vector3f::Zero());
      glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(r.scratch.size() * sizeof(float)), r.scratch.data(),
                   GL_STREAM_DRAW);
      glDrawArrays(GL_TRIANGLES, 0, 6);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindTexture(GL_TEXTURE_2D, 0);
  }

  // Lines, then sphere triangles, from one buffer.
  r.scratch.clear();
  for (const OverlaySegment& s : g.lines) {
    push(r.scratch, s.a, s.colour);
    push(r.scratch, s.b, s.colour);
  }
  const GLsizei line_vertices = GLsizei(r.scratch.size() / 6);
  for (const OverlaySphere& s : g.spheres) push_sphere(r.scratch, s);
  const GLsizei all_vertices = GLsizei(r.scratch.size() / 6);
  if (all_vertices > 0) {
    glUseProgram(r.colour_program);
    gl::set_matrix(r.colour_program, "clip_from_world", clip_from_world);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(r.scratch.size() * sizeof(float)), r.scratch.data(),
                 GL_STREAM_DRAW);
    if (line_vertices > 0) {
      glLineWidth(2.0f);
      (void)glGetError();  // wide lines unsupported: 1 px (GL_INVALID_VALUE), drawn anyway
      glDrawArrays(GL_LINES, 0, line_vertices);
      glLineWidth(1.0f);
    }
    // The head marker sits inside the actor's head mesh: drawn over everything (x-ray), so it
    // shows where the tracker puts the head.
    if (all_vertices > line_vertices) {
      glDisable(GL_DEPTH_TEST);
      glDrawArrays(GL_TRIANGLES, line_vertices, all_vertices - line_vertices);
      glEnable(GL_DEPTH_TEST);
    }
  }
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace studio::preview
