#pragma once
// Shader programs and uniforms shared by the preview's GL drawers (actor_texturer.h,
// overlay_renderer.h). Needs a current OpenGL 3.3 core context.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <Eigen/Core>
#include <string>

#include "core/error.h"

namespace studio::preview::gl {

// Compiles and links a vertex + fragment shader pair; the error names `name` and the first line
// of the compiler's log.
Expected<GLuint> program(const char* vs, const char* fs, const std::string& name);
// Sets a mat4 uniform (column-major, as Eigen stores it).
void set_matrix(GLuint program, const char* name, const Eigen::Matrix4d& m);

}  // namespace studio::preview::gl
