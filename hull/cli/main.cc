// studio-hull: the visual hull service's command line (DESIGN §6): the DDS node (--config, see
// node/hull_node.h) and the offline mode.
//
//   studio-hull offline --rig rig.yaml --masks DIR --box X0,Y0,Z0,X1,Y1,Z1 --grid N
//                       [--axis x|y|z] [--frames A:B] --out FILE|DIR [--format ply|obj|glb]
//                       [--outside keep|cut] [--threads N] [--timing]
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hull/mesh_io.h"
#include "hull_node.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;
using namespace studio;
using namespace studio::hull;

namespace {

constexpr const char* kUsage = R"(usage: studio-hull --config hull.yaml      the real-time DDS service (keys below)
       studio-hull offline --rig rig.yaml --masks DIR --box X0,Y0,Z0,X1,Y1,Z1 --grid N
                           [--axis x|y|z] [--frames A:B] --out FILE|DIR [--format ply|obj|glb]
                           [--outside keep|cut] [--threads N] [--timing]

Offline visual hull (line-segment representation, segment marching cubes) from silhouette masks.
  --rig FILE        rig.yaml with the calibrated cameras
  --masks DIR       DIR/<camera_id>.png (one frame) or DIR/<frame>/<camera_id>.png (a sequence);
                    0 = background, non-zero = actor; every camera of the rig needs its mask
  --box ...         the reconstruction box in the studio frame (metres)
  --grid N          N x N columns (e.g. 512)
  --axis A          continuous axis of the line segments (default y, the studio's up)
  --frames A:B      only frames A..B inclusive of a sequence (share a long take between PCs)
  --out PATH        mesh file for one frame (.ply/.obj/.glb), a folder for a sequence
                    (<frame>.<format>)
  --format F        mesh format in a folder (default ply)
  --outside M       keep (default) or cut the parts of a column that leave a camera's image
  --threads N       worker threads (default: all cores; frames run in parallel)
  --timing          print per-stage milliseconds (load, cut, mesh, write) as JSON on stdout
)";

struct Args {
  std::string rig, masks, out, format = "ply";
  std::optional<std::string> box_text;
  Eigen::Vector3d box_min, box_max;
  int grid = 0;
  Axis axis = Axis::y;
  std::optional<std::pair<long, long>> frames;
  Outside outside = Outside::keep;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  bool timing = false;
};

Expected<Args> parse(int argc, char** argv) {
  Args a;
  for (int k = 2; k < argc; ++k) {
    const std::string opt = argv[k];
    const auto value = [&]() -> Expected<std::string> {
      if (k + 1 >= argc) return fail(opt + ": missing value");
      return std::string(argv[++k]);
    };
    if (opt == "--timing") {
      a.timing = true;
      continue;
    }
    auto v = value();
    if (!v) return std::unexpected(v.error());
    if (opt == "--rig") a.rig = *v;
    else if (opt == "--masks") a.masks = *v;
    else if (opt == "--out") a.out = *v;
    else if (opt == "--format") a.format = *v;
    else if (opt == "--box") {
      std::vector<double> n;
      std::stringstream ss(*v);
      std::string item;
      while (std::getline(ss, item, ',')) {
        try {
          std::size_t used = 0;
          n.push_back(std::stod(item, &used));
          if (used != item.size()) return fail("--box: '" + item + "' is not a number");
        } catch (...) {
          return fail("--box: '" + item + "' is not a number");
        }
      }
      if (n.size() != 6) return fail("--box: expected 6 numbers X0,Y0,Z0,X1,Y1,Z1");
      a.box_min = {n[0], n[1], n[2]};
      a.box_max = {n[3], n[4], n[5]};
      a.box_text = *v;
    } else if (opt == "--grid" || opt == "--threads") {
      int n = 0;
      try {
        std::size_t used = 0;
        n = std::stoi(*v, &used);
        if (used != v->size()) throw 0;
      } catch (...) {
        return fail(opt + ": '" + *v + "' is not an integer");
      }
      (opt == "--grid" ? a.grid : a.threads) = n;
    } else if (opt == "--axis") {
      auto ax = parse_axis(*v);
      if (!ax) return std::unexpected(ax.error());
      a.axis = *ax;
    } else if (opt == "--frames") {
      long lo = 0, hi = 0;
      char c = 0;
      std::stringstream ss(*v);
      if (!(ss >> lo >> c >> hi) || c != ':' || !ss.eof() || hi < lo) {
        return fail("--frames: '" + *v + "': expected A:B with A <= B");
      }
      a.frames = {lo, hi};
    } else if (opt == "--outside") {
      if (*v == "keep") a.outside = Outside::keep;
      else if (*v == "cut") a.outside = Outside::cut;
      else return fail("--outside: '" + *v + "': expected keep or cut");
    } else {
      return fail("unknown option " + opt + " (see --help)");
    }
  }
  if (a.rig.empty()) return fail("--rig is required");
  if (a.masks.empty()) return fail("--masks is required");
  if (!a.box_text) return fail("--box is required");
  if (a.grid <= 0) return fail("--grid N is required (N >= 1)");
  if (a.out.empty()) return fail("--out is required");
  if (a.threads < 1 || a.threads > 64) return fail("--threads: need 1..64");
  if (a.format != "ply" && a.format != "obj" && a.format != "glb") {
    return fail("--format: '" + a.format + "': expected ply, obj or glb");
  }
  return a;
}

struct Frame {
  std::string name;  // "" for a single frame
  fs::path dir;
};

Expected<RunMask> load_mask(const fs::path& path, const Camera& cam) {
  if (!fs::exists(path)) return fail(path.string() + ": missing mask for camera " + cam.id);
  const cv::Mat m = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (m.empty()) return fail(path.string() + ": not a readable image");
  if (m.cols != cam.width || m.rows != cam.height) {
    return fail(path.string() + ": mask is " + std::to_string(m.cols) + "x" + std::to_string(m.rows) +
                ", camera " + cam.id + " is " + std::to_string(cam.width) + "x" +
                std::to_string(cam.height));
  }
  return RunMask::from_mask(MaskView(m.ptr<uint8_t>(), m.cols, m.rows, std::ptrdiff_t(m.step)));
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int run_offline(int argc, char** argv) {
  auto args = parse(argc, argv);
  if (!args) {
    std::cerr << "studio-hull: " << args.error().message << "\n";
    return 2;
  }
  GridSpec grid;
  grid.box_min = args->box_min;
  grid.box_max = args->box_max;
  grid.axis = args->axis;
  grid.cells_u = grid.cells_v = args->grid;
  if (auto ok = grid.validate(); !ok) {
    std::cerr << "studio-hull: --box/--grid: " << ok.error().message << "\n";
    return 2;
  }
  auto rig = yaml::read_rig(args->rig);
  if (!rig) {
    std::cerr << "studio-hull: " << rig.error().message << "\n";
    return 2;
  }
  if (rig->cameras.empty()) {
    std::cerr << "studio-hull: " << args->rig << ": no cameras\n";
    return 2;
  }
  if (!fs::is_directory(args->masks)) {
    std::cerr << "studio-hull: " << args->masks << ": not a folder\n";
    return 2;
  }
  // One frame (DIR/<camera>.png) or a sequence (DIR/<frame>/<camera>.png).
  std::vector<Frame> frames;
  bool single = false;
  for (const Camera& c : rig->cameras) single |= fs::exists(fs::path(args->masks) / (c.id + ".png"));
  if (single) {
    frames.push_back({"", args->masks});
  } else {
    std::vector<std::pair<long, fs::path>> found;
    for (const auto& e : fs::directory_iterator(args->masks)) {
      if (!e.is_directory()) continue;
      const std::string n = e.path().filename().string();
      if (n.empty() || !std::all_of(n.begin(), n.end(), ::isdigit)) continue;
      const long f = std::stol(n);
      if (args->frames && (f < args->frames->first || f > args->frames->second)) continue;
      found.emplace_back(f, e.path());
    }
    std::sort(found.begin(), found.end());
    for (const auto& [f, p] : found) frames.push_back({p.filename().string(), p});
    if (frames.empty()) {
      std::cerr << "studio-hull: " << args->masks << ": no masks (" << rig->cameras[0].id
                << ".png) and no frame folders" << (args->frames ? " in --frames" : "") << "\n";
      return 2;
    }
    std::error_code ec;
    fs::create_directories(args->out, ec);
    if (ec || !fs::is_directory(args->out)) {
      std::cerr << "studio-hull: " << args->out << ": cannot create output folder\n";
      return 2;
    }
  }

  // Frames in parallel; a single frame uses the threads inside the cut.
  const int workers = std::min<int>(args->threads, int(frames.size()));
  CutOptions cut_options;
  cut_options.outside = args->outside;
  cut_options.threads = frames.size() == 1 ? args->threads : 1;
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> failed{false};
  std::mutex lock;
  std::string error;
  double t_load = 0, t_cut = 0, t_mesh = 0, t_write = 0;
  const bool progress = frames.size() > 1;
  const auto work = [&] {
    while (!failed) {
      const std::size_t k = next++;
      if (k >= frames.size()) return;
      const Frame& fr = frames[k];
      auto t0 = std::chrono::steady_clock::now();
      std::vector<RunMask> masks;
      for (const Camera& c : rig->cameras) {
        auto m = load_mask(fr.dir / (c.id + ".png"), c);
        if (!m) {
          std::lock_guard g(lock);
          if (!failed.exchange(true)) error = m.error().message;
          return;
        }
        masks.push_back(std::move(*m));
      }
      const double load = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      std::vector<View> views;
      for (std::size_t c = 0; c < masks.size(); ++c) views.push_back({&rig->cameras[c], &masks[c]});
      auto hull = visual_hull(grid, views, cut_options);
      if (!hull) {
        std::lock_guard g(lock);
        if (!failed.exchange(true)) error = hull.error().message;
        return;
      }
      const double cut = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      const Mesh mesh = segment_marching_cubes(*hull);
      const double mesh_ms = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      const std::string out = fr.name.empty()
                                  ? args->out
                                  : (fs::path(args->out) / (fr.name + "." + args->format)).string();
      auto w = write_mesh(mesh, out);
      if (!w) {
        std::lock_guard g(lock);
        if (!failed.exchange(true)) error = w.error().message;
        return;
      }
      const double write = ms_since(t0);
      std::lock_guard g(lock);
      t_load += load, t_cut += cut, t_mesh += mesh_ms, t_write += write;
      const std::size_t n = ++done;
      if (progress) {
        const int width = 40, filled = int(width * n / frames.size());
        std::fprintf(stderr, "\r[%s%s] %zu/%zu frames", std::string(filled, '#').c_str(),
                     std::string(width - filled, ' ').c_str(), n, frames.size());
        if (n == frames.size()) std::fprintf(stderr, "\n");
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    for (int k = 1; k < workers; ++k) pool.emplace_back(work);
    work();
  }
  if (failed) {
    if (progress) std::fprintf(stderr, "\n");
    std::cerr << "studio-hull: " << error << "\n";
    return 1;
  }
  if (args->timing) {
    const double n = double(frames.size());
    std::printf(
        "{\"frames\": %zu, \"grid\": %d, \"cameras\": %zu, \"load\": %.3f, \"cut\": %.3f, "
        "\"mesh\": %.3f, \"write\": %.3f, \"unit\": \"ms per frame\"}\n",
        frames.size(), args->grid, rig->cameras.size(), t_load / n, t_cut / n, t_mesh / n,
        t_write / n);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string verb = argc > 1 ? argv[1] : "";
  if (verb == "-h" || verb == "--help" || verb == "help") {
    const auto service = hull_service_definition();
    std::cout << kUsage << "\nService config (studio-hull --config FILE): " << service.summary << "\n"
              << service.config_help
              << "  plus the common service keys: instance, domain, dds_config, status_period, log\n";
    return 0;
  }
  if (verb == "--config" || verb.starts_with("--config=")) {
    return studio::runtime::service_main(argc, argv, hull_service_definition());
  }
  if (verb == "offline") {
    for (int k = 2; k < argc; ++k) {
      if (std::string(argv[k]) == "--help" || std::string(argv[k]) == "-h") {
        std::cout << kUsage;
        return 0;
      }
    }
    try {
      return run_offline(argc, argv);
    } catch (const std::exception& e) {
      std::cerr << "studio-hull: " << e.what() << "\n";
      return 1;
    }
  }
  std::cerr << "studio-hull: " << (verb.empty() ? "missing command" : "unknown command '" + verb + "'")
            << " (usage: studio-hull offline ...; see --help)\n";
  return 2;
}
