#pragma once
// A node's local transform: translation, rotation, scale (the glTF TRS decomposition).
//
//   parent_from_node = T(translation) * R(rotation) * S(scale)
//   x_in_parent      = parent_from_node * x_in_node
// Studio frame: metres, y up, floor is the xz-plane (DESIGN §2 rule 3).

#include <Eigen/Geometry>

#include "core/error.h"

namespace studio::scene {

struct Transform {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();

  // parent_from_node as a 4x4 matrix.
  Eigen::Matrix4d matrix() const;

  // Finite numbers, a rotation of norm > 1e-9 (normalised by normalized()), every scale factor
  // finite and |s| >= 1e-9. The message names the offending part: "translation is not finite".
  Expected<void> validate() const;
  // Same transform with a unit rotation (the canonical form stored in a Scene).
  Transform normalized() const;

  bool operator==(const Transform& o) const {
    return translation == o.translation && rotation.coeffs() == o.rotation.coeffs() &&
           scale == o.scale;
  }
};

}  // namespace studio::scene
