// studio-hull: the visual hull service's command line (DESIGN §6): the DDS node (--config, see
// node/hull_node.h) and the offline mode, from a mask folder or a recorded take keyed on the fly
// (cli/frame_input.h). Per frame: load (+ key) -> cut -> segment marching cubes -> exact crossings
// (hull/crossing_refine.h; --no-refine skips them) -> mesh file. Frames run in parallel on the
// worker threads; a single frame uses them inside the cut.
#include <unistd.h>

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

#include "frame_input.h"
#include "offline_refined.h"
#include "hull/crossing_refine.h"
#include "hull/mesh_io.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "hull/visibility.h"
#include "hull_node.h"
#include "keyer/config/keyer_yaml.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;
using namespace studio;
using namespace studio::hull;

namespace {

constexpr const char* kUsage =
    R"(usage: studio-hull --config hull.yaml      the real-time DDS service (keys below)
       studio-hull offline (--rig rig.yaml --masks DIR | [--rig rig.yaml] --take DIR)
                           --box X0,Y0,Z0,X1,Y1,Z1
                           --grid N [--axis x|y|z] [--frames A:B] --out FILE|DIR
                           [--format ply|obj|glb] [--keyer keyer.yaml | --key blue|green]
                           [--min-views N|all] [--no-refine] [--threads N] [--timing]
                           [--progress | --quiet]

Offline visual hull (line-segment representation, segment marching cubes) from silhouettes.
  --rig FILE        rig.yaml with the calibrated cameras; with --take the default is the
                    calibration each camera recorded in its take.yaml (its pose when the take
                    began); a tracked (Free-D) camera's take records its calibration per frame,
                    and each frame is cut with that
  --masks DIR       DIR/<camera_id>.png (one frame) or DIR/<frame>/<camera_id>.png (a sequence);
                    0 = background, non-zero = actor; every camera of the rig needs its mask
  --take DIR        a recorded take, takes/<take>/ holding <camera_id>/frames.raw (+ index) for
                    every camera of the rig; frames are matched by frame number and keyed on the
                    fly (RGB8 frames)
  --keyer FILE      keyer.yaml for --take (keys of keyer/keyer.example.yaml; blue or green key)
  --key K           blue (default) or green: the keyer's defaults for that backing, for --take
  --box ...         the reconstruction box in the studio frame (metres)
  --grid N          N x N columns (e.g. 512)
  --axis A          continuous axis of the line segments (default y, the studio's up)
  --frames A:B      only frames A..B inclusive of a sequence or take (share a long take
                    between PCs)
  --out PATH        mesh file for one frame (.ply/.obj/.glb), else a folder (<frame>.<format>)
  --format F        mesh format in a folder (default ply)
  --min-views N     visibility policy (default 2): a point is actor only if it is inside the
                    silhouette of every camera that sees it (in front, inside its image) AND
                    at least N cameras see it. 2 is the fewest views that bound a point in depth:
                    parts of a loose box seen by no camera or by one (slabs, single silhouette
                    cones) are cut, while every point of a studio's acting area is seen by at
                    least 2 cameras, so the hull stays a superset of the actor there. 0 keeps
                    what no camera sees (the former --outside keep); all: every camera must see
                    the point (the former --outside cut: cuts an actor who leaves one image)
  --no-refine       skip the exact crossings (vertices between an inside and an outside column
                    stay at half a cell, which re-projects about half a cell too wide)
  --threads N       worker threads (default: all cores; frames run in parallel, a single frame
                    cuts its columns in parallel)
  --timing          print JSON on stdout: milliseconds per frame of each stage (load, key, cut,
                    mesh, refine, write), the wall time and the box coverage (below)
  --progress        progress bar on stderr even when it is not a terminal (default: only on a
                    terminal, for more than one frame); --quiet: never
Box coverage: the fraction of the box no camera sees and the fraction seen by fewer than
--min-views cameras (cut whatever the silhouettes; large means the box is looser than the rig)
are in the --timing JSON (unseen_fraction, below_min_views_fraction) and, on a terminal or with
--progress, on one stderr line after the last frame.
Exit status: 0 done; 2 bad arguments or input found before any frame (missing camera, empty
box, ...); 1 a frame failed (unreadable or wrong-size mask or take frame, CRC, disk); frames
finished before it stay written. Errors are one line on stderr.
)";

struct Args {
  std::string rig, masks, take, keyer_file, out, format = "ply";
  std::optional<keyer::KeyMode> key;
  std::optional<std::string> box_text;
  Eigen::Vector3d box_min, box_max;
  int grid = 0;
  Axis axis = Axis::y;
  std::optional<cli::FrameRange> frames;
  int min_views = kDefaultMinViews;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  bool timing = false, refine = true;
  std::optional<bool> progress;
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
    if (opt == "--no-refine") {
      a.refine = false;
      continue;
    }
    if (opt == "--progress" || opt == "--quiet") {
      a.progress = opt == "--progress";
      continue;
    }
    auto v = value();
    if (!v) return std::unexpected(v.error());
    if (opt == "--rig")
      a.rig = *v;
    else if (opt == "--masks")
      a.masks = *v;
    else if (opt == "--take")
      a.take = *v;
    else if (opt == "--keyer")
      a.keyer_file = *v;
    else if (opt == "--key") {
      auto m = keyer::parse_key_mode(*v);
      if (!m || *m == keyer::KeyMode::kDifference) {
        return fail("--key: '" + *v + "': expected blue or green");
      }
      a.key = *m;
    } else if (opt == "--out")
      a.out = *v;
    else if (opt == "--format")
      a.format = *v;
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
      if (!(ss >> lo >> c >> hi) || c != ':' || !ss.eof() || lo < 0 || hi < lo) {
        return fail("--frames: '" + *v + "': expected A:B with 0 <= A <= B");
      }
      a.frames = cli::FrameRange{lo, hi};
    } else if (opt == "--min-views") {
      if (*v == "all") {
        a.min_views = kAllViews;
      } else {
        try {
          std::size_t used = 0;
          a.min_views = std::stoi(*v, &used);
          if (used != v->size() || a.min_views < 0 || a.min_views > 64) throw 0;
        } catch (...) {
          return fail("--min-views: '" + *v + "': expected 0..64 or all");
        }
      }
    } else if (opt == "--outside") {
      return fail("--outside was replaced by --min-views N|all (keep = 0, cut = all; see --help)");
    } else {
      return fail("unknown option " + opt + " (see --help)");
    }
  }
  if (a.rig.empty() && a.take.empty()) return fail("--rig is required with --masks");
  if (a.masks.empty() == a.take.empty())
    return fail("give exactly one of --masks DIR or --take DIR");
  if (!a.keyer_file.empty() && a.key) return fail("give --keyer FILE or --key, not both");
  if (a.take.empty() && (!a.keyer_file.empty() || a.key)) {
    return fail("--keyer/--key only apply to --take (masks are already keyed)");
  }
  if (!a.box_text) return fail("--box is required");
  if (a.grid <= 0) return fail("--grid N is required (N >= 1)");
  if (a.out.empty()) return fail("--out is required");
  if (a.threads < 1 || a.threads > 64) return fail("--threads: need 1..64");
  if (a.format != "ply" && a.format != "obj" && a.format != "glb") {
    return fail("--format: '" + a.format + "': expected ply, obj or glb");
  }
  return a;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int run_offline(int argc, char** argv) {
  const auto wall0 = std::chrono::steady_clock::now();
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
  // The cameras: the rig file, else (a take) the calibration recorded in the take.
  Rig rig;
  if (!args->rig.empty()) {
    auto read = yaml::read_rig(args->rig);
    if (!read) {
      std::cerr << "studio-hull: " << read.error().message << "\n";
      return 2;
    }
    rig = std::move(*read);
    if (rig.cameras.empty()) {
      std::cerr << "studio-hull: " << args->rig << ": no cameras\n";
      return 2;
    }
  } else {
    auto recorded = cli::cameras_of_take(args->take);
    if (!recorded) {
      std::cerr << "studio-hull: " << recorded.error().message << "\n";
      return 2;
    }
    rig.cameras = std::move(*recorded);
  }
  const std::vector<Camera>& cameras = rig.cameras;

  // Where the silhouettes come from. Slots: one keyer set per worker thread.
  Expected<std::unique_ptr<cli::FrameInput>> input = fail("no input");
  if (!args->masks.empty()) {
    input = cli::open_mask_folder(args->masks, cameras, args->frames);
  } else {
    keyer::KeyerOptions key;
    if (!args->keyer_file.empty()) {
      auto loaded = keyer::load_keyer_options(args->keyer_file);
      if (!loaded) {
        std::cerr << "studio-hull: " << loaded.error().message << "\n";
        return 2;
      }
      key = *loaded;
    } else if (args->key) {
      key.mode = *args->key;
    }
    input = cli::open_take(args->take, cameras, args->frames, key, args->threads);
  }
  if (!input) {
    std::cerr << "studio-hull: " << input.error().message << "\n";
    return 2;
  }
  cli::FrameInput& in = **input;
  const std::vector<std::string>& frames = in.frames();

  // One mesh file for one frame (always for a one-frame mask folder; for a single selected frame
  // of a sequence or take when --out names a mesh file), a folder otherwise.
  const bool one_file =
      frames.size() == 1 && (frames[0].empty() || mesh_format_from_path(args->out).has_value());
  if (!one_file && mesh_format_from_path(args->out).has_value()) {
    std::cerr << "studio-hull: --out " << args->out << " names a mesh file but " << frames.size()
              << " frames are selected; give a folder\n";
    return 2;
  }
  if (!one_file) {
    std::error_code ec;
    fs::create_directories(args->out, ec);
    if (ec || !fs::is_directory(args->out)) {
      std::cerr << "studio-hull: " << args->out << ": cannot create output folder\n";
      return 2;
    }
  } else if (auto f = mesh_format_from_path(args->out); !f) {
    std::cerr << "studio-hull: --out " << f.error().message << "\n";
    return 2;
  }

  const int workers = std::min<int>(args->threads, int(frames.size()));
  CutOptions cut_options;
  cut_options.min_views = args->min_views;
  cut_options.threads = frames.size() == 1 ? args->threads : 1;
  const bool progress = frames.size() > 1 && args->progress.value_or(::isatty(2) != 0);
  // How much of the box the rig covers (a fraction: at most 128 x 128 columns suffice).
  GridSpec coarse = grid;
  coarse.cells_u = coarse.cells_v = std::min(grid.cells_u, 128);
  auto covered = coverage(coarse, cameras, args->min_views);
  if (!covered) {
    std::cerr << "studio-hull: " << covered.error().message << "\n";
    return 2;
  }
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> failed{false};
  std::mutex lock;
  std::string error;
  bool bar_drawn = false;
  cli::LoadTimes t_load;
  double t_cut = 0, t_mesh = 0, t_refine = 0, t_write = 0;
  const auto work = [&](int slot) {
    std::vector<RunMask> masks;
    std::vector<View> views;
    const auto give_up = [&](const std::string& message) {
      std::lock_guard g(lock);
      if (!failed.exchange(true)) error = message;
    };
    while (!failed) {
      const std::size_t k = next++;
      if (k >= frames.size()) return;
      cli::LoadTimes load;
      if (auto ok = in.load(k, slot, masks, load); !ok) return give_up(ok.error().message);
      auto t0 = std::chrono::steady_clock::now();
      views.clear();
      for (std::size_t c = 0; c < masks.size(); ++c) {  // a tracked camera: its frame's pose
        const Camera* moved = in.camera(k, c);
        views.push_back({moved ? moved : &cameras[c], &masks[c]});
      }
      auto hull = visual_hull(grid, views, cut_options);
      if (!hull) return give_up(hull.error().message);
      const double cut = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      Mesh mesh = segment_marching_cubes(*hull);
      const double mesh_ms = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      if (args->refine) {
        if (auto ok = refine_crossings(mesh, *hull, views, cut_options); !ok) {
          return give_up(ok.error().message);
        }
      }
      const double refine = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      const std::string out =
          one_file ? args->out : (fs::path(args->out) / (frames[k] + "." + args->format)).string();
      if (auto w = write_mesh(mesh, out); !w) return give_up(w.error().message);
      const double write = ms_since(t0);
      std::lock_guard g(lock);
      t_load.read += load.read, t_load.key += load.key;
      t_cut += cut, t_mesh += mesh_ms, t_refine += refine, t_write += write;
      const std::size_t n = ++done;
      if (progress && !failed) {
        const int width = 40, filled = int(width * n / frames.size());
        std::fprintf(stderr, "\r[%s%s] %zu/%zu frames", std::string(filled, '#').c_str(),
                     std::string(width - filled, ' ').c_str(), n, frames.size());
        if (n == frames.size()) std::fprintf(stderr, "\n");
        bar_drawn = n < frames.size();
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    for (int k = 1; k < workers; ++k) pool.emplace_back(work, k);
    work(0);
  }
  if (failed) {
    if (bar_drawn) std::fprintf(stderr, "\n");
    std::cerr << "studio-hull: " << error << "\n";
    return 1;
  }
  if (args->progress.value_or(::isatty(2) != 0)) {
    std::fprintf(stderr,
                 "studio-hull: box coverage: %.1f %% seen by no camera, %.1f %% by fewer than %d "
                 "(cut by --min-views)\n",
                 100 * covered->unseen, 100 * covered->below_min_views, covered->min_views);
  }
  if (args->timing) {
    const double n = double(frames.size());
    std::printf(
        "{\"input\": \"%s\", \"frames\": %zu, \"grid\": %d, \"cameras\": %zu, \"threads\": %d, "
        "\"frames_in_parallel\": %d, "
        "\"exact_crossings\": %s, \"load\": %.3f, \"key\": %.3f, \"cut\": %.3f, \"mesh\": %.3f, "
        "\"refine\": %.3f, \"write\": %.3f, \"unit\": \"ms per frame\", \"wall_ms\": %.3f, "
        "\"min_views\": %d, \"unseen_fraction\": %.5f, \"below_min_views_fraction\": %.5f}\n",
        in.keyed() ? "take" : "masks", frames.size(), args->grid, cameras.size(), args->threads,
        workers, args->refine ? "true" : "false", t_load.read / n, t_load.key / n, t_cut / n,
        t_mesh / n, t_refine / n, t_write / n, ms_since(wall0), covered->min_views, covered->unseen,
        covered->below_min_views);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string verb = argc > 1 ? argv[1] : "";
  if (verb == "-h" || verb == "--help" || verb == "help") {
    const auto service = hull_service_definition();
    std::cout
        << kUsage << "\n" << cli::refined_usage() << "\nService config (studio-hull --config FILE): " << service.summary << "\n"
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
        std::cout << kUsage << "\n" << cli::refined_usage();
        return 0;
      }
    }
    try {
      if (cli::wants_refined(argc, argv)) return cli::run_refined(argc, argv);
      return run_offline(argc, argv);
    } catch (const std::exception& e) {
      std::cerr << "studio-hull: " << e.what() << "\n";
      return 1;
    }
  }
  std::cerr << "studio-hull: "
            << (verb.empty() ? "missing command" : "unknown command '" + verb + "'")
            << " (usage: studio-hull offline ...; see --help)\n";
  return 2;
}
