#pragma once
// Frame-named rigid transforms (DESIGN §2 rule 3).
//
// A Rigid3 named `b_from_a` maps coordinates of a point in frame a to frame b:
//   x_in_cam = cam_from_world * x_in_world
// Composition reads right to left: cam_from_rig * rig_from_world = cam_from_world.
// Studio frame: metres, y up, floor is the xz-plane (the paper's).

#include <Eigen/Geometry>

namespace studio {

struct Rigid3 {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q.normalized()), translation(t) {}
  Rigid3(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) : rotation(Eigen::Quaterniond(R).normalized()), translation(t) {}

  static Rigid3 identity() { return {}; }

  Eigen::Matrix3d R() const { return rotation.toRotationMatrix(); }
  // 3x4 [R | t].
  Eigen::Matrix<double, 3, 4> matrix3x4() const {
    Eigen::Matrix<double, 3, 4> m;
    m.leftCols<3>() = R();
    m.col(3) = translation;
    return m;
  }
  Eigen::Matrix4d matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topRows<3>() = matrix3x4();
    return m;
  }

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  Rigid3 operator*(const Rigid3& other) const {
    return Rigid3(rotation * other.rotation, rotation * other.translation + translation);
  }
  // a_from_b.inverse() == b_from_a
  Rigid3 inverse() const {
    const Eigen::Quaterniond qi = rotation.conjugate();
    return Rigid3(qi, -(qi * translation));
  }
};

}  // namespace studio
