// studio-calibrate projector: the projector's K and pose (and its screen) from a projected ChArUco
// pattern seen by the calibrated studio cameras (calibrate/projector_pattern.h), into rig.yaml.
#include "projector_cli.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "calibrate/projector_pattern.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio::calibrate {
namespace {

constexpr const char* kUsage =
    R"(usage: studio-calibrate projector --rig rig.yaml --captures DIR --pattern SPEC [options]
       studio-calibrate projector --pattern SPEC --draw-pattern FILE.png [--size WxH] [--origin X0,Y0]

Calibrates a data projector (an inverse camera: K and pose) and its screen from a ChArUco pattern
it projects, seen by two or more calibrated studio cameras (TCSVT 2004 III-C, V-C). Writes the
projector into the rig file (replacing one with the same id).

Getting a usable view of the pattern: the retro-reflective cloth returns the projector's light
to the projector, so a studio camera mostly sees its own LED ring's blue light on it. For the
captures, switch the cameras' LED rings off (or dim them well down) and lengthen the exposure
(4x or more, e.g. studioctl camera set CAM ExposureTime ...), so the pattern's white squares stand
out on the cloth; check one image before capturing. Capture the pattern on the cloth once, then
on a flat white board held in the beam at two or more distances (e.g. ~2.5 m and ~4 m from the
projector) so that the whole pattern falls on the board: the cloth alone is one plane and does
not determine the projector's distance against its focal length.

  --rig rig.yaml         the calibrated cameras (and any projectors already known)
  --captures DIR         DIR/<capture>/<camera_id>.png|jpg: one folder per capture, each camera's
                         image of the same instant (a camera may be missing from a capture)
  --boards C1,C2,...     captures with the pattern on a board held in the beam (the others are
                         on the cloth; the cloth's largest plane is the screen)
  --pattern SPEC         charuco:COLSxROWS:SQUARE_PX:MARKER_PX:DICT, sizes in projector pixels
                         (default charuco:16x9:110:80:DICT_4X4_100)
  --origin X0,Y0         projector pixel edge of the board's top-left corner (default: centred)
  --margin PX            white border around the squares (default: a third of a square)
  --projector ID         projector id in the rig (default proj0)
  --size WxH             projector resolution (default 1920x1080)
  --screen-corners X,Y,Z,... 12 numbers: measured corners (lower-left, lower-right, upper-right,
                         upper-left), projected onto the fitted screen plane; default: the extent
                         of the pattern on the screen
  --fit-radial           also fit the projector's radial distortion (rd3, rd5)
  --out rig.yaml         where to write the rig (default: --rig, in place)
  --draw-pattern FILE    write the projector frame to show (PNG, 8-bit grey) and exit
  --json                 print the result as JSON on stdout
  --quiet                no progress
)";

int usage_error(const std::string& m) {
  std::fprintf(stderr, "studio-calibrate projector: %s (see --help)\n", m.c_str());
  return 2;
}
int error(const std::string& m) {
  std::fprintf(stderr, "studio-calibrate projector: %s\n", m.c_str());
  return 1;
}

bool numbers(const std::string& s, char sep, std::vector<double>* out) {
  out->clear();
  std::stringstream in(s);
  std::string part;
  while (std::getline(in, part, sep)) {
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (part.empty() || end == part.c_str() || *end != '\0' || !std::isfinite(v)) return false;
    out->push_back(v);
  }
  return true;
}

// DIR/<capture>/<camera_id>.(png|jpg|jpeg), captures sorted by name.
Expected<std::vector<PatternCapture>> read_captures(const std::string& dir,
                                                    const std::vector<Camera>& cameras,
                                                    const std::set<std::string>& boards,
                                                    bool quiet) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(dir + ": not a directory");
  std::vector<fs::path> folders;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_directory()) folders.push_back(e.path());
  std::sort(folders.begin(), folders.end());
  if (folders.empty()) return fail(dir + ": no capture folders");
  std::set<std::string> unknown = boards;
  std::vector<PatternCapture> out;
  for (const fs::path& folder : folders) {
    PatternCapture c;
    c.name = folder.filename().string();
    c.board = boards.count(c.name) > 0;
    unknown.erase(c.name);
    int found = 0;
    for (const Camera& cam : cameras) {
      cv::Mat image;
      for (const char* ext : {".png", ".jpg", ".jpeg"}) {
        const fs::path p = folder / (cam.id + ext);
        if (!fs::exists(p, ec)) continue;
        image = cv::imread(p.string(), cv::IMREAD_GRAYSCALE);
        if (image.empty()) return fail(p.string() + ": unreadable image");
        break;
      }
      found += !image.empty();
      c.images.push_back(image);
    }
    if (found < 2) return fail(folder.string() + ": images of fewer than 2 rig cameras");
    if (!quiet)
      std::fprintf(stderr, "capture %s: %d camera images%s\n", c.name.c_str(), found,
                   c.board ? " (board)" : "");
    out.push_back(std::move(c));
  }
  if (!unknown.empty()) return fail("--boards: no capture folder '" + *unknown.begin() + "'");
  return out;
}

}  // namespace

int run_projector(const std::vector<std::string>& args) {
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
  std::string rig_path, captures_dir, out_path, draw, spec = "charuco:16x9:110:80:DICT_4X4_100";
  std::set<std::string> boards;
  std::vector<double> origin, corners;
  int width = 1920, height = 1080, margin = -1;
  bool json = false, quiet = false;
  ProjectorCalibrationOptions options;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string* into) {
      if (i + 1 >= args.size()) return false;
      *into = args[++i];
      return true;
    };
    std::string v;
    std::vector<double> nums;
    if (a == "--rig") {
      if (!value(&rig_path)) return usage_error("--rig needs a file");
    } else if (a == "--captures") {
      if (!value(&captures_dir)) return usage_error("--captures needs a folder");
    } else if (a == "--boards") {
      if (!value(&v)) return usage_error("--boards needs a list");
      std::stringstream in(v);
      for (std::string part; std::getline(in, part, ',');)
        if (!part.empty()) boards.insert(part);
    } else if (a == "--pattern") {
      if (!value(&spec)) return usage_error("--pattern needs a spec");
    } else if (a == "--origin") {
      if (!value(&v) || !numbers(v, ',', &origin) || origin.size() != 2)
        return usage_error("--origin needs X0,Y0");
    } else if (a == "--margin") {
      if (!value(&v) || !numbers(v, ',', &nums) || nums.size() != 1 || nums[0] < 0)
        return usage_error("--margin needs a number of pixels >= 0");
      margin = static_cast<int>(nums[0]);
    } else if (a == "--projector") {
      if (!value(&options.id) || options.id.empty()) return usage_error("--projector needs an id");
    } else if (a == "--size") {
      if (!value(&v) || !numbers(v, 'x', &nums) || nums.size() != 2 || nums[0] < 16 || nums[1] < 16)
        return usage_error("--size needs WxH");
      width = static_cast<int>(nums[0]);
      height = static_cast<int>(nums[1]);
    } else if (a == "--screen-corners") {
      if (!value(&v) || !numbers(v, ',', &corners) || corners.size() != 12)
        return usage_error("--screen-corners needs 12 numbers");
    } else if (a == "--fit-radial") {
      options.fit_radial = true;
    } else if (a == "--out") {
      if (!value(&out_path)) return usage_error("--out needs a file");
    } else if (a == "--draw-pattern") {
      if (!value(&draw)) return usage_error("--draw-pattern needs a file");
    } else if (a == "--json") {
      json = true;
    } else if (a == "--quiet") {
      quiet = true;
    } else {
      return usage_error("unknown option '" + a + "'");
    }
  }
  auto target = parse_target_spec(spec);
  if (!target) return error("--pattern: " + target.error().message);
  ProjectedPattern pattern;
  pattern.board = *target;
  const int s = pattern.square_px();
  pattern.margin_px = margin >= 0 ? margin : s / 3;
  pattern.x0 = origin.empty() ? (width - target->cols * s) / 2 : static_cast<int>(origin[0]);
  pattern.y0 = origin.empty() ? (height - target->rows * s) / 2 : static_cast<int>(origin[1]);
  if (auto ok = pattern.validate(width, height); !ok) return error(ok.error().message);
  if (!draw.empty()) {
    auto frame = draw_pattern(pattern, width, height);
    if (!frame) return error(frame.error().message);
    if (!cv::imwrite(draw, *frame)) return error(draw + ": cannot write");
    return 0;
  }
  if (rig_path.empty()) return usage_error("missing --rig");
  if (captures_dir.empty()) return usage_error("missing --captures");
  auto rig = yaml::read_rig(rig_path);
  if (!rig) return error(rig.error().message);
  if (rig->cameras.size() < 2) return error(rig_path + ": needs at least 2 calibrated cameras");
  auto captures = read_captures(captures_dir, rig->cameras, boards, quiet);
  if (!captures) return error(captures.error().message);
  options.width = width;
  options.height = height;
  if (!corners.empty()) {
    std::array<Eigen::Vector3d, 4> c;
    for (int k = 0; k < 4; ++k)
      c[k] = Eigen::Vector3d(corners[3 * k], corners[3 * k + 1], corners[3 * k + 2]);
    options.screen_corners = c;
  }
  auto cal = calibrate_projector_from_captures(rig->cameras, *captures, pattern, options);
  if (!cal) return error(cal.error().message);
  const ProjectorCalibrationResult& r = cal->result;
  store_projector(&*rig, r.projector);
  const std::string out = out_path.empty() ? rig_path : out_path;
  if (auto ok = yaml::write_rig(*rig, out); !ok) return error(ok.error().message);
  const auto& k = r.projector.camera.intrinsics;
  const Eigen::Vector3d C = r.projector.camera.centre_in_world();
  if (!quiet) {
    for (const CaptureReport& c : cal->captures)
      std::fprintf(stderr, "capture %s: %d corners seen by >= 2 cameras (%d on the screen)\n",
                   c.name.c_str(), c.features, c.screen);
    std::fprintf(
        stderr,
        "%s: f = %.2f, %.2f px, c = %.2f, %.2f; centre (%.4f, %.4f, %.4f) m; projector RMS "
        "%.3f px, cameras %.3f px; screen plane RMS %.2f mm -> %s\n",
        options.id.c_str(), k.fx, k.fy, k.cx, k.cy, C.x(), C.y(), C.z(), r.rms_px, r.camera_rms_px,
        1000 * r.plane_rms_m, out.c_str());
  }
  if (json) {
    std::printf(
        "{\"projector\": \"%s\", \"fx\": %.6f, \"fy\": %.6f, \"cx\": %.6f, \"cy\": %.6f, "
        "\"centre\": [%.6f, %.6f, %.6f], \"features\": %d, \"triangulated\": %d, "
        "\"screen_points\": %d, \"rms_px\": %.6f, \"camera_rms_px\": %.6f, \"plane_rms_m\": %.6f, "
        "\"out\": \"%s\"}\n",
        options.id.c_str(), k.fx, k.fy, k.cx, k.cy, C.x(), C.y(), C.z(), r.features, r.triangulated,
        r.screen_points, r.rms_px, r.camera_rms_px, r.plane_rms_m, out.c_str());
  }
  return 0;
}

}  // namespace studio::calibrate
