// studio-scene: the virtual scene's command line (DESIGN §6). For now one subcommand, `render`,
// which renders one frame of a scene headless (EGL surfaceless, llvmpipe) into a PNG. The scene
// server (`studio-scene --config scene.yaml`) is a separate node built on the scene library.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scene/view.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "scene_render/renderer.h"

using namespace studio;

namespace {

constexpr const char* kUsage = R"(usage: studio-scene render [--scene FILE] [--view eye=X,Y,Z,at=X,Y,Z[,fov=DEG]]
                           [--size WxH] [--frame N] [--mesh FILE.ply] --out PNG

Commands:
  render    render one frame of a scene headless (OpenGL 3.3 core on EGL surfaceless; Mesa's
            llvmpipe without a GPU; no display needed) and write it as a PNG

render options:
  --scene FILE   scene.yaml naming the set (glTF/GLB/OBJ), extra nodes, animations, a default
                 view (keys: scene/config/include/scene_config/scene_yaml.h); default: the demo
                 museum scene generated at build time
  --view V       camera: eye position and look-at point in the studio frame (metres, y up) and
                 vertical field of view in degrees (default 60); default: the scene file's
                 `view`, else a wide view of the whole set
  --size WxH     image size in pixels (default 1280x720; 16..8192 each)
  --frame N      studio frame at which animations are evaluated (default 0)
  --mesh FILE    an actor mesh (PLY, OBJ, glTF; studio frame) drawn at the scene's actor node
                 (one named `actor` for actor0 is added when the scene has none)
  --out PNG      output image

Exit status: 0 written; 2 bad arguments or input (missing or malformed scene file, unknown set,
bad --view); 1 rendering failed (no EGL, output not writable). Errors are one line on stderr.
)";


[[noreturn]] void die(const std::string& message, int status = 2) {
  std::fprintf(stderr, "studio-scene: %s\n", message.c_str());
  std::exit(status);
}

std::optional<double> number(std::string_view s) {
  double v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

// "eye=X,Y,Z,at=X,Y,Z,fov=DEG" -> ViewSpec.
scene_assets::ViewSpec parse_view(const std::string& text) {
  const std::string usage = "--view: expected eye=X,Y,Z,at=X,Y,Z[,fov=DEG], got '" + text + "'";
  scene_assets::ViewSpec v;
  std::string key;
  std::vector<double>* target = nullptr;
  std::vector<double> fov;
  bool seen_eye = false, seen_at = false;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string token = text.substr(start, end - start);
    if (auto eq = token.find('='); eq != std::string::npos) {
      key = token.substr(0, eq);
      token = token.substr(eq + 1);
      if (key == "eye" && !seen_eye) {
        target = &v.eye;
        seen_eye = true;
      } else if (key == "at" && !seen_at) {
        target = &v.at;
        seen_at = true;
      } else if (key == "fov" && fov.empty()) {
        target = &fov;
      } else {
        die(usage);
      }
      target->clear();
    }
    if (!target) die(usage);
    auto x = number(token);
    if (!x) die(usage);
    target->push_back(*x);
    start = end + 1;
  }
  if (!seen_eye || !seen_at || v.eye.size() != 3 || v.at.size() != 3 || fov.size() > 1) die(usage);
  if (!fov.empty()) v.fov_deg = fov[0];
  if (!(v.fov_deg > 1 && v.fov_deg < 179)) die("--view: fov must be in (1, 179) degrees");
  if (Eigen::Vector3d(v.eye[0] - v.at[0], v.eye[1] - v.at[1], v.eye[2] - v.at[2]).norm() < 1e-6)
    die("--view: eye and at are the same point");
  return v;
}

std::pair<int, int> parse_size(const std::string& text) {
  const auto x = text.find('x');
  int w = 0, h = 0;
  auto ok = [](std::string_view s, int& out) {
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && p == s.data() + s.size();
  };
  if (x == std::string::npos || !ok(std::string_view(text).substr(0, x), w) ||
      !ok(std::string_view(text).substr(x + 1), h) || w < 16 || h < 16 || w > 8192 || h > 8192)
    die("--size: expected WxH with 16..8192 pixels each, got '" + text + "'");
  return {w, h};
}

// A wide view of every model node from above and in front of the set.
scene_assets::ViewSpec auto_view(const scene::Scene& s, const scene_assets::AssetCache& cache) {
  Eigen::AlignedBox3d box;
  for (const auto& [id, n] : s.nodes())
    if (n.kind == scene::NodeKind::model)
      if (auto a = cache.find(n.asset.path)) box.extend(scene_assets::world_bounds(s, id, *a));
  if (box.isEmpty()) box = Eigen::AlignedBox3d(Eigen::Vector3d(-2, 0, -2), Eigen::Vector3d(2, 2, 2));
  const Eigen::Vector3d c = box.center();
  const double d = box.sizes().norm();
  scene_assets::ViewSpec v;
  v.at = {c.x(), c.y(), c.z()};
  v.eye = {c.x(), c.y() + 0.35 * d, c.z() + 0.6 * d};
  v.fov_deg = 60;
  return v;
}

int render(int argc, char** argv) {
  std::string scene_file = std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml", out, mesh_file;
  std::optional<scene_assets::ViewSpec> view;
  int width = 1280, height = 720;
  std::int64_t frame = 0;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) die(a + ": missing value (see --help)");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--scene") {
      scene_file = value();
    } else if (a == "--view") {
      view = parse_view(value());
    } else if (a == "--size") {
      std::tie(width, height) = parse_size(value());
    } else if (a == "--frame") {
      const std::string v = value();
      auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), frame);
      if (ec != std::errc() || p != v.data() + v.size() || frame < 0)
        die("--frame: expected a frame number >= 0, got '" + v + "'");
    } else if (a == "--mesh") {
      mesh_file = value();
    } else if (a == "--out") {
      out = value();
    } else {
      die("render: unknown option '" + a + "' (see --help)");
    }
  }
  if (out.empty()) die("render: --out PNG is required (see --help)");

  auto description = scene_config::read_scene_file(scene_file);
  if (!description) die(description.error().message);
  scene_assets::AssetCache cache;
  auto built = scene_assets::build_scene(*description, cache, frame);
  if (!built) die(built.error().message);
  scene::Scene& s = *built;

  std::optional<scene::ActorMesh> actor;
  if (!mesh_file.empty()) {
    auto a = scene_assets::load_asset(mesh_file);
    if (!a) die("--mesh: " + a.error().message);
    std::string actor_id;
    for (const auto& [id, n] : s.nodes())
      if (n.kind == scene::NodeKind::actor) {
        actor_id = n.actor_id;
        break;
      }
    if (actor_id.empty()) {
      actor_id = "actor0";
      scene::Node n;
      n.id = "actor";
      n.kind = scene::NodeKind::actor;
      n.actor_id = actor_id;
      n.material.colour = {0.8f, 0.7f, 0.6f, 1.0f};
      if (auto ok = s.apply({frame, scene::AddNode{n}}); !ok) die("--mesh: " + ok.error().message);
    }
    actor.emplace();
    actor->actor_id = actor_id;
    actor->frame = frame;
    for (const auto& m : a->meshes) {
      const auto base = static_cast<std::uint32_t>(actor->vertices.size());
      actor->vertices.insert(actor->vertices.end(), m.positions.begin(), m.positions.end());
      actor->normals.insert(actor->normals.end(), m.normals.begin(), m.normals.end());
      if (!m.colours.empty()) actor->colours.insert(actor->colours.end(), m.colours.begin(), m.colours.end());
      for (std::size_t k = 0; k + 2 < m.indices.size(); k += 3)
        actor->triangles.push_back({base + m.indices[k], base + m.indices[k + 1], base + m.indices[k + 2]});
    }
    if (actor->colours.size() != actor->vertices.size()) actor->colours.clear();
  }

  const scene_assets::ViewSpec v = view ? *view : description->view ? *description->view : auto_view(s, cache);
  scene_render::View camera;
  camera.cam_from_world = scene::look_at({v.eye[0], v.eye[1], v.eye[2]}, {v.at[0], v.at[1], v.at[2]});
  camera.clip_from_cam = scene::perspective(v.fov_deg * std::numbers::pi / 180,
                                            static_cast<double>(width) / height, 0.05, 200.0);

  auto context = scene_render::HeadlessContext::create();
  if (!context) die(context.error().message, 1);
  auto renderer = scene_render::Renderer::create();
  if (!renderer) die(renderer.error().message, 1);
  for (const auto& [path, asset] : cache.all())
    if (auto ok = renderer->upload(*asset); !ok) die(ok.error().message, 1);
  if (actor)
    if (auto ok = renderer->set_actor_mesh(*actor); !ok) die("--mesh: " + ok.error().message);
  auto target = scene_render::RenderTarget::create(width, height);
  if (!target) die(target.error().message, 1);
  target->bind();
  renderer->draw(s, camera);
  std::vector<std::uint8_t> rgba;
  target->read_rgba(rgba);
  cv::Mat image(height, width, CV_8UC4, rgba.data()), bgr;
  cv::cvtColor(image, bgr, cv::COLOR_RGBA2BGR);
  bool written = false;
  try {
    written = cv::imwrite(out, bgr);
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) die("cannot write '" + out + "' (a .png path in an existing folder)", 1);
  std::printf("%s: %dx%d, frame %lld, %d draw calls, %s\n", out.c_str(), width, height,
              static_cast<long long>(frame), renderer->draw_calls_last_frame(), context->renderer().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 2) die("a command is required: render (see --help)");
    const std::string command = argv[1];
    if (command == "--help" || command == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (command == "render") return render(argc, argv);
    if (command == "--config") die("--config: the scene server is not part of this build; only 'render' (see --help)");
    die("unknown command '" + command + "'; only 'render' (see --help)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "studio-scene: internal error: %s\n", e.what());
    return 1;
  }
}
