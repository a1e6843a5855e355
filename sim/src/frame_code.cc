#include "sim/frame_code.h"

#include <algorithm>
#include <cmath>

namespace studio::sim::frame_code {

int band_of(double unit_y) {
  if (!(unit_y >= kLow && unit_y < kHigh)) return -1;
  return std::min(kBands - 1, static_cast<int>((unit_y - kLow) / (kHigh - kLow) * kBands));
}

int digit(int64_t frame, int band) {
  int64_t v = ((frame % kModulus) + kModulus) % kModulus;
  for (int b = 0; b < band; ++b) v /= 3;
  return static_cast<int>(v % 3);
}

Albedo albedo(int d) {
  switch (d) {
    case 0:
      return {0.75f, 0.07f, 0.05f};  // red
    case 1:
      return {0.07f, 0.60f, 0.05f};  // green
    default:
      return {0.72f, 0.62f, 0.05f};  // yellow
  }
}

int classify(double r, double g, double b) {
  const double hi = std::max(r, g);
  if (hi < 35 || b > 0.8 * hi) return -1;  // dark, or the cloth / grey
  const double q = g / std::max(r, 1.0);
  // Display ratios (gamma 1/2.2 of the albedo ratios): red 0.34, green 2.6, yellow 0.93.
  if (q < 0.55) return 0;
  if (q > 1.7) return 1;
  if (q > 0.75 && q < 1.25) return 2;
  return -1;
}

std::optional<int> decode(std::span<const int> digits) {
  if (digits.size() != kBands) return std::nullopt;
  int v = 0;
  for (int b = kBands - 1; b >= 0; --b) {
    if (digits[b] < 0 || digits[b] > 2) return std::nullopt;
    v = 3 * v + digits[b];
  }
  return v;
}

Eigen::Vector3d band_point(const ActorBody& body, int band, const Eigen::Vector3d& eye,
                           double along) {
  const Part& torso = body.part(PartId::torso);
  const double uy = kLow + (band + along) * (kHigh - kLow) / kBands;
  // Direction to the eye in the torso's unit-sphere frame, without its axial part.
  const Eigen::Vector3d local = torso.axes.transpose() * (eye - torso.centre);
  Eigen::Vector3d dir = local.cwiseQuotient(torso.radii);  // unit-sphere coordinates of the eye
  dir.y() = 0;
  if (dir.norm() < 1e-9) dir = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d u = std::sqrt(1 - uy * uy) * dir.normalized() + Eigen::Vector3d(0, uy, 0);
  return torso.centre + torso.axes * u.cwiseProduct(torso.radii);
}

}  // namespace studio::sim::frame_code
