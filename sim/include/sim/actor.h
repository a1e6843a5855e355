#pragma once
// The simulated actor: an articulated human made of analytic solids (capsules and ellipsoids)
// on a skeleton driven by joint angles, with scripted, seeded motions (issue 3 item 1). It is the
// ground truth every other component is scored against: the true solid (inside()), the true
// surface (ray_hit(), surface_samples(), mesh()) and the true head centre (head_centre()).
//
// Frames: studio frame (metres, y up, floor = xz-plane). The body frame has +z forward, +y up
// and +x towards the actor's LEFT; heading is the rotation of the body frame about +y (heading 0
// faces +z). Left limbs have index 0, right limbs index 1.
//
// The solid is the UNION of the parts; a point is inside the actor iff it is inside any part.
// Everything is deterministic: the same Options and time give bit-identical bodies.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::sim {

enum class PartShape { capsule, ellipsoid };

// Which body part (also the index of the part in ActorBody::parts).
enum class PartId {
  pelvis,
  torso,
  shoulders,
  neck,
  head,
  hair,
  upper_arm_l,
  lower_arm_l,
  hand_l,
  upper_arm_r,
  lower_arm_r,
  hand_r,
  upper_leg_l,
  lower_leg_l,
  foot_l,
  upper_leg_r,
  lower_leg_r,
  foot_r,
  count
};
const char* part_name(PartId id);

// Linear RGB reflectance in [0, 1].
struct Albedo {
  float r = 0.5f, g = 0.5f, b = 0.5f;
};

// One analytic solid in the studio frame.
//  capsule:   all points within `radius` of the segment [a, b].
//  ellipsoid: { centre + axes * diag(radii) * u : |u| <= 1 }; axes is a rotation (columns are
//             the part's principal directions in the studio frame).
struct Part {
  PartId id = PartId::pelvis;
  PartShape shape = PartShape::capsule;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();
  Albedo albedo;

  bool inside(const Eigen::Vector3d& x) const;
  // Smallest ray parameter t > t_min with origin + t * direction on the surface, if any
  // (direction need not be unit; t is in units of |direction|). A ray starting inside the part
  // hits where it leaves it.
  std::optional<double> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double t_min = 0) const;
  // Outward unit normal at a surface point.
  Eigen::Vector3d normal(const Eigen::Vector3d& on_surface) const;
  // Axis-aligned bounds of the solid.
  void bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const;
  double surface_area() const;
  // A point on the part's surface from two uniform numbers in [0, 1) (area-uniform for
  // capsules, approximately so for ellipsoids).
  Eigen::Vector3d surface_point(double u1, double u2) const;
};

struct RayHit {
  double t = 0;                  // ray parameter (distance when the direction is unit)
  Eigen::Vector3d point;         // studio frame
  Eigen::Vector3d normal;        // outward unit normal
  int part = -1;                 // index into ActorBody::parts
};

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise seen from outside
};

// The actor's solid at one instant, in the studio frame.
struct ActorBody {
  double time = 0;
  std::vector<Part> parts;  // indexed by PartId

  const Part& part(PartId id) const { return parts[static_cast<int>(id)]; }
  // The true head centre: the centre of the head ellipsoid (skull, without hair).
  Eigen::Vector3d head_centre() const { return part(PartId::head).centre; }
  bool inside(const Eigen::Vector3d& x) const;
  // Nearest intersection of origin + t * direction (t > 0) with the union of the parts.
  std::optional<RayHit> ray_hit(const Eigen::Vector3d& origin,
                                const Eigen::Vector3d& direction) const;
  // n points on the true surface of the union (each lies on one part's surface and inside no
  // other part), deterministic for a seed.
  std::vector<Eigen::Vector3d> surface_samples(int n, uint64_t seed = 1) const;
  // Axis-aligned bounds of the whole body.
  void bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const;
  // A closed triangle mesh per part (not the boolean union: parts interpenetrate), for viewing
  // and for renderers; `segments` controls the tessellation (>= 4).
  TriangleMesh mesh(int segments = 16) const;
};

// Scripted motions. `sequence` loops walk (5 s) → turn on the spot (3 s) → raise the right
// hand (4 s) → crouch (4 s), blending joint angles over 0.4 s at each change.
// `arm_swing` stands and swings the right arm forward and back through 130 degrees (shoulder
// flexion -40..90) with the elbow nearly straight, timed so that the fingertips' peak speed is
// Options::swing_peak_speed (1.5 m/s: the fast motion the projector mask is tested against).
enum class Motion { idle, walk, turn, raise_hand, crouch, sequence, arm_swing };
const char* motion_name(Motion m);
Expected<Motion> parse_motion(const std::string& name);

// Joint angles (radians) and root placement. Positive flexion moves a limb forward (knee flexion
// bends the shin backwards, as a knee does).
struct ActorPose {
  Eigen::Vector2d root_xz = Eigen::Vector2d::Zero();  // pelvis (or feet midpoint, see anchor)
  double heading = 0;
  double feet_anchor = 0;  // 0: root_xz is the pelvis; 1: root_xz is the feet midpoint
  double spine_flex = 0, spine_twist = 0;
  double neck_flex = 0, head_yaw = 0;
  struct Arm {
    double shoulder_flex = 0, shoulder_abduct = 0, elbow_flex = 0;
  };
  struct Leg {
    double hip_flex = 0, hip_abduct = 0, knee_flex = 0, foot_pitch = 0;  // foot pitch: world
  };
  std::array<Arm, 2> arm;  // 0 left, 1 right
  std::array<Leg, 2> leg;
};

// Blend two poses joint by joint (w = 0 → a, w = 1 → b).
ActorPose blend(const ActorPose& a, const ActorPose& b, double w);

class Actor {
 public:
  struct Options {
    uint64_t seed = 1;             // body proportions, clothing, path and phase
    Motion motion = Motion::sequence;
    double walk_radius = 0.8;      // metres; the walk follows a circle around the studio centre
    double walk_speed = 0.9;       // metres per second
    double swing_peak_speed = 1.5;  // arm_swing: peak fingertip speed, metres per second
    Expected<void> validate() const;
  };

  explicit Actor(const Options& options);  // options must validate (programming error if not)

  const Options& options() const { return options_; }
  double scale() const { return scale_; }
  ActorPose pose_at(double t) const;
  // Forward kinematics; the body is lifted so that its lowest point touches the floor (y = 0).
  ActorBody body(const ActorPose& pose, double time = 0) const;
  ActorBody body_at(double t) const { return body(pose_at(t), t); }

 private:
  ActorPose motion_pose(Motion m, double t) const;
  Options options_;
  double scale_ = 1;
  double phase_ = 0;          // seeded phase offsets
  double walk_start_ = 0;     // start angle on the circle
  double walk_dir_ = 1;       // +1 counter-clockwise seen from above, -1 clockwise
  std::array<Albedo, static_cast<int>(PartId::count)> albedo_{};
};

}  // namespace studio::sim
