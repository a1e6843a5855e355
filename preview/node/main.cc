// studio-preview: the director's preview and control panel (issue 16). GUI (GLFW + Dear ImGui,
// OpenGL 3.3) by default; --headless renders through EGL with no display.
#include <charconv>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "core/log.h"
#include "gui.h"
#include "headless.h"
#include "preview_config.h"

using namespace studio;

namespace {

constexpr const char* kUsage =
    R"(usage: studio-preview [--config preview.yaml] [--viewpoint V] [--texturing blend|nearest]
                      [--colour-balance on|off] [--size WxH] [--overlays LIST]
       studio-preview --headless --screenshot PNG [--frames N | --duration S] [--every S]
                      [--record DIR] [--timeout S] [--settle S]
                      [--match-cameras] [--json] [same options]

The director's preview and control panel: the virtual scene (studio/scene/node) and the live
actor mesh (studio/actor/mesh) from any viewpoint, the actor textured from the studio cameras
with the images of exactly the frame that built the mesh (requested from the capture servers'
rings: studio/camera/image_request -> image_reply); panels for the cameras (CameraControl and
read-back), capture (takes at a frame), animation (play, pause, seek, speed), services and
projectors (each projector's latest thumbnail). Over the 3D view: the tracked head
(studio/actor/head), the studio cameras' frusta (studio/camera/calibration), the projectors'
frusta and their screens showing what each projector shows (studio/projector/calibration and
the thumbnails of studio/projector/frame).
Publishes its own studio/service/status (service "preview", the config's instance).

Options:
  --config FILE     preview.yaml (keys below); without it, the defaults and the environment
  --viewpoint V     eye=X,Y,Z,at=X,Y,Z[,fov=DEG] (studio frame, metres, y up)
  --texturing T     blend (up to three cameras: the hull carved per pixel by their keys and
                    every camera's mask of the mesh's frame, visibility by depth maps,
                    per-point ULR weights) or nearest (the paper's)
  --colour-balance B
                    on (default; preview.yaml's colour_balance) or off: each texturing camera's
                    image drawn with its colour gains, estimated live from the surface points two
                    cameras both see, so that cameras whose exposure or white balance differ
                    leave no seams; gains stay 1 while every camera is within 5 % of the rig
  --size WxH        window or screenshot size
  --overlays LIST   which overlays the 3D view draws: any of head, cameras, projectors,
                    screens (comma separated), all or none (default all; preview.yaml's
                    head_marker, camera_frusta, projector_frusta, projector_screens)
  --headless        no window: EGL surfaceless rendering (Mesa llvmpipe without a GPU)
  --screenshot PNG  headless: the last frame
  --frames N        headless: draw N new meshes, then stop (default 1; 0 = the scene only)
  --record DIR      headless: every drawn mesh's frame as DIR/<n>.png plus DIR/frames.jsonl
                    ({"image", "source_frame", "textured", "cameras", "gains", "estimated"}
                    per line: gains drawn with, the colour balance's estimate then)
  --timeout S       headless: give up after S seconds (default 30)
  --settle S        headless with --frames 0: draw for S seconds before the screenshot, so
                    the scene and the overlays' topics arrive (default 1)
  --duration S      headless: draw every mesh that arrives for S seconds, then stop (instead
                    of --frames)
  --every S         headless: low-rate pictures: at most one new mesh every S seconds, the
                    screenshot rewritten with each (renamed into place, never half written);
                    only the drawn meshes' images are requested; runs for --duration, else
                    until SIGINT/SIGTERM; exit 1 if no mesh was drawn
  --match-cameras   headless: whenever the colour balance finds some camera more than 8 % off
                    the rig (24 frames pooled since the last match; 3 rounds at most; less is
                    within the live estimate's own error), send the whole rig's estimate (16
                    samples of every camera's images, one each colour_balance_rig_s, 0.5 s) to
                    the cameras: CameraControl Gain (dB, the green factor; one level for the
                    rig, no camera pushed below its lowest gain; cameras the balance has not
                    linked take that level only) and BalanceRatioRed / BalanceRatioBlue (white
                    balance against green) where the camera has them; the balance then starts
                    afresh and learns what the controls did not take. In the window: the View
                    panel's "Match cameras"
  --json            headless: the summary as one JSON line ("overlays": the heads, cameras,
                    calibrated projectors and thumbnails received; "colour_balance": applied,
                    frames pooled, busy (meshes skipped while pooling the previous),
                    rig_frames / rig_dropped (rig samples pooled / given up), camera
                    pairs and per camera id its gains; "camera_match": null without
                    --match-cameras, else per round the changes sent {"level_db", "matched",
                    "changes": [{"camera", "feature", "from", "to"}], "left"} or {"error"})
  --test-script F   GUI: scripted input for tests (gui.h: one action per line)

Headless, SIGINT/SIGTERM end the run like its deadline (the screenshot is written).
Exit status: 0 done; 1 runtime failure (no display / EGL, DDS, fewer meshes than asked within
the timeout: the screenshot is still written); 2 bad arguments or config.
)";

[[noreturn]] void die(const std::string& message, int status = 2) {
  std::fprintf(stderr, "studio-preview: %s\n", message.c_str());
  std::exit(status);
}

template <class T>
T number(const std::string& flag, const std::string& text, T lo, T hi) {
  T v{};
  auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || p != text.data() + text.size() || !(v >= lo && v <= hi))
    die(flag + ": expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
        "], got '" + text + "'");
  return v;
}

int run(int argc, char** argv) {
  std::string config_path, viewpoint, texturing, size, script, overlays, balance;
  bool headless = false;
  preview::HeadlessOptions h;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) die(a + ": missing value (see --help)");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      std::fputs(preview::kConfigHelp, stdout);
      return 0;
    } else if (a == "--config") {
      config_path = value();
    } else if (a == "--viewpoint") {
      viewpoint = value();
    } else if (a == "--texturing") {
      texturing = value();
    } else if (a == "--colour-balance") {
      balance = value();
    } else if (a == "--size") {
      size = value();
    } else if (a == "--overlays") {
      overlays = value();
    } else if (a == "--settle") {
      h.settle_s = number<double>(a, value(), 0, 3600);
    } else if (a == "--headless") {
      headless = true;
    } else if (a == "--screenshot") {
      h.screenshot = value();
    } else if (a == "--frames") {
      h.frames = number<int>(a, value(), 0, 1000000);
    } else if (a == "--record") {
      h.record = value();
    } else if (a == "--timeout") {
      h.timeout_s = number<double>(a, value(), 0.1, 86400);
    } else if (a == "--duration") {
      h.duration_s = number<double>(a, value(), 0.1, 86400);
    } else if (a == "--every") {
      h.every_s = number<double>(a, value(), 0.04, 3600);
    } else if (a == "--json") {
      h.json = true;
    } else if (a == "--match-cameras") {
      h.match_cameras = true;
    } else if (a == "--test-script") {
      script = value();
    } else {
      die("unknown option '" + a + "' (see --help)");
    }
  }
  auto config = preview::read_preview_config(config_path);
  if (!config) die(config.error().message);
  if (!viewpoint.empty()) {
    auto v = preview::parse_viewpoint(viewpoint);
    if (!v) die("--viewpoint: " + v.error().message);
    config->viewpoint = *v;
  }
  if (!texturing.empty()) {
    if (texturing != "blend" && texturing != "nearest")
      die("--texturing: expected blend or nearest, got '" + texturing + "'");
    config->blend = texturing == "blend";
  }
  if (!balance.empty()) {
    if (balance != "on" && balance != "off")
      die("--colour-balance: expected on or off, got '" + balance + "'");
    config->colour_balance = balance == "on";
  }
  if (!size.empty()) {
    const auto x = size.find('x');
    if (x == std::string::npos) die("--size: expected WxH, got '" + size + "'");
    config->width = number<int>("--size", size.substr(0, x), 16, 8192);
    config->height = number<int>("--size", size.substr(x + 1), 16, 8192);
  }
  if (!overlays.empty())
    if (auto ok = preview::parse_overlay_list(overlays, config->overlays); !ok)
      die("--overlays: " + ok.error().message);
  if (!config->log.empty() && !log::configure(config->log))
    die("log: bad spec '" + config->log + "'");
  if (headless) {
    if (h.screenshot.empty()) die("--headless needs --screenshot PNG (see --help)");
    if (h.every_s > 0 && h.frames == 0)
      die("--every draws meshes; --frames 0 draws the scene only: use one of them");
    return preview::run_headless(*config, h);
  }
  if (!h.screenshot.empty() || !h.record.empty())
    die("--screenshot and --record are headless options (add --headless)");
  if (h.match_cameras)
    die("--match-cameras is a headless option (the window has the View panel's Match cameras)");
  return preview::run_gui(*config, script);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "studio-preview: %s\n", e.what());
    return 1;
  }
}
