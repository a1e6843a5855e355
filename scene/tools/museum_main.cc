// studio-scene-museum: writes the project's default demo scene, a museum hall with exhibits, as a
// GLB (run at build time; the output stays in the build folder). Echoes the paper's demonstration
// (TCSVT 2004 §VI): a virtual set around the acting area and an animated object flying close to
// the actor. Studio frame: metres, y up, floor y = 0, acting area around the origin.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>
#include <string>

#include "glb_writer.h"
#include "shapes.h"
#include "textures.h"

using namespace studio::scene_tools;

namespace {

constexpr const char* kUsage = R"(usage: studio-scene-museum --out FILE.glb

Writes the default demo scene of studio-scene: a museum hall (24 m x 28 m x 6 m) with marble
floor, panelled walls, paintings, columns, six named exhibits on pedestals
(exhibit_red_sphere, exhibit_green_torus, exhibit_blue_vase, exhibit_yellow_knot,
exhibit_magenta_cone, exhibit_cyan_cube), four lights (KHR_lights_punctual) and the animation
"flight": the node "flyer" loops in 8 s past the acting area, 1 m from a head at (0, 1.7, 0).
Prints the triangle count. Exit status 0 on success, 1 when the file cannot be written.
)";

constexpr float kPi = std::numbers::pi_v<float>;

int add_model(GlbWriter& w, int root, const std::string& name, const MeshBuild& mesh, int material,
              const Eigen::Vector3d& at) {
  GltfNode n;
  n.name = name;
  n.translation = at;
  n.mesh = w.add_mesh(name, mesh, material);
  const int id = w.add_node(n);
  w.node(root).children.push_back(id);
  return id;
}

// The flyer's path: an ellipse around the acting area, lowest and nearest at t = 0, where it
// passes (0, 1.9, 1.0), about 1 m in front of a head at (0, 1.7, 0).
Eigen::Vector3f flight_position(float theta) {
  return {6.0f * std::sin(theta), 2.5f - 0.6f * std::cos(theta), -3.0f + 4.0f * std::cos(theta)};
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else {
      std::fprintf(stderr, "studio-scene-museum: unknown argument '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (out.empty()) {
    std::fprintf(stderr, "studio-scene-museum: --out FILE.glb is required (see --help)\n");
    return 2;
  }

  GlbWriter w;
  const int t_marble = w.add_texture_png("marble", marble_png(512));
  const int t_panel = w.add_texture_png("wall_panel", wall_panel_png(512));
  const int t_stone = w.add_texture_png("stone", stone_png(256));
  const int t_landscape = w.add_texture_png("painting_landscape", landscape_png(512, 384));
  const int t_abstract = w.add_texture_png("painting_abstract", abstract_png(512, 384));

  const Eigen::Vector4f white(1, 1, 1, 1);
  const int m_floor = w.add_material("marble_floor", white, t_marble);
  const int m_wall = w.add_material("wall_panels", white, t_panel);
  const int m_ceiling = w.add_material("ceiling", Eigen::Vector4f(0.45f, 0.45f, 0.45f, 1), -1);
  const int m_stone = w.add_material("stone", white, t_stone);
  const int m_landscape = w.add_material("painting_landscape", white, t_landscape);
  const int m_abstract = w.add_material("painting_abstract", white, t_abstract);

  GltfNode root_node;
  root_node.name = "museum";
  const int root = w.add_node(root_node);

  // Hall: x in [-12, 12], z in [-18, 10], height 6.
  const float x0 = -12, x1 = 12, z0 = -18, z1 = 10, h = 6;
  const Eigen::Vector3f X = Eigen::Vector3f::UnitX(), Y = Eigen::Vector3f::UnitY(),
                        Z = Eigen::Vector3f::UnitZ();
  std::size_t triangles = 0;
  auto model = [&](const std::string& name, const MeshBuild& mesh, int material,
                   Eigen::Vector3d at) {
    triangles += mesh.triangles();
    return add_model(w, root, name, mesh, material, at);
  };
  model("floor", grid({x0, 0, z1}, (x1 - x0) * X, (z0 - z1) * Z, 48, 56, 4.0f), m_floor, {0, 0, 0});
  // 0.5 m cells like the floor: the lights hang 1.7 m below the ceiling, so its light changes
  // within a metre, and a renderer that lights per vertex (scene_render's fast shading) needs
  // the vertices to follow it.
  model("ceiling", grid({x0, h, z0}, (x1 - x0) * X, (z1 - z0) * Z, 48, 56, 4.0f), m_ceiling,
        {0, 0, 0});
  MeshBuild walls;
  walls.append(grid({x0, 0, z0}, (x1 - x0) * X, h * Y, 24, 6, 3.0f));  // back, facing +z
  walls.append(grid({x1, 0, z1}, (x0 - x1) * X, h * Y, 24, 6, 3.0f));  // front, facing -z
  walls.append(grid({x0, 0, z1}, (z0 - z1) * Z, h * Y, 28, 6, 3.0f));  // left, facing +x
  walls.append(grid({x1, 0, z0}, (z1 - z0) * Z, h * Y, 28, 6, 3.0f));  // right, facing -x
  model("walls", walls, m_wall, {0, 0, 0});

  // Paintings on the side walls, 5 cm off the wall.
  for (int k = 0; k < 3; ++k) {
    const float z = -12.0f + 7.0f * k;
    const float pw = 2.8f, ph = 2.1f;
    // The whole image once: glTF's v = 0 is the top of the image, the top edge of the canvas.
    auto canvas = [&](MeshBuild m) {
      m.uvs = {{0, 1}, {1, 1}, {0, 0}, {1, 0}};
      return m;
    };
    model("painting_left_" + std::to_string(k),
          canvas(grid({0, -ph / 2, pw / 2}, -pw * Z, ph * Y, 1, 1, pw)),
          k % 2 ? m_abstract : m_landscape, {x0 + 0.05, 3.0, z});
    model("painting_right_" + std::to_string(k),
          canvas(grid({0, -ph / 2, -pw / 2}, pw * Z, ph * Y, 1, 1, pw)),
          k % 2 ? m_landscape : m_abstract, {x1 - 0.05, 3.0, z});
  }

  // Columns.
  const MeshBuild column =
      lathe([&](float s) { return Eigen::Vector2f(s < 0.04f || s > 0.96f ? 0.45f : 0.35f, s * h); },
            48, 24);
  int c = 0;
  for (float x : {-9.0f, 9.0f})
    for (float z : {-14.0f, -3.0f, 6.0f})
      model("column_" + std::to_string(c++), column, m_stone, {x, 0, z});

  // Exhibits on pedestals along z = -8.
  struct Exhibit {
    const char* name;
    Eigen::Vector4f colour;
    MeshBuild mesh;
  };
  const Exhibit exhibits[] = {
      {"exhibit_red_sphere", {0.90f, 0.08f, 0.08f, 1}, uv_sphere(0.5f, 128, 72)},
      {"exhibit_green_torus",
       {0.08f, 0.80f, 0.15f, 1},
       torus(0.38f, 0.14f, 128, 48)
           .transformed(Eigen::AngleAxisf(kPi / 2, X).toRotationMatrix(), Eigen::Vector3f::Zero())},
      {"exhibit_blue_vase",
       {0.10f, 0.25f, 0.95f, 1},
       lathe(
           [](float s) {
             return Eigen::Vector2f(0.18f + 0.22f * std::sin(kPi * s * 1.2f) + 0.05f * s,
                                    s * 1.0f - 0.5f);
           },
           96, 48)},
      {"exhibit_yellow_knot", {0.95f, 0.80f, 0.05f, 1}, torus_knot(0.15f, 0.1f, 2, 3, 384, 16)},
      {"exhibit_magenta_cone",
       {0.85f, 0.08f, 0.80f, 1},
       lathe([](float s) { return Eigen::Vector2f(0.45f * (1 - s) + 0.001f, s - 0.5f); }, 128, 16)},
      {"exhibit_cyan_cube",
       {0.05f, 0.80f, 0.85f, 1},
       box({0.8f, 0.8f, 0.8f})
           .transformed(Eigen::AngleAxisf(kPi / 5, Y).toRotationMatrix(), Eigen::Vector3f::Zero())},
  };
  const MeshBuild pedestal = box({0.9f, 1.0f, 0.9f});
  for (int k = 0; k < 6; ++k) {
    const double x = -7.5 + 3.0 * k;
    model("pedestal_" + std::to_string(k), pedestal, m_stone, {x, 0.5, -8});
    const int mat = w.add_material(std::string(exhibits[k].name), exhibits[k].colour, -1);
    model(exhibits[k].name, exhibits[k].mesh, mat, {x, 1.55, -8});
  }

  // The flyer: a bird-like body (nose along -z) with two wings; animated.
  MeshBuild flyer_mesh =
      uv_sphere(0.5f, 48, 32)
          .transformed(Eigen::Vector3f(0.25f, 0.18f, 0.55f).asDiagonal(), Eigen::Vector3f::Zero());
  flyer_mesh.append(
      box({1.4f, 0.04f, 0.35f}).transformed(Eigen::Matrix3f::Identity(), {0, 0.02f, 0.05f}));
  flyer_mesh.append(
      box({0.5f, 0.03f, 0.2f}).transformed(Eigen::Matrix3f::Identity(), {0, 0.05f, 0.45f}));
  const int m_flyer = w.add_material("flyer", Eigen::Vector4f(1.0f, 0.55f, 0.05f, 1), -1,
                                     Eigen::Vector3f(0.3f, 0.15f, 0.0f));
  const int flyer = model("flyer", flyer_mesh, m_flyer, flight_position(0).cast<double>());
  std::vector<float> times;
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector4f> rotations;
  Eigen::Quaternionf previous = Eigen::Quaternionf::Identity();
  for (int k = 0; k <= 32; ++k) {
    const float t = 0.25f * k, theta = 2 * kPi * t / 8;
    const Eigen::Vector3f p = flight_position(theta);
    const Eigen::Vector3f v = flight_position(theta + 1e-3f) - flight_position(theta - 1e-3f);
    const float yaw = std::atan2(-v.x(), -v.z());  // nose (-z) along the velocity
    Eigen::Quaternionf q(Eigen::AngleAxisf(yaw, Y) * Eigen::AngleAxisf(0.25f * std::sin(theta), Z));
    if (q.dot(previous) < 0) q.coeffs() *= -1;  // continuous signs
    previous = q;
    times.push_back(t);
    positions.push_back(p);
    rotations.push_back(q.coeffs());
  }
  w.node(flyer).rotation = Eigen::Quaterniond(rotations[0].cast<double>());
  w.add_animation("flight", flyer, times, positions, rotations);

  // Lights: three points over the hall and a directional "skylight" pointing down and back.
  auto light = [&](const std::string& name, const std::string& type, Eigen::Vector3f colour,
                   float intensity, Eigen::Vector3d at, Eigen::Quaterniond rotation) {
    GltfNode n;
    n.name = name;
    n.translation = at;
    n.rotation = rotation;
    n.light = w.add_light(name, type, colour, intensity);
    // add_node first: it may grow the node vector, which would leave a reference taken by
    // w.node(root) in the same expression dangling (ASan: heap-use-after-free).
    const int id = w.add_node(n);
    w.node(root).children.push_back(id);
  };
  light("light_exhibits_left", "point", {1.0f, 0.97f, 0.92f}, 25, {-5, 4.3, -7},
        Eigen::Quaterniond::Identity());
  light("light_exhibits_right", "point", {1.0f, 0.97f, 0.92f}, 25, {5, 4.3, -7},
        Eigen::Quaterniond::Identity());
  light("light_stage", "point", {0.95f, 0.97f, 1.0f}, 20, {0, 4.3, 3},
        Eigen::Quaterniond::Identity());
  light("light_sky", "directional", {1.0f, 1.0f, 1.0f}, 0.6f, {0, 5.9, 0},
        Eigen::Quaterniond(Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitX())));

  const std::vector<std::uint8_t> bytes = w.bytes();
  std::ofstream file(out, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  file.close();
  if (!file) {
    std::fprintf(stderr, "studio-scene-museum: cannot write %s: %s\n", out.c_str(),
                 std::strerror(errno));
    return 1;
  }
  std::printf("%s: %zu triangles, %zu bytes\n", out.c_str(), triangles, bytes.size());
  return 0;
}
