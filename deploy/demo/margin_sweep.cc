#include "margin_sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/sim_source.h"
#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "json_writer.h"
#include "projector/mask_planner.h"
#include "sim/projector_light.h"
#include "sim/studio.h"
#include "testing/raster.h"

namespace studio::demo {

Expected<void> SweepOptions::validate() const {
  if (cameras.size() < 2) return fail("sweep: at least 2 cameras");
  if (!(latency_s >= 0 && latency_s < 1)) return fail("sweep: latency outside [0, 1) s");
  if (!(display_lag_s > 0 && display_lag_s < 1)) return fail("sweep: display lag outside (0, 1) s");
  if (first_frame < 0 || frames < 3) return fail("sweep: frames >= 3, first frame >= 0");
  if (grid < 8 || grid > 1024) return fail("sweep: grid 8..1024");
  if (margins_m.empty()) return fail("sweep: no margins");
  for (double m : margins_m)
    if (!(m >= 0 && m <= 0.5)) return fail("sweep: margins within [0, 0.5] m");
  return {};
}

Expected<SweepResult> margin_sweep(const SweepOptions& o, bool progress) {
  if (auto ok = o.validate(); !ok) return std::unexpected(ok.error());
  sim::StudioOptions so = capture::SimSourceOptions{}.studio;  // the live cameras' scene
  so.actor.motion = sim::Motion::arm_swing;
  auto studio = sim::SimulatedStudio::create(o.cameras, so);
  if (!studio) return std::unexpected(studio.error());
  const double fps = studio->options().fps;
  const int64_t frame_ns = int64_t(std::llround(1e9 / fps));
  hull::GridSpec g;
  g.box_min = o.box_min;
  g.box_max = o.box_max;
  g.axis = hull::Axis::y;
  g.cells_u = g.cells_v = o.grid;
  hull::CutOptions cut;
  cut.threads = 2;
  const Camera& proj = o.projector.camera;

  projector::MaskPlannerOptions po;
  po.initial_latency_s = o.latency_s;  // never replaced: shown() is not called
  if (o.outline) po.grow.projector = proj;
  projector::MaskPlanner planner(po);
  SweepResult r;
  r.options = o;
  r.predicted.prediction = true;
  for (SweepCurve* c : {&r.predicted, &r.unpredicted})
    for (double m : o.margins_m) c->points.push_back({m});
  double actor_sum = 0;
  const std::size_t n = std::size_t(studio->camera_count());
  for (int k = 0; k < o.frames; ++k) {
    const int f = o.first_frame + k;
    std::vector<Mask> truth(n);
    std::vector<RunMask> runs(n);
    std::vector<hull::View> views;
    for (std::size_t c = 0; c < n; ++c) {
      studio->render(int(c), f, nullptr, &truth[c]);
      runs[c] = RunMask::from_mask(truth[c].view());
      views.push_back({&studio->cameras()[c], &runs[c]});
    }
    auto set = hull::visual_hull(g, views, cut);
    if (!set) return std::unexpected(set.error());
    hull::Mesh mesh = hull::segment_marching_cubes(*set);
    if (auto ok = hull::refine_crossings(mesh, *set, views, cut); !ok)
      return std::unexpected(ok.error());
    if (mesh.empty()) return fail("sweep: frame " + std::to_string(f) + " has no actor mesh");
    projector::ActorMesh am;
    am.vertices = mesh.vertices;
    am.triangles = mesh.triangles;
    const int64_t capture_ns = int64_t(f) * frame_ns;
    am.capture_ns = capture_ns;
    if (auto ok = planner.set_mesh("actor0", uint64_t(f), std::move(am)); !ok)
      return std::unexpected(ok.error());
    if (k < 2) continue;  // the third mesh on: the motion has accelerations (prediction possible)
    const int64_t render_ns = capture_ns + int64_t(std::llround(o.latency_s * 1e9));
    sim::DisplayOptions display;
    display.display_lag_s = o.display_lag_s;
    const Mask actor = sim::actor_at_display(studio->actor(), proj, render_ns * 1e-9, display);
    ++r.frames_scored;
    for (SweepCurve* c : {&r.predicted, &r.unpredicted}) {
      for (SweepPoint& pt : c->points) {
        projector::MarginOptions mo;
        mo.floor_m = mo.cap_m = pt.margin_m;
        mo.prediction = c->prediction;
        if (auto ok = planner.set_margin_options(mo); !ok) return std::unexpected(ok.error());
        auto plan = planner.plan(render_ns);
        if (!plan) return std::unexpected(plan.error());
        if (c->prediction && !plan->margin.predicted)
          return fail("sweep: frame " + std::to_string(f) + ": the planner did not predict");
        r.max_speed_mps = std::max(r.max_speed_mps, plan->margin.speed_mps);
        hull::Mesh drawn;
        drawn.vertices = plan->masks.at(0).vertices;
        drawn.triangles = plan->masks.at(0).triangles;
        const RunMask blackout = RunMask::from_mask(hull::testing::rasterise(drawn, proj).view());
        const sim::LitCount lit = sim::count_lit(actor, blackout);
        if (c == &r.predicted && &pt == &c->points.front()) actor_sum += double(lit.actor);
        pt.lit_actor_px += lit.lit_actor;
        pt.max_per_frame = std::max(pt.max_per_frame, lit.lit_actor);
        pt.frames_with_lit += lit.lit_actor > 0;
        pt.wasted_px_mean += double(lit.wasted);
      }
    }
    if (progress && k % 10 == 0) std::fprintf(stderr, "[sweep] frame %d/%d\n", k + 1, o.frames);
  }
  r.actor_px_mean = actor_sum / std::max(r.frames_scored, 1);
  for (SweepCurve* c : {&r.predicted, &r.unpredicted}) {
    for (SweepPoint& pt : c->points) pt.wasted_px_mean /= std::max(r.frames_scored, 1);
    // The smallest margin from which every larger margin of the sweep also lights nothing.
    for (auto it = c->points.rbegin(); it != c->points.rend() && it->lit_actor_px == 0; ++it)
      c->needed_margin_m = it->margin_m;
  }
  return r;
}

std::string sweep_json(const SweepResult& r) {
  JsonWriter j;
  j.begin_object();
  j.field("what",
          "projector mask margin sweep, offline: sim arm_swing (1.5 m/s) -> true masks -> hull "
          "library (live grid, exact crossings) -> projector::MaskPlanner (floor = cap = margin) "
          "-> rasterised mask vs sim::actor_at_display at render + display lag");
  j.field("projector", r.options.projector.camera.id);
  j.field("latency_s", r.options.latency_s).field("display_lag_s", r.options.display_lag_s);
  j.field("grid", r.options.grid).field("first_frame", r.options.first_frame);
  j.field("frames_scored", r.frames_scored).field("actor_px_mean", r.actor_px_mean);
  j.field("max_region_speed_mps", r.max_speed_mps);
  for (const SweepCurve* c : {&r.predicted, &r.unpredicted}) {
    j.key(c->prediction ? "prediction" : "no_prediction").begin_object();
    j.key("needed_margin_m");
    if (c->needed_margin_m >= 0)
      j.value(c->needed_margin_m);
    else
      j.null();
    j.key("points").begin_array();
    for (const SweepPoint& p : c->points) {
      j.begin_object();
      j.field("margin_m", p.margin_m).field("lit_actor_px", p.lit_actor_px);
      j.field("max_per_frame", p.max_per_frame).field("frames_with_lit", p.frames_with_lit);
      j.field("wasted_px_mean", p.wasted_px_mean);
      j.end_object();
    }
    j.end_array();
    j.end_object();
  }
  j.end_object();
  return j.str();
}

bool draw_sweep_png(const SweepResult& r, const std::string& path) {
  const int W = 900, H = 420, left = 70, right = 20, top = 40, bottom = 50;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  double max_m = 0, max_lit = 1, max_wasted = 1;
  for (const SweepCurve* c : {&r.predicted, &r.unpredicted})
    for (const SweepPoint& p : c->points) {
      max_m = std::max(max_m, p.margin_m);
      max_lit = std::max(max_lit, double(p.lit_actor_px) / std::max(r.frames_scored, 1));
      max_wasted = std::max(max_wasted, p.wasted_px_mean);
    }
  const double ymax = std::max(max_lit, max_wasted);
  auto X = [&](double m) { return left + int((W - left - right) * m / std::max(max_m, 1e-9)); };
  auto Y = [&](double v) {  // log10(1 + v)
    return H - bottom - int((H - top - bottom) * std::log10(1 + v) / std::log10(1 + ymax));
  };
  cv::line(img, {left, H - bottom}, {W - right, H - bottom}, cv::Scalar(0, 0, 0));
  cv::line(img, {left, top}, {left, H - bottom}, cv::Scalar(0, 0, 0));
  for (double v = 1; v <= ymax * 1.01; v *= 10) {
    cv::line(img, {left - 4, Y(v)}, {W - right, Y(v)}, cv::Scalar(225, 225, 225));
    cv::putText(img, std::to_string(int64_t(v)), {5, Y(v) + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(0, 0, 0));
  }
  for (double m = 0; m <= max_m + 1e-9; m += 0.02) {
    cv::line(img, {X(m), H - bottom}, {X(m), H - bottom + 4}, cv::Scalar(0, 0, 0));
    cv::putText(img, std::to_string(int(std::lround(m * 1000))), {X(m) - 8, H - bottom + 18},
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  }
  cv::putText(img, "margin (mm)", {W / 2 - 40, H - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(0, 0, 0));
  const double nf = std::max(r.frames_scored, 1);
  auto curve = [&](const SweepCurve& c, bool wasted, const cv::Scalar& colour, bool dashed) {
    for (std::size_t i = 0; i + 1 < c.points.size(); ++i) {
      const auto& a = c.points[i];
      const auto& b = c.points[i + 1];
      const double va = wasted ? a.wasted_px_mean : a.lit_actor_px / nf;
      const double vb = wasted ? b.wasted_px_mean : b.lit_actor_px / nf;
      if (dashed && i % 2) continue;
      cv::line(img, {X(a.margin_m), Y(va)}, {X(b.margin_m), Y(vb)}, colour, 2, cv::LINE_AA);
    }
  };
  const cv::Scalar red(0, 0, 220), blue(200, 80, 0);
  curve(r.predicted, false, red, false);
  curve(r.unpredicted, false, red, true);
  curve(r.predicted, true, blue, false);
  curve(r.unpredicted, true, blue, true);
  char title[200];
  std::snprintf(title, sizeof title,
                "px per frame (log) vs margin; latency %.0f ms; needed: %s mm predicted, %s mm not",
                r.options.latency_s * 1e3,
                r.predicted.needed_margin_m >= 0
                    ? std::to_string(int(std::lround(r.predicted.needed_margin_m * 1e3))).c_str()
                    : "> max",
                r.unpredicted.needed_margin_m >= 0
                    ? std::to_string(int(std::lround(r.unpredicted.needed_margin_m * 1e3))).c_str()
                    : "> max");
  cv::putText(img, title, {left, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0));
  cv::putText(img, "red: lit actor px, blue: wasted px; solid: prediction, dashed: none",
              {left + 10, top + 15}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(60, 60, 60));
  return cv::imwrite(path, img);
}

}  // namespace studio::demo
