// studio-hull offline --refine --texture as a farm job (issue 21): a 50-frame take recorded from
// the simulated studio, reconstructed unsharded and as 4 shards through the farm script's local
// mode with one shard killed midway and restarted: exactly the same files, byte for byte (frames
// and index); a rerun skips every verified frame and changes nothing; a damaged frame is
// recomputed; the same through Slurm (an sbatch job array on a single-node Slurm started for the
// test).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "capture/recorder.h"
#include "offline/frame_files.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio::hull {
namespace {

constexpr uint64_t kFirst = 0, kLast = 49;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

struct Result {
  int code;
  std::string out, err;
};

Result run(const std::string& cmd, const fs::path& dir) {
  const std::string full =
      cmd + " >" + (dir / "out.txt").string() + " 2>" + (dir / "err.txt").string();
  const int status = std::system(full.c_str());
  return {WEXITSTATUS(status), slurp(dir / "out.txt"), slurp(dir / "err.txt")};
}

std::map<std::string, std::string> files_of(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    out[e.path().filename().string()] = slurp(e.path());
  return out;
}

// The farm take's rig: 6 cameras (5 on the ring + overhead) at 176x144.
sim::RingOptions small_rig() {
  sim::RingOptions ring;
  ring.width = 176;
  ring.height = 144;
  ring.focal_px = 140;
  return ring;
}

// A take of the simulated studio with frames 0..last in `dir`.
void record_take(const fs::path& dir, const sim::StudioOptions& so, uint64_t last,
                 const sim::RingOptions& ring = small_rig()) {
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(ring), so);
  ASSERT_TRUE(studio) << studio.error().message;
  for (int c = 0; c < studio->camera_count(); ++c) {
    const Camera& cam = studio->cameras()[std::size_t(c)];
    capture::TakeInfo info;
    info.take = "take";
    info.camera_id = cam.id;
    info.width = uint32_t(cam.width);
    info.height = uint32_t(cam.height);
    info.period_ns = 40'000'000;
    info.start_frame = 0;
    info.calibration_yaml = yaml::format_camera(cam, 2);
    auto rec = capture::Recorder::start({.dir = (dir / cam.id).string(), .queue_frames = 64}, info);
    ASSERT_TRUE(rec) << rec.error().message;
    for (uint64_t f = 0; f <= last; ++f) {
      Image<Rgb8> image;
      studio->render(c, int64_t(f), &image, nullptr);
      ASSERT_TRUE((*rec)->push(f, int64_t(f) * 40'000'000, image.view()));
    }
    (*rec)->stop(last + 1);
    auto done = (*rec)->wait();
    ASSERT_TRUE(done) << done.error().message;
  }
}

class HullFarm : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("hull_farm_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    sim::StudioOptions so;
    so.actor.motion = sim::Motion::walk;
    record_take(dir_ / "take", so, kLast);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static std::string args(const fs::path& out) {
    return "--take " + (dir_ / "take").string() +
           " --box -1.5,0,-1.5,1.5,2.4,1.5 --grid 48 --refine --texture --out " + out.string();
  }
  static std::string hull() { return STUDIO_HULL_CLI; }
  static inline fs::path dir_;
};

TEST_F(HullFarm, ShardsWithOneKilledAndRestartedEqualAnUnshardedRun) {
  // The unsharded run.
  const fs::path whole = dir_ / "whole";
  auto r = run(hull() + " offline " + args(whole) + " --threads 2 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"event\":\"summary\",\"frames\":50,\"computed\":50,\"skipped\":0,\"index_"
                       "written\":true"),
            std::string::npos)
      << r.out;
  const auto expected = files_of(whole);
  ASSERT_EQ(expected.size(), 51u);  // 50 frames + the index
  ASSERT_TRUE(expected.contains("actor_000000.glb") && expected.contains("actor_000049.glb") &&
              expected.contains("actor.gltf"));
  for (const auto& [name, bytes] : expected) {
    if (name.ends_with(".glb")) {
      auto info = offline::verify_frame_glb(
          std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
      ASSERT_TRUE(info) << name << ": " << info.error().message;
      EXPECT_TRUE(info->coloured);
      EXPECT_GT(info->triangles, 100u);
    }
  }

  // The plan: 4 contiguous shards.
  r = run(hull() + " offline " + args(dir_ / "unused") + " --plan 4", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "0:11\n12:24\n25:36\n37:49\n");

  // Shard 12:24 started alone and killed after a few frames.
  const fs::path sharded = dir_ / "sharded";
  fs::create_directories(sharded);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string cmd =
        "exec " + hull() + " offline " + args(sharded) + " --frames 12:24 --threads 1 --quiet";
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), nullptr);
    ::_exit(127);
  }
  ASSERT_GT(pid, 0);
  const auto count = [&] {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(sharded)) n += e.path().extension() == ".glb";
    return n;
  };
  const auto t0 = std::chrono::steady_clock::now();
  while (count() < 3 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(300)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the shard finished before it could be killed";
  const std::size_t before = count();
  ASSERT_GE(before, 3u);
  ASSERT_LT(before, 13u);

  // The whole take through the farm script (local mode): the killed shard resumes.
  const fs::path logs = dir_ / "logs";
  r = run(std::string(STUDIO_HULL_FARM) + " --local --shards 4 --parallel 2 --log-dir " +
              logs.string() + " --hull " + hull() + " -- " + args(sharded) + " --threads 1",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string resumed = slurp(logs / "shard-12-24.json");
  EXPECT_NE(resumed.find("\"skipped\":" + std::to_string(before)), std::string::npos) << resumed;
  EXPECT_EQ(files_of(sharded), expected);

  // Idempotent: a rerun skips every frame and changes nothing.
  r = run(hull() + " offline " + args(whole) + " --threads 2 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":0,\"skipped\":50"), std::string::npos) << r.out;
  EXPECT_EQ(files_of(whole), expected);

  // Progress for people: a bar with the rate and the ETA on stderr (--progress forces it here).
  r = run(hull() + " offline " + args(dir_ / "progress") + " --frames 0:3 --threads 1 --progress",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("4/4 frames (0 skipped)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames/min ETA 00:00"), std::string::npos) << r.err;

  // A damaged frame fails verification and is recomputed, identical.
  {
    const std::string damaged = expected.at("actor_000030.glb").substr(0, 1000);
    std::ofstream(whole / "actor_000030.glb", std::ios::binary | std::ios::trunc) << damaged;
  }
  r = run(hull() + " offline " + args(whole) + " --frames 25:36 --threads 2 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":1,\"skipped\":11"), std::string::npos) << r.out;
  EXPECT_EQ(files_of(whole), expected);

  // Frames made with other settings are recomputed, not skipped.
  r = run(hull() + " offline " + args(whole) + " --threshold 8 --frames 0:1 --threads 2 --json",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":2,\"skipped\":0"), std::string::npos) << r.out;
  // The carve's judges are a setting too: all judges recompute, the default's own value skips.
  r = run(hull() + " offline " + args(whole) +
              " --threshold 8 --judges all --frames 0:1 --threads 2 --json",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":2,\"skipped\":0"), std::string::npos) << r.out;
  r = run(hull() + " offline " + args(whole) +
              " --threshold 8 --judges all --frames 0:1 --threads 2 --json",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":0,\"skipped\":2"), std::string::npos) << r.out;
}

// --surface: the surface stage after carving (offline/surface_refine.h) runs in the process: the
// same topology as the carved frames, vertices moved (the hull's bulges inwards, so no frame's
// bounds grow), its setting in the fingerprint (a rerun skips, another setting recomputes).
// --refine runs it with 10 steps unless told otherwise: the default's files are --surface 10's.
TEST_F(HullFarm, SurfaceStage) {
  const fs::path carved = dir_ / "surface_carved", surface = dir_ / "surface_on";
  auto r = run(
      hull() + " offline " + args(carved) + " --surface off --frames 0:3 --threads 2 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(hull() + " offline " + args(surface) + " --frames 0:3 --threads 2 --json", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":4,\"skipped\":0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"surface\":"), std::string::npos) << r.out;
  for (int f = 0; f <= 3; ++f) {
    const std::string name = offline::frame_file_name("actor", f);
    const auto a = offline::verify_frame_file((carved / name).string());
    const auto b = offline::verify_frame_file((surface / name).string());
    ASSERT_TRUE(a && b) << name;
    EXPECT_EQ(a->vertices, b->vertices);
    EXPECT_EQ(a->triangles, b->triangles);
    EXPECT_TRUE(b->coloured);
    EXPECT_NE(a->options, b->options);
    EXPECT_NE(slurp(carved / name), slurp(surface / name)) << name;
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(b->min[k], a->min[k] - 1e-5f) << name;
      EXPECT_LE(b->max[k], a->max[k] + 1e-5f) << name;
    }
  }
  r = run(hull() + " offline " + args(surface) + " --surface 10 --frames 0:3 --threads 2 --json",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":0,\"skipped\":4"), std::string::npos) << r.out;
  r = run(hull() + " offline " + args(surface) + " --surface 4 --frames 0:0 --threads 2 --json",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"computed\":1,\"skipped\":0"), std::string::npos) << r.out;
  // Refused by reason, one line: a negative step count, the photo term without the stage.
  for (const std::string& bad :
       {std::string(" --surface -1"), std::string(" --surface off --surface-photo 2"),
        std::string(" --surface x")}) {
    r = run(hull() + " offline " + args(surface) + bad, dir_);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("--surface"), std::string::npos) << r.err;
  }
}

// --colour-balance: a take whose cameras differ in exposure and white balance (camera 2 about
// 20 % brighter) is equalised; the default estimates once for the take (a "colour_balance" JSON
// event; a shard computes the same gains, so its frame is the same file), frame estimates each
// frame (the gains in its event); both are the simulated ones (display values, the rig's mean 1)
// within 3 %; the camera far off the mean is named on stderr for the operator; off: no gains,
// other files (the setting is in the fingerprint).
TEST_F(HullFarm, ColourBalanceEqualisesTheCameras) {
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::walk;
  // The offline tests' rig (8 on the ring + overhead, 704x576): the small take's 6 cameras at
  // 176x144 share too few surface points seen from similar angles (their gains stay 1).
  sim::RingOptions rig;
  rig.count = 9;
  so.camera_response = sim::random_camera_response(9, 5, 0.05, 0.03);
  so.camera_response[2] = {1.5, 1.5, 1.5};  // ~ +20 % in display values
  const fs::path take = dir_ / "tinted_take";
  record_take(take, so, 3, rig);
  const std::string common = "--take " + take.string() +
                             " --box -1.5,0,-1.5,1.5,2.4,1.5 --grid 128 --refine --texture"
                             " --threads 2 --json --out ";
  const std::vector<std::array<double, 3>> want = sim::balancing_gains(so.camera_response);
  // The largest relative difference of the gains in a JSON line from the simulated ones.
  const auto gain_error = [&](const std::string& line) {
    double worst = 0;
    for (std::size_t c = 0; c < 9; ++c) {
      const std::string key = "\"cam" + std::to_string(c) + "\":[";
      const auto at = line.find(key);
      if (at == std::string::npos) return 1.0;
      double g[3];
      if (std::sscanf(line.c_str() + at + key.size(), "%lf,%lf,%lf", &g[0], &g[1], &g[2]) != 3)
        return 1.0;
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(g[k] / want[c][std::size_t(k)] - 1));
    }
    return worst;
  };
  const auto lines_of = [](const std::string& out, const std::string& event) {
    std::vector<std::string> found;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);)
      if (line.find("\"event\":\"" + event + "\"") != std::string::npos) found.push_back(line);
    return found;
  };

  // The default: one estimate for the take, pooled over its frames (4 here), applied to all.
  const fs::path on = dir_ / "balance_take", per_frame = dir_ / "balance_frame",
                 off = dir_ / "balance_off";
  auto r = run(hull() + " offline " + common + on.string(), dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto take_event = lines_of(r.out, "colour_balance");
  ASSERT_EQ(take_event.size(), 1u) << r.out;
  EXPECT_NE(take_event[0].find("\"frames\":4"), std::string::npos) << take_event[0];
  EXPECT_NE(take_event[0].find("\"applied\":true"), std::string::npos) << take_event[0];
  const double take_error = gain_error(take_event[0]);
  EXPECT_EQ(lines_of(r.out, "frame").size(), 4u) << r.out;
  EXPECT_NE(r.out.find("\"colour_balanced_frames\":4"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"balance\":"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("camera cam2: colours"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("camera cam1: colours"), std::string::npos) << r.err;
  // A shard computes the same take estimate: frame 2 alone gives the same file.
  const fs::path shard = dir_ / "balance_shard";
  r = run(hull() + " offline " + common + shard.string() + " --frames 2:2", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(slurp(shard / offline::frame_file_name("actor", 2)),
            slurp(on / offline::frame_file_name("actor", 2)));

  // Frame by frame: each frame's own estimate in its event.
  r = run(hull() + " offline " + common + per_frame.string() + " --colour-balance frame", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(lines_of(r.out, "colour_balance").empty()) << r.out;
  double frame_error = 0;
  const auto frame_events = lines_of(r.out, "frame");
  EXPECT_EQ(frame_events.size(), 4u) << r.out;
  for (const std::string& line : frame_events) {
    EXPECT_NE(line.find("\"colour_balanced\":true"), std::string::npos) << line;
    frame_error = std::max(frame_error, gain_error(line));
  }
  std::printf(
      "  colour gains vs the simulated responses: the take's %.2f %%, frame by frame "
      "worst %.2f %%\n",
      100 * take_error, 100 * frame_error);
  EXPECT_LT(take_error, 0.03);
  EXPECT_LT(frame_error, 0.03);

  r = run(hull() + " offline " + common + off.string() + " --colour-balance off", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.find("colour_gains"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("camera cam2"), std::string::npos) << r.err;
  for (int f = 0; f <= 3; ++f) {
    const std::string name = offline::frame_file_name("actor", f);
    const auto a = offline::verify_frame_file((on / name).string());
    const auto b = offline::verify_frame_file((off / name).string());
    const auto c = offline::verify_frame_file((per_frame / name).string());
    ASSERT_TRUE(a && b && c) << name;
    EXPECT_NE(a->options, b->options) << name;
    EXPECT_NE(a->options, c->options) << name;
  }
  // Another value is refused, one line.
  r = run(hull() + " offline " + common + off.string() + " --colour-balance maybe", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("--colour-balance"), std::string::npos) << r.err;
}

TEST_F(HullFarm, BadInputIsOneLine) {
  const fs::path out = dir_ / "bad";
  for (const std::string& a :
       {std::string("--refine --box 0,0,0,1,1,1 --grid 8 --out ") + out.string(),  // no take
        "--take " + (dir_ / "nothing").string() + " --refine --box 0,0,0,1,1,1 --grid 8 --out " +
            out.string(),
        "--take " + (dir_ / "take").string() + " --box 0,0,0,1,1,1 --grid 8 --out " + out.string() +
            " --refine --threshold -1",
        "--take " + (dir_ / "take").string() + " --refine --box 0,0,0,1,1,1 --grid 8 --out " +
            out.string() + " --name a/b",
        "--take " + (dir_ / "take").string() + " --refine --box 0,0,0,1,1,1 --grid 8 --out " +
            out.string() + " --judges 1"}) {
    auto r = run(hull() + " offline " + a, dir_);
    EXPECT_EQ(r.code, 2) << a;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("studio-hull: ", 0), 0u) << r.err;
  }
  // The farm script refuses --frames (it chooses them) and unknown options.
  auto r = run(std::string(STUDIO_HULL_FARM) + " --local -- " + args(out) + " --frames 0:1", dir_);
  EXPECT_EQ(r.code, 2);
  r = run(std::string(STUDIO_HULL_FARM) + " --help", dir_);
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--local"), std::string::npos);
  r = run(hull() + " offline --help", dir_);
  EXPECT_NE(r.out.find("--refine"), std::string::npos);
  EXPECT_NE(r.out.find("--texture"), std::string::npos);
  EXPECT_NE(r.out.find("--surface"), std::string::npos);
  EXPECT_NE(r.out.find("--colour-balance take|frame|off"), std::string::npos);
}

// The Slurm submission itself (no Slurm needed): one job array over the plan's shards, each task
// running the same command as the local mode with its range, and a dependent index job.
TEST_F(HullFarm, SlurmSubmission) {
  auto r = run(std::string(STUDIO_HULL_FARM) +
                   " --dry-run --shards 4 --cpus 2 --partition render --hull " + hull() + " -- " +
                   args(dir_ / "slurm"),
               dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("sbatch --parsable -c 2 -J studio-hull-offline -p render --array 0-3"),
            std::string::npos)
      << r.out;
  for (const char* range : {"0:11", "12:24", "25:36", "37:49"})
    EXPECT_NE(r.out.find(range), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("SLURM_ARRAY_TASK_ID"), std::string::npos) << r.out;
}

// The same shards as a Slurm job array on a single-node Slurm started for the test
// (cli/slurm-single-node.sh: munged, slurmctld and slurmd in a temporary folder, on ports of this
// process's own): the array and the dependent index job write exactly the unsharded run's files.
// Needs slurm-wlm and munge (deploy/debian-packages.txt) and root (slurmd starts the jobs).
TEST_F(HullFarm, SlurmJobArray) {
  const fs::path cluster = dir_ / "slurm_cluster";
  const int port = 20000 + int(::getpid() % 20000) * 2;
  auto started = run(std::string(STUDIO_SLURM_SINGLE_NODE) + " start " + cluster.string() + " " +
                         std::to_string(port),
                     dir_);
  ASSERT_EQ(started.code, 0) << started.err;
  struct Stop {
    fs::path dir;
    ~Stop() {
      (void)std::system((std::string(STUDIO_SLURM_SINGLE_NODE) + " stop " + dir.string()).c_str());
    }
  } stop{cluster};
  ::setenv("SLURM_CONF", (cluster / "slurm.conf").c_str(), 1);
  const fs::path whole = dir_ / "slurm_whole", farm = dir_ / "slurm_farm";
  auto r = run(hull() + " offline " + args(whole) + " --threads 2", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(std::string(STUDIO_HULL_FARM) + " --shards 4 --log-dir " +
              (dir_ / "slurm_logs").string() + " --hull " + hull() + " -- " + args(farm) +
              " --threads 2",
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto t0 = std::chrono::steady_clock::now();
  // Until the array and the index job have left the queue.
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(900)) {
    const auto q = run("squeue -h -o '%i %r'", dir_);
    if (q.code == 0 && q.out.empty()) break;
    // A failed array task: the index job waits for ever.
    ASSERT_EQ(q.out.find("DependencyNeverSatisfied"), std::string::npos)
        << q.out << slurp(dir_ / "slurm_logs" / "task-1_0.err");
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  ASSERT_TRUE(fs::exists(farm / "actor.gltf"));
  EXPECT_EQ(files_of(farm), files_of(whole));
  // Slurm ran the array: one log per task, each with its shard's JSON summary.
  int task_logs = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "slurm_logs")) {
    const std::string name = e.path().filename().string();
    if (name.starts_with("task-") && name.ends_with(".json")) {
      ++task_logs;
      EXPECT_NE(slurp(e.path()).find("\"event\":\"summary\""), std::string::npos) << name;
    }
  }
  EXPECT_EQ(task_logs, 4);
  ::unsetenv("SLURM_CONF");
}

}  // namespace
}  // namespace studio::hull
