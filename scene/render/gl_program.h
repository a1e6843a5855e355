#pragma once
// Shader program building with one-line errors (the GLSL log's first line).
#include <string>

#include "core/error.h"
#include "gl.h"

namespace studio::scene_render {

Expected<GLuint> build_program(const char* vertex, const char* fragment, const std::string& name);

}  // namespace studio::scene_render
