#include "preview/viewpoint.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>

namespace studio::preview {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

// Right, up, forward of a view (up is +y re-orthogonalised).
void basis(const Viewpoint& v, Eigen::Vector3d& right, Eigen::Vector3d& up, Eigen::Vector3d& fwd) {
  fwd = (v.at - v.eye).normalized();
  right = fwd.cross(Eigen::Vector3d::UnitY()).normalized();
  up = right.cross(fwd);
}

}  // namespace

Expected<void> Viewpoint::validate() const {
  if (!finite(eye) || !finite(at) || !std::isfinite(fov_deg))
    return fail("viewpoint: numbers must be finite");
  if ((at - eye).norm() < 1e-6) return fail("viewpoint: eye and at are the same point");
  if (!(fov_deg > 1 && fov_deg < 179)) return fail("viewpoint: fov must be in (1, 179) degrees");
  const Eigen::Vector3d d = (at - eye).normalized();
  if (std::abs(d.y()) > 0.9999) return fail("viewpoint: looking straight up or down (no roll)");
  return {};
}

Expected<Viewpoint> parse_viewpoint(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return fail("viewpoint '" + text + "': " + why + " (expected eye=X,Y,Z,at=X,Y,Z[,fov=DEG])");
  };
  Viewpoint v;
  std::vector<double>* target = nullptr;
  std::vector<double> eye, at, fov;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string token = text.substr(start, end - start);
    if (const auto eq = token.find('='); eq != std::string::npos) {
      const std::string key = token.substr(0, eq);
      token = token.substr(eq + 1);
      if (key == "eye" && eye.empty())
        target = &eye;
      else if (key == "at" && at.empty())
        target = &at;
      else if (key == "fov" && fov.empty())
        target = &fov;
      else
        return bad("unknown or repeated key '" + key + "'");
    }
    if (!target) return bad("a value before any key");
    double x = 0;
    const auto [p, ec] = std::from_chars(token.data(), token.data() + token.size(), x);
    if (ec != std::errc() || p != token.data() + token.size() || !std::isfinite(x))
      return bad("'" + token + "' is not a number");
    target->push_back(x);
    start = end + 1;
  }
  if (eye.size() != 3 || at.size() != 3 || fov.size() > 1) return bad("eye and at take 3 numbers");
  v.eye = {eye[0], eye[1], eye[2]};
  v.at = {at[0], at[1], at[2]};
  if (!fov.empty()) v.fov_deg = fov[0];
  if (auto ok = v.validate(); !ok) return std::unexpected(ok.error());
  return v;
}

std::string to_string(const Viewpoint& v) {
  std::ostringstream s;
  s.precision(6);
  s << "eye=" << v.eye.x() << ',' << v.eye.y() << ',' << v.eye.z() << ",at=" << v.at.x() << ','
    << v.at.y() << ',' << v.at.z() << ",fov=" << v.fov_deg;
  return s.str();
}

Orbit Orbit::from(const Viewpoint& v) {
  Orbit o;
  o.target = v.at;
  const Eigen::Vector3d d = v.eye - v.at;
  o.distance = d.norm();
  o.yaw = std::atan2(d.x(), d.z());
  o.pitch = std::asin(std::clamp(d.y() / o.distance, -1.0, 1.0));
  o.fov_deg = v.fov_deg;
  return o;
}

Viewpoint Orbit::viewpoint() const {
  Viewpoint v;
  v.at = target;
  v.eye = target + distance * Eigen::Vector3d(std::cos(pitch) * std::sin(yaw), std::sin(pitch),
                                              std::cos(pitch) * std::cos(yaw));
  v.fov_deg = fov_deg;
  return v;
}

void Orbit::rotate(double dyaw, double dpitch) {
  yaw = std::remainder(yaw + dyaw, 2 * std::numbers::pi);
  pitch = std::clamp(pitch + dpitch, -85 * kDeg, 85 * kDeg);
}

void Orbit::zoom(double factor) {
  if (factor > 0 && std::isfinite(factor)) distance = std::clamp(distance * factor, 0.2, 100.0);
}

Viewpoint fly(const Viewpoint& v, const Eigen::Vector3d& d) {
  Eigen::Vector3d right, up, fwd;
  basis(v, right, up, fwd);
  const Eigen::Vector3d step = d.x() * right + d.y() * up + d.z() * fwd;
  Viewpoint out = v;
  out.eye += step;
  out.at += step;
  return out;
}

Viewpoint turn(const Viewpoint& v, double dyaw, double dpitch) {
  Orbit o = Orbit::from({v.at, v.eye, v.fov_deg});  // an orbit of the look-at point about the eye
  o.rotate(dyaw, -dpitch);
  Viewpoint out = v;
  out.at = o.viewpoint().eye;
  return out;
}

const Viewpoint* Bookmarks::find(const std::string& name) const {
  const auto it = marks_.find(name);
  return it == marks_.end() ? nullptr : &it->second;
}

Expected<CameraMove> CameraMove::create(std::vector<MoveKey> keys) {
  if (keys.empty()) return fail("camera move: no keys");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!std::isfinite(keys[i].time)) return fail("camera move: key times must be finite");
    if (i > 0 && !(keys[i].time > keys[i - 1].time))
      return fail("camera move: key times must increase (key " + std::to_string(i) + ")");
    if (auto ok = keys[i].view.validate(); !ok)
      return fail("camera move: key " + std::to_string(i) + ": " + ok.error().message);
  }
  CameraMove m;
  m.keys_ = std::move(keys);
  return m;
}

Viewpoint CameraMove::at(double t) const {
  if (t <= keys_.front().time) return keys_.front().view;
  if (t >= keys_.back().time) return keys_.back().view;
  std::size_t i = 0;
  while (keys_[i + 1].time <= t) ++i;
  const auto& k1 = keys_[i];
  const auto& k2 = keys_[i + 1];
  const auto& k0 = i > 0 ? keys_[i - 1] : k1;
  const auto& k3 = i + 2 < keys_.size() ? keys_[i + 2] : k2;
  const double s = (t - k1.time) / (k2.time - k1.time);
  // Uniform Catmull-Rom through p1..p2 with neighbours p0, p3.
  auto spline = [s](const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                    const Eigen::Vector3d& p3) {
    const double s2 = s * s, s3 = s2 * s;
    return Eigen::Vector3d(0.5 * ((2 * p1) + (-p0 + p2) * s + (2 * p0 - 5 * p1 + 4 * p2 - p3) * s2 +
                                  (-p0 + 3 * p1 - 3 * p2 + p3) * s3));
  };
  Viewpoint v;
  v.eye = spline(k0.view.eye, k1.view.eye, k2.view.eye, k3.view.eye);
  v.at = spline(k0.view.at, k1.view.at, k2.view.at, k3.view.at);
  v.fov_deg = k1.view.fov_deg + s * (k2.view.fov_deg - k1.view.fov_deg);
  if (!v.validate()) v.at = k1.view.at + s * (k2.view.at - k1.view.at);  // degenerate spline
  return v;
}

}  // namespace studio::preview
