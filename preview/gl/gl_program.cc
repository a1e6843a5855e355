// Shader programs for the preview's GL drawers (gl_program.h).
#define GL_GLEXT_PROTOTYPES 1
#include "gl_program.h"

namespace studio::preview::gl {
namespace {

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

}  // namespace

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

}  // namespace studio::preview::gl
