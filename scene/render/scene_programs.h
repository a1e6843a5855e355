#pragma once
// The programs draw() and the flat passes use, with their uniform locations.
//
// The lit program comes in two variants, textured and untextured, chosen per mesh: llvmpipe
// runs a sampler inside `if (uniform)` for every fragment whatever the uniform's value (its
// shaders branch by execution mask), so one program with a "textured" flag made every untextured
// pixel (ceiling, exhibits, actor) pay a texture fetch and filter. The flat program (one colour,
// nothing interpolated) draws the projector's black surround and actor masks.

#include <array>

#include "core/error.h"
#include "gl.h"

namespace studio::scene_render {

struct LitUniforms {
  GLint clip_from_world, world_from_model, normal_matrix, inflate, base, texture, emissive, unlit,
      eye, ambient, light_count, light_position, light_radiance, light_spot, light_spot_inner,
      light_range, clip_plane, alpha;
};

struct LitProgram {
  GLuint id = 0;
  LitUniforms u{};
};

// fast: lights per vertex (shaders::kFastVertex); else per fragment (the reference).
Expected<LitProgram> build_lit_program(bool fast, bool textured);

struct FlatProgram {
  GLuint id = 0;
  GLint clip_from_world = -1, inflate = -1, colour = -1;
};

Expected<FlatProgram> build_flat_program();

}  // namespace studio::scene_render
