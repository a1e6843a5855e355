#include "report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <thread>

#include "cpu_budget.h"
#include "json_writer.h"
#include "projector_report.h"

namespace studio::demo {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Stats {
  std::vector<double> v;  // sorted, ms
  double pct(double p) const {
    if (v.empty()) return kNaN;
    const std::size_t k = std::size_t(std::ceil(p / 100.0 * double(v.size())));  // nearest rank
    return v[std::clamp<std::size_t>(k, 1, v.size()) - 1];
  }
  double mean() const {
    return v.empty() ? kNaN : std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
  }
  void write(JsonWriter& j) const {
    j.begin_object();
    j.field("p50", pct(50)).field("p95", pct(95)).field("p99", pct(99));
    j.field("max", v.empty() ? kNaN : v.back()).field("mean", mean());
    j.field("n", uint64_t(v.size()));
    j.end_object();
  }
};

void add(Stats& s, int64_t from_ns, int64_t to_ns) {
  if (from_ns && to_ns) s.v.push_back(double(to_ns - from_ns) * 1e-6);
}

void draw_histogram(const Stats& s, const std::string& title, const std::string& path) {
  const int W = 900, H = 460, L = 70, R = 30, T = 60, B = 60;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const double hi = std::max(80.0, s.v.empty() ? 80.0 : std::ceil(s.pct(99) * 1.3 / 10) * 10);
  const int bins = 80;
  const double bw = hi / bins;
  std::vector<int> count(bins, 0);
  for (double x : s.v) count[std::clamp(int(x / bw), 0, bins - 1)]++;
  const int top = std::max(1, *std::max_element(count.begin(), count.end()));
  const double px = double(W - L - R) / bins;
  for (int i = 0; i < bins; ++i) {
    const int h = int(double(count[i]) / top * (H - T - B));
    cv::rectangle(img, cv::Point(L + int(i * px), H - B - h),
                  cv::Point(L + int((i + 1) * px) - 1, H - B), cv::Scalar(180, 120, 40),
                  cv::FILLED);
  }
  cv::line(img, {L, H - B}, {W - R, H - B}, cv::Scalar(0, 0, 0));
  cv::line(img, {L, T}, {L, H - B}, cv::Scalar(0, 0, 0));
  for (double x = 0; x <= hi + 1e-9; x += hi / 8) {
    const int u = L + int(x / hi * (W - L - R));
    cv::line(img, {u, H - B}, {u, H - B + 5}, cv::Scalar(0, 0, 0));
    cv::putText(img, std::to_string(int(x)), {u - 10, H - B + 22}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 0));
  }
  cv::putText(img, "ms (capture_ns -> delivered)", {W / 2 - 120, H - 12}, cv::FONT_HERSHEY_SIMPLEX,
              0.5, cv::Scalar(0, 0, 0));
  cv::putText(img, "frames", {8, T - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0));
  cv::putText(img, "max " + std::to_string(top), {8, T + 12}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(0, 0, 0));
  const std::pair<double, cv::Scalar> marks[] = {
      {50, cv::Scalar(0, 160, 0)}, {95, cv::Scalar(0, 140, 255)}, {99, cv::Scalar(0, 0, 220)}};
  int row = 0;
  for (const auto& [p, colour] : marks) {
    const double x = s.pct(p);
    if (!std::isfinite(x)) continue;
    const int u = L + int(std::min(x, hi) / hi * (W - L - R));
    cv::line(img, {u, T}, {u, H - B}, colour, 2);
    char label[64];
    std::snprintf(label, sizeof label, "p%d %.1f ms", int(p), x);
    cv::putText(img, label, {W - R - 170, T + 18 + 20 * row++}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                colour, 1);
  }
  cv::putText(img, title, {L, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1);
  cv::imwrite(path, img);
}

// "; inside hull:hull mask_to_mesh 7.4 ms: refine 4.0, mesh 1.4, cut 0.9 ms" from the stage gauges
// of the first service named `service` (its last status); "" when it publishes none.
std::string inside_line(const Collected& c, const std::string& service) {
  for (const ServiceSeen& s : c.services) {
    if (s.service != service) continue;
    std::vector<std::pair<double, std::string>> stages;
    std::string total;
    char buf[96];
    for (const auto& [name, v] : s.counters) {
      if (name.starts_with("stage_") && name.ends_with("_ms") && v > 0) {
        stages.emplace_back(v, name.substr(6, name.size() - 9));
      } else if (name.ends_with("_to_mesh_ms") || name.ends_with("_to_frame_ms")) {
        std::snprintf(buf, sizeof buf, " %s %.1f ms", name.substr(0, name.size() - 3).c_str(), v);
        total = buf;
      }
    }
    if (stages.empty()) return {};
    std::sort(stages.rbegin(), stages.rend());
    std::string out = "; inside " + s.service + ":" + s.instance + total + ":";
    for (std::size_t k = 0; k < std::min<std::size_t>(4, stages.size()); ++k) {
      std::snprintf(buf, sizeof buf, "%s %s %.1f", k ? "," : "", stages[k].second.c_str(),
                    stages[k].first);
      out += buf;
    }
    return out + " ms (running means)";
  }
  return {};
}

}  // namespace

std::string make_report(const ProbeOptions& o, const Collected& c) {
  const auto& clock = o.studio.clock;
  const int64_t half = clock.period_ns / 2;
  const double rate = 1e9 / double(clock.period_ns);
  const int ncams = int(o.studio.camera_ids.size());
  const double window_s = double(c.window_end_ns - c.window_start_ns) * 1e-9;

  // Frames whose capture instant lies in the window.
  uint64_t f_lo = clock.frame_at(c.window_start_ns - half);
  while (clock.time_of(f_lo) + half < c.window_start_ns) ++f_lo;
  uint64_t f_hi = clock.frame_at(c.window_end_ns - half);
  while (clock.time_of(f_hi) + half < c.window_end_ns) ++f_hi;
  if (!c.ready) f_hi = f_lo;

  Stats cap_mask, mask_seg, seg_mesh, seg_head, cap_mesh, cap_head, cap_both;
  uint64_t expected = 0, received = 0, complete = 0, meshes = 0, heads = 0, any_mask = 0;
  std::vector<uint64_t> per_camera(ncams, 0);
  std::optional<uint64_t> worst;  // the frame with the longest capture -> delivered
  int64_t worst_ns = 0;
  for (uint64_t f = f_lo; f < f_hi; ++f) {
    expected += uint64_t(ncams);
    auto it = c.frames.find(f);
    if (it == c.frames.end()) continue;
    const FrameTimes& t = it->second;
    received += uint64_t(t.masks);
    for (int i = 0; i < ncams; ++i) per_camera[i] += (t.mask_bits >> i) & 1u;
    if (t.masks > 0) ++any_mask;
    if (t.masks == ncams) ++complete;
    if (t.mesh_ns) ++meshes;
    if (t.head_ns) ++heads;
    if (t.masks == ncams) add(cap_mask, t.capture_ns, t.last_mask_ns);
    if (t.masks == ncams) add(mask_seg, t.last_mask_ns, t.segments_ns);
    add(seg_mesh, t.segments_ns, t.mesh_ns);
    add(seg_head, t.segments_ns, t.head_ns);
    add(cap_mesh, t.capture_ns, t.mesh_ns);
    add(cap_head, t.capture_ns, t.head_ns);
    if (t.mesh_ns && t.head_ns) add(cap_both, t.capture_ns, std::max(t.mesh_ns, t.head_ns));
    const int64_t done = std::max(t.mesh_ns, t.head_ns);
    if (t.mesh_ns && (!worst || done - t.capture_ns > worst_ns)) {
      worst = f;
      worst_ns = done - t.capture_ns;
    }
  }
  for (Stats* s : {&cap_mask, &mask_seg, &seg_mesh, &seg_head, &cap_mesh, &cap_head, &cap_both})
    std::sort(s->v.begin(), s->v.end());
  const bool have_heads = !cap_both.v.empty();
  // The projector (studio/projector/frame): when its frames arrived, the headline is its motion
  // to photon and fps counts the meshes that reached it.
  const ProjectorFigures proj = projector_figures(c, window_s);
  const Stats cap_proj{proj.motion_to_photon_ms}, mesh_proj{proj.mesh_to_projector_ms};
  const bool have_proj = !cap_proj.v.empty();
  const Stats& headline = have_proj ? cap_proj : have_heads ? cap_both : cap_mesh;
  const char* headline_stage =
      have_proj    ? "capture -> first projector frame rendered with that mesh (motion to photon: "
                     "the mesh's capture_ns -> studio/projector/frame render_done_ns)"
      : have_heads ? "capture -> actor mesh and head both delivered to a subscriber (no projector "
                     "frames arrived)"
                   : "capture -> actor mesh delivered to a subscriber (no head updates arrived)";

  JsonWriter j;
  j.begin_object();
  j.field("complete", c.ready);
  if (!c.ready) j.field("not_ready", c.not_ready_reason);
  j.field("cameras", ncams).field("camera_fps", rate).field("window_s", window_s);
  j.key("frames").begin_object();
  j.field("expected", f_hi - f_lo)
      .field("with_any_mask", any_mask)
      .field("with_all_masks", complete);
  j.field("with_mesh", meshes).field("with_head", heads);
  j.end_object();
  const double hull_fps = window_s > 0 ? double(meshes) / window_s : 0;
  const double fps = proj.ran ? proj.mesh_fps : hull_fps;
  j.field("fps", fps);
  j.field("fps_stage", proj.ran ? "actor meshes reaching the projector: distinct mesh frames in "
                                  "studio/projector/frame per second (the slowest projector)"
                                : "studio/actor/mesh delivered (hull output; no projector frames "
                                  "arrived)");
  j.field("hull_fps", hull_fps);
  j.field("heads_per_s", window_s > 0 ? double(heads) / window_s : 0);
  j.key("latency_ms");
  {
    j.begin_object();
    j.field("stage", headline_stage);
    j.field("p50", headline.pct(50)).field("p95", headline.pct(95)).field("p99", headline.pct(99));
    j.field("max", headline.v.empty() ? kNaN : headline.v.back())
        .field("n", uint64_t(headline.v.size()));
    j.key("stages").begin_object();
    j.key("capture_to_mask");
    cap_mask.write(j);
    j.key("mask_to_segments");
    mask_seg.write(j);
    j.key("segments_to_mesh");
    seg_mesh.write(j);
    j.key("segments_to_head");
    seg_head.write(j);
    j.key("mesh_to_projector_frame");
    mesh_proj.write(j);
    j.end_object();
    j.key("end_to_end").begin_object();
    j.key("capture_to_mesh");
    cap_mesh.write(j);
    j.key("capture_to_head");
    cap_head.write(j);
    j.key("capture_to_mesh_and_head");
    cap_both.write(j);
    j.key("capture_to_projector_frame");
    cap_proj.write(j);
    j.end_object();
    // Inside the services: their own per-stage gauges (running means over ~20 frames, ms) from
    // the last status: the hull's (hull/node/hull_stages.h: mask delivery, cut, mesh, refine,
    // publish, mask_to_mesh) and the projector's (projector/node/frame_stages.h).
    j.key("inside_services").begin_object();
    for (const ServiceSeen& s : c.services) {
      bool any = false;
      for (const auto& [name, v] : s.counters) {
        if (!name.starts_with("stage_") && !name.starts_with("scene_image_") &&
            !name.ends_with("_to_mesh_ms") && !name.ends_with("_to_frame_ms") &&
            !name.ends_with("_to_mask_ms"))
          continue;
        if (!any) j.key(s.service + ":" + s.instance).begin_object();
        any = true;
        j.field(name, v);
      }
      if (any) j.end_object();
    }
    j.end_object();
    // Where the slowest frame spent its time (a stall shows up in one stage).
    j.key("slowest_frame").begin_object();
    if (worst) {
      const FrameTimes& t = c.frames.at(*worst);
      auto ms = [](int64_t a, int64_t b) { return a && b ? double(b - a) * 1e-6 : kNaN; };
      j.field("frame", *worst).field("total", double(worst_ns) * 1e-6);
      j.field("masks", t.masks);
      j.field("capture_to_mask", t.masks == ncams ? ms(t.capture_ns, t.last_mask_ns) : kNaN);
      j.field("mask_to_segments", t.masks == ncams ? ms(t.last_mask_ns, t.segments_ns) : kNaN);
      j.field("segments_to_mesh", ms(t.segments_ns, t.mesh_ns));
      j.field("segments_to_head", ms(t.segments_ns, t.head_ns));
    }
    j.end_object();
    j.end_object();
  }
  // Hull IoU.
  j.key("hull_iou");
  if (c.mesh_scores.empty()) {
    j.null();
  } else {
    double sum = 0;
    for (const auto& m : c.mesh_scores) sum += m.mean_iou;
    j.value(sum / double(c.mesh_scores.size()));
  }
  j.key("hull_iou_detail").begin_object();
  {
    double worst = 1;
    std::string where;
    for (const auto& m : c.mesh_scores)
      if (m.min_iou < worst) {
        worst = m.min_iou;
        where = m.worst_camera + " frame " + std::to_string(m.frame);
      }
    j.field("frames_scored", uint64_t(c.mesh_scores.size()));
    j.field("worst_camera_iou", c.mesh_scores.empty() ? kNaN : worst).field("worst_at", where);
    j.field("truth",
            "simulator's geometric silhouette (true mask) of the same frame number, "
            "mesh rasterised at pixel centres, every camera");
  }
  j.end_object();
  // Head error.
  j.key("head_error_m");
  double rms = kNaN, worst_head = kNaN;
  if (!c.heads.empty()) {
    double ss = 0;
    worst_head = 0;
    for (const auto& h : c.heads) {
      ss += h.error_m * h.error_m;
      worst_head = std::max(worst_head, h.error_m);
    }
    rms = std::sqrt(ss / double(c.heads.size()));
  }
  j.value(rms);
  j.key("head_error_detail").begin_object();
  j.field("updates", uint64_t(c.heads.size())).field("max_m", worst_head);
  j.field("truth", "the simulated actor's head centre at the same frame number");
  j.end_object();
  write_projector(j, proj, c);
  // Masks lost.
  j.field("masks_lost", expected - received);
  j.key("masks_detail").begin_object();
  j.field("expected", expected).field("received", received);
  j.field("rejected_by_validator", c.masks_rejected);
  j.key("per_camera_per_s").begin_object();
  for (int i = 0; i < ncams; ++i)
    j.field(o.studio.camera_ids[i], window_s > 0 ? double(per_camera[i]) / window_s : 0.0);
  j.end_object();
  j.end_object();
  // Rig check.
  if (!o.rig.empty()) {
    j.key("rig_check").begin_object();
    j.field("rig", o.rig);
    if (c.rig_max_diff) j.field("max_abs_diff", *c.rig_max_diff);
    j.field("matches", c.rig_max_diff.has_value() && *c.rig_max_diff < 1e-9);
    j.field("detail", c.rig_detail);
    j.end_object();
  }
  // Services.
  j.key("per_service").begin_array();
  std::string busiest;
  double busiest_cpu = -1;
  std::map<std::string, double> delivered_by_service;  // for the CPU budget
  for (const ServiceSeen& s : c.services) {
    j.begin_object();
    j.field("service", s.service).field("instance", s.instance).field("pid", s.pid);
    j.field("host", s.host).field("state", s.state);
    j.field("rate_hz", s.statuses_in_window ? s.output_hz_sum / s.statuses_in_window : s.output_hz);
    j.field("input_hz", s.statuses_in_window ? s.input_hz_sum / s.statuses_in_window : s.input_hz);
    j.field("latency_ms", s.latency_ms);
    // What reached the probe from this service, per second (its status may not report a rate).
    double delivered = kNaN;
    if (s.service == "capture") {
      for (int i = 0; i < ncams; ++i)
        if (o.studio.camera_ids[i] == s.instance && window_s > 0)
          delivered = double(per_camera[i]) / window_s;
    } else if (s.service == "hull") {
      delivered = hull_fps;
    } else if (s.service == "projector" && proj.per_projector.contains(s.instance)) {
      delivered = proj.per_projector.at(s.instance).first;
    } else if (s.service == "tracker" && window_s > 0) {
      delivered = double(heads) / window_s;
    }
    j.field("delivered_hz", delivered);
    delivered_by_service[s.service + ":" + s.instance] = delivered;
    double cpu = kNaN;
    if (s.proc_start && s.proc_end) cpu = cpu_percent(*s.proc_start, *s.proc_end);
    j.field("cpu_percent", cpu).field("rss_mb", s.proc_end ? s.proc_end->rss_mb : kNaN);
    if (std::isfinite(cpu) && cpu > busiest_cpu) {
      busiest_cpu = cpu;
      busiest = s.service + ":" + s.instance;
    }
    j.key("counters_in_window").begin_object();
    for (const auto& [name, v] : s.counters) {
      if (name.ends_with("_hz")) continue;  // the status's per-second rates, not counts
      auto at = s.counters_at_start.find(name);
      j.field(name, at == s.counters_at_start.end() ? v : v - at->second);
    }
    j.end_object();
    j.end_object();
  }
  j.end_array();
  j.key("probe").begin_object();
  j.field("cpu_percent",
          c.probe_start && c.probe_end ? cpu_percent(*c.probe_start, *c.probe_end) : kNaN);
  j.field("rss_mb", c.probe_end ? c.probe_end->rss_mb : kNaN);
  j.field("note", "the probe's own cost (truth rendering for scoring), on the same cores");
  j.end_object();
  const CpuBudget budget = cpu_budget(
      c, rate, int(std::max(1u, std::thread::hardware_concurrency())), delivered_by_service);
  write_cpu_budget(j, budget);
  j.key("load_average").begin_object();
  j.key("start")
      .begin_array()
      .value(c.load_start[0])
      .value(c.load_start[1])
      .value(c.load_start[2])
      .end_array();
  j.key("end")
      .begin_array()
      .value(c.load_end[0])
      .value(c.load_end[1])
      .value(c.load_end[2])
      .end_array();
  j.end_object();

  // What holds the figures back.
  std::string rate_limit, latency_limit;
  if (c.ready && window_s > 0) {
    const double min_cam =
        per_camera.empty()
            ? 0
            : double(*std::min_element(per_camera.begin(), per_camera.end())) / window_s;
    const double all_masks = double(complete) / window_s;
    const double any = double(any_mask) / window_s;
    char buf[400];
    if (min_cam < 0.95 * rate) {
      std::snprintf(buf, sizeof buf,
                    "capture: the slowest camera delivered %.1f masks/s of %.0f (simulated "
                    "rendering + in-process keying per frame; busiest process %s at %.0f %% CPU)",
                    min_cam, rate, busiest.c_str(), busiest_cpu);
    } else if (all_masks < 0.95 * rate) {
      std::snprintf(buf, sizeof buf,
                    "transport: frames with every camera's mask %.1f/s of %.0f (masks lost on "
                    "the way)",
                    all_masks, rate);
    } else if (hull_fps < 0.95 * any) {
      std::snprintf(buf, sizeof buf, "hull: %.1f meshes/s from %.1f frames/s of masks", hull_fps,
                    any);
    } else if (have_heads && double(heads) / window_s < 0.95 * fps) {
      std::snprintf(buf, sizeof buf, "tracker: %.1f head updates/s from %.1f meshes/s",
                    double(heads) / window_s, hull_fps);
    } else if (proj.ran && proj.mesh_fps < 0.95 * hull_fps) {
      std::snprintf(buf, sizeof buf,
                    "projector: %.1f meshes/s reach a projector frame from %.1f meshes/s "
                    "(rendering %.1f frames/s)",
                    proj.mesh_fps, hull_fps, proj.rendered_fps);
    } else {
      std::snprintf(buf, sizeof buf, "none: every stage keeps the camera rate (%.1f fps)", fps);
    }
    rate_limit = buf;
    const std::pair<const char*, const Stats*> stages[] = {{"capture_to_mask", &cap_mask},
                                                           {"mask_to_segments", &mask_seg},
                                                           {"segments_to_mesh", &seg_mesh},
                                                           {"segments_to_head", &seg_head},
                                                           {"mesh_to_projector_frame", &mesh_proj}};
    double worst = -1;
    for (const auto& [name, s] : stages)
      if (std::isfinite(s->pct(99)) && s->pct(99) > worst) {
        worst = s->pct(99);
        latency_limit = name;
      }
    if (worst >= 0) {
      std::snprintf(buf, sizeof buf, "%s (p99 %.1f ms)", latency_limit.c_str(), worst);
      latency_limit = buf;
      // The service that owns the stage: its own gauges say where inside it the time goes.
      const char* owner = latency_limit.starts_with("mesh_to_projector")  ? "projector"
                          : latency_limit.starts_with("segments_to_head") ? "tracker"
                          : latency_limit.starts_with("capture_to_mask")  ? "capture"
                                                                          : "hull";
      latency_limit += inside_line(c, owner);
      // The simulated cameras render each picture ahead, in the half period before it is due,
      // and deliver it at capture_ns + the modelled read-out (capture/sim_source.h): this stage
      // holds that read-out (a real camera's exposure rest and transfer), then the keying.
      if (latency_limit.starts_with("capture_to_mask")) {
        latency_limit +=
            ": for the simulated cameras this includes the modelled camera read-out "
            "(the rest of the exposure and the link transfer), then keying";
        // As written by the capture servers, before any subscriber's own wake-up delay.
        for (const ServiceSeen& s : c.services)
          if (auto g = s.counters.find("capture_to_mask_ms");
              s.service == "hull" && g != s.counters.end()) {
            std::snprintf(buf, sizeof buf,
                          "; the last mask written %.1f ms after capture (mean, "
                          "the hull's capture_to_mask_ms)",
                          g->second);
            latency_limit += buf;
          }
      }
    }
  }
  j.key("held_back_by").begin_object();
  j.field("rate", rate_limit).field("latency", latency_limit);
  j.field("cpu", cpu_budget_line(budget));
  j.end_object();
  j.end_object();

  if (!o.histogram_png.empty()) {
    char title[200];
    std::snprintf(title, sizeof title, "%s, %zu frames, %d cameras",
                  have_proj    ? "capture -> projector frame rendered"
                  : have_heads ? "capture -> mesh + head delivered"
                               : "capture -> mesh delivered",
                  headline.v.size(), ncams);
    draw_histogram(headline, title, o.histogram_png);
  }
  if (!o.projector_png.empty() && !draw_projector_png(c, o.projector_png))
    std::fprintf(stderr, "[demo] could not write %s\n", o.projector_png.c_str());
  return j.str();
}

}  // namespace studio::demo
