// studio-tracker locate: the head tracker's offline entry point (DESIGN §6). Loads a rig and a
// mask folder, cuts the line-segment visual hull itself, finds the heads and prints JSON:
//   {"heads": [{"position": [x, y, z], "score": s, "confidence": c}]}
// (score: the template match M = 2·a2 − a1 in m³; confidence: M relative to a reference head).
// A mask folder holds <camera_id>.png per camera (one frame) or <frame>/<camera_id>.png (a
// sequence, printed as {"frames": [{"frame": "<name>", "heads": [...]}, ...]}).
//
// Everything but `locate` (--config FILE, --help) goes to the tracker node's service_main
// (tracker/node/tracker_node.h).

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/run_mask.h"
#include "hull/silhouette_cut.h"
#include "tracker/head_search.h"
#include "tracker/segment_raster.h"
#include "tracker_node.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;
using namespace studio;

namespace {

constexpr const char* kUsage =
    "usage: studio-tracker locate --rig rig.yaml --masks DIR --box X0,Y0,Z0,X1,Y1,Z1 --grid N\n"
    "                             [--axis x|y|z] [--max-heads K] [--min-confidence C]\n"
    "  Cuts the visual hull of the masks (DIR/<camera_id>.png, or DIR/<frame>/<camera_id>.png\n"
    "  for a sequence) on N x N columns over the box (metres, studio frame) along --axis\n"
    "  (default y), finds the heads (two-box template, TCSVT 2004 §IV-D) and prints JSON:\n"
    "  {\"heads\": [{\"position\": [x, y, z], \"score\": m3, \"confidence\": c}]}.\n"
    "  The tracker node: studio-tracker --config tracker.yaml (see studio-tracker --help).\n";

int fail_line(const std::string& message) {
  std::fprintf(stderr, "studio-tracker: %s\n", message.c_str());
  return 2;
}

Expected<std::vector<double>> parse_numbers(const std::string& text, std::size_t n,
                                            const char* what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v))
      return fail(std::string(what) + ": '" + item + "' is not a number");
    out.push_back(v);
  }
  if (out.size() != n)
    return fail(std::string(what) + ": expected " + std::to_string(n) + " comma-separated numbers");
  return out;
}

// Masks of one frame, in rig camera order.
Expected<std::vector<RunMask>> load_masks(const Rig& rig, const fs::path& dir) {
  std::vector<RunMask> masks;
  for (const Camera& cam : rig.cameras) {
    const fs::path p = dir / (cam.id + ".png");
    if (!fs::is_regular_file(p)) return fail("missing mask " + p.string());
    const cv::Mat m = cv::imread(p.string(), cv::IMREAD_GRAYSCALE);
    if (m.empty()) return fail("cannot decode " + p.string());
    if (m.cols != cam.width || m.rows != cam.height)
      return fail(p.string() + ": " + std::to_string(m.cols) + "x" + std::to_string(m.rows) +
                  " but camera " + cam.id + " is " + std::to_string(cam.width) + "x" +
                  std::to_string(cam.height));
    masks.push_back(RunMask::from_mask(MaskView(m.ptr<uint8_t>(), m.cols, m.rows, m.step)));
  }
  return masks;
}

std::string heads_json(const std::vector<tracker::HeadDetection>& heads) {
  std::string s = "[";
  char buf[256];
  for (std::size_t i = 0; i < heads.size(); ++i) {
    const auto& h = heads[i];
    std::snprintf(buf, sizeof buf,
                  "%s{\"position\": [%.4f, %.4f, %.4f], \"score\": %.6g, \"confidence\": %.3f}",
                  i ? ", " : "", h.position.x(), h.position.y(), h.position.z(), h.score,
                  h.confidence);
    s += buf;
  }
  return s + "]";
}

int locate(int argc, char** argv) {
  std::string rig_path, masks_dir, box_text, axis_text = "y";
  int grid = 0;
  tracker::HeadSearchOptions options;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (i + 1 >= argc) return fail_line("option " + a + " needs a value (see --help)");
    const std::string v = argv[++i];
    char* end = nullptr;
    if (a == "--rig")
      rig_path = v;
    else if (a == "--masks")
      masks_dir = v;
    else if (a == "--box")
      box_text = v;
    else if (a == "--axis")
      axis_text = v;
    else if (a == "--grid") {
      const long n = std::strtol(v.c_str(), &end, 10);
      if (*end || n < 4 || n > 4096) return fail_line("--grid: expected an integer in [4, 4096]");
      grid = int(n);
    } else if (a == "--max-heads") {
      const long n = std::strtol(v.c_str(), &end, 10);
      if (*end || n < 1 || n > 64) return fail_line("--max-heads: expected an integer in [1, 64]");
      options.max_heads = int(n);
    } else if (a == "--min-confidence") {
      options.min_confidence = std::strtod(v.c_str(), &end);
      if (*end) return fail_line("--min-confidence: not a number");
    } else {
      return fail_line("unknown option " + a + " (see --help)");
    }
  }
  if (rig_path.empty() || masks_dir.empty() || box_text.empty() || grid == 0)
    return fail_line("locate needs --rig, --masks, --box and --grid (see --help)");
  if (auto ok = options.validate(); !ok) return fail_line(ok.error().message);
  const auto box = parse_numbers(box_text, 6, "--box");
  if (!box) return fail_line(box.error().message);
  const auto axis = hull::parse_axis(axis_text);
  if (!axis) return fail_line(axis.error().message);
  hull::GridSpec spec;
  spec.box_min = {(*box)[0], (*box)[1], (*box)[2]};
  spec.box_max = {(*box)[3], (*box)[4], (*box)[5]};
  spec.axis = *axis;
  spec.cells_u = spec.cells_v = grid;
  if (auto ok = spec.validate(); !ok) return fail_line("--box/--grid: " + ok.error().message);
  const auto rig = yaml::read_rig(rig_path);
  if (!rig) return fail_line(rig.error().message);
  if (rig->cameras.empty()) return fail_line(rig_path + ": no cameras");
  if (!fs::is_directory(masks_dir)) return fail_line("--masks: no directory " + masks_dir);

  // One frame (DIR/<cam>.png) or a sequence of frame folders.
  std::vector<fs::path> frames;
  if (fs::is_regular_file(fs::path(masks_dir) / (rig->cameras[0].id + ".png"))) {
    frames.push_back(masks_dir);
  } else {
    for (const auto& e : fs::directory_iterator(masks_dir))
      if (e.is_directory()) frames.push_back(e.path());
    std::sort(frames.begin(), frames.end());
    if (frames.empty())
      return fail_line("--masks: " + masks_dir + " holds neither " + rig->cameras[0].id +
                       ".png nor frame folders");
  }
  auto search = tracker::HeadSearch::create(options);
  if (!search) return fail_line(search.error().message);
  tracker::OccupancyGrid occupancy;
  std::string out;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const auto masks = load_masks(*rig, frames[f]);
    if (!masks) return fail_line(masks.error().message);
    std::vector<hull::View> views;
    for (std::size_t c = 0; c < rig->cameras.size(); ++c)
      views.push_back({&rig->cameras[c], &(*masks)[c]});
    const auto set = hull::visual_hull(spec, views);
    if (!set) return fail_line(set.error().message);
    tracker::rasterise(*set, &occupancy);
    const auto heads = search->find(occupancy);
    if (frames.size() == 1) {
      out = "{\"heads\": " + heads_json(heads) + "}";
    } else {
      out += (f ? ",\n  " : "{\"frames\": [\n  ");
      out += "{\"frame\": \"" + frames[f].filename().string() +
             "\", \"heads\": " + heads_json(heads) + "}";
      std::fprintf(stderr, "\rstudio-tracker: frame %zu/%zu", f + 1, frames.size());
    }
  }
  if (frames.size() > 1) {
    out += "\n]}";
    std::fputc('\n', stderr);
  }
  std::printf("%s\n", out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && !std::strcmp(argv[1], "locate")) return locate(argc - 2, argv + 2);
  return runtime::service_main(argc, argv, tracker::node::service_definition());
}
