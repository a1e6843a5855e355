#include "offline_refined.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "frame_input.h"
#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "keyer/config/keyer_yaml.h"
#include "offline/colour_balance.h"
#include "offline/frame_files.h"
#include "offline/photo_carve.h"
#include "offline/surface_refine.h"
#include "offline/texture.h"
#include "offline_take.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio::hull::cli {
namespace {

// --refine runs the surface stage with this many steps unless --surface says otherwise: the carve
// alone leaves the hull's bulges between the silhouette cones (-12 % / -19 % mean / p95 surface
// distance vs the hull, against -21 % / -26 % with the steps; docs/offline.md).
constexpr int kDefaultSurfaceSteps = 10;
constexpr int kSurfaceUnset = -2;

constexpr const char* kUsage =
    R"(       studio-hull offline --take DIR [--rig rig.yaml] --box X0,Y0,Z0,X1,Y1,Z1 --grid N
                           --out DIR (--refine | --texture | --surface S, any together)
                           [--frames A:B] [--name NAME] [--fps F] [--axis x|y|z]
                           [--keyer keyer.yaml | --key blue|green] [--min-views N|all]
                           [--threshold T] [--ncc T|off] [--judges N|all]
                           [--max-depth CELLS] [--colour-balance take|frame|off]
                           [--threads N]
                           [--surface STEPS|off] [--surface-photo ITERATIONS]
                           [--json | --progress | --quiet]
       studio-hull offline --take DIR [--rig rig.yaml] --plan SHARDS   (prints A:B per shard)
       studio-hull offline --take DIR [--rig rig.yaml] --out DIR --index-only [--name] [--fps]

Post-production (docs/offline.md): per frame of a recorded take, the visual hull refined by
photo-consistency and/or textured from the cameras' colour images, one glTF binary per frame.
  --refine          carve the hull where the cameras' colours disagree (voxel colouring with
                    visibility; concavities the silhouettes cannot see)
  --texture         per-vertex colour blended from the cameras that see each vertex (COLOR_0)
  --out DIR         DIR/<name>_<frame:06>.glb per frame and DIR/<name>.gltf, the index (all
                    frames as one flip-book animation at --fps; Blender imports it as one
                    animated object), written when every frame of the take is in DIR
  --name NAME       file and node name stem (default actor; letters, digits, _ and -)
  --fps F           frame rate of the index's animation (default 25)
  --frames A:B      a shard: only frames A..B inclusive (the farm script gives each job one)
  --threshold T     photo-consistency threshold, RMS grey levels (default 6)
  --ncc T|off       also carve where shading patches disagree: mean NCC over camera pairs below
                    T (default 0) and a point 1-3 cells deeper matching clearly better; off:
                    colours alone
  --judges N|all    at most N of the cameras that see a voxel judge it, the most frontal
                    (default 3: on large rigs the grazing views' spill and light tint carve
                    the true surface); all: every camera that sees it
  --max-depth C     carving stops C cells below the hull (default 12)
  --colour-balance take|frame|off
                    equalise the cameras' colours before carving and texturing: each camera's
                    gains estimated from hull surface points that two cameras see, applied when
                    some camera is more than 2 % off the rig's mean (cameras 5-10 % apart in
                    exposure or white balance disagree on every bright point and the carve
                    removes the true surface; docs/offline.md). take (default): one estimate for
                    the whole take, pooled over up to 8 frames spread over it (the same in every
                    shard; no frame-to-frame colour flicker); frame: each frame its own (cameras
                    whose exposure changes during the take); off. The gains are in --json (a
                    "colour_balance" event, or per frame), and a camera more than 10 % off the
                    rig's mean is named on stderr
  --surface S|off   surface stage on the mesh (after carving with --refine): S Laplacian steps
                    with the silhouette rims (the middle of each facet) anchored, each move
                    kept inside the visual hull, moving the hull's bulges between the
                    silhouette cones inwards (10: -21 % mean / -26 % p95 surface distance vs
                    the hull with --refine on the two concave test poses, against -12 % / -19 %
                    carving alone; 30: -23 % / -28 %, also on five other poses not tuned on, at
                    3x the stage's cost; union PSNR +1.2-1.6 dB). Default: 10 with --refine,
                    off without it (--surface S alone smooths the hull itself)
  --surface-photo N photo-consistency iterations of the surface stage before the steps (patch
                    search along the normals; default 0: measured no gain, docs/offline.md)
  --plan N          print the take's frames split into N contiguous shards, one A:B per line
  --index-only      (re)write the index from the frame files in DIR (every take frame needed)
  --json            one JSON object per line on stdout: a "frame" event per frame written or
                    skipped (with done, total, eta_s) and a final "summary" with per-stage ms
  --progress        progress bar with rate and ETA on stderr even when it is not a terminal
                    (default: on a terminal only); --quiet: never
Resumable and idempotent: a frame whose file exists and verifies (structure, counts, hash of its
data, and a fingerprint of the settings and cameras that made it) is skipped; files are written
to a temporary name and renamed, so a killed job leaves no partial frame, and the bytes depend only on the take and the options (not on --threads or the
sharding). Farm: hull/cli/studio-hull-farm.sh submits a take as a Slurm job array (--local runs
the same shard commands here).
Exit status: 0 done; 2 bad arguments or input; 1 a frame failed (frames before it stay written).
)";

struct Args {
  std::string rig, take, keyer_file, out, name = "actor";
  std::optional<keyer::KeyMode> key;
  std::optional<std::string> box_text;
  Eigen::Vector3d box_min, box_max;
  int grid = 0;
  Axis axis = Axis::y;
  std::optional<FrameRange> frames;
  int min_views = kDefaultMinViews;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  bool refine = false, texture = false, json = false, index_only = false;
  int plan = 0;
  double fps = 25, threshold = 6, ncc = 0;
  bool patches = true;
  enum class Balance { off, take, frame } balance = Balance::take;  // --colour-balance
  int max_depth = 12;
  int judges = offline::CarveOptions{}.max_judges;  // 0: all
  // -1: no surface stage; kSurfaceUnset until the arguments are read: --refine's default steps.
  int surface = kSurfaceUnset, surface_photo = 0;
  std::optional<bool> progress;
};

Expected<double> number(const std::string& opt, const std::string& v) {
  try {
    std::size_t used = 0;
    const double d = std::stod(v, &used);
    if (used != v.size() || !std::isfinite(d)) throw 0;
    return d;
  } catch (...) {
    return fail(opt + ": '" + v + "' is not a number");
  }
}

Expected<Args> parse(int argc, char** argv) {
  Args a;
  for (int k = 2; k < argc; ++k) {
    const std::string opt = argv[k];
    if (opt == "--refine") {
      a.refine = true;
      continue;
    }
    if (opt == "--texture") {
      a.texture = true;
      continue;
    }
    if (opt == "--json") {
      a.json = true;
      continue;
    }
    if (opt == "--index-only") {
      a.index_only = true;
      continue;
    }
    if (opt == "--progress" || opt == "--quiet") {
      a.progress = opt == "--progress";
      continue;
    }
    if (k + 1 >= argc) return fail(opt + ": missing value (see --help)");
    const std::string v = argv[++k];
    if (opt == "--rig")
      a.rig = v;
    else if (opt == "--take")
      a.take = v;
    else if (opt == "--keyer")
      a.keyer_file = v;
    else if (opt == "--out")
      a.out = v;
    else if (opt == "--name")
      a.name = v;
    else if (opt == "--key") {
      auto m = keyer::parse_key_mode(v);
      if (!m || *m == keyer::KeyMode::kDifference)
        return fail("--key: '" + v + "': expected blue or green");
      a.key = *m;
    } else if (opt == "--box") {
      std::vector<double> n;
      std::stringstream ss(v);
      std::string item;
      while (std::getline(ss, item, ',')) {
        auto d = number("--box", item);
        if (!d) return std::unexpected(d.error());
        n.push_back(*d);
      }
      if (n.size() != 6) return fail("--box: expected 6 numbers X0,Y0,Z0,X1,Y1,Z1");
      a.box_min = {n[0], n[1], n[2]}, a.box_max = {n[3], n[4], n[5]}, a.box_text = v;
    } else if (opt == "--grid" || opt == "--threads" || opt == "--plan" || opt == "--max-depth") {
      auto d = number(opt, v);
      if (!d || *d != std::floor(*d)) return fail(opt + ": '" + v + "' is not an integer");
      (opt == "--grid"      ? a.grid
       : opt == "--threads" ? a.threads
       : opt == "--plan"    ? a.plan
                            : a.max_depth) = int(*d);
    } else if (opt == "--fps" || opt == "--threshold") {
      auto d = number(opt, v);
      if (!d || !(*d > 0)) return fail(opt + ": '" + v + "': expected a number > 0");
      (opt == "--fps" ? a.fps : a.threshold) = *d;
    } else if (opt == "--surface" || opt == "--surface-photo") {
      const bool off = opt == "--surface" && v == "off";
      auto d = off ? Expected<double>(-1.0) : number(opt, v);
      if (!d || *d != std::floor(*d) || (!off && (*d < 0 || *d > 1000)))
        return fail(opt + ": '" + v + "': expected 0..1000" +
                    (opt == "--surface" ? " or off" : ""));
      (opt == "--surface" ? a.surface : a.surface_photo) = int(*d);
    } else if (opt == "--judges") {
      if (v == "all") {
        a.judges = 0;
      } else {
        auto d = number(opt, v);
        if (!d || *d != std::floor(*d) || *d < 2 || *d > 64)
          return fail("--judges: '" + v + "': expected 2..64 or all");
        a.judges = int(*d);
      }
    } else if (opt == "--colour-balance") {
      if (v != "take" && v != "frame" && v != "off")
        return fail("--colour-balance: '" + v + "': expected take, frame or off");
      a.balance = v == "take"    ? Args::Balance::take
                  : v == "frame" ? Args::Balance::frame
                                 : Args::Balance::off;
    } else if (opt == "--ncc") {
      if (v == "off") {
        a.patches = false;
      } else {
        auto d = number(opt, v);
        if (!d || !(*d >= -1 && *d <= 1)) return fail("--ncc: '" + v + "': expected -1..1 or off");
        a.ncc = *d;
      }
    } else if (opt == "--axis") {
      auto ax = parse_axis(v);
      if (!ax) return std::unexpected(ax.error());
      a.axis = *ax;
    } else if (opt == "--frames") {
      long lo = 0, hi = 0;
      char c = 0;
      std::stringstream ss(v);
      if (!(ss >> lo >> c >> hi) || c != ':' || !ss.eof() || lo < 0 || hi < lo) {
        return fail("--frames: '" + v + "': expected A:B with 0 <= A <= B");
      }
      a.frames = FrameRange{lo, hi};
    } else if (opt == "--min-views") {
      if (v == "all")
        a.min_views = kAllViews;
      else {
        auto d = number(opt, v);
        if (!d || *d < 0 || *d > 64 || *d != std::floor(*d))
          return fail("--min-views: '" + v + "': expected 0..64 or all");
        a.min_views = int(*d);
      }
    } else {
      return fail("unknown option " + opt + " (see --help)");
    }
  }
  if (a.take.empty())
    return fail("--take DIR is required (the colour images come from a recorded take)");
  if (!a.keyer_file.empty() && a.key) return fail("give --keyer FILE or --key, not both");
  if (a.name.empty() || !std::all_of(a.name.begin(), a.name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
      })) {
    return fail("--name: '" + a.name + "': use letters, digits, _ and -");
  }
  if (a.plan < 0) return fail("--plan: need N >= 1");
  if (a.plan > 0) return a;
  if (a.out.empty()) return fail("--out DIR is required");
  if (a.index_only) return a;
  if (a.surface == kSurfaceUnset) a.surface = a.refine ? kDefaultSurfaceSteps : -1;
  if (!a.refine && !a.texture && a.surface < 0)
    return fail("give --refine, --surface and/or --texture");
  if (!a.box_text) return fail("--box is required");
  if (a.grid <= 0) return fail("--grid N is required (N >= 1)");
  if (a.threads < 1 || a.threads > 64) return fail("--threads: need 1..64");
  if (a.max_depth < 0 || a.max_depth > 1000) return fail("--max-depth: need 0..1000");
  if (a.surface_photo > 0 && a.surface < 0) return fail("--surface-photo needs --surface");
  return a;
}

// {"<camera id>":[r,g,b],...}: a colour balance's gains per camera.
std::string gains_json(const std::vector<Camera>& cameras,
                       const std::vector<Eigen::Vector3f>& gains) {
  std::string out = "{";
  char buf[160];
  for (std::size_t c = 0; c < gains.size() && c < cameras.size(); ++c) {
    std::snprintf(buf, sizeof buf, "%s\"%s\":[%.4f,%.4f,%.4f]", c ? "," : "", cameras[c].id.c_str(),
                  gains[c].x(), gains[c].y(), gains[c].z());
    out += buf;
  }
  return out + "}";
}

// Whether the images' colours shape the output (the colour balance matters only then).
bool uses_colour(const Args& a) { return a.refine || a.texture || a.surface_photo > 0; }

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Temporary files (<file>.tmp.<pid>) of writers on this machine that are no longer running: a
// killed job leaves them; the rerun removes them so the folder holds exactly the frames.
void remove_stale_temporaries(const std::string& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    const auto at = n.rfind(".tmp.");
    if (at == std::string::npos) continue;
    const std::string pid = n.substr(at + 5);
    if (pid.empty() || !std::all_of(pid.begin(), pid.end(), ::isdigit)) continue;
    if (::kill(pid_t(std::stol(pid)), 0) != 0 && errno == ESRCH) fs::remove(e.path(), ec);
  }
}

// Writes the index when every frame of the take verifies in the folder; false if some are missing.
Expected<bool> write_index_if_complete(const Args& a, const std::vector<uint64_t>& all) {
  std::vector<offline::FrameFileInfo> infos;
  for (uint64_t f : all) {
    const std::string path =
        (fs::path(a.out) / offline::frame_file_name(a.name, int64_t(f))).string();
    if (!fs::exists(path)) return false;
    auto info = offline::verify_frame_file(path);
    if (!info) return false;
    infos.push_back(*info);
  }
  const std::string json = offline::encode_index_gltf(a.name, a.fps, infos);
  const std::string path = (fs::path(a.out) / offline::index_file_name(a.name)).string();
  if (auto ok = offline::write_file_atomic(
          path, std::span(reinterpret_cast<const uint8_t*>(json.data()), json.size()));
      !ok) {
    return std::unexpected(ok.error());
  }
  return true;
}

}  // namespace

bool wants_refined(int argc, char** argv) {
  for (int k = 2; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--refine" || a == "--texture" || a == "--surface" || a == "--plan" ||
        a == "--index-only")
      return true;
  }
  return false;
}

const char* refined_usage() { return kUsage; }

int run_refined(int argc, char** argv) {
  const auto wall0 = std::chrono::steady_clock::now();
  auto args = parse(argc, argv);
  if (!args) {
    std::cerr << "studio-hull: " << args.error().message << "\n";
    return 2;
  }
  const Args& a = *args;
  std::vector<Camera> cameras;
  if (!a.rig.empty()) {
    auto rig = yaml::read_rig(a.rig);
    if (!rig) {
      std::cerr << "studio-hull: " << rig.error().message << "\n";
      return 2;
    }
    cameras = std::move(rig->cameras);
  } else {
    auto recorded = cameras_of_take(a.take);
    if (!recorded) {
      std::cerr << "studio-hull: " << recorded.error().message << "\n";
      return 2;
    }
    cameras = std::move(*recorded);
  }
  if (cameras.empty()) {
    std::cerr << "studio-hull: no cameras\n";
    return 2;
  }
  keyer::KeyerOptions key;
  if (!a.keyer_file.empty()) {
    auto loaded = keyer::load_keyer_options(a.keyer_file);
    if (!loaded) {
      std::cerr << "studio-hull: " << loaded.error().message << "\n";
      return 2;
    }
    key = *loaded;
  } else if (a.key) {
    key.mode = *a.key;
  }
  auto take = ColourTake::open(a.take, cameras, key, a.threads);
  if (!take) {
    std::cerr << "studio-hull: " << take.error().message << "\n";
    return 2;
  }
  const std::vector<uint64_t>& all = (*take)->all_frames();
  if (a.plan > 0) {
    // Contiguous shards of (nearly) equal size, in frame order.
    const std::size_t n = all.size(), shards = std::min<std::size_t>(std::size_t(a.plan), n);
    for (std::size_t s = 0; s < shards; ++s) {
      const std::size_t lo = s * n / shards, hi = (s + 1) * n / shards - 1;
      std::printf("%llu:%llu\n", (unsigned long long)all[lo], (unsigned long long)all[hi]);
    }
    return 0;
  }
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec || !fs::is_directory(a.out)) {
    std::cerr << "studio-hull: " << a.out << ": cannot create output folder\n";
    return 2;
  }
  if (a.index_only) {
    auto done = write_index_if_complete(a, all);
    if (!done || !*done) {
      std::cerr << "studio-hull: "
                << (done ? "the take's frames are not all written and verified in " + a.out
                         : done.error().message)
                << "\n";
      return 1;
    }
    return 0;
  }
  GridSpec grid;
  grid.box_min = a.box_min, grid.box_max = a.box_max, grid.axis = a.axis;
  grid.cells_u = grid.cells_v = a.grid;
  if (auto ok = grid.validate(); !ok) {
    std::cerr << "studio-hull: --box/--grid: " << ok.error().message << "\n";
    return 2;
  }
  offline::CarveOptions carve;
  carve.threshold = a.threshold;
  carve.max_depth_cells = a.max_depth;
  carve.ncc_threshold = a.ncc;
  carve.max_judges = a.judges;
  if (!a.patches) carve.patch_half = 0;
  if (auto ok = carve.validate(); !ok) {
    std::cerr << "studio-hull: " << ok.error().message << "\n";
    return 2;
  }
  offline::SurfaceRefineOptions surface;
  surface.cell = 0.5 * (grid.du() + grid.dv());
  surface.iterations = a.surface_photo;
  surface.shape_steps = std::max(0, a.surface);
  if (auto ok = surface.validate(); a.surface >= 0 && !ok) {
    std::cerr << "studio-hull: " << ok.error().message << "\n";
    return 2;
  }
  std::vector<uint64_t> selected;
  for (uint64_t f : all) {
    if (!a.frames || (long(f) >= a.frames->first && long(f) <= a.frames->last))
      selected.push_back(f);
  }
  if (selected.empty()) {
    std::cerr << "studio-hull: take " << a.take << ": no frames in --frames\n";
    return 2;
  }
  remove_stale_temporaries(a.out);
  // What makes a frame's bytes, besides its images: a frame file made with other settings or
  // cameras is recomputed, not skipped.
  std::string settings = "studio-hull offline v2";
  {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  " grid %d box %.9g %.9g %.9g %.9g %.9g %.9g axis %d min_views %d refine %d "
                  "texture %d threshold %.9g ncc %.9g patch %d max_depth %d key %d",
                  a.grid, a.box_min.x(), a.box_min.y(), a.box_min.z(), a.box_max.x(), a.box_max.y(),
                  a.box_max.z(), int(a.axis), a.min_views, int(a.refine), int(a.texture),
                  a.threshold, a.ncc, carve.patch_half, a.max_depth, int(key.mode));
    settings += buf;
    if (a.refine) {  // (a carve's judges; absent without --refine, where they change nothing)
      std::snprintf(buf, sizeof buf, " judges %d", a.judges);
      settings += buf;
    }
    if (a.balance != Args::Balance::off && uses_colour(a)) {  // (absent when off)
      settings +=
          a.balance == Args::Balance::take ? " colour_balance take" : " colour_balance frame";
    }
    if (a.surface >= 0) {  // (absent when off: files made without it keep their fingerprint)
      std::snprintf(buf, sizeof buf, " surface %d photo %d inside_hull %d rim_band %.9g", a.surface,
                    a.surface_photo, int(surface.inside_hull), surface.rim_band_cells);
      settings += buf;
    }
    if (!a.keyer_file.empty()) {
      std::ifstream in(a.keyer_file, std::ios::binary);
      settings += " keyer " + std::string(std::istreambuf_iterator<char>(in), {});
    }
    for (const Camera& c : cameras) {
      const Eigen::Quaterniond& q = c.cam_from_world.rotation;
      const Eigen::Vector3d& t = c.cam_from_world.translation;
      const auto& k = c.intrinsics;
      std::snprintf(
          buf, sizeof buf,
          " cam %s %d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g "
          "%.17g",
          c.id.c_str(), c.width, c.height, k.fx, k.fy, k.cx, k.cy, k.skew, q.w(), q.x(), q.y(),
          q.z(), t.x(), t.y(), t.z());
      settings += buf;
      const auto d = polynomial(c.distortion);
      std::snprintf(buf, sizeof buf, " d %.17g %.17g %.17g %.17g %.17g", d.k1, d.k2, d.k3, d.p1,
                    d.p2);
      settings += buf;
    }
  }
  const std::string tag = offline::fingerprint(settings);

  const bool bar = a.progress.value_or(::isatty(2) != 0) && !a.json;
  const int workers = std::min<int>(a.threads, int(selected.size()));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex lock;
  std::string error;
  std::size_t done = 0, skipped = 0, computed = 0;
  double computed_ms = 0;
  struct Stages {
    double read = 0, key = 0, cut = 0, balance = 0, carve = 0, mesh = 0, surface = 0, texture = 0,
           write = 0;
  } total;
  const bool balancing = a.balance != Args::Balance::off && uses_colour(a);
  const bool take_balance = balancing && a.balance == Args::Balance::take;
  // --colour-balance take: one estimate pooled over up to kBalanceFrames frames spread over the
  // whole take (not the shard: every shard computes the same gains), made when the first frame
  // needs it (a rerun that skips every frame reads none).
  constexpr std::size_t kBalanceFrames = 8;
  std::once_flag take_once;
  std::optional<offline::ColourBalance> take_gains;
  std::string take_error;
  double take_ms = 0;
  const auto estimate_take = [&](ColourFrame& frame, int slot) {
    const auto t0 = std::chrono::steady_clock::now();
    offline::ColourBalanceEstimator estimator(cameras.size());
    const std::size_t n = std::min(kBalanceFrames, all.size());
    CutOptions cut;
    cut.min_views = a.min_views;
    for (std::size_t i = 0; i < n; ++i) {
      const uint64_t f = all[n == 1 ? 0 : i * (all.size() - 1) / (n - 1)];
      double read = 0, key = 0;
      if (auto ok = (*take)->load(f, slot, frame, read, key); !ok) {
        take_error = "colour balance: frame " + std::to_string(f) + ": " + ok.error().message;
        return;
      }
      std::vector<offline::ColourView> views;
      for (std::size_t c = 0; c < cameras.size(); ++c)
        views.push_back({&cameras[c], frame.images[c].view(), &frame.masks[c]});
      if (auto ok = estimator.add(grid, views, cut); !ok) {
        take_error = "colour balance: frame " + std::to_string(f) + ": " + ok.error().message;
        return;
      }
    }
    take_gains = estimator.solve();
    take_ms = ms_since(t0);
  };
  // Per camera: the sum of the estimated log gains over computed frames (the summary's mean).
  std::vector<Eigen::Vector3d> log_gain_sum(cameras.size(), Eigen::Vector3d::Zero());
  std::size_t balanced_frames = 0;  // frames whose images the balance changed
  const auto report = [&](uint64_t f, bool skip, double ms,
                          const std::vector<Eigen::Vector3f>& gains,
                          bool applied) {  // under lock
    ++done;
    if (skip)
      ++skipped;
    else
      ++computed, computed_ms += ms;
    const std::size_t left = selected.size() - done;
    // ETA: frames left at the measured rate of computed frames, frames in parallel.
    const double per_frame = computed ? computed_ms / double(computed) / workers : 0;
    const double eta_s = per_frame * double(left) / 1000;
    if (a.json) {
      std::printf(
          "{\"event\":\"frame\",\"frame\":%llu,\"skipped\":%s,\"ms\":%.1f,\"done\":%zu,\"total\":%"
          "zu,\"eta_s\":%.1f%s}\n",
          (unsigned long long)f, skip ? "true" : "false", ms, done, selected.size(), eta_s,
          gains.empty() ? ""
                        : (",\"colour_gains\":" + gains_json(cameras, gains) +
                           ",\"colour_balanced\":" + (applied ? "true" : "false"))
                              .c_str());
      std::fflush(stdout);
    }
    if (bar) {
      const int width = 30, filled = int(width * done / selected.size());
      std::fprintf(stderr, "\r[%s%s] %zu/%zu frames (%zu skipped) %.1f frames/min ETA %02d:%02d ",
                   std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(), done,
                   selected.size(), skipped, per_frame > 0 ? 60000.0 / per_frame : 0.0,
                   int(eta_s) / 60, int(eta_s) % 60);
      if (done == selected.size()) std::fprintf(stderr, "\n");
    }
  };
  const auto work = [&](int slot) {
    ColourFrame frame;
    const auto give_up = [&](const std::string& message) {
      std::lock_guard g(lock);
      if (!failed.exchange(true)) error = message;
    };
    while (!failed) {
      const std::size_t k = next++;
      if (k >= selected.size()) return;
      const uint64_t f = selected[k];
      const std::string path =
          (fs::path(a.out) / offline::frame_file_name(a.name, int64_t(f))).string();
      const auto t_frame = std::chrono::steady_clock::now();
      if (fs::exists(path)) {
        if (auto ok = offline::verify_frame_file(path);
            ok && ok->frame == int64_t(f) && ok->options == tag) {
          std::lock_guard g(lock);
          report(f, true, ms_since(t_frame), {}, false);
          continue;
        }
      }
      if (take_balance) {
        std::call_once(take_once, [&] {
          estimate_take(frame, slot);
          if (!take_gains || !a.json) return;
          std::lock_guard g(lock);
          std::printf(
              "{\"event\":\"colour_balance\",\"frames\":%d,\"points\":%zu,\"pairs\":%d,"
              "\"residual\":%.4f,\"applied\":%s,\"ms\":%.1f,\"colour_gains\":%s}\n",
              take_gains->frames, take_gains->points, take_gains->pairs, take_gains->residual,
              take_gains->applied ? "true" : "false", take_ms,
              gains_json(cameras, take_gains->estimated).c_str());
          std::fflush(stdout);
        });
      }
      Stages s;
      if (auto ok = (*take)->load(f, slot, frame, s.read, s.key); !ok)
        return give_up(ok.error().message);
      std::vector<offline::ColourView> views;
      std::vector<View> cut_views;
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        views.push_back({&cameras[c], frame.images[c].view(), &frame.masks[c]});
        cut_views.push_back({&cameras[c], &frame.masks[c]});
      }
      auto t0 = std::chrono::steady_clock::now();
      CutOptions cut;
      cut.min_views = a.min_views;
      auto hull = visual_hull(grid, cut_views, cut);
      if (!hull) return give_up(hull.error().message);
      s.cut = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      Mesh mesh;
      if (!a.refine) {  // the hull's mesh is the output
        mesh = segment_marching_cubes(*hull);
        if (auto ok = refine_crossings(mesh, *hull, cut_views, cut); !ok)
          return give_up(ok.error().message);
        s.mesh = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
      }
      std::vector<Image<Rgb8>> balanced;
      std::vector<Eigen::Vector3f> gains;  // --colour-balance frame: the estimate (reported) ...
      bool applied = false;                // ... and whether the images were balanced by it
      if (take_balance) {
        if (!take_gains) return give_up(take_error);
        views = offline::apply_colour_balance(views, *take_gains, &balanced);
        applied = take_gains->applied;
        s.balance = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
      } else if (balancing) {
        auto cb = offline::estimate_colour_balance(grid, views, cut);
        if (!cb) return give_up(cb.error().message);
        views = offline::apply_colour_balance(views, *cb, &balanced);
        gains = cb->estimated;
        applied = cb->applied;
        s.balance = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
      }
      if (a.refine) {
        auto carved = offline::photo_carve(*hull, views, carve);
        if (!carved) return give_up(carved.error().message);
        s.carve = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
        auto refined = offline::refined_mesh(carved->set, *hull, views);
        if (!refined) return give_up(refined.error().message);
        mesh = std::move(*refined);
        s.mesh = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
      }
      if (a.surface >= 0) {
        auto refined = offline::refine_surface(mesh, views, surface);
        if (!refined) return give_up(refined.error().message);
        mesh = std::move(refined->mesh);
      }
      s.surface = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      std::optional<std::vector<Eigen::Vector3f>> colours;
      if (a.texture) {
        auto c = offline::vertex_colours(mesh, views);
        if (!c) return give_up(c.error().message);
        colours = std::move(*c);
      }
      s.texture = ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      const auto bytes =
          offline::encode_frame_glb(mesh, colours ? &*colours : nullptr, a.name, int64_t(f), tag);
      if (auto ok = offline::write_file_atomic(path, bytes); !ok)
        return give_up(ok.error().message);
      s.write = ms_since(t0);
      std::lock_guard g(lock);
      total.read += s.read, total.key += s.key, total.cut += s.cut, total.balance += s.balance,
          total.carve += s.carve;
      for (std::size_t c = 0; c < gains.size(); ++c)
        log_gain_sum[c] += gains[c].cast<double>().array().log().matrix();
      total.mesh += s.mesh, total.surface += s.surface, total.texture += s.texture,
          total.write += s.write;
      balanced_frames += applied;
      report(f, false, ms_since(t_frame), gains, applied);
    }
  };
  {
    std::vector<std::jthread> pool;
    for (int k = 1; k < workers; ++k) pool.emplace_back(work, k);
    work(0);
  }
  if (failed) {
    if (bar) std::fprintf(stderr, "\n");
    std::cerr << "studio-hull: " << error << "\n";
    return 1;
  }
  auto indexed = write_index_if_complete(a, all);
  if (!indexed) {
    std::cerr << "studio-hull: " << indexed.error().message << "\n";
    return 1;
  }
  // The take's gains (or, frame by frame, their geometric mean over the computed frames); a
  // camera far off the rig's mean is worth an operator's look (its exposure, aperture or white
  // balance), balanced or not.
  std::vector<Eigen::Vector3f> mean_gains;
  if (take_balance && take_gains) {
    mean_gains = take_gains->estimated;
  } else if (balancing && computed > 0) {
    for (const Eigen::Vector3d& l : log_gain_sum)
      mean_gains.push_back((l / double(computed)).array().exp().matrix().cast<float>());
  }
  for (std::size_t c = 0; c < mean_gains.size(); ++c) {
    const Eigen::Vector3f& g = mean_gains[c];
    const float off = std::max({std::abs(g.x() - 1), std::abs(g.y() - 1), std::abs(g.z() - 1)});
    if (off > 0.10f)
      std::fprintf(stderr,
                   "studio-hull: camera %s: colours %.0f %% off the rig's mean (gains R %.3f G "
                   "%.3f B %.3f, balanced before carving and texturing): check its exposure "
                   "and white balance\n",
                   cameras[c].id.c_str(), 100 * off, g.x(), g.y(), g.z());
  }
  if (a.json) {
    const double n = std::max<double>(1, double(computed));
    std::printf(
        "{\"event\":\"summary\",\"frames\":%zu,\"computed\":%zu,\"skipped\":%zu,\"index_written\":%"
        "s,"
        "\"grid\":%d,\"cameras\":%zu,\"refine\":%s,\"texture\":%s,\"unit\":\"ms per computed "
        "frame\","
        "\"read\":%.2f,\"key\":%.2f,\"cut\":%.2f,\"balance\":%.2f,\"carve\":%.2f,\"mesh\":%.2f,"
        "\"surface\":%.2f,\"texture_ms\":%.2f,"
        "\"write\":%.2f,\"wall_ms\":%.1f%s}\n",
        selected.size(), computed, skipped, *indexed ? "true" : "false", a.grid, cameras.size(),
        a.refine ? "true" : "false", a.texture ? "true" : "false", total.read / n, total.key / n,
        total.cut / n, total.balance / n, total.carve / n, total.mesh / n, total.surface / n,
        total.texture / n, total.write / n, ms_since(wall0),
        mean_gains.empty() ? ""
                           : (",\"colour_gains\":" + gains_json(cameras, mean_gains) +
                              ",\"colour_balanced_frames\":" + std::to_string(balanced_frames))
                                 .c_str());
  }
  return 0;
}

}  // namespace studio::hull::cli
