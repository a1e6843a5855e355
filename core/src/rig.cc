#include "core/rig.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <set>

namespace studio {
namespace {

const std::string& id_of(const Camera& c) { return c.id; }
const std::string& id_of(const Projector& p) { return p.camera.id; }

template <class Items>
auto find_by_id(Items& items, std::string_view id) -> decltype(items.data()) {
  for (auto& item : items) {
    if (id_of(item) == id) return &item;
  }
  return nullptr;
}

std::string num(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", x);
  return buffer;
}

}  // namespace

const Camera* Rig::find_camera(std::string_view id) const { return find_by_id(cameras, id); }
Camera* Rig::find_camera(std::string_view id) { return find_by_id(cameras, id); }
const Projector* Rig::find_projector(std::string_view id) const {
  return find_by_id(projectors, id);
}
Projector* Rig::find_projector(std::string_view id) { return find_by_id(projectors, id); }

Expected<void> validate_camera(const Camera& c, std::string_view where) {
  const std::string at = std::string(where) + " (" + c.id + "): ";
  if (c.id.empty()) return fail(std::string(where) + ": empty id");
  if (c.width <= 0 || c.height <= 0) {
    return fail(at + "image size must be positive, got " + std::to_string(c.width) + "x" +
                std::to_string(c.height));
  }
  const Intrinsics& k = c.intrinsics;
  for (double x : {k.fx, k.fy, k.cx, k.cy, k.skew}) {
    if (!std::isfinite(x)) return fail(at + "non-finite intrinsics");
  }
  if (!(k.fx > 0) || !(k.fy > 0)) {
    return fail(at + "focal lengths must be positive, got fx " + num(k.fx) + ", fy " + num(k.fy));
  }
  const Distortion& d = c.distortion;
  for (double x : {d.rd3, d.rd5, d.k1, d.k2, d.p1, d.p2, d.k3}) {
    if (!std::isfinite(x)) return fail(at + "non-finite distortion coefficient");
  }
  if (!c.cam_from_world.rotation.coeffs().allFinite() ||
      !c.cam_from_world.translation.allFinite()) {
    return fail(at + "non-finite cam_from_world");
  }
  if (std::abs(c.cam_from_world.rotation.norm() - 1) > 1e-9) {
    return fail(at + "cam_from_world rotation is not a unit quaternion");
  }
  return {};
}

Expected<void> Rig::validate() const {
  std::set<std::string, std::less<>> ids;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const std::string where = "cameras[" + std::to_string(i) + "]";
    if (auto ok = validate_camera(cameras[i], where); !ok) return ok;
    if (!ids.insert(cameras[i].id).second) {
      return fail(where + " (" + cameras[i].id + "): duplicate id");
    }
  }
  for (size_t i = 0; i < projectors.size(); ++i) {
    const Projector& p = projectors[i];
    const std::string where = "projectors[" + std::to_string(i) + "]";
    if (auto ok = validate_camera(p.camera, where); !ok) return ok;
    if (!ids.insert(p.camera.id).second) {
      return fail(where + " (" + p.camera.id + "): duplicate id");
    }
    const std::string at = where + " (" + p.camera.id + "): screen: ";
    for (const Eigen::Vector3d& corner : p.screen) {
      if (!corner.allFinite()) return fail(at + "non-finite corner");
    }
    // Non-degenerate: the two diagonals' cross product gives twice the (planar) area.
    const Eigen::Vector3d normal = (p.screen[2] - p.screen[0]).cross(p.screen[3] - p.screen[1]);
    const double size =
        std::max((p.screen[2] - p.screen[0]).norm(), (p.screen[3] - p.screen[1]).norm());
    if (!(normal.norm() > 1e-9 * size * size) || !(size > 0)) {
      return fail(at + "corners are degenerate (zero area)");
    }
    const Eigen::Vector3d n = normal.normalized();
    for (const Eigen::Vector3d& corner : p.screen) {
      if (std::abs(n.dot(corner - p.screen[0])) > 1e-3 * size) {
        return fail(at + "corners are not coplanar");
      }
    }
  }
  return {};
}

Expected<Rigid3> rigid_from_matrix(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  if (!R.allFinite() || !t.allFinite()) return fail("non-finite number");
  const double orthogonality =
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = R.determinant();
  if (orthogonality > 1e-4 || !(det > 0)) {
    return fail("not a rotation matrix (max |R^T R - I| = " + num(orthogonality) +
                ", det = " + num(det) + ")");
  }
  return Rigid3(R, t);
}

Expected<Intrinsics> intrinsics_from_matrix(const Eigen::Matrix3d& K) {
  if (!K.allFinite()) return fail("non-finite number");
  if (K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0) {
    return fail("camera matrix is not upper triangular");
  }
  if (K(2, 2) == 0) return fail("camera matrix has K(2,2) = 0");
  const Intrinsics k = Intrinsics::from_K(K);
  if (!(k.fx > 0) || !(k.fy > 0)) {
    return fail("camera matrix needs positive focal lengths, got fx " + num(k.fx) + ", fy " +
                num(k.fy));
  }
  return k;
}

}  // namespace studio
