// Skeleton, forward kinematics, clothing and scripted motions of the simulated actor.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "sim/actor.h"

#include "message.h"

namespace studio::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double deg(double d) { return d * kPi / 180.0; }

Eigen::Matrix3d rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }
Eigen::Matrix3d ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}
double lerp(double a, double b, double w) { return a + (b - a) * w; }

// Clothing palettes: no blue, so the chroma key has something to find.
constexpr Albedo kShirts[] = {{0.62f, 0.12f, 0.10f}, {0.80f, 0.45f, 0.10f}, {0.78f, 0.76f, 0.70f},
                              {0.20f, 0.48f, 0.20f}, {0.70f, 0.60f, 0.18f}, {0.52f, 0.50f, 0.48f}};
constexpr Albedo kTrousers[] = {{0.20f, 0.19f, 0.19f}, {0.36f, 0.25f, 0.15f},
                                {0.55f, 0.50f, 0.36f}, {0.30f, 0.30f, 0.28f}};
constexpr Albedo kSkins[] = {{0.86f, 0.66f, 0.54f}, {0.66f, 0.46f, 0.33f}, {0.45f, 0.30f, 0.21f}};
constexpr Albedo kHair[] = {{0.16f, 0.10f, 0.06f}, {0.08f, 0.07f, 0.06f}, {0.62f, 0.48f, 0.26f}};
constexpr Albedo kShoes[] = {{0.12f, 0.09f, 0.07f}, {0.35f, 0.33f, 0.31f}};

template <class T, std::size_t N>
const T& pick(const T (&palette)[N], std::mt19937_64& rng) {
  return palette[std::uniform_int_distribution<std::size_t>(0, N - 1)(rng)];
}

Part capsule(PartId id, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  Part p;
  p.id = id;
  p.shape = PartShape::capsule;
  p.a = a;
  p.b = b;
  p.radius = radius;
  return p;
}

Part ellipsoid(PartId id, const Eigen::Vector3d& centre, const Eigen::Matrix3d& axes,
               const Eigen::Vector3d& radii) {
  Part p;
  p.id = id;
  p.shape = PartShape::ellipsoid;
  p.centre = centre;
  p.axes = axes;
  p.radii = radii;
  return p;
}

// Standing pose with a little life in it.
ActorPose standing(double t) {
  ActorPose p;
  p.feet_anchor = 1;
  p.spine_flex = deg(2 + 1 * std::sin(2 * kPi * t / 4.0));
  p.head_yaw = deg(8 * std::sin(2 * kPi * t / 7.0));
  for (int i = 0; i < 2; ++i) {
    p.arm[i].shoulder_abduct = deg(7);
    p.arm[i].elbow_flex = deg(10);
    p.leg[i].hip_abduct = deg(3);
  }
  return p;
}

}  // namespace

const char* part_name(PartId id) {
  static constexpr const char* kNames[] = {
      "pelvis",      "torso",       "shoulders",   "neck",        "head",        "hair",
      "upper_arm_l", "lower_arm_l", "hand_l",      "upper_arm_r", "lower_arm_r", "hand_r",
      "upper_leg_l", "lower_leg_l", "foot_l",      "upper_leg_r", "lower_leg_r", "foot_r"};
  const int i = static_cast<int>(id);
  return i >= 0 && i < static_cast<int>(PartId::count) ? kNames[i] : "?";
}

const char* motion_name(Motion m) {
  switch (m) {
    case Motion::idle: return "idle";
    case Motion::walk: return "walk";
    case Motion::turn: return "turn";
    case Motion::raise_hand: return "raise_hand";
    case Motion::crouch: return "crouch";
    case Motion::sequence: return "sequence";
    case Motion::arm_swing: return "arm_swing";
  }
  return "?";
}

Expected<Motion> parse_motion(const std::string& name) {
  for (Motion m : {Motion::idle, Motion::walk, Motion::turn, Motion::raise_hand, Motion::crouch,
                   Motion::sequence, Motion::arm_swing}) {
    if (name == motion_name(m)) return m;
  }
  return fail(detail::cat("unknown motion '", name, "' (expected idle, walk, turn, raise_hand, crouch, sequence or arm_swing)"));
}

ActorPose blend(const ActorPose& a, const ActorPose& b, double w) {
  ActorPose p;
  p.root_xz = a.root_xz + (b.root_xz - a.root_xz) * w;
  p.heading = lerp(a.heading, b.heading, w);
  p.feet_anchor = lerp(a.feet_anchor, b.feet_anchor, w);
  p.spine_flex = lerp(a.spine_flex, b.spine_flex, w);
  p.spine_twist = lerp(a.spine_twist, b.spine_twist, w);
  p.neck_flex = lerp(a.neck_flex, b.neck_flex, w);
  p.head_yaw = lerp(a.head_yaw, b.head_yaw, w);
  for (int i = 0; i < 2; ++i) {
    p.arm[i].shoulder_flex = lerp(a.arm[i].shoulder_flex, b.arm[i].shoulder_flex, w);
    p.arm[i].shoulder_abduct = lerp(a.arm[i].shoulder_abduct, b.arm[i].shoulder_abduct, w);
    p.arm[i].elbow_flex = lerp(a.arm[i].elbow_flex, b.arm[i].elbow_flex, w);
    p.leg[i].hip_flex = lerp(a.leg[i].hip_flex, b.leg[i].hip_flex, w);
    p.leg[i].hip_abduct = lerp(a.leg[i].hip_abduct, b.leg[i].hip_abduct, w);
    p.leg[i].knee_flex = lerp(a.leg[i].knee_flex, b.leg[i].knee_flex, w);
    p.leg[i].foot_pitch = lerp(a.leg[i].foot_pitch, b.leg[i].foot_pitch, w);
  }
  return p;
}

Expected<void> Actor::Options::validate() const {
  if (!(walk_radius >= 0.2 && walk_radius <= 1.0)) {
    return fail(detail::cat("actor walk_radius ", walk_radius, " m outside [0.2, 1.0] (the actor must stay in the 3 m acting area)"));
  }
  if (!(walk_speed > 0 && walk_speed <= 2.0)) {
    return fail(detail::cat("actor walk_speed ", walk_speed, " m/s outside (0, 2]"));
  }
  if (!(swing_peak_speed > 0 && swing_peak_speed <= 4.0)) {
    return fail(detail::cat("actor swing_peak_speed ", swing_peak_speed, " m/s outside (0, 4]"));
  }
  return {};
}

Actor::Actor(const Options& options) : options_(options) {
  if (auto ok = options.validate(); !ok) throw std::invalid_argument(ok.error().message);
  std::mt19937_64 rng(options.seed * 0x9E3779B97F4A7C15ull + 17);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  scale_ = 0.95 + 0.1 * uni(rng);
  phase_ = 2 * kPi * uni(rng);
  walk_start_ = 2 * kPi * uni(rng);
  walk_dir_ = uni(rng) < 0.5 ? 1.0 : -1.0;
  const Albedo shirt = pick(kShirts, rng), trousers = pick(kTrousers, rng),
               skin = pick(kSkins, rng), hair = pick(kHair, rng), shoes = pick(kShoes, rng);
  const bool long_sleeves = uni(rng) < 0.5;
  auto set = [&](PartId id, const Albedo& a) { albedo_[static_cast<int>(id)] = a; };
  set(PartId::pelvis, trousers);
  set(PartId::torso, shirt);
  set(PartId::shoulders, shirt);
  set(PartId::neck, skin);
  set(PartId::head, skin);
  set(PartId::hair, hair);
  for (PartId id : {PartId::upper_arm_l, PartId::upper_arm_r}) set(id, shirt);
  for (PartId id : {PartId::lower_arm_l, PartId::lower_arm_r}) set(id, long_sleeves ? shirt : skin);
  for (PartId id : {PartId::hand_l, PartId::hand_r}) set(id, skin);
  for (PartId id : {PartId::upper_leg_l, PartId::upper_leg_r, PartId::lower_leg_l,
                    PartId::lower_leg_r}) {
    set(id, trousers);
  }
  for (PartId id : {PartId::foot_l, PartId::foot_r}) set(id, shoes);
}

ActorBody Actor::body(const ActorPose& pose, double time) const {
  const double s = scale_;
  std::vector<Part> parts;
  parts.reserve(static_cast<int>(PartId::count));
  // Body frame, origin at the pelvis centre; lengths in metres for scale 1.
  const Eigen::Vector3d spine_base(0, 0.05 * s, 0);
  const Eigen::Matrix3d r_spine = ry(pose.spine_twist) * rx(pose.spine_flex);
  parts.push_back(ellipsoid(PartId::pelvis, Eigen::Vector3d(0, -0.02 * s, 0),
                            Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.165, 0.11, 0.11) * s));
  parts.push_back(ellipsoid(PartId::torso, spine_base + r_spine * Eigen::Vector3d(0, 0.24 * s, 0),
                            r_spine, Eigen::Vector3d(0.16, 0.25, 0.105) * s));
  parts.push_back(capsule(PartId::shoulders, spine_base + r_spine * Eigen::Vector3d(0.15, 0.42, 0) * s,
                          spine_base + r_spine * Eigen::Vector3d(-0.15, 0.42, 0) * s, 0.07 * s));
  const Eigen::Vector3d neck_base = spine_base + r_spine * Eigen::Vector3d(0, 0.44 * s, 0);
  const Eigen::Matrix3d r_neck = r_spine * rx(pose.neck_flex);
  const Eigen::Vector3d neck_top = neck_base + r_neck * Eigen::Vector3d(0, 0.09 * s, 0);
  parts.push_back(capsule(PartId::neck, neck_base, neck_top, 0.05 * s));
  const Eigen::Matrix3d r_head = r_neck * ry(pose.head_yaw);
  const Eigen::Vector3d head = neck_top + r_head * Eigen::Vector3d(0, 0.10, 0.015) * s;
  parts.push_back(ellipsoid(PartId::head, head, r_head, Eigen::Vector3d(0.075, 0.105, 0.095) * s));
  parts.push_back(ellipsoid(PartId::hair, head + r_head * Eigen::Vector3d(0, 0.022, -0.014) * s,
                            r_head, Eigen::Vector3d(0.081, 0.094, 0.097) * s));
  for (int i = 0; i < 2; ++i) {
    const double side = i == 0 ? 1.0 : -1.0;
    const auto& arm = pose.arm[i];
    const Eigen::Vector3d shoulder = spine_base + r_spine * Eigen::Vector3d(side * 0.185, 0.42, 0) * s;
    const Eigen::Matrix3d r_upper =
        r_spine * rz(side * arm.shoulder_abduct) * rx(-arm.shoulder_flex);
    const Eigen::Vector3d elbow = shoulder + r_upper * Eigen::Vector3d(0, -0.29 * s, 0);
    const Eigen::Matrix3d r_lower = r_upper * rx(-arm.elbow_flex);
    const Eigen::Vector3d wrist = elbow + r_lower * Eigen::Vector3d(0, -0.26 * s, 0);
    const int base = static_cast<int>(i == 0 ? PartId::upper_arm_l : PartId::upper_arm_r);
    parts.push_back(capsule(PartId(base), shoulder, elbow, 0.048 * s));
    parts.push_back(capsule(PartId(base + 1), elbow, wrist, 0.038 * s));
    parts.push_back(ellipsoid(PartId(base + 2), wrist + r_lower * Eigen::Vector3d(0, -0.08 * s, 0),
                              r_lower, Eigen::Vector3d(0.022, 0.08, 0.045) * s));
  }
  Eigen::Vector3d feet_mid = Eigen::Vector3d::Zero();
  for (int i = 0; i < 2; ++i) {
    const double side = i == 0 ? 1.0 : -1.0;
    const auto& leg = pose.leg[i];
    const Eigen::Vector3d hip(side * 0.09 * s, -0.06 * s, 0);
    const Eigen::Matrix3d r_upper = rz(side * leg.hip_abduct) * rx(-leg.hip_flex);
    const Eigen::Vector3d knee = hip + r_upper * Eigen::Vector3d(0, -0.44 * s, 0);
    const Eigen::Matrix3d r_lower = r_upper * rx(leg.knee_flex);
    const Eigen::Vector3d ankle = knee + r_lower * Eigen::Vector3d(0, -0.42 * s, 0);
    const Eigen::Matrix3d r_foot = rx(-leg.foot_pitch);
    const Eigen::Vector3d heel = ankle + r_foot * Eigen::Vector3d(0, -0.035, -0.045) * s;
    const Eigen::Vector3d toe = ankle + r_foot * Eigen::Vector3d(0, -0.035, 0.15) * s;
    const int base = static_cast<int>(i == 0 ? PartId::upper_leg_l : PartId::upper_leg_r);
    parts.push_back(capsule(PartId(base), hip, knee, 0.075 * s));
    parts.push_back(capsule(PartId(base + 1), knee, ankle, 0.055 * s));
    parts.push_back(capsule(PartId(base + 2), heel, toe, 0.04 * s));
    feet_mid += 0.25 * (heel + toe);
  }
  // Place in the studio: heading, root position, then lift so the lowest point is on the floor.
  const Eigen::Matrix3d r_world = ry(pose.heading);
  const Eigen::Vector3d mid_world = r_world * feet_mid;
  const Eigen::Vector3d root(pose.root_xz.x() - pose.feet_anchor * mid_world.x(), 0,
                             pose.root_xz.y() - pose.feet_anchor * mid_world.z());
  double lowest = std::numeric_limits<double>::infinity();
  for (Part& p : parts) {
    p.a = root + r_world * p.a;
    p.b = root + r_world * p.b;
    p.centre = root + r_world * p.centre;
    p.axes = r_world * p.axes;
    Eigen::Vector3d lo, hi;
    p.bounds(&lo, &hi);
    lowest = std::min(lowest, lo.y());
  }
  const Eigen::Vector3d lift(0, -lowest, 0);
  for (Part& p : parts) {
    p.a += lift;
    p.b += lift;
    p.centre += lift;
    p.albedo = albedo_[static_cast<int>(p.id)];
  }
  ActorBody body;
  body.time = time;
  body.parts = std::move(parts);
  return body;
}

ActorPose Actor::motion_pose(Motion m, double t) const {
  ActorPose p = standing(t + phase_);
  switch (m) {
    case Motion::idle:
    case Motion::sequence:
      break;
    case Motion::walk: {
      p.feet_anchor = 0;
      const double period = 1.1 * 0.9 / options_.walk_speed * std::clamp(scale_, 0.9, 1.1);
      const double phi = 2 * kPi * t / period + phase_;
      p.spine_flex = deg(4);
      p.spine_twist = deg(4 * std::sin(phi));
      for (int i = 0; i < 2; ++i) {
        const double f = phi + i * kPi;
        p.leg[i].hip_flex = deg(3 + 22 * std::sin(f));
        p.leg[i].knee_flex = deg(5 + 55 * std::pow(std::max(0.0, std::cos(f)), 1.5));
        p.leg[i].foot_pitch = deg(14 * std::sin(f));
        p.leg[i].hip_abduct = deg(2);
        p.arm[i].shoulder_flex = deg(-18 * std::sin(f));
        p.arm[i].shoulder_abduct = deg(6);
        p.arm[i].elbow_flex = deg(15 + 10 * std::max(0.0, -std::sin(f)));
      }
      break;
    }
    case Motion::turn: {
      // Stepping on the spot while turning (heading set by the caller).
      for (int i = 0; i < 2; ++i) {
        const double lift = std::max(0.0, std::sin(2 * kPi * t / 0.8 + i * kPi));
        p.leg[i].hip_flex = deg(12 * lift);
        p.leg[i].knee_flex = deg(24 * lift);
      }
      break;
    }
    case Motion::raise_hand: {
      const double tau = std::fmod(t, 4.0);
      const double a = smoothstep(0, 1, tau) - smoothstep(2.5, 3.5, tau);
      auto& arm = p.arm[1];
      arm.shoulder_flex = deg(165 * a);
      arm.shoulder_abduct = deg(7 + 5 * a + 8 * a * std::sin(2 * kPi * 1.5 * tau));
      arm.elbow_flex = deg(10 + 10 * a);
      p.neck_flex = deg(-10 * a);
      break;
    }
    case Motion::arm_swing: {
      // Shoulder flexion f(t) = mid + amp sin(w t); the fingertip (hand ellipsoid's far end, at
      // reach L from the shoulder with the elbow at 8 degrees) moves at |f'| L = amp w L, so
      // w = v_peak / (amp L). The rest of the body keeps its standing pose.
      const double amp = deg(65), mid = deg(25), elbow = deg(8);
      const double upper = 0.29 * scale_, lower = 0.26 * scale_ + 0.16 * scale_;
      const double reach = std::sqrt(upper * upper + lower * lower + 2 * upper * lower * std::cos(elbow));
      const double w = options_.swing_peak_speed / (amp * reach);
      auto& arm = p.arm[1];
      arm.shoulder_flex = mid + amp * std::sin(w * t);
      arm.shoulder_abduct = deg(10);
      arm.elbow_flex = elbow;
      break;
    }
    case Motion::crouch: {
      const double tau = std::fmod(t, 4.0);
      const double c = smoothstep(0, 1.2, tau) - smoothstep(2.4, 3.6, tau);
      p.spine_flex = deg(2 + 30 * c);
      p.neck_flex = deg(-20 * c);
      for (int i = 0; i < 2; ++i) {
        p.leg[i].hip_flex = deg(100 * c);
        p.leg[i].knee_flex = deg(125 * c);
        p.leg[i].hip_abduct = deg(3 + 7 * c);
        p.arm[i].shoulder_flex = deg(45 * c);
        p.arm[i].elbow_flex = deg(10 + 30 * c);
      }
      break;
    }
  }
  return p;
}

ActorPose Actor::pose_at(double t) const {
  const double R = options_.walk_radius, v = options_.walk_speed;
  auto place_on_circle = [&](ActorPose* p, double walk_time, double extra_heading) {
    const double theta = walk_start_ + walk_dir_ * v * walk_time / R;
    p->root_xz = Eigen::Vector2d(R * std::cos(theta), R * std::sin(theta));
    // Direction of travel (dx, dz) = walk_dir * (-sin, cos); heading h faces (sin h, cos h).
    p->heading = std::atan2(-walk_dir_ * std::sin(theta), walk_dir_ * std::cos(theta)) +
                 extra_heading;
  };
  const Motion m = options_.motion;
  if (m != Motion::sequence) {
    ActorPose p = motion_pose(m, t);
    if (m == Motion::walk) {
      place_on_circle(&p, t, 0);
    } else {
      place_on_circle(&p, 0, m == Motion::turn ? walk_dir_ * deg(90) * t : 0);
    }
    return p;
  }
  // The sequence: segments of (motion, duration), looping.
  struct Segment {
    Motion motion;
    double duration;
  };
  static constexpr Segment kSegments[] = {
      {Motion::walk, 5}, {Motion::turn, 3}, {Motion::raise_hand, 4}, {Motion::crouch, 4}};
  constexpr double kPeriod = 16, kWalk = 5, kBlend = 0.4;
  const double cycle = std::floor(t / kPeriod);
  const double local = t - cycle * kPeriod;
  int k = 0;
  double start = 0;
  while (k < 3 && local >= start + kSegments[k].duration) start += kSegments[k++].duration;
  ActorPose p = motion_pose(kSegments[k].motion, local - start);
  const double since = local - start;
  if (since < kBlend) {
    const int prev = (k + 3) % 4;
    const ActorPose before = motion_pose(kSegments[prev].motion, kSegments[prev].duration);
    p = blend(before, p, smoothstep(0, kBlend, since));
  }
  const double walk_time = cycle * kWalk + std::min(local, kWalk);
  double extra = 0;
  if (kSegments[k].motion == Motion::turn) {
    extra = walk_dir_ * 2 * kPi * smoothstep(0, kSegments[k].duration, since);
  }
  place_on_circle(&p, walk_time, extra);
  return p;
}

}  // namespace studio::sim
