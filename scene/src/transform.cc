#include "scene/transform.h"

#include <cmath>

namespace studio::scene {

Eigen::Matrix4d Transform::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation.normalized().toRotationMatrix() * scale.asDiagonal();
  m.topRightCorner<3, 1>() = translation;
  return m;
}

Expected<void> Transform::validate() const {
  if (!translation.allFinite()) return fail("translation is not finite");
  if (!rotation.coeffs().allFinite()) return fail("rotation is not finite");
  if (rotation.norm() < 1e-9) return fail("rotation is not a quaternion (norm 0)");
  if (!scale.allFinite()) return fail("scale is not finite");
  if (scale.cwiseAbs().minCoeff() < 1e-9) return fail("scale has a zero factor");
  return {};
}

Transform Transform::normalized() const {
  Transform t = *this;
  t.rotation.normalize();
  return t;
}

}  // namespace studio::scene
