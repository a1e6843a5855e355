#include "projector/motion_fit.h"

#include <chrono>

namespace studio::projector {

FitResult fit_motion(MotionTracker& tracker, const std::string& actor, const ActorMesh& mesh,
                     double field_cell_m) {
  using Clock = std::chrono::steady_clock;
  FitResult r;
  r.actor = actor;
  r.capture_ns = mesh.capture_ns;
  const auto t0 = Clock::now();
  auto m = tracker.update(mesh);
  const auto t1 = Clock::now();
  r.motion_s = std::chrono::duration<double>(t1 - t0).count();
  if (!m) {
    r.error = m.error().message;
    return r;
  }
  if (!*m) return r;  // first mesh, or after a gap: no motion yet
  r.motion = std::move(**m);
  if (auto f = VelocityField::create(mesh, *r.motion, field_cell_m))
    r.field = std::move(*f);
  else
    r.error = f.error().message;
  r.field_s = std::chrono::duration<double>(Clock::now() - t1).count();
  return r;
}

}  // namespace studio::projector
