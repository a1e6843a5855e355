#pragma once
// The preview's virtual camera (issue 16): a pose (eye, look-at point, vertical field of view),
// driven either as an orbit around a target or as a free fly camera; named bookmarks; and
// keyframed moves to rehearse shots.
//
// Frames: studio frame, metres, y up. Orbit: yaw about +y measured from +z towards +x, pitch
// above the horizon, distance from the target. Fly: the eye moves in its own frame (forward =
// towards `at`, right, up = +y).
// Moves: keyframes at increasing times; between two keys the eye and the look-at point follow a
// Catmull-Rom spline through the neighbouring keys (so a move through several keys has no
// corners) and the field of view is linear; before the first key the first pose, after the last
// the last.

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::preview {

struct Viewpoint {
  Eigen::Vector3d eye{0, 1.6, 5};
  Eigen::Vector3d at{0, 1, 0};
  double fov_deg = 50;
  Expected<void> validate()
      const;  // finite, eye != at, fov in (1, 179), not looking straight up/down
};

// "eye=X,Y,Z,at=X,Y,Z[,fov=DEG]" → Viewpoint; errors are one line naming the problem.
Expected<Viewpoint> parse_viewpoint(const std::string& text);
std::string to_string(const Viewpoint& v);

struct Orbit {
  Eigen::Vector3d target{0, 1, 0};
  double yaw = 0, pitch = 0.2, distance = 4;  // radians, radians, metres
  double fov_deg = 50;
  static Orbit from(const Viewpoint& v);
  Viewpoint viewpoint() const;
  // Mouse drag in radians; pitch is kept within +-85 degrees.
  void rotate(double dyaw, double dpitch);
  // Multiplies the distance (wheel), kept within [0.2, 100] m.
  void zoom(double factor);
};

// Moves the eye and the look-at point together by (right, up, forward) metres in the view's
// frame, or turns the view by yaw/pitch radians about the eye.
Viewpoint fly(const Viewpoint& v, const Eigen::Vector3d& right_up_forward);
Viewpoint turn(const Viewpoint& v, double dyaw, double dpitch);

class Bookmarks {
 public:
  void set(const std::string& name, const Viewpoint& v) { marks_[name] = v; }
  const Viewpoint* find(const std::string& name) const;
  bool remove(const std::string& name) { return marks_.erase(name) > 0; }
  const std::map<std::string, Viewpoint>& all() const { return marks_; }

 private:
  std::map<std::string, Viewpoint> marks_;
};

struct MoveKey {
  double time = 0;  // seconds from the start of the move
  Viewpoint view;
};

class CameraMove {
 public:
  // Keys must have strictly increasing times and valid viewpoints; at least one.
  static Expected<CameraMove> create(std::vector<MoveKey> keys);
  Viewpoint at(double t) const;
  double duration() const { return keys_.back().time - keys_.front().time; }
  const std::vector<MoveKey>& keys() const { return keys_; }

 private:
  std::vector<MoveKey> keys_;
};

}  // namespace studio::preview
