#pragma once
// GLSL 3.30 core sources of the renderer.

#include <string>

namespace studio::scene_render::shaders {

// The lights' uniforms and their geometry, shared by the reference (per-fragment) and the fast
// (per-vertex) lit passes so both evaluate the same lights: light_towards(i, p, attenuation)
// returns the unit direction from world point p towards light i and sets its attenuation
// (inverse square past 1 m, the range window, the spot cone).
inline constexpr const char* kLights = R"(uniform int u_light_count;
uniform vec4 u_light_position[8];   // w = 0: xyz = unit direction towards the light
uniform vec3 u_light_radiance[8];   // colour x intensity x exposure
uniform vec4 u_light_spot[8];       // xyz = unit spot direction, w = cos(outer); w < -1: no cone
uniform float u_light_spot_inner[8];
uniform float u_light_range[8];
vec3 light_towards(int i, vec3 p, out float attenuation) {
  attenuation = 1.0;
  if (u_light_position[i].w == 0.0) return u_light_position[i].xyz;
  vec3 d = u_light_position[i].xyz - p;
  float d2 = max(dot(d, d), 1e-4);
  vec3 l = d * inversesqrt(d2);
  attenuation = 1.0 / max(d2, 1.0);
  if (u_light_range[i] > 0.0) {
    float r = sqrt(d2) / u_light_range[i];
    attenuation *= clamp(1.0 - r * r * r * r, 0.0, 1.0);
  }
  if (u_light_spot[i].w >= -1.0)
    attenuation *= smoothstep(u_light_spot[i].w, u_light_spot_inner[i], dot(-l, u_light_spot[i].xyz));
  return l;
}
)";

// Lit pass: per-fragment Blinn-Phong over up to 8 lights, base colour x texture x vertex colour.
// The fragment shaders are built twice (scene_programs.h): TEXTURED defined 1 or 0 after the
// #version line.
inline constexpr const char* kSceneVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec3 a_colour;
uniform mat4 u_clip_from_world;
uniform mat4 u_world_from_model;
uniform mat3 u_normal_matrix;
uniform float u_inflate;
uniform vec4 u_clip_plane;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_colour;
void main() {
  vec4 world = u_world_from_model * vec4(a_position + u_inflate * a_normal, 1.0);
  v_world = world.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_uv = a_uv;
  v_colour = a_colour;
  gl_Position = u_clip_from_world * world;
  gl_ClipDistance[0] = dot(u_clip_plane, world);
}
)";

inline const std::string kSceneFragment = std::string(R"(#version 330 core
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec3 v_colour;
out vec4 o_colour;
uniform vec4 u_base;
uniform sampler2D u_texture;
uniform vec3 u_emissive;
uniform bool u_unlit;
uniform float u_alpha;              // alpha written (1; the actor mask pass writes its colour's)
uniform vec3 u_eye;
uniform vec3 u_ambient;
)") + kLights + R"(void main() {
  vec4 base = u_base * vec4(v_colour, 1.0);
#if TEXTURED
  base *= texture(u_texture, v_uv);
#endif
  if (u_unlit) { o_colour = vec4(base.rgb, u_alpha); return; }
  vec3 n = normalize(v_normal);
  vec3 v = normalize(u_eye - v_world);
  if (dot(n, v) < 0.0) n = -n;  // two-sided
  vec3 c = u_ambient * base.rgb + u_emissive;
  for (int i = 0; i < u_light_count; ++i) {
    float attenuation;
    vec3 l = light_towards(i, v_world, attenuation);
    float ndl = max(dot(n, l), 0.0);
    if (ndl <= 0.0) continue;
    float spec = pow(max(dot(n, normalize(l + v)), 0.0), 32.0) * 0.15;
    c += u_light_radiance[i] * attenuation * (base.rgb * ndl + vec3(spec));
  }
  o_colour = vec4(clamp(c, 0.0, 1.0), u_alpha);
}
)";

// Fast lit pass (RendererOptions::Shading::fast): the same lights and Blinn-Phong terms evaluated
// per vertex (Gouraud), so the fragment stage is texture x interpolated light: what keeps a
// 1080p frame affordable on a software rasteriser. Close to the reference where meshes are
// tessellated finer than the light varies (the museum's floor and walls are grids of 0.5-1 m
// cells under lights 4 m up); a specular highlight smaller than a triangle is smoothed out.
inline const std::string kFastVertex = std::string(R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec3 a_colour;
uniform mat4 u_clip_from_world;
uniform mat4 u_world_from_model;
uniform mat3 u_normal_matrix;
uniform float u_inflate;
uniform vec4 u_clip_plane;
uniform bool u_unlit;
uniform vec3 u_eye;
)") + kLights + R"(uniform vec3 u_ambient;
out vec2 v_uv;
out vec3 v_light;     // vertex colour x (ambient + sum of radiance x attenuation x n.l)
out vec3 v_specular;  // sum of the specular terms (added)
void main() {
  vec4 world = u_world_from_model * vec4(a_position + u_inflate * a_normal, 1.0);
  gl_Position = u_clip_from_world * world;
  gl_ClipDistance[0] = dot(u_clip_plane, world);
  v_uv = a_uv;
  v_specular = vec3(0.0);
  if (u_unlit) { v_light = a_colour; return; }
  vec3 diffuse = u_ambient;
  vec3 n = normalize(u_normal_matrix * a_normal);
  vec3 v = normalize(u_eye - world.xyz);
  if (dot(n, v) < 0.0) n = -n;  // two-sided
  for (int i = 0; i < u_light_count; ++i) {
    float attenuation;
    vec3 l = light_towards(i, world.xyz, attenuation);
    float ndl = max(dot(n, l), 0.0);
    if (ndl <= 0.0) continue;
    float spec = pow(max(dot(n, normalize(l + v)), 0.0), 32.0) * 0.15;
    diffuse += u_light_radiance[i] * attenuation * ndl;
    v_specular += u_light_radiance[i] * attenuation * spec;
  }
  v_light = a_colour * diffuse;
}
)";

inline constexpr const char* kFastFragment = R"(#version 330 core
in vec2 v_uv;
in vec3 v_light;
in vec3 v_specular;
out vec4 o_colour;
uniform vec4 u_base;
uniform sampler2D u_texture;
uniform vec3 u_emissive;  // zero when unlit
uniform float u_alpha;
void main() {
  vec3 base = u_base.rgb;
#if TEXTURED
  base *= texture(u_texture, v_uv).rgb;
#endif
  o_colour = vec4(clamp(base * v_light + v_specular + u_emissive, 0.0, 1.0), u_alpha);
}
)";

// Flat pass (the projector's black surround and actor masks): one colour, alpha included, every
// vertex moved u_inflate along its normal; nothing interpolated, no clip plane.
inline constexpr const char* kFlatVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_clip_from_world;
uniform float u_inflate;
void main() { gl_Position = u_clip_from_world * vec4(a_position + u_inflate * a_normal, 1.0); }
)";

inline constexpr const char* kFlatFragment = R"(#version 330 core
out vec4 o_colour;
uniform vec4 u_colour;
void main() { o_colour = u_colour; }
)";

// Textured pass with a homography on the texture coordinates, over a convex quad of the
// framebuffer (u_corners, normalised coordinates in [0, 1]^2; the whole frame by default): two
// triangles, 6 vertices from gl_VertexID. The pixel's normalised position comes from
// gl_FragCoord and the viewport, not from interpolation, so a pixel gets the same colour
// whatever quad covers it.
inline constexpr const char* kQuadVertex = R"(#version 330 core
uniform vec2 u_corners[4];
void main() {
  const int corner[6] = int[6](0, 1, 2, 0, 2, 3);
  gl_Position = vec4(u_corners[corner[gl_VertexID]] * 2.0 - 1.0, 0.0, 1.0);
}
)";

inline constexpr const char* kQuadFragment = R"(#version 330 core
out vec4 o_colour;
uniform sampler2D u_texture;
uniform mat3 u_tex_from_screen;
uniform vec4 u_viewport;  // x, y, width, height
void main() {
  vec2 screen = (gl_FragCoord.xy - u_viewport.xy) / u_viewport.zw;
  vec3 t = u_tex_from_screen * vec3(screen, 1.0);
  vec2 uv = t.xy / t.z;
  if (t.z <= 0.0 || any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
    o_colour = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  o_colour = texture(u_texture, uv);
}
)";

}  // namespace studio::scene_render::shaders
