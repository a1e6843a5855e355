#include "scene_programs.h"

#include <string>

#include "gl_program.h"
#include "shaders.h"

namespace studio::scene_render {
namespace {

// The source with `#define TEXTURED 0|1` after its #version line.
std::string with_textured(const std::string& source, bool textured) {
  const auto end = source.find('\n') + 1;
  return source.substr(0, end) + "#define TEXTURED " + (textured ? "1" : "0") + "\n" +
         source.substr(end);
}

}  // namespace

Expected<LitProgram> build_lit_program(bool fast, bool textured) {
  const std::string name = std::string(fast ? "scene (fast" : "scene (reference") +
                           (textured ? ", textured)" : ", untextured)");
  const std::string fragment =
      with_textured(fast ? std::string(shaders::kFastFragment) : shaders::kSceneFragment, textured);
  auto id = fast ? build_program(shaders::kFastVertex.c_str(), fragment.c_str(), name)
                 : build_program(shaders::kSceneVertex, fragment.c_str(), name);
  if (!id) return std::unexpected(id.error());
  auto loc = [p = *id](const char* n) { return glGetUniformLocation(p, n); };
  LitProgram p;
  p.id = *id;
  p.u = LitUniforms{loc("u_clip_from_world"),
                    loc("u_world_from_model"),
                    loc("u_normal_matrix"),
                    loc("u_inflate"),
                    loc("u_base"),
                    loc("u_texture"),
                    loc("u_emissive"),
                    loc("u_unlit"),
                    loc("u_eye"),
                    loc("u_ambient"),
                    loc("u_light_count"),
                    loc("u_light_position[0]"),
                    loc("u_light_radiance[0]"),
                    loc("u_light_spot[0]"),
                    loc("u_light_spot_inner[0]"),
                    loc("u_light_range[0]"),
                    loc("u_clip_plane"),
                    loc("u_alpha")};
  return p;
}

Expected<FlatProgram> build_flat_program() {
  auto id = build_program(shaders::kFlatVertex, shaders::kFlatFragment, "flat");
  if (!id) return std::unexpected(id.error());
  FlatProgram p;
  p.id = *id;
  p.clip_from_world = glGetUniformLocation(p.id, "u_clip_from_world");
  p.inflate = glGetUniformLocation(p.id, "u_inflate");
  p.colour = glGetUniformLocation(p.id, "u_colour");
  return p;
}

}  // namespace studio::scene_render
