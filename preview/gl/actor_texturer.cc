// ActorTexturer (actor_texturer.h): a depth pass per camera slot and one textured draw.
#define GL_GLEXT_PROTOTYPES 1
#include "actor_texturer.h"

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <string>

#include "gl_program.h"

namespace studio::preview {
namespace {

constexpr const char* kDepthVs = R"(#version 330 core
layout(location = 0) in vec3 world;
uniform mat4 clip_from_world;
uniform mat4 cam_from_world;
out float z;
void main() {
  z = (cam_from_world * vec4(world, 1)).z;
  gl_Position = clip_from_world * vec4(world, 1);
})";
constexpr const char* kDepthFs = R"(#version 330 core
in float z;
out float depth;
void main() { depth = z; })";

constexpr const char* kDrawVs = R"(#version 330 core
layout(location = 0) in vec3 world;
layout(location = 1) in vec3 normal;
uniform mat4 clip_from_world;
uniform float inflate;  // blend mode: the mesh pushed out along its normals (carved back below)
out vec3 p;
out vec3 n;
void main() {
  p = world + inflate * normal;
  n = normal;
  gl_Position = clip_from_world * vec4(p, 1);
})";
// Slots 0..2: clip (the camera's clip_from_world), cam (cam_from_world), centre (world), colour
// and depth textures (separate samplers: GLSL 3.30 cannot index sampler arrays with a loop
// variable). mode: 0 flat, 1 nearest, 2 blend (actor_texturer.h).
constexpr const char* kDrawFs = R"(#version 330 core
in vec3 p;
in vec3 n;
uniform int mode;
uniform vec3 eye;
uniform vec3 flat_colour;
uniform vec3 unseen;
uniform float tolerance;
uniform float carve_step;
uniform int carve_steps;
uniform float angle_threshold;
uniform float weight[3];
uniform vec3 gain[3];  // per camera: its colour balance (preview/rig_balance.h), 1 when none
uniform mat4 clip[3];
uniform mat4 cam[3];
uniform vec3 centre[3];
uniform sampler2D colour0, colour1, colour2;
uniform sampler2D depth0, depth1, depth2;
uniform float key_threshold;
uniform int mask_count;
uniform mat4 mask_clip[16];
uniform sampler2DArray masks;
out vec4 frag;
vec3 shade(vec3 c) {
  vec3 nn = normalize(n);
  float l = 0.45 + 0.55 * abs(dot(nn, normalize(vec3(0.4, 1.0, 0.5))));
  return c * l;
}
// Camera images carry their key in alpha (set_camera: 1 where the pixel is actor by keyer/'s
// rule, blue not above red and green by a margin; 0 on the backing). Backing at x: the
// bilinear key there is under `key_threshold` (the share of actor texels around x).
bool backing(vec4 c) { return c.a < key_threshold; }
// Camera i's image position of x (uv, rows top first) and its depth-map position; false when x
// is behind camera i or outside its image.
bool project(int i, vec3 x, out vec2 uv, out vec2 st) {
  vec4 q = clip[i] * vec4(x, 1);
  if (q.w <= 0.0) return false;
  vec2 ndc = q.xy / q.w;
  if (any(greaterThan(abs(ndc), vec2(1.0)))) return false;
  st = ndc * 0.5 + 0.5;
  uv = vec2(st.x, 1.0 - st.y);
  return true;
}
// Camera i (selected) sees the backing at x: x is outside its silhouette.
bool outside(int i, sampler2D colour, vec3 x) {
  if (weight[i] <= 0.0) return false;
  vec2 uv, st;
  if (!project(i, x, uv, st)) return false;
  return backing(texture(colour, uv));
}
// x is outside one of the carving masks (set_carving_masks) that sees it.
bool outside_masks(vec3 x) {
  for (int i = 0; i < mask_count; ++i) {
    vec4 q = mask_clip[i] * vec4(x, 1);
    if (q.w <= 0.0) continue;
    vec2 ndc = q.xy / q.w;
    if (any(greaterThan(abs(ndc), vec2(1.0)))) continue;
    vec2 st = ndc * 0.5 + 0.5;
    if (texture(masks, vec3(st.x, 1.0 - st.y, float(i))).r < key_threshold) return true;
  }
  return false;
}
void add(int i, sampler2D colour, sampler2D depth, vec3 x, float tol, inout vec3 sum,
         inout float wsum, inout int keyed) {
  if (weight[i] <= 0.0) return;
  vec2 uv, st;
  if (!project(i, x, uv, st)) return;
  float z = (cam[i] * vec4(x, 1)).z;
  if (z > texture(depth, st).r + tol) return;  // another part of the actor is nearer to camera i
  vec4 texel = texture(colour, uv);
  if (backing(texel)) { keyed += 1; return; }
  vec3 c = texel.rgb * gain[i];
  float w = weight[i];
  if (mode == 2) {  // ULR at x: (1 - a / a_thr) / a, a = angle(novel ray, camera ray)
    vec3 to_cam = normalize(centre[i] - x);
    float a = acos(clamp(dot(normalize(eye - x), to_cam), -1.0, 1.0));
    a = max(a, 1e-3);
    w = max((1.0 - a / angle_threshold) / a, 1e-4);
    // ULR's resolution penalty, simplest form: a camera sees x's surface foreshortened (and
    // mixed with the backing's spill near its rim) as cos(normal, ray to camera) falls.
    w *= max(abs(dot(normalize(n), to_cam)), 0.05);
  }
  sum += w * c;
  wsum += w;
}
void main() {
  if (mode == 0) { frag = vec4(shade(flat_colour), 1); return; }
  vec3 x = p;
  float carved = 0.0;
  if (mode == 2 && carve_steps > 0) {
    // The image-based visual hull along the novel ray: the first point inside every selected
    // camera's silhouette.
    vec3 d = normalize(p - eye);
    bool found = false;
    for (int s = 0; s < carve_steps; ++s) {
      vec3 y = p + d * (float(s) * carve_step);
      if (!outside(0, colour0, y) && !outside(1, colour1, y) && !outside(2, colour2, y) &&
          !outside_masks(y)) {
        x = y;
        carved = float(s) * carve_step;
        found = true;
        break;
      }
    }
    if (!found) discard;
  }
  vec3 sum = vec3(0);
  float wsum = 0.0;
  int keyed = 0;
  float tol = tolerance + carved;
  add(0, colour0, depth0, x, tol, sum, wsum, keyed);
  add(1, colour1, depth1, x, tol, sum, wsum, keyed);
  add(2, colour2, depth2, x, tol, sum, wsum, keyed);
  if (wsum == 0.0 && keyed > 0) discard;  // every camera that sees the point sees the backing
  frag = vec4(wsum > 0.0 ? sum / wsum : shade(unseen), 1);
})";

Eigen::Matrix4d cam_from_world(const Camera& c) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = c.cam_from_world.R();
  m.topRightCorner<3, 1>() = c.cam_from_world.translation;
  return m;
}

struct Slot {
  GLuint colour = 0, depth = 0, fbo = 0, depth_rb = 0;
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;  // the image with its key in alpha (scratch)
  Eigen::Matrix4d clip = Eigen::Matrix4d::Identity(), cam = Eigen::Matrix4d::Identity();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // world
  Eigen::Vector3f gains = Eigen::Vector3f::Ones();
};

// RGB8 → RGBA8 with the chroma key in alpha: 0 where blue exceeds red and green by `margin`
// of full scale (keyer/'s rule), else 255.
void add_key(const uint8_t* rgb, std::size_t pixels, float margin, std::vector<uint8_t>& out) {
  out.resize(4 * pixels);
  const int m = int(margin * 255.0f + 0.5f);
  for (std::size_t i = 0; i < pixels; ++i) {
    const int r = rgb[3 * i], g = rgb[3 * i + 1], b = rgb[3 * i + 2];
    uint8_t* o = &out[4 * i];
    o[0] = uint8_t(r);
    o[1] = uint8_t(g);
    o[2] = uint8_t(b);
    o[3] = b > r + m && b > g + m ? 0 : 255;
  }
}

}  // namespace

Eigen::Matrix4d clip_from_camera(const Camera& c, double n, double f) {
  const auto& k = c.intrinsics;
  const double W = c.width, H = c.height;
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2 * k.fx / W;
  m(0, 1) = 2 * k.skew / W;
  m(0, 2) = 2 * (k.cx + 0.5) / W - 1;
  m(1, 1) = -2 * k.fy / H;
  m(1, 2) = 1 - 2 * (k.cy + 0.5) / H;
  m(2, 2) = (f + n) / (f - n);
  m(2, 3) = -2 * f * n / (f - n);
  m(3, 2) = 1;
  return m;
}

struct ActorTexturer::Impl {
  TexturerOptions options;
  GLuint depth_program = 0, draw_program = 0;
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei index_count = 0;
  std::vector<float> interleaved;
  std::array<Slot, kMaxCameras> slots;
  GLuint mask_array = 0;
  int mask_count = 0, mask_width = 0, mask_height = 0, mask_layers = 0;
  std::vector<Eigen::Matrix4d> mask_clip;

  ~Impl() {
    for (auto& s : slots) {
      glDeleteTextures(1, &s.colour);
      glDeleteTextures(1, &s.depth);
      glDeleteFramebuffers(1, &s.fbo);
      glDeleteRenderbuffers(1, &s.depth_rb);
    }
    glDeleteTextures(1, &mask_array);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ebo);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(depth_program);
    glDeleteProgram(draw_program);
  }

  void draw_mesh() const {
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
  }
};

ActorTexturer::ActorTexturer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ActorTexturer::ActorTexturer(ActorTexturer&&) noexcept = default;
ActorTexturer& ActorTexturer::operator=(ActorTexturer&&) noexcept = default;
ActorTexturer::~ActorTexturer() = default;

Expected<ActorTexturer> ActorTexturer::create(const TexturerOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  auto d = gl::program(kDepthVs, kDepthFs, "actor depth");
  if (!d) return std::unexpected(d.error());
  impl->depth_program = *d;
  auto p = gl::program(kDrawVs, kDrawFs, "textured actor");
  if (!p) return std::unexpected(p.error());
  impl->draw_program = *p;
  glGenVertexArrays(1, &impl->vao);
  glGenBuffers(1, &impl->vbo);
  glGenBuffers(1, &impl->ebo);
  glBindVertexArray(impl->vao);
  glBindBuffer(GL_ARRAY_BUFFER, impl->vbo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, impl->ebo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<void*>(3 * sizeof(float)));
  glBindVertexArray(0);
  return ActorTexturer(std::move(impl));
}

Expected<void> ActorTexturer::set_mesh(const scene::ActorMesh& mesh) {
  if (auto ok = mesh.validate(); !ok) return ok;
  Impl& r = *impl_;
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  r.interleaved.resize(mesh.vertices.size() * 6);
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    float* o = &r.interleaved[6 * i];
    for (int k = 0; k < 3; ++k) {
      o[k] = mesh.vertices[i][k];
      o[3 + k] = normals ? mesh.normals[i][k] : 0.0f;
    }
  }
  glBindVertexArray(r.vao);
  glBindBuffer(GL_ARRAY_BUFFER, r.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(r.interleaved.size() * sizeof(float)),
               r.interleaved.data(), GL_DYNAMIC_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.triangles.size() * 3 * sizeof(uint32_t)),
               mesh.triangles.data(), GL_DYNAMIC_DRAW);
  glBindVertexArray(0);
  r.index_count = GLsizei(mesh.triangles.size() * 3);
  return {};
}

Expected<void> ActorTexturer::set_camera(int slot, const Camera& camera, const uint8_t* rgb,
                                         const Eigen::Vector3f& gains) {
  if (slot < 0 || slot >= kMaxCameras) return fail("actor texturer: slot out of range");
  if (camera.width < 1 || camera.height < 1 || !rgb)
    return fail("actor texturer: camera " + camera.id + " without an image");
  if (!gains.allFinite() || (gains.array() <= 0).any())
    return fail("actor texturer: camera " + camera.id + ": colour gains must be finite and > 0");
  Slot& s = impl_->slots[slot];
  s.gains = gains;
  // The caller's framebuffer and viewport, restored at the end (creating the slot binds its own).
  GLint previous_fbo = 0, viewport[4];
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous_fbo);
  glGetIntegerv(GL_VIEWPORT, viewport);
  if (s.width != camera.width || s.height != camera.height) {
    if (!s.colour) {
      glGenTextures(1, &s.colour);
      glGenTextures(1, &s.depth);
      glGenFramebuffers(1, &s.fbo);
      glGenRenderbuffers(1, &s.depth_rb);
    }
    s.width = camera.width;
    s.height = camera.height;
    glBindTexture(GL_TEXTURE_2D, s.colour);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, s.width, s.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 nullptr);
    for (GLenum p : {GL_TEXTURE_MIN_FILTER, GL_TEXTURE_MAG_FILTER})
      glTexParameteri(GL_TEXTURE_2D, p, GL_LINEAR);
    for (GLenum p : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T})
      glTexParameteri(GL_TEXTURE_2D, p, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, s.depth);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, s.width, s.height, 0, GL_RED, GL_FLOAT, nullptr);
    for (GLenum p : {GL_TEXTURE_MIN_FILTER, GL_TEXTURE_MAG_FILTER})
      glTexParameteri(GL_TEXTURE_2D, p, GL_NEAREST);
    for (GLenum p : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T})
      glTexParameteri(GL_TEXTURE_2D, p, GL_CLAMP_TO_EDGE);
    glBindRenderbuffer(GL_RENDERBUFFER, s.depth_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, s.width, s.height);
    glBindFramebuffer(GL_FRAMEBUFFER, s.fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, s.depth, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, s.depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous_fbo));
      return fail("actor texturer: depth framebuffer incomplete");
    }
  }
  glBindTexture(GL_TEXTURE_2D, s.colour);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  add_key(rgb, std::size_t(s.width) * s.height, impl_->options.key_margin, s.rgba);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.width, s.height, GL_RGBA, GL_UNSIGNED_BYTE,
                  s.rgba.data());
  s.cam = cam_from_world(camera);
  s.centre = camera.centre_in_world();
  s.clip = clip_from_camera(camera) * s.cam;
  // Visibility: the nearest depth of the mesh along every pixel's ray of this camera.
  glBindFramebuffer(GL_FRAMEBUFFER, s.fbo);
  glViewport(0, 0, s.width, s.height);
  const float far_depth[4] = {1e9f, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, far_depth);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glUseProgram(impl_->depth_program);
  gl::set_matrix(impl_->depth_program, "clip_from_world", s.clip);
  gl::set_matrix(impl_->depth_program, "cam_from_world", s.cam);
  impl_->draw_mesh();
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous_fbo));
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  return {};
}

Expected<void> ActorTexturer::set_carving_masks(const std::vector<CarvingMask>& masks) {
  Impl& r = *impl_;
  if (int(masks.size()) > kMaxMasks) return fail("actor texturer: more than 16 carving masks");
  for (const CarvingMask& m : masks)
    if (!m.camera || !m.mask || m.camera->width != masks[0].camera->width ||
        m.camera->height != masks[0].camera->height)
      return fail("actor texturer: carving masks need a camera, a mask and one size");
  r.mask_count = 0;
  r.mask_clip.clear();
  if (masks.empty()) return {};
  const int w = masks[0].camera->width, h = masks[0].camera->height, n = int(masks.size());
  if (!r.mask_array) glGenTextures(1, &r.mask_array);
  glBindTexture(GL_TEXTURE_2D_ARRAY, r.mask_array);
  if (w != r.mask_width || h != r.mask_height || n > r.mask_layers) {
    r.mask_width = w;
    r.mask_height = h;
    r.mask_layers = std::max(n, r.mask_layers);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R8, w, h, r.mask_layers, 0, GL_RED, GL_UNSIGNED_BYTE,
                 nullptr);
    for (GLenum p : {GL_TEXTURE_MIN_FILTER, GL_TEXTURE_MAG_FILTER})
      glTexParameteri(GL_TEXTURE_2D_ARRAY, p, GL_LINEAR);
    for (GLenum p : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T})
      glTexParameteri(GL_TEXTURE_2D_ARRAY, p, GL_CLAMP_TO_EDGE);
  }
  std::vector<uint8_t> layer(std::size_t(w) * h);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < layer.size(); ++k) layer[k] = masks[i].mask[k] ? 255 : 0;
    glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, i, w, h, 1, GL_RED, GL_UNSIGNED_BYTE,
                    layer.data());
    r.mask_clip.push_back(clip_from_camera(*masks[i].camera) * cam_from_world(*masks[i].camera));
  }
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  r.mask_count = n;
  return {};
}

void ActorTexturer::draw(const DrawView& view, TextureMode mode,
                         const std::array<float, kMaxCameras>& weights, double angle_threshold) {
  Impl& r = *impl_;
  if (r.index_count == 0) return;
  glViewport(0, 0, view.width, view.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  // The mesh is closed and wound counter-clockwise seen from outside (hull/segment_mesh.h): its
  // back faces are never the nearest surface, and culling them halves the fragments that run
  // the texturing shader (its discard turns off the early depth test).
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  glDisable(GL_BLEND);
  const GLuint p = r.draw_program;
  glUseProgram(p);
  auto at = [&](const std::string& name) { return glGetUniformLocation(p, name.c_str()); };
  gl::set_matrix(p, "clip_from_world", view.clip_from_world);
  const int m = mode == TextureMode::flat ? 0 : mode == TextureMode::nearest ? 1 : 2;
  const TexturerOptions& o = r.options;
  glUniform1i(at("mode"), m);
  glUniform3f(at("eye"), float(view.eye.x()), float(view.eye.y()), float(view.eye.z()));
  glUniform1f(at("inflate"), m == 2 ? o.inflate_m : 0.0f);
  glUniform3fv(at("flat_colour"), 1, o.untextured.data());
  glUniform3fv(at("unseen"), 1, o.unseen.data());
  glUniform1f(at("tolerance"), o.depth_tolerance_m + (m == 2 ? o.inflate_m : 0.0f));
  glUniform1f(at("carve_step"), o.carve_step_m);
  glUniform1f(at("key_threshold"), o.key_threshold);
  glUniform1i(at("carve_steps"), o.carve_steps);
  glUniform1f(at("angle_threshold"), float(angle_threshold > 0 ? angle_threshold : 3.14159265));
  for (int i = 0; i < kMaxCameras; ++i) {
    const Slot& s = r.slots[i];
    const std::string k = "[" + std::to_string(i) + "]";
    float w = s.colour ? weights[i] : 0.0f;
    if (mode == TextureMode::nearest && i > 0) w = 0;
    glUniform1f(at("weight" + k), w);
    glUniform3fv(at("gain" + k), 1, s.gains.data());
    gl::set_matrix(p, ("clip" + k).c_str(), s.clip);
    gl::set_matrix(p, ("cam" + k).c_str(), s.cam);
    const Eigen::Vector3f c = s.centre.cast<float>();
    glUniform3f(at("centre" + k), c.x(), c.y(), c.z());
    glActiveTexture(GL_TEXTURE0 + 2 * i);
    glBindTexture(GL_TEXTURE_2D, s.colour);
    glUniform1i(at("colour" + std::to_string(i)), 2 * i);
    glActiveTexture(GL_TEXTURE0 + 2 * i + 1);
    glBindTexture(GL_TEXTURE_2D, s.depth);
    glUniform1i(at("depth" + std::to_string(i)), 2 * i + 1);
  }
  glUniform1i(at("mask_count"), m == 2 ? r.mask_count : 0);
  for (int i = 0; i < r.mask_count; ++i)
    gl::set_matrix(p, ("mask_clip[" + std::to_string(i) + "]").c_str(), r.mask_clip[i]);
  glActiveTexture(GL_TEXTURE0 + 2 * kMaxCameras);
  glBindTexture(GL_TEXTURE_2D_ARRAY, r.mask_array);
  glUniform1i(at("masks"), 2 * kMaxCameras);
  r.draw_mesh();
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  glDisable(GL_CULL_FACE);
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace studio::preview
