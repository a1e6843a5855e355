// studio-demo-probe: the demo's measuring instrument (a demo/test tool, not a service).
//   studio-demo-probe watch --capture FILE... [--rig FILE] [--seconds S] [--warmup S]
//                           [--ready-timeout S] [--score-rate HZ] [--histogram PNG] [--out FILE]
//                           [--projector-png PNG] [--display-lag S]
//   studio-demo-probe take  --capture FILE... [--name TAKE] [--frames N] [--lead S] [--timeout S]
//   studio-demo-probe rig   (--from RIG | --published --capture FILE...) [--cameras ID,...] --out
//   FILE studio-demo-probe score --rig RIG --meshes DIR [--out FILE]
//   studio-demo-probe sweep --rig RIG --latency-ms L [--projectors RIG --projector ID]
//                           [--frames N] [--grid N] [--display-lag S] --out FILE [--png PNG]
// DDS domain and profile as every service: $STUDIO_DDS_DOMAIN, $CYCLONEDDS_URI.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/clock.h"
#include "json_writer.h"
#include "margin_sweep.h"
#include "probe.h"
#include "sim/projector_light.h"
#include "take.h"
#include "testing/mesh_read.h"
#include "truth.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"
#include "yaml_io/rig_yaml.h"

namespace {

using namespace studio;

constexpr const char* kUsage = R"(usage: studio-demo-probe watch --capture FILE... [options]
       studio-demo-probe take  --capture FILE... [--name TAKE] [--frames N] [--lead S]
       studio-demo-probe rig   (--from RIG | --published --capture FILE...) [--cameras ID,...] --out FILE
       studio-demo-probe score --rig RIG --meshes DIR [--out FILE]
       studio-demo-probe sweep --rig RIG --latency-ms L [--projectors RIG --projector ID]
                               [--frames N] [--grid N] [--display-lag S] [--mask-growth G]
                               [--out FILE] [--png PNG]

The demo's measuring instrument (deploy/demo.sh runs it; not a service). It joins the studio's
DDS domain ($STUDIO_DDS_DOMAIN, profile $CYCLONEDDS_URI) like any subscriber.

watch   records masks, segments, meshes, heads and service status for a bounded time and prints
        the figures as JSON: fps (actor meshes delivered per second), latency_ms {p50,p95,p99}
        with per-stage timings (capture->mask, mask->segments, segments->mesh, segments->head),
        hull_iou (live meshes re-projected vs the simulator's true masks of the same frame),
        head_error_m (RMS vs the simulator's true head), masks_lost, per_service (rate from
        studio/service/status, CPU % and RSS from /proc), cpu_budget (each local service's
        CPU ms per frame period and per output, summed per stage, against cores x period: the
        load-robust cost) and held_back_by (rate, latency, cpu). With projectors
        running (studio/projector/frame): lit_actor_px (projector pixels on the simulator's true
        actor at display time that the frame's blackout mask leaves lit, every frame of the
        window), the projector's motion-to-photon latency (then the headline latency_ms) and fps
        (meshes reaching the projector). One progress line per second on stderr.
  --capture FILE...   the capture configs the cameras run with (clock, camera ids); the truth
                      cameras are the calibrations those servers publish
  --rig FILE          the hull's rig.yaml: checked against the published calibrations
  --seconds S         measurement window (default 10)
  --warmup S          after the pipeline is up, before the window (default 3)
  --ready-timeout S   wait for every calibration and a first mesh (default 60)
  --score-rate HZ     live meshes scored against the truth per second (default 2; 0 = none)
  --histogram PNG     latency histogram of the window
  --projector-png PNG the scored projector frame with the most lit actor pixels (thumbnail,
                      blackout, true actor)
  --display-lag S     projector frame rendered -> on the cloth, for the truth (default 0.016)
  --actor-view PNG    what the actor sees: the projector.png frame (its thumbnail scaled up,
                      the full-resolution blackout black) on the cloth, from the true eye
  --out FILE          write the JSON there instead of stdout
  --quiet             no progress lines
take    records a take on every capture server, frame-accurate: START at a future frame, STOP
        N frames later; prints {take, start_frame, stop_frame, complete} as JSON.
  --name TAKE (default demo)  --frames N (default 50)  --lead S (default 1)  --timeout S (30)
rig     writes a rig.yaml: the cameras of RIG (--from), or the calibrations the running capture
        servers publish (--published, cameras of --capture); --cameras keeps only those ids.
score   scores meshes DIR/<frame>.ply (studio-hull offline --out DIR) against the simulator's true
        masks of the same frame in every camera of RIG: {frames, mean_iou, min_iou, worst_at}.
sweep   the projector mask's margin sweep, offline (margin_sweep.h): the simulated actor's fast
        arm swing seen by RIG's cameras -> true masks -> hull library (--grid, default 160) ->
        the projector's MaskPlanner with floor = cap = each margin, prediction on and off ->
        the mask rasterised into the projector (projector ID of the rig file --projectors;
        default a 1280x720 projector of the simulated studio on the side wall, whose beam
        covers the spot where the arm swing stands, which the example proj1's does not) ->
        lit-actor and
        wasted pixels against the true actor, the mesh drawn --latency-ms after its capture
        (the demo passes its live motion-to-photon p99) and shown --display-lag later (0.016).
        --frames N (default 100) scored frames; --mask-growth outline|push (default
        outline, as the projector's mask_growth). JSON: both curves and needed_margin_m (the
        smallest margin with 0 lit pixels); --png: the plot.
Exit status: 0 done; 1 the pipeline delivered nothing / the take did not complete; 2 bad
arguments or setup error (one line on stderr).
)";

int usage_error(const std::string& message) {
  std::cerr << "studio-demo-probe: " << message << "\n";
  return 2;
}

struct Args {
  std::string verb;
  std::vector<std::string> capture;
  std::map<std::string, std::string> opts;
  bool quiet = false, published = false;
};

Expected<Args> parse(int argc, char** argv) {
  Args a;
  a.verb = argv[1];
  for (int i = 2; i < argc; ++i) {
    const std::string o = argv[i];
    if (o == "--capture") {
      while (i + 1 < argc && std::strncmp(argv[i + 1], "--", 2) != 0)
        a.capture.push_back(argv[++i]);
      if (a.capture.empty()) return fail("--capture needs at least one file");
    } else if (o == "--quiet") {
      a.quiet = true;
    } else if (o == "--published") {
      a.published = true;
    } else if (o.starts_with("--") && i + 1 < argc) {
      a.opts[o.substr(2)] = argv[++i];
    } else {
      return fail("unexpected argument '" + o + "' (see --help)");
    }
  }
  return a;
}

Expected<double> number(const Args& a, const std::string& key, double fallback) {
  auto it = a.opts.find(key);
  if (it == a.opts.end()) return fallback;
  try {
    std::size_t used = 0;
    const double v = std::stod(it->second, &used);
    if (used != it->second.size()) throw std::invalid_argument("");
    return v;
  } catch (...) {
    return fail("--" + key + ": '" + it->second + "' is not a number");
  }
}

std::string opt(const Args& a, const std::string& key, const std::string& fallback = {}) {
  auto it = a.opts.find(key);
  return it == a.opts.end() ? fallback : it->second;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

int emit(const std::string& json, const std::string& out) {
  if (out.empty()) {
    std::cout << json << "\n";
    return 0;
  }
  std::ofstream f(out);
  f << json << "\n";
  if (!f) return usage_error("cannot write " + out);
  return 0;
}

int watch(const Args& a) {
  demo::ProbeOptions o;
  auto studio = demo::read_studio_config(a.capture);
  if (!studio) return usage_error(studio.error().message);
  o.studio = *studio;
  if (!o.studio.all_simulated())
    return usage_error("watch scores against the simulator: every camera must be a sim source");
  o.rig = opt(a, "rig");
  auto seconds = number(a, "seconds", o.seconds), warmup = number(a, "warmup", o.warmup_s),
       ready = number(a, "ready-timeout", o.ready_timeout_s),
       rate = number(a, "score-rate", o.score_rate_hz),
       lag = number(a, "display-lag", o.display_lag_s);
  for (auto* v : {&seconds, &warmup, &ready, &rate, &lag})
    if (!*v) return usage_error(v->error().message);
  o.seconds = *seconds;
  o.warmup_s = *warmup;
  o.ready_timeout_s = *ready;
  o.score_rate_hz = *rate;
  o.display_lag_s = *lag;
  o.histogram_png = opt(a, "histogram");
  o.projector_png = opt(a, "projector-png");
  o.actor_view_png = opt(a, "actor-view");
  o.progress = !a.quiet;
  for (const auto& [k, v] : a.opts)
    if (k != "rig" && k != "seconds" && k != "warmup" && k != "ready-timeout" &&
        k != "score-rate" && k != "histogram" && k != "out" && k != "projector-png" &&
        k != "display-lag" && k != "actor-view")
      return usage_error("watch: unknown option --" + k);
  auto json = demo::run_probe(o);
  if (!json) return usage_error(json.error().message);
  if (int rc = emit(*json, opt(a, "out")); rc) return rc;
  return json->find("\"complete\": true") != std::string::npos ? 0 : 1;
}

int take(const Args& a) {
  demo::TakeOptions o;
  auto studio = demo::read_studio_config(a.capture);
  if (!studio) return usage_error(studio.error().message);
  o.studio = *studio;
  o.name = opt(a, "name", o.name);
  auto frames = number(a, "frames", o.frames), lead = number(a, "lead", o.lead_s),
       timeout = number(a, "timeout", o.timeout_s);
  for (auto* v : {&frames, &lead, &timeout})
    if (!*v) return usage_error(v->error().message);
  o.frames = int(*frames);
  o.lead_s = *lead;
  o.timeout_s = *timeout;
  auto json = demo::run_take(o);
  if (!json) return usage_error(json.error().message);
  if (int rc = emit(*json, opt(a, "out")); rc) return rc;
  return json->find("\"complete\": true") != std::string::npos ? 0 : 1;
}

int rig(const Args& a) {
  const std::string out = opt(a, "out");
  if (out.empty()) return usage_error("rig: --out FILE is required");
  Rig rig;
  if (a.published) {
    auto studio = demo::read_studio_config(a.capture);
    if (!studio) return usage_error(studio.error().message);
    auto p = wire::Participant::create();
    if (!p) return usage_error(p.error().message);
    auto cals = wire::Subscription<studio_CameraCalibration>::create(*p);
    if (!cals) return usage_error(cals.error().message);
    std::map<std::string, Camera> seen;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (seen.size() < studio->camera_ids.size() && std::chrono::steady_clock::now() < deadline) {
      (*cals)->visit([&](const studio_CameraCalibration& s, const wire::SampleMeta& meta) {
        if (!meta.valid_data) return;
        if (auto cam = wire::to_core(s)) seen.insert_or_assign(std::string(s.camera_id), *cam);
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    for (const auto& id : studio->camera_ids) {
      auto it = seen.find(id);
      if (it == seen.end()) return usage_error("rig: no calibration of " + id + " within 30 s");
      rig.cameras.push_back(it->second);
    }
  } else {
    const std::string from = opt(a, "from");
    if (from.empty()) return usage_error("rig: give --from RIG or --published");
    auto r = yaml::read_rig(from);
    if (!r) return usage_error(r.error().message);
    rig = *r;
  }
  if (a.opts.contains("cameras")) {
    Rig kept;
    kept.projectors = rig.projectors;
    for (const auto& id : split(opt(a, "cameras"))) {
      const Camera* c = rig.find_camera(id);
      if (!c) return usage_error("rig: camera " + id + " is not in the rig");
      kept.cameras.push_back(*c);
    }
    rig = std::move(kept);
  }
  if (auto w = yaml::write_rig(rig, out); !w) return usage_error(w.error().message);
  return 0;
}

int sweep(const Args& a) {
  const std::string rig_path = opt(a, "rig"), proj_path = opt(a, "projectors"),
                    id = opt(a, "projector");
  if (rig_path.empty() || !a.opts.contains("latency-ms"))
    return usage_error("sweep: --rig and --latency-ms are required");
  if (proj_path.empty() != id.empty())
    return usage_error("sweep: give --projectors and --projector together (or neither)");
  auto rig = yaml::read_rig(rig_path);
  if (!rig) return usage_error(rig.error().message);
  // Default: a 1280x720 projector of the simulated studio lighting the side wall (x = -4.5),
  // whose beam covers the spot where the arm swing stands and sees the swing across its image.
  Projector chosen = sim::studio_projector(sim::Cyclorama{}, {3.8, 2.3, 0.6}, 6.0, 1280, 720,
                                           Eigen::Vector3d(-4.5, 1.4, 0.3), "sim_side_wall");
  if (!proj_path.empty()) {
    auto projectors = yaml::read_rig(proj_path);
    if (!projectors) return usage_error(projectors.error().message);
    const Projector* p = projectors->find_projector(id);
    if (!p) return usage_error("sweep: no projector '" + id + "' in " + proj_path);
    chosen = *p;
  }
  demo::SweepOptions o;
  o.projector = chosen;
  o.cameras = rig->cameras;
  auto latency = number(a, "latency-ms", 0), frames = number(a, "frames", o.frames),
       grid = number(a, "grid", o.grid), lag = number(a, "display-lag", o.display_lag_s);
  for (auto* v : {&latency, &frames, &grid, &lag})
    if (!*v) return usage_error(v->error().message);
  o.latency_s = *latency * 1e-3;
  o.frames = int(*frames);
  o.grid = int(*grid);
  o.display_lag_s = *lag;
  if (const std::string g = opt(a, "mask-growth"); !g.empty()) {
    if (g != "outline" && g != "push")
      return usage_error("sweep: --mask-growth '" + g + "' (expected outline or push)");
    o.outline = g == "outline";
  }
  for (const auto& [k, v] : a.opts)
    if (k != "rig" && k != "projectors" && k != "projector" && k != "latency-ms" && k != "frames" &&
        k != "grid" && k != "display-lag" && k != "out" && k != "png" && k != "mask-growth")
      return usage_error("sweep: unknown option --" + k);
  auto r = demo::margin_sweep(o, !a.quiet);
  if (!r) return usage_error(r.error().message);
  if (const std::string png = opt(a, "png"); !png.empty() && !demo::draw_sweep_png(*r, png))
    return usage_error("sweep: could not write " + png);
  return emit(demo::sweep_json(*r), opt(a, "out"));
}

int score(const Args& a) {
  const std::string rig_path = opt(a, "rig"), dir = opt(a, "meshes");
  if (rig_path.empty() || dir.empty())
    return usage_error("score: --rig RIG and --meshes DIR are required");
  auto rig = yaml::read_rig(rig_path);
  if (!rig) return usage_error(rig.error().message);
  auto truth = demo::TruthScorer::create(rig->cameras);
  if (!truth) return usage_error(truth.error().message);
  std::vector<std::pair<uint64_t, std::string>> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (e.path().extension() != ".ply") continue;
    try {
      std::size_t used = 0;
      const std::string stem = e.path().stem().string();
      const uint64_t f = std::stoull(stem, &used);
      if (used == stem.size()) files.emplace_back(f, e.path().string());
    } catch (...) {
    }
  }
  if (ec) return usage_error("score: " + dir + ": " + ec.message());
  if (files.empty()) return usage_error("score: no <frame>.ply in " + dir);
  std::sort(files.begin(), files.end());
  double sum = 0, worst = 1;
  std::string where;
  for (const auto& [frame, path] : files) {
    auto mesh = hull::testing::read_ply(path);
    if (!mesh) return usage_error(mesh.error().message);
    const demo::MeshScore m = truth->score_meshes(frame, {*mesh});
    sum += m.mean_iou;
    if (m.min_iou < worst) {
      worst = m.min_iou;
      where = m.worst_camera + " frame " + std::to_string(frame);
    }
  }
  demo::JsonWriter j;
  j.begin_object();
  j.field("frames", uint64_t(files.size())).field("mean_iou", sum / double(files.size()));
  j.field("min_iou", worst).field("worst_at", where);
  j.end_object();
  return emit(j.str(), opt(a, "out"));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  for (int i = 2; i < argc; ++i)
    if (std::strcmp(argv[i], "--help") == 0) {
      std::cout << kUsage;
      return 0;
    }
  auto args = parse(argc, argv);
  if (!args) return usage_error(args.error().message);
  try {
    if (args->verb == "watch") return watch(*args);
    if (args->verb == "take") return take(*args);
    if (args->verb == "rig") return rig(*args);
    if (args->verb == "score") return score(*args);
    if (args->verb == "sweep") return sweep(*args);
  } catch (const std::exception& e) {
    return usage_error(e.what());
  }
  return usage_error("unknown command '" + args->verb +
                     "' (watch, take, rig, score or sweep; see --help)");
}
