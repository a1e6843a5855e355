// studio-projector: one data projector (DESIGN §6). `--config projector.yaml` runs the projector
// service (projector/node/projector_node.h) through runtime::service_main; `render` renders one
// projector frame headless into a PNG: the scene from the eye through the projector's screen
// (single or two pass) and, with --mesh, the actor masked black, grown by --margin.
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "projector/mask_geometry.h"
#include "projector_node.h"
#include "projector_render/frame_renderer.h"
#include "runtime/service.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "yaml_io/rig_yaml.h"

using namespace studio;

namespace {

constexpr const char* kUsage =
    R"(usage: studio-projector --config projector.yaml      the projector service (keys below)
       studio-projector render --rig rig.yaml --projector ID --scene FILE --head X,Y,Z
                               [--mesh FILE] [--margin M] [--form single_pass|two_pass]
                               --out PNG [--mask-out PNG] [--json]

render: one projector frame, headless (OpenGL 3.3 on EGL surfaceless; Mesa llvmpipe without a
GPU): the virtual scene as the actor at --head sees it through the projector's screen rectangle
(the generalised off-axis projection, TCSVT 2004 §V-C), mapped into the projector's image by the
screen->projector homography from its calibration, and the actor mesh drawn black from the
projector's viewpoint with no depth test, grown by the security margin (§V-D).
  --rig FILE        rig.yaml with the projector (K, cam_from_world, size, screen corners)
  --projector ID    the projector's id in the rig
  --scene FILE      scene.yaml (set, nodes, animations; see studio-scene render --help) or a set
                    file (.glb/.gltf/.obj)
  --head X,Y,Z      the actor's eye, studio frame, metres; must be in front of the screen
  --mesh FILE       actor mesh (PLY, OBJ, glTF; studio frame) to mask
  --margin M        grow the mask by M metres (default 0.01)
  --form F          single_pass (the homography folded into the projection, default) or
                    two_pass (eye texture + warp)
  --out PNG         the projector frame (projector width x height)
  --mask-out PNG    the blackout mask (255 = blacked out by the actor mask)
  --json            print {"width", "height", "form", "blackout_px", "render_ms"} on stdout
Exit status: 0 written; 2 bad arguments or input (missing file, unknown projector, degenerate
screen, eye behind the screen, malformed mesh); 1 rendering failed. One line on stderr.
)";

[[noreturn]] void die(const std::string& message, int status = 2) {
  std::fprintf(stderr, "studio-projector: %s\n", message.c_str());
  std::exit(status);
}

Eigen::Vector3d parse_point(const std::string& flag, const std::string& text) {
  Eigen::Vector3d p;
  std::size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t end = k < 2 ? text.find(',', start) : text.size();
    if (end == std::string::npos) die(flag + ": expected X,Y,Z, got '" + text + "'");
    double v = 0;
    auto [q, ec] = std::from_chars(text.data() + start, text.data() + end, v);
    if (ec != std::errc() || q != text.data() + end || !std::isfinite(v))
      die(flag + ": expected X,Y,Z, got '" + text + "'");
    p[k] = v;
    start = end + 1;
  }
  return p;
}

bool write_png(const std::string& path, const cv::Mat& image) {
  try {
    return cv::imwrite(path, image);
  } catch (const cv::Exception&) {
    return false;
  }
}

int render(int argc, char** argv) {
  std::string rig_file, projector_id, scene_file, mesh_file, out, mask_out;
  std::optional<Eigen::Vector3d> head;
  double margin = 0.01;
  bool json = false;
  projector_render::Form form = projector_render::Form::single_pass;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) die(a + ": missing value (see --help)");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--rig") {
      rig_file = value();
    } else if (a == "--projector") {
      projector_id = value();
    } else if (a == "--scene") {
      scene_file = value();
    } else if (a == "--head") {
      head = parse_point(a, value());
    } else if (a == "--mesh") {
      mesh_file = value();
    } else if (a == "--margin") {
      const std::string v = value();
      auto [q, ec] = std::from_chars(v.data(), v.data() + v.size(), margin);
      if (ec != std::errc() || q != v.data() + v.size() || !(margin >= 0 && margin <= 1))
        die("--margin: expected metres in 0..1, got '" + v + "'");
    } else if (a == "--form") {
      const std::string v = value();
      if (v == "single_pass")
        form = projector_render::Form::single_pass;
      else if (v == "two_pass")
        form = projector_render::Form::two_pass;
      else
        die("--form: expected single_pass or two_pass, got '" + v + "'");
    } else if (a == "--out") {
      out = value();
    } else if (a == "--mask-out") {
      mask_out = value();
    } else if (a == "--json") {
      json = true;
    } else {
      die("render: unknown option '" + a + "' (see --help)");
    }
  }
  if (rig_file.empty() || projector_id.empty() || scene_file.empty() || !head || out.empty())
    die("render: --rig, --projector, --scene, --head and --out are required (see --help)");

  auto rig = yaml::read_rig(rig_file);
  if (!rig) die(rig.error().message);
  const Projector* p = rig->find_projector(projector_id);
  if (!p) die(rig_file + ": no projector '" + projector_id + "'");
  auto view = projector::ProjectorView::create(*p);
  if (!view) die("projector " + projector_id + ": " + view.error().message);
  if (auto ok = view->two_pass(*head); !ok) die("--head: " + ok.error().message);

  auto description = scene_config::read_scene_file(scene_file);
  if (!description) die(description.error().message);
  scene_assets::AssetCache cache;
  auto built = scene_assets::build_scene(*description, cache, 0);
  if (!built) die(built.error().message);

  std::vector<projector::ActorMesh> masks;
  if (!mesh_file.empty()) {
    auto a = scene_assets::load_asset(mesh_file);
    if (!a) die("--mesh: " + a.error().message);
    projector::ActorMesh m;
    for (const auto& md : a->meshes) {
      const auto base = static_cast<std::uint32_t>(m.vertices.size());
      m.vertices.insert(m.vertices.end(), md.positions.begin(), md.positions.end());
      for (std::size_t k = 0; k + 2 < md.indices.size(); k += 3)
        m.triangles.push_back(
            {base + md.indices[k], base + md.indices[k + 1], base + md.indices[k + 2]});
    }
    if (auto ok = m.validate(); !ok) die("--mesh: " + ok.error().message);
    auto grown = projector::grow_mesh(m, margin);
    if (!grown) die("--mesh: " + grown.error().message);
    masks.push_back(std::move(*grown));
  }

  auto context = scene_render::HeadlessContext::create();
  if (!context) die(context.error().message, 1);
  projector_render::FrameRendererOptions fo;
  fo.form = form;
  fo.thumb_width = fo.thumb_height = 0;
  auto fr = projector_render::FrameRenderer::create(*view, fo);
  if (!fr) die(fr.error().message, 1);
  for (const auto& [path, asset] : cache.all())
    if (auto ok = fr->renderer().upload(*asset); !ok) die(ok.error().message, 1);
  const auto t0 = std::chrono::steady_clock::now();
  auto drawn = fr->render(*built, *head, masks);
  if (!drawn) die("--head: " + drawn.error().message);
  fr->finish();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  projector_render::Readback rb;
  fr->read(rb, true);
  const int w = fr->width(), h = fr->height();
  cv::Mat rgba(h, w, CV_8UC4, rb.rgba.data()), bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  if (!write_png(out, bgr))
    die("cannot write '" + out + "' (a .png path in an existing folder)", 1);
  if (!mask_out.empty()) {
    const Mask m = rb.blackout.to_mask();
    cv::Mat mask(h, w, CV_8UC1, const_cast<std::uint8_t*>(m.data()));
    if (!write_png(mask_out, mask)) die("cannot write '" + mask_out + "'", 1);
  }
  if (json)
    std::printf(
        "{\"width\": %d, \"height\": %d, \"form\": \"%s\", \"blackout_px\": %llu, "
        "\"render_ms\": %.2f}\n",
        w, h, form == projector_render::Form::two_pass ? "two_pass" : "single_pass",
        static_cast<unsigned long long>(rb.blackout.area()), ms);
  else
    std::printf("%s: %dx%d, %s, %llu px blacked out, %s\n", out.c_str(), w, h,
                form == projector_render::Form::two_pass ? "two pass" : "single pass",
                static_cast<unsigned long long>(rb.blackout.area()), context->renderer().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 2) die("a command is required: render or --config FILE (see --help)");
    const std::string command = argv[1];
    if (command == "--help" || command == "-h") {
      std::fputs(kUsage, stdout);
      std::fputs("\n", stdout);
      std::fflush(stdout);  // then the service's usage and config keys
      return runtime::service_main(argc, argv, projector::projector_service_definition());
    }
    if (command == "render") return render(argc, argv);
    if (command == "--config")
      return runtime::service_main(argc, argv, projector::projector_service_definition());
    die("unknown command '" + command + "'; 'render' or --config FILE (see --help)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "studio-projector: %s\n", e.what());
    return 1;
  }
}
