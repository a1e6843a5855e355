#include "gl_program.h"

#include <vector>

namespace studio::scene_render {
namespace {

std::string first_line(std::string s) {
  if (auto n = s.find('\n'); n != std::string::npos) s.resize(n);
  return s;
}

Expected<GLuint> compile(GLenum type, const char* source, const std::string& name) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::vector<char> log(4096);
    glGetShaderInfoLog(s, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(s);
    return fail(name + " shader: " + first_line(log.data()));
  }
  return s;
}

}  // namespace

Expected<GLuint> build_program(const char* vertex, const char* fragment, const std::string& name) {
  auto vs = compile(GL_VERTEX_SHADER, vertex, name + " vertex");
  if (!vs) return std::unexpected(vs.error());
  auto fs = compile(GL_FRAGMENT_SHADER, fragment, name + " fragment");
  if (!fs) {
    glDeleteShader(*vs);
    return std::unexpected(fs.error());
  }
  const GLuint p = glCreateProgram();
  glAttachShader(p, *vs);
  glAttachShader(p, *fs);
  glLinkProgram(p);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    std::vector<char> log(4096);
    glGetProgramInfoLog(p, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteProgram(p);
    return fail(name + " program: " + first_line(log.data()));
  }
  return p;
}

}  // namespace studio::scene_render
