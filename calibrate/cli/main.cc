// studio-calibrate: one-stage multi-camera calibration (DESIGN §6, TCSVT 2004 §IV-A).
//
//   studio-calibrate cameras (--images DIR | --observations FILE) --target SPEC --out rig.yaml
//                    [--report FILE.json] [options]
//
// Exit 0 on success; 1 with one line on stderr for bad input or a failed calibration; 2 for a
// usage error. Progress goes to stderr; the report is JSON.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "calibrate/camera_calibration.h"
#include "calibrate/detect.h"
#include "calibrate/report.h"
#include "calibrate/text.h"
#include "core/rig.h"
#include "observations_yaml.h"
#include "projector_cli.h"
#include "yaml_io/opencv_yaml.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;
using namespace studio;
using namespace studio::calibrate;

namespace {

constexpr const char* kUsage = R"(usage: studio-calibrate cameras (--images DIR | --observations FILE) --target SPEC --out rig.yaml
                        [--report FILE.json] [options]

One-stage calibration of every camera from synchronous views of a planar target (TCSVT 2004 IV-A).

  --images DIR           DIR/<camera_id>/<frame_id>.png|jpg, same frame id = same instant
  --observations FILE    observations.yaml (DESIGN 4): target, optional camera sizes, frames
  --target SPEC          chessboard:COLSxROWS:SPACING_M (inner corners) | grid:COLSxROWS:SPACING_M |
                         charuco:COLSxROWS:SQUARE_M:MARKER_M:DICT | FILE.yaml
                         (optional with --observations when the file has a target)
  --out rig.yaml         the calibrated rig (DESIGN 4)
  --report FILE.json     overall, per-camera, per-frame, held-out RMS, iterations, time, outliers
  --plots DIR            residual plot PNG per camera (default: <report or out>_residuals/)
  --opencv DIR           one OpenCV FileStorage YAML per camera (default: <out>_opencv/)
  --origin FRAME         the frame with the target on the floor at the studio origin
  --floor F1,F2,...      frames with the target lying on the floor elsewhere
  --holdout F1,F2,...    frames left out of the solve and scored after it
  --kfold K              also score K-fold cross-validation (K >= 2)
  --fix LIST             keep fixed: focal,aspect,principal-point,rd3,rd5
  --loss huber|cauchy|none   robust loss (default huber)   --loss-scale PX (default 1)
  --outlier-sigmas S     drop residuals over S robust sigmas (default 5) and
  --outlier-min-px PX    ... over PX pixels (default 0.5)
  --threads N            Ceres threads (default 2)
  --save-observations FILE   write the detections as observations.yaml
  --quiet                no progress
Without --origin (or an origin frame in the file) the first camera is the studio frame.

       studio-calibrate projector --rig rig.yaml --captures DIR --pattern SPEC [options]
Calibrates a projector from a projected pattern (see studio-calibrate projector --help).
)";

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string part;
  while (std::getline(in, part, ','))
    if (!part.empty()) out.push_back(part);
  return out;
}

int usage_error(const std::string& message) {
  std::fprintf(stderr, "studio-calibrate: %s (see --help)\n", message.c_str());
  return 2;
}

int error(const std::string& message) {
  std::fprintf(stderr, "studio-calibrate: %s\n", message.c_str());
  return 1;
}

bool write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  return static_cast<bool>(out);
}

std::string without_yaml(const std::string& path) {
  fs::path p(path);
  if (p.extension() == ".yaml" || p.extension() == ".yml" || p.extension() == ".json") p.replace_extension();
  return p.string();
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && args[0] == "projector") return run_projector(args);
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
  if (args.empty()) return usage_error("missing command 'cameras' or 'projector'");
  if (args[0] != "cameras") return usage_error("unknown command '" + args[0] + "'");

  std::string images, observations_file, target_spec, out, report, plots, opencv_dir, origin,
      save_observations;
  std::vector<std::string> floor_frames, holdout;
  bool quiet = false;
  CalibrationOptions options;
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string* into) {
      if (i + 1 >= args.size()) return false;
      *into = args[++i];
      return true;
    };
    auto number = [&](double* into) {
      std::string v;
      if (!value(&v)) return false;
      char* end = nullptr;
      *into = std::strtod(v.c_str(), &end);
      return end != v.c_str() && *end == '\0';
    };
    std::string list;
    double x = 0;
    if (a == "--images") { if (!value(&images)) return usage_error("--images needs a folder"); }
    else if (a == "--observations") { if (!value(&observations_file)) return usage_error("--observations needs a file"); }
    else if (a == "--target") { if (!value(&target_spec)) return usage_error("--target needs a SPEC"); }
    else if (a == "--out") { if (!value(&out)) return usage_error("--out needs a file"); }
    else if (a == "--report") { if (!value(&report)) return usage_error("--report needs a file"); }
    else if (a == "--plots") { if (!value(&plots)) return usage_error("--plots needs a folder"); }
    else if (a == "--opencv") { if (!value(&opencv_dir)) return usage_error("--opencv needs a folder"); }
    else if (a == "--origin") { if (!value(&origin)) return usage_error("--origin needs a frame id"); }
    else if (a == "--save-observations") { if (!value(&save_observations)) return usage_error("--save-observations needs a file"); }
    else if (a == "--floor") { if (!value(&list)) return usage_error("--floor needs frame ids"); floor_frames = split_list(list); }
    else if (a == "--holdout") { if (!value(&list)) return usage_error("--holdout needs frame ids"); holdout = split_list(list); }
    else if (a == "--kfold") { if (!number(&x) || x != static_cast<int>(x)) return usage_error("--kfold needs an integer"); options.k_fold = static_cast<int>(x); }
    else if (a == "--threads") { if (!number(&x) || x != static_cast<int>(x)) return usage_error("--threads needs an integer"); options.bundle.threads = static_cast<int>(x); }
    else if (a == "--loss-scale") { if (!number(&options.bundle.loss_scale_px)) return usage_error("--loss-scale needs a number"); }
    else if (a == "--outlier-sigmas") { if (!number(&options.outlier_sigmas)) return usage_error("--outlier-sigmas needs a number"); }
    else if (a == "--outlier-min-px") { if (!number(&options.outlier_min_px)) return usage_error("--outlier-min-px needs a number"); }
    else if (a == "--quiet") { quiet = true; }
    else if (a == "--loss") {
      if (!value(&list)) return usage_error("--loss needs huber, cauchy or none");
      if (list == "huber") options.bundle.loss = BundleOptions::Loss::huber;
      else if (list == "cauchy") options.bundle.loss = BundleOptions::Loss::cauchy;
      else if (list == "none") options.bundle.loss = BundleOptions::Loss::none;
      else return usage_error("--loss must be huber, cauchy or none");
    } else if (a == "--fix") {
      if (!value(&list)) return usage_error("--fix needs a list");
      for (const auto& f : split_list(list)) {
        if (f == "focal") options.fixed.focal = true;
        else if (f == "aspect") options.fixed.aspect = true;
        else if (f == "principal-point") options.fixed.principal_point = true;
        else if (f == "rd3") options.fixed.rd3 = true;
        else if (f == "rd5") options.fixed.rd5 = true;
        else return usage_error("--fix: unknown parameter '" + f + "'");
      }
    } else {
      return usage_error("unknown option '" + a + "'");
    }
  }
  if (images.empty() == observations_file.empty())
    return usage_error("give exactly one of --images DIR and --observations FILE");
  if (out.empty()) return usage_error("missing --out rig.yaml");
  if (target_spec.empty() && images.size()) return usage_error("missing --target SPEC");
  if (auto v = options.validate(); !v) return error(v.error().message);
  auto progress = [&](const std::string& line) {
    if (!quiet) std::fprintf(stderr, "%s\n", line.c_str());
  };
  options.progress = progress;

  std::optional<TargetSpec> target;
  if (!target_spec.empty()) {
    const std::string ext = fs::path(target_spec).extension().string();
    auto t = (ext == ".yaml" || ext == ".yml") ? read_target_yaml(target_spec)
                                               : parse_target_spec(target_spec);
    if (!t) return error(t.error().message);
    target = *t;
  }
  Observations obs;
  if (!images.empty()) {
    auto detected = detect_directory(images, *target, progress);
    if (!detected) return error(detected.error().message);
    obs = std::move(*detected);
  } else {
    auto file = read_observations_yaml(observations_file);
    if (!file) return error(file.error().message);
    if (!target) target = file->target;
    if (!target) return error(observations_file + ": no target in the file; give --target SPEC");
    obs = std::move(file->observations);
  }
  // Placement flags override the file's.
  std::set<std::string> known;
  for (const auto& f : obs.frames) known.insert(f.id);
  auto check = [&](const std::string& id, const char* flag) {
    return known.count(id) ? std::string() : format("{} {}: no such frame (or the target was never detected in it)", flag, id);
  };
  if (!origin.empty()) {
    if (auto e = check(origin, "--origin"); !e.empty()) return error(e);
    for (auto& f : obs.frames) {
      if (f.placement == Placement::origin) f.placement = Placement::free;
      if (f.id == origin) f.placement = Placement::origin;
    }
  }
  for (const auto& id : floor_frames) {
    if (auto e = check(id, "--floor"); !e.empty()) return error(e);
    for (auto& f : obs.frames) if (f.id == id) f.placement = Placement::floor;
  }
  for (const auto& id : holdout) {
    if (auto e = check(id, "--holdout"); !e.empty()) return error(e);
    for (auto& f : obs.frames) if (f.id == id) f.holdout = true;
  }
  if (!save_observations.empty() && !write_text(save_observations, format_observations_yaml(obs, *target)))
    return error(save_observations + ": cannot write");

  progress(format("calibrating {} cameras from {} frames, {} observations", obs.cameras.size(),
                  obs.frames.size(), obs.observation_count()));
  auto result = calibrate_cameras(obs, target->points(), options);
  if (!result) return error(result.error().message);

  Rig rig;
  rig.cameras = result->cameras;
  if (auto v = rig.validate(); !v) return error("calibrated rig is invalid: " + v.error().message);
  if (auto w = yaml::write_rig(rig, out); !w) return error(w.error().message);
  if (opencv_dir.empty()) opencv_dir = without_yaml(out) + "_opencv";
  std::error_code ec;
  fs::create_directories(opencv_dir, ec);
  if (ec) return error(opencv_dir + ": " + ec.message());
  for (const Camera& c : rig.cameras)
    if (auto w = yaml::export_opencv_yaml(c, (fs::path(opencv_dir) / (c.id + ".yaml")).string()); !w)
      return error(w.error().message);
  if (!report.empty() && !write_text(report, report_json(*result))) return error(report + ": cannot write");
  if (plots.empty()) plots = without_yaml(report.empty() ? out : report) + "_residuals";
  auto written = write_residual_plots(*result, plots);
  if (!written) return error(written.error().message);

  std::printf("rms %.4f px over %d observations, held-out %.4f px (%d), %zu outliers, %d iterations, "
              "%.2f s; gauge %s; wrote %s\n",
              result->rms_px, result->observations, result->heldout_rms_px,
              result->heldout_observations, result->outliers.size(), result->iterations,
              result->seconds, result->gauge.c_str(), out.c_str());
  return 0;
}
