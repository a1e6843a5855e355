#include "scene/animation.h"

#include <algorithm>
#include <cmath>
#include <Eigen/Geometry>

namespace studio::scene {
namespace {

Eigen::Vector4d interpolate(const Track& track, std::size_t k, double t) {
  const std::size_t n = track.times.size();
  if (k + 1 >= n || track.interpolation == Interpolation::step) return track.values[k];
  const double t0 = track.times[k], t1 = track.times[k + 1];
  const double u = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
  const Eigen::Vector4d& a = track.values[k];
  const Eigen::Vector4d& b = track.values[k + 1];
  if (track.path == TrackPath::rotation) {
    const Eigen::Quaterniond qa(a[3], a[0], a[1], a[2]), qb(b[3], b[0], b[1], b[2]);
    const Eigen::Quaterniond q = qa.slerp(u, qb);  // Eigen's slerp takes the shortest arc
    return {q.x(), q.y(), q.z(), q.w()};
  }
  return a + u * (b - a);
}

}  // namespace

Expected<void> Track::validate() const {
  if (times.empty()) return fail("track of '" + node + "' has no keys");
  if (times.size() != values.size())
    return fail("track of '" + node + "' has " + std::to_string(times.size()) + " times and " +
                std::to_string(values.size()) + " values");
  if (static_cast<unsigned>(path) > 2 || static_cast<unsigned>(interpolation) > 1)
    return fail("track of '" + node + "': bad path or interpolation");
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i]) || times[i] < 0)
      return fail("track of '" + node + "': key time is not finite and >= 0");
    if (i > 0 && !(times[i] > times[i - 1]))
      return fail("track of '" + node + "': key times are not strictly increasing");
    const Eigen::Vector4d& v = values[i];
    if (!v.allFinite()) return fail("track of '" + node + "': key value is not finite");
    if (path == TrackPath::rotation && v.norm() < 1e-9)
      return fail("track of '" + node + "': rotation key is not a quaternion (norm 0)");
    if (path == TrackPath::scale && v.head<3>().cwiseAbs().minCoeff() < 1e-9)
      return fail("track of '" + node + "': scale key has a zero factor");
  }
  return {};
}

double Animation::duration() const {
  double d = 0;
  for (const Track& t : tracks)
    if (!t.times.empty()) d = std::max(d, t.times.back());
  return d;
}

Expected<void> Animation::validate() const {
  if (name.empty()) return fail("animation name is empty");
  for (unsigned char c : name)
    if (c < 0x20 || c == 0x7f) return fail("animation name has control characters");
  if (static_cast<unsigned>(mode) > 2) return fail("animation '" + name + "': bad play mode");
  if (tracks.empty()) return fail("animation '" + name + "' has no tracks");
  for (const Track& t : tracks)
    if (auto ok = t.validate(); !ok) return fail("animation '" + name + "': " + ok.error().message);
  return {};
}

double AnimationClock::clock_time(std::int64_t frame, double frame_period) const {
  if (!playing || frame <= anchor_frame) return anchor_time;
  return anchor_time + speed * static_cast<double>(frame - anchor_frame) * frame_period;
}

double animation_time(double c, double d, PlayMode mode) {
  if (!(d > 0)) return 0.0;
  switch (mode) {
    case PlayMode::once:
      return std::clamp(c, 0.0, d);
    case PlayMode::loop: {
      double t = std::fmod(c, d);
      return t < 0 ? t + d : t;
    }
    case PlayMode::ping_pong: {
      double t = std::fmod(c, 2 * d);
      if (t < 0) t += 2 * d;
      return t <= d ? t : 2 * d - t;
    }
  }
  return 0.0;
}

Eigen::Vector4d sample(const Track& track, double t) {
  const auto& ts = track.times;
  if (t <= ts.front()) return track.values.front();
  if (t >= ts.back()) return track.values.back();
  // Last key with time <= t.
  const std::size_t k = std::upper_bound(ts.begin(), ts.end(), t) - ts.begin() - 1;
  return interpolate(track, k, t);
}

Eigen::Vector4d sample_linear_scan(const Track& track, double t) {
  const auto& ts = track.times;
  if (t <= ts.front()) return track.values.front();
  if (t >= ts.back()) return track.values.back();
  std::size_t k = 0;
  while (k + 1 < ts.size() && ts[k + 1] <= t) ++k;
  return interpolate(track, k, t);
}

const char* to_string(TrackPath p) {
  switch (p) {
    case TrackPath::translation: return "translation";
    case TrackPath::rotation: return "rotation";
    case TrackPath::scale: return "scale";
  }
  return "?";
}
const char* to_string(Interpolation i) { return i == Interpolation::step ? "step" : "linear"; }
const char* to_string(PlayMode m) {
  switch (m) {
    case PlayMode::once: return "once";
    case PlayMode::loop: return "loop";
    case PlayMode::ping_pong: return "ping_pong";
  }
  return "?";
}

}  // namespace studio::scene
