// ActorTexturer (actor_texturer.h): a depth pass per camera slot and one textured draw.
#define GL_GLEXT_PROTOTYPES 1
#include "actor_texturer.h"

#include <GL/gl.h>
#include <GL/glext.h>

#include <string>

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
out vec3 p;
out vec3 n;
void main() {
  p = world;
  n = normal;
  gl_Position = clip_from_world * vec4(world, 1);
})";
// Slots: clip (the camera's clip_from_world), cam (cam_from_world), colour and depth textures.
// Slots 0..2: clip (the camera's clip_from_world), cam (cam_from_world), colour and depth
// textures (separate uniforms: GLSL 3.30 cannot index sampler arrays with a loop variable).
constexpr const char* kDrawFs = R"(#version 330 core
in vec3 p;
in vec3 n;
uniform int textured;
uniform vec3 flat_colour;
uniform vec3 unseen;
uniform float tolerance;
uniform float key_margin;
uniform float weight[3];
uniform mat4 clip[3];
uniform mat4 cam[3];
uniform sampler2D colour0, colour1, colour2;
uniform sampler2D depth0, depth1, depth2;
out vec4 frag;
vec3 shade(vec3 c) {
  vec3 nn = normalize(n);
  float l = 0.45 + 0.55 * abs(dot(nn, normalize(vec3(0.4, 1.0, 0.5))));
  return c * l;
}
// The cyclorama's key (keyer/: blue exceeds red and green by a margin): a camera whose pixel
// at the point is backing blue sees past the actor there (the hull is larger than the actor).
bool backing(vec3 c) { return c.b > c.r + key_margin && c.b > c.g + key_margin; }
void add(int i, sampler2D colour, sampler2D depth, inout vec3 sum, inout float wsum,
         inout int keyed) {
  if (weight[i] <= 0.0) return;
  vec4 q = clip[i] * vec4(p, 1);
  if (q.w <= 0.0) return;
  vec3 ndc = q.xyz / q.w;
  if (any(greaterThan(abs(ndc.xy), vec2(1.0)))) return;
  float z = (cam[i] * vec4(p, 1)).z;
  float seen = texture(depth, ndc.xy * 0.5 + 0.5).r;
  if (z > seen + tolerance) return;  // another part of the actor is nearer to camera i
  vec2 uv = vec2(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);  // image rows top first
  vec3 c = texture(colour, uv).rgb;
  if (backing(c)) { keyed += 1; return; }
  sum += weight[i] * c;
  wsum += weight[i];
}
void main() {
  if (textured == 0) { frag = vec4(shade(flat_colour), 1); return; }
  vec3 sum = vec3(0);
  float wsum = 0.0;
  int keyed = 0;
  add(0, colour0, depth0, sum, wsum, keyed);
  add(1, colour1, depth1, sum, wsum, keyed);
  add(2, colour2, depth2, sum, wsum, keyed);
  if (wsum == 0.0 && keyed > 0) discard;  // every camera that sees the point sees the backing
  frag = vec4(wsum > 0.0 ? sum / wsum : shade(unseen), 1);
})";

Expected<GLuint> compile(GLenum type, const char* source, const std::string& name) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[512] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    std::string first = log;
    return fail(name + ": shader: " + first.substr(0, first.find('\n')));
  }
  return s;
}

Expected<GLuint> program(const char* vs, const char* fs, const std::string& name) {
  auto v = compile(GL_VERTEX_SHADER, vs, name);
  if (!v) return std::unexpected(v.error());
  auto f = compile(GL_FRAGMENT_SHADER, fs, name);
  if (!f) {
    glDeleteShader(*v);
    return std::unexpected(f.error());
  }
  const GLuint p = glCreateProgram();
  glAttachShader(p, *v);
  glAttachShader(p, *f);
  glLinkProgram(p);
  glDeleteShader(*v);
  glDeleteShader(*f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    glDeleteProgram(p);
    return fail(name + ": link failed");
  }
  return p;
}

void set_matrix(GLuint program, const char* name, const Eigen::Matrix4d& m) {
  const Eigen::Matrix4f f = m.cast<float>();
  glUniformMatrix4fv(glGetUniformLocation(program, name), 1, GL_FALSE, f.data());
}

Eigen::Matrix4d cam_from_world(const Camera& c) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = c.cam_from_world.R();
  m.topRightCorner<3, 1>() = c.cam_from_world.translation;
  return m;
}

struct Slot {
  GLuint colour = 0, depth = 0, fbo = 0, depth_rb = 0;
  int width = 0, height = 0;
  Eigen::Matrix4d clip = Eigen::Matrix4d::Identity(), cam = Eigen::Matrix4d::Identity();
};

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

  ~Impl() {
    for (auto& s : slots) {
      glDeleteTextures(1, &s.colour);
      glDeleteTextures(1, &s.depth);
      glDeleteFramebuffers(1, &s.fbo);
      glDeleteRenderbuffers(1, &s.depth_rb);
    }
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
  auto d = program(kDepthVs, kDepthFs, "actor depth");
  if (!d) return std::unexpected(d.error());
  impl->depth_program = *d;
  auto p = program(kDrawVs, kDrawFs, "textured actor");
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

Expected<void> ActorTexturer::set_camera(int slot, const Camera& camera, const uint8_t* rgb) {
  if (slot < 0 || slot >= kMaxCameras) return fail("actor texturer: slot out of range");
  if (camera.width < 1 || camera.height < 1 || !rgb)
    return fail("actor texturer: camera " + camera.id + " without an image");
  Slot& s = impl_->slots[slot];
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
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, s.width, s.height, 0, GL_RGB, GL_UNSIGNED_BYTE,
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
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.width, s.height, GL_RGB, GL_UNSIGNED_BYTE, rgb);
  s.cam = cam_from_world(camera);
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
  set_matrix(impl_->depth_program, "clip_from_world", s.clip);
  set_matrix(impl_->depth_program, "cam_from_world", s.cam);
  impl_->draw_mesh();
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous_fbo));
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  return {};
}

void ActorTexturer::draw(const Eigen::Matrix4d& clip_from_world,
                         const std::array<float, kMaxCameras>& weights, bool textured, int width,
                         int height) {
  Impl& r = *impl_;
  if (r.index_count == 0) return;
  glViewport(0, 0, width, height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  const GLuint p = r.draw_program;
  glUseProgram(p);
  set_matrix(p, "clip_from_world", clip_from_world);
  glUniform1i(glGetUniformLocation(p, "textured"), textured ? 1 : 0);
  glUniform3fv(glGetUniformLocation(p, "flat_colour"), 1, r.options.untextured.data());
  glUniform3fv(glGetUniformLocation(p, "unseen"), 1, r.options.unseen.data());
  glUniform1f(glGetUniformLocation(p, "tolerance"), r.options.depth_tolerance_m);
  glUniform1f(glGetUniformLocation(p, "key_margin"), r.options.key_margin);
  for (int i = 0; i < kMaxCameras; ++i) {
    const Slot& s = r.slots[i];
    const std::string k = "[" + std::to_string(i) + "]";
    const float w = s.colour ? weights[i] : 0.0f;
    glUniform1f(glGetUniformLocation(p, ("weight" + k).c_str()), w);
    set_matrix(p, ("clip" + k).c_str(), s.clip);
    set_matrix(p, ("cam" + k).c_str(), s.cam);
    glActiveTexture(GL_TEXTURE0 + 2 * i);
    glBindTexture(GL_TEXTURE_2D, s.colour);
    glUniform1i(glGetUniformLocation(p, ("colour" + std::to_string(i)).c_str()), 2 * i);
    glActiveTexture(GL_TEXTURE0 + 2 * i + 1);
    glBindTexture(GL_TEXTURE_2D, s.depth);
    glUniform1i(glGetUniformLocation(p, ("depth" + std::to_string(i)).c_str()), 2 * i + 1);
  }
  r.draw_mesh();
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace studio::preview
