#include "projector/mask_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <system_error>
#include <thread>

namespace studio::projector {

Expected<void> MaskPlannerOptions::validate() const {
  if (auto ok = margin.validate(); !ok) return ok;
  if (auto ok = motion.validate(); !ok) return ok;
  if (latency_window < 1 || latency_window > 100000) return fail("latency_window: 1..100000");
  if (!(latency_quantile > 0 && latency_quantile <= 1)) return fail("latency_quantile: (0, 1]");
  if (!(initial_latency_s >= 0 && initial_latency_s <= 10))
    return fail("initial_latency_s: 0..10 seconds");
  return {};
}

namespace {
// The fitted motion's velocity at each vertex of the simplified mask mesh (its input vertex's).
std::vector<Eigen::Vector3f> velocities_at(const MaskBase& base, const MeshMotion& motion) {
  std::vector<Eigen::Vector3f> v(base.source.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = motion.velocity(base.source[i]);
  return v;
}
}  // namespace

MaskPlanner::MaskPlanner(MaskPlannerOptions options)
    : options_(std::move(options)),
      latencies_(options_.latency_window, options_.latency_quantile),
      overruns_(options_.latency_window, options_.latency_quantile) {}

Expected<MaskPlanner::Actor*> MaskPlanner::accept(const std::string& actor_id,
                                                  const ActorMesh& mesh) {
  if (auto ok = mesh.validate(); !ok) return fail("actor " + actor_id + ": " + ok.error().message);
  auto it = actors_.find(actor_id);
  if (it == actors_.end())
    it = actors_.emplace(actor_id, Actor(MotionTracker(options_.motion))).first;
  Actor& a = it->second;
  if (!a.mesh.vertices.empty() && mesh.capture_ns <= a.mesh.capture_ns)
    return fail("actor " + actor_id + ": mesh capture time not after the previous mesh's");
  return &a;
}

Expected<void> MaskPlanner::set_mesh(const std::string& actor_id, std::uint64_t frame,
                                     ActorMesh mesh) {
  auto accepted = accept(actor_id, mesh);
  if (!accepted) return std::unexpected(accepted.error());
  Actor& a = **accepted;
  using Clock = std::chrono::steady_clock;
  // The two per-mesh stages read the mesh only and share nothing else: with parallel_mesh_work
  // the simplification runs on a thread of its own while this one fits the motion, so a mesh
  // waits for the longer of the two, not their sum (same results, same CPU).
  const auto t0 = Clock::now();
  std::optional<Expected<MaskBase>> base;
  double simplify_s = 0;
  auto simplify = [&] {
    const auto s0 = Clock::now();
    base.emplace(simplify_for_mask(mesh, options_.grow));
    simplify_s = std::chrono::duration<double>(Clock::now() - s0).count();
  };
  std::optional<Expected<std::optional<MeshMotion>>> motion;
  std::jthread worker;  // joined on every way out, a throwing motion fit included
  if (options_.parallel_mesh_work) {
    try {
      worker = std::jthread(simplify);
    } catch (const std::system_error&) {  // no thread to be had: one after the other
    }
  }
  const bool parallel = worker.joinable();
  if (!parallel) simplify();
  motion.emplace(a.tracker.update(mesh));
  if (parallel) worker.join();
  const double motion_s =
      std::chrono::duration<double>(Clock::now() - t0).count() - (parallel ? 0.0 : simplify_s);
  if (!*base) return fail("actor " + actor_id + ": " + base->error().message);
  a.motion = *motion ? **motion : std::nullopt;  // no motion: the margin's no-prediction term
  if (a.motion) a.known_speed_mps = a.motion->max_speed_mps;
  a.mesh = std::move(mesh);
  a.base = std::move(**base);
  a.fitted = a.motion ? velocities_at(a.base, *a.motion) : std::vector<Eigen::Vector3f>{};
  a.frame = frame;
  a.pending = false;
  a.latched.clear();
  last_cost_ = {motion_s, simplify_s, 0, 0};
  return {};
}

Expected<void> MaskPlanner::latch_mesh(const std::string& actor_id, std::uint64_t frame,
                                       ActorMesh mesh) {
  auto accepted = accept(actor_id, mesh);
  if (!accepted) return std::unexpected(accepted.error());
  Actor& a = **accepted;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto base = simplify_for_mask(mesh, options_.grow);
  if (!base) return fail("actor " + actor_id + ": " + base.error().message);
  const auto t1 = Clock::now();
  // A mesh latched over one never fitted (two latches without fit_pending between them): that
  // one is skipped by the tracker; the next fit is against the last mesh fitted.
  a.motion.reset();  // this mesh's own motion: after fit_pending() / apply_fit()
  a.fitted.clear();
  a.mesh = std::move(mesh);
  a.base = std::move(*base);
  a.frame = frame;
  a.pending = true;
  relatch(a);
  last_cost_ = {0, std::chrono::duration<double>(t1 - t0).count(),
                std::chrono::duration<double>(Clock::now() - t1).count(), 0};
  return {};
}

int MaskPlanner::fit_pending() {
  int fitted = 0;
  double motion_s = 0, field_s = 0;
  for (auto& [id, a] : actors_) {
    if (!a.pending) continue;
    ++fitted;
    FitResult r = fit_motion(a.tracker, id, a.mesh, options_.motion.region_size_m);
    motion_s += r.motion_s;
    field_s += r.field_s;
    apply_fit(std::move(r));
  }
  last_cost_.motion_s = motion_s;
  last_cost_.field_s = field_s;
  return fitted;
}

MaskPlanner::Applied MaskPlanner::apply_fit(FitResult fit) {
  auto it = actors_.find(fit.actor);
  if (it == actors_.end()) return Applied::ignored;
  Actor& a = it->second;
  if (fit.capture_ns == a.mesh.capture_ns) {  // the current mesh's own fit
    a.pending = false;
    a.field.reset();
    a.field_motion.reset();
    if (!fit.motion) return Applied::ignored;  // refused or no estimate: not predicted
    a.motion = std::move(*fit.motion);
    a.fitted = velocities_at(a.base, *a.motion);
    a.known_speed_mps = a.motion->max_speed_mps;
    a.latched.clear();  // the mesh's own motion from now on
    if (fit.field) {
      a.field = std::move(*fit.field);
      a.field_motion = a.motion;
    }
    return Applied::own;
  }
  // An older mesh's fit that finished after a newer mesh was latched (FitWorker): its field is
  // newer than the one that mesh was latched with, so the mesh is latched again from it.
  if (fit.capture_ns > a.mesh.capture_ns || !fit.motion || !fit.field) return Applied::ignored;
  if (a.field && a.field->capture_ns() >= fit.capture_ns) return Applied::ignored;
  a.known_speed_mps = fit.motion->max_speed_mps;
  a.field = std::move(*fit.field);
  a.field_motion = std::move(*fit.motion);
  if (a.motion) return Applied::field;  // the mesh has its own fit already
  relatch(a);
  return Applied::field;
}

void MaskPlanner::relatch(Actor& a) {
  a.latched.clear();
  a.latched_age_s = 0;
  if (a.field && a.field_motion &&
      (a.mesh.capture_ns - a.field->capture_ns()) * 1e-9 <= options_.motion.max_dt_s) {
    if (auto v = a.field->at(a.base.mesh)) {
      a.latched = std::move(*v);
      a.latched_age_s =
          (a.mesh.capture_ns - a.field->capture_ns()) * 1e-9 + 0.5 * a.field_motion->dt_s;
    }
  }
}

void MaskPlanner::remove(const std::string& actor_id) { actors_.erase(actor_id); }

void MaskPlanner::set_head_speed(const std::string& actor_id, double speed_mps) {
  if (!std::isfinite(speed_mps) || speed_mps < 0) return;
  auto it = actors_.find(actor_id);
  if (it != actors_.end()) it->second.head_speed_mps = speed_mps;
}

Expected<void> MaskPlanner::set_margin_options(const MarginOptions& margin) {
  if (auto ok = margin.validate(); !ok) return ok;
  options_.margin = margin;
  return {};
}

double MaskPlanner::latency_s() const {
  return latencies_.empty() ? options_.initial_latency_s : latencies_.latency_s();
}

Expected<MaskPlan> MaskPlanner::plan(std::int64_t display_ns) const {
  MaskPlan out;
  out.display_ns = display_ns;
  const double latency = latency_s();  // for the record when there is no actor
  std::vector<bool> predicted;
  bool first = true;
  for (const auto& [id, a] : actors_) {
    const double age = std::clamp((display_ns - a.mesh.capture_ns) * 1e-9, 0.0, 10.0);
    const double L =
        overruns_.empty() ? std::max(age, options_.initial_latency_s) : age + overrun_s();
    // No estimate for this mesh: the last known speed stands in (the head's when faster).
    // Latched (not fitted yet): the previous fit's motion, its velocity older by latched_age_s.
    const bool latched = !a.motion && !a.latched.empty() && a.field_motion;
    const MeshMotion* motion = a.motion ? &*a.motion : latched ? &*a.field_motion : nullptr;
    const double speed = motion ? a.head_speed_mps : std::max(a.head_speed_mps, a.known_speed_mps);
    auto m = security_margin(options_.margin, L, speed, motion, latched ? a.latched_age_s : -1);
    if (!m) return std::unexpected(m.error());
    predicted.push_back(m->predicted);
    if (first || m->margin_m > out.margin.margin_m) out.margin = *m;
    first = false;
    if (a.mesh.capture_ns > out.newest_capture_ns) {
      out.newest_capture_ns = a.mesh.capture_ns;
      out.newest_frame = a.frame;
    }
  }
  if (first) {  // no actor: the floor, for the record
    out.margin.margin_m = out.margin.floor_m = options_.margin.floor_m;
    out.margin.latency_s = latency;
  }
  std::size_t k = 0;
  for (const auto& [id, a] : actors_) {
    const MaskBase* base = &a.base;
    MaskBase moved;
    // Each actor moved forward when its own margin relies on the prediction; the margin drawn
    // is the largest, which covers every actor's own. The simplified mesh's vertices are the
    // mesh's (MaskBase::source), so the motion moves them as it would the mesh.
    const bool latched = !a.motion && !a.latched.empty() && a.field_motion;
    if (predicted[k++] && (a.motion || latched)) {
      const double horizon = std::clamp((display_ns - a.mesh.capture_ns) * 1e-9, 0.0, 1.0);
      auto p = predict_by_velocities(a.base.mesh, a.motion ? a.fitted : a.latched, horizon);
      if (p) {
        moved = {std::move(*p), a.base.error_m, {}};
        base = &moved;
      }
    }
    auto grown = grow_mask(*base, out.margin.margin_m, options_.grow);
    if (!grown) return std::unexpected(grown.error());
    out.masks.push_back(std::move(*grown));
  }
  return out;
}

bool MaskPlanner::shown(const MaskPlan& plan, std::int64_t shown_ns) {
  if (plan.newest_capture_ns == 0) return false;
  if (!latencies_.add(plan.newest_capture_ns, shown_ns)) return false;
  if (plan.display_ns > 0)
    (void)overruns_.add(plan.display_ns, std::max(shown_ns, plan.display_ns));
  return true;
}

}  // namespace studio::projector
