#include "projector_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

namespace studio::demo {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double pct(const std::vector<double>& v, double p) {  // nearest rank of a sorted vector
  if (v.empty()) return kNaN;
  const std::size_t k = std::size_t(std::ceil(p / 100.0 * double(v.size())));
  return v[std::clamp<std::size_t>(k, 1, v.size()) - 1];
}

void write_stats(JsonWriter& j, const std::vector<double>& v) {
  j.begin_object();
  j.field("p50", pct(v, 50)).field("p95", pct(v, 95)).field("p99", pct(v, 99));
  j.field("max", v.empty() ? kNaN : v.back()).field("n", uint64_t(v.size()));
  j.end_object();
}

}  // namespace

ProjectorFigures projector_figures(const Collected& c, double window_s) {
  ProjectorFigures f;
  f.ran = !c.projector.empty();
  if (!f.ran) return f;
  // (projector, mesh frame) -> first render_done_ns.
  std::map<std::pair<std::string, uint64_t>, const ProjectorSample*> first;
  std::map<std::string, std::pair<uint64_t, std::set<uint64_t>>> per;  // rendered, mesh frames
  double actor = 0, wasted = 0, blackout = 0, margin = 0;
  f.margin_min_m = std::numeric_limits<double>::infinity();
  f.margin_max_m = 0;
  // A mesh of the window: captured in it (its first frame may come after it: after_window).
  auto mesh_of_window = [&](const ProjectorSample& p) {
    return p.mesh_frame && p.capture_ns >= c.window_start_ns && p.capture_ns < c.window_end_ns;
  };
  for (const ProjectorSample& p : c.projector) {
    auto& pp = per[p.projector_id];
    if (p.after_window) {
      if (mesh_of_window(p)) {
        pp.second.insert(p.mesh_frame);
        auto& slot = first[{p.projector_id, p.mesh_frame}];
        if (!slot || p.render_done_ns < slot->render_done_ns) slot = &p;
      }
      continue;
    }
    ++f.rendered;
    ++pp.first;
    margin += p.margin_m;
    f.margin_min_m = std::min(f.margin_min_m, p.margin_m);
    f.margin_max_m = std::max(f.margin_max_m, p.margin_m);
    f.predicted_frames += p.predicted ? 1 : 0;
    if (p.mesh_frame && p.capture_ns) {
      f.mask_age_ms.push_back(p.latency_ms);
      // Only meshes captured in the window: an older one may have been first rendered before it.
      if (mesh_of_window(p)) {
        pp.second.insert(p.mesh_frame);
        auto& slot = first[{p.projector_id, p.mesh_frame}];
        if (!slot || p.render_done_ns < slot->render_done_ns) slot = &p;
      }
    }
    if (!p.scored) {
      ++f.unscored;
      continue;
    }
    ++f.scored;
    if (p.eye_error_m >= 0) f.eye_error_m.push_back(p.eye_error_m);
    actor += double(p.actor_px);
    wasted += double(p.wasted_px);
    blackout += double(p.blackout_px);
    f.lit_sum += p.lit_actor_px;
    if (p.lit_actor_px) ++f.frames_with_lit;
    if (f.lit_max_at.empty() || p.lit_actor_px > f.lit_max) {
      f.lit_max = p.lit_actor_px;
      f.lit_max_at = p.projector_id + " render frame " + std::to_string(p.render_frame);
    }
  }
  for (const auto& [key, p] : first) {
    f.motion_to_photon_ms.push_back(double(p->render_done_ns - p->capture_ns) * 1e-6);
    auto it = c.frames.find(key.second);
    if (it != c.frames.end() && it->second.mesh_ns)
      f.mesh_to_projector_ms.push_back(double(p->render_done_ns - it->second.mesh_ns) * 1e-6);
  }
  for (auto* v : {&f.motion_to_photon_ms, &f.mask_age_ms, &f.mesh_to_projector_ms, &f.eye_error_m})
    std::sort(v->begin(), v->end());
  f.mesh_fps = f.rendered_fps = std::numeric_limits<double>::infinity();
  for (const auto& [id, pp] : per) {
    const double r = window_s > 0 ? double(pp.first) / window_s : 0;
    const double m = window_s > 0 ? double(pp.second.size()) / window_s : 0;
    f.per_projector[id] = {r, m};
    f.rendered_fps = std::min(f.rendered_fps, r);
    f.mesh_fps = std::min(f.mesh_fps, m);
  }
  const double n = double(std::max<uint64_t>(f.scored, 1));
  f.actor_px_mean = actor / n;
  f.wasted_px_mean = wasted / n;
  f.blackout_px_mean = blackout / n;
  f.margin_mean_m = margin / double(f.rendered);
  return f;
}

void write_projector(JsonWriter& j, const ProjectorFigures& f, const Collected& c) {
  j.key("lit_actor_px");
  if (f.scored)
    j.value(f.lit_sum);
  else
    j.null();
  j.key("lit_actor_detail").begin_object();
  j.field("frames_rendered", f.rendered).field("frames_scored", f.scored);
  j.field("frames_unscored", f.unscored).field("frames_with_lit", f.frames_with_lit);
  j.field("sum", f.lit_sum).field("max_per_frame", f.lit_max).field("worst_at", f.lit_max_at);
  j.field("mean_actor_px", f.scored ? f.actor_px_mean : kNaN);
  j.field("mean_wasted_px", f.scored ? f.wasted_px_mean : kNaN);
  j.field("mean_blackout_px", f.scored ? f.blackout_px_mean : kNaN);
  j.field("display_lag_s", c.display_lag_s);
  j.field("score_errors", c.projector_score_errors).field("first_error", c.projector_score_error);
  j.field("truth",
          "sim::actor_at_display: projector pixels whose ray meets the simulated actor's true "
          "solid at render_done_ns (studio clock) + display_lag_s, not in the frame's blackout "
          "mask (studio/projector/frame runs), every frame rendered in the window");
  j.end_object();
  j.key("projector").begin_object();
  j.field("ran", f.ran);
  j.field("rendered_fps", f.ran ? f.rendered_fps : 0.0).field("mesh_fps", f.ran ? f.mesh_fps : 0.0);
  j.key("per_projector").begin_object();
  for (const auto& [id, r] : f.per_projector) {
    j.key(id).begin_object();
    j.field("rendered_fps", r.first).field("mesh_fps", r.second);
    auto cal = c.projector_calibrations.find(id);
    j.field("calibration_seen", cal != c.projector_calibrations.end());
    j.end_object();
  }
  j.end_object();
  j.key("motion_to_photon_ms");
  write_stats(j, f.motion_to_photon_ms);
  j.key("mask_age_ms");
  write_stats(j, f.mask_age_ms);
  j.key("mesh_to_projector_ms");
  write_stats(j, f.mesh_to_projector_ms);
  // The eye the scene was drawn from against the true head centre at the frame's display.
  j.key("eye_error_m");
  write_stats(j, f.eye_error_m);
  j.key("margin_m").begin_object();
  j.field("min", f.ran ? f.margin_min_m : kNaN).field("mean", f.ran ? f.margin_mean_m : kNaN);
  j.field("max", f.ran ? f.margin_max_m : kNaN);
  j.end_object();
  j.field("predicted_frames", f.predicted_frames);
  j.field("frames_rejected_by_validator", c.projector_frames_rejected);
  j.end_object();
}

bool draw_projector_png(const Collected& c, const std::string& path) {
  if (!c.projector_picture) return true;
  const ProjectorPicture& p = *c.projector_picture;
  const int W = p.actor.width(), H = p.actor.height();
  if (W <= 0 || H <= 0) return true;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(0, 0, 0));
  if (p.thumb_width > 0 && p.thumb_height > 0 &&
      p.thumbnail.size() == std::size_t(p.thumb_width) * p.thumb_height * 3) {
    cv::Mat thumb(p.thumb_height, p.thumb_width, CV_8UC3, const_cast<uint8_t*>(p.thumbnail.data()));
    cv::Mat bgr;
    cv::cvtColor(thumb, bgr, cv::COLOR_RGB2BGR);
    cv::resize(bgr, img, cv::Size(W, H), 0, 0, cv::INTER_LINEAR);
  }
  for (int y = 0; y < H; ++y) {
    auto* row = img.ptr<cv::Vec3b>(y);
    for (const Run& r : p.blackout.row(y))
      for (int x = r.begin; x < r.end; ++x) row[x] = cv::Vec3b(0, 0, 0);
    for (int x = 0; x < W; ++x) {
      if (!p.actor(x, y)) continue;
      row[x] = p.blackout.contains(x, y) ? cv::Vec3b(90, 30, 0) : cv::Vec3b(0, 0, 255);
    }
  }
  char line1[160], line2[160];
  std::snprintf(line1, sizeof line1, "%s render frame %llu: %llu lit actor px (red)",
                p.projector_id.c_str(), static_cast<unsigned long long>(p.render_frame),
                static_cast<unsigned long long>(p.lit_actor_px));
  std::snprintf(line2, sizeof line2, "black: blackout mask; blue: true actor masked");
  cv::Mat out;
  cv::resize(img, out, cv::Size(W / 2, H / 2), 0, 0, cv::INTER_AREA);
  cv::putText(out, line1, {10, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1);
  cv::putText(out, line2, {10, 42}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1);
  return cv::imwrite(path, out);
}

}  // namespace studio::demo
