#pragma once
// OpenGL declarations for the renderer's sources (GL 3.3 core entry points from glvnd's
// libOpenGL). Sources live in scene/render/ (not src/), like core/yaml's: only they may include GL.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
