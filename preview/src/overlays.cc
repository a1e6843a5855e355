#include "preview/overlays.h"

#include <cmath>
#include <sstream>

namespace studio::preview {
namespace {

OverlaySegment segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3f& colour) {
  return {a.cast<float>(), b.cast<float>(), colour};
}

bool finite_projector(const Projector& p) {
  if (!p.camera.centre_in_world().allFinite()) return false;
  for (const auto& c : p.screen)
    if (!c.allFinite()) return false;
  return true;
}

}  // namespace

Expected<void> OverlayOptions::validate() const {
  if (!(camera_frustum_m > 0 && camera_frustum_m <= 20))
    return fail("camera_frustum_m: expected (0, 20] metres");
  if (!(head_radius_m > 0 && head_radius_m <= 1)) return fail("head_radius_m: expected (0, 1] m");
  if (!(velocity_lead_s >= 0 && velocity_lead_s <= 10))
    return fail("velocity_lead_s: expected [0, 10] s");
  return {};
}

std::vector<OverlaySegment> camera_frustum(const Camera& camera, double depth_m) {
  const double w = camera.width, h = camera.height;
  // Image corners clockwise from the top-left (image y down): top-left, top-right,
  // bottom-right, bottom-left.
  const std::array<Eigen::Vector2d, 4> px = {
      Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w - 0.5, -0.5),
      Eigen::Vector2d(w - 0.5, h - 0.5), Eigen::Vector2d(-0.5, h - 0.5)};
  const Eigen::Vector3d c = camera.centre_in_world();
  std::array<Eigen::Vector3d, 4> far;
  for (int k = 0; k < 4; ++k) far[k] = camera.unproject(px[k], depth_m);
  std::vector<OverlaySegment> out;
  const Eigen::Vector3f& colour = overlay_colour::camera;
  for (int k = 0; k < 4; ++k) out.push_back(segment(c, far[k], colour));
  for (int k = 0; k < 4; ++k) out.push_back(segment(far[k], far[(k + 1) % 4], colour));
  // The up tick: a triangle's two sides over the top edge, apex a quarter of the height above.
  const Eigen::Vector3d apex = camera.unproject({0.5 * (w - 1), -0.5 - 0.25 * h}, depth_m);
  const Eigen::Vector3d left = camera.unproject({0.25 * w, -0.5}, depth_m);
  const Eigen::Vector3d right = camera.unproject({0.75 * w, -0.5}, depth_m);
  out.push_back(segment(left, apex, colour));
  out.push_back(segment(apex, right, colour));
  return out;
}

std::vector<OverlaySegment> projector_frustum(const Projector& p) {
  const Eigen::Vector3d c = p.camera.centre_in_world();
  std::vector<OverlaySegment> out;
  const Eigen::Vector3f& colour = overlay_colour::projector;
  for (int k = 0; k < 4; ++k) out.push_back(segment(c, p.screen[k], colour));
  for (int k = 0; k < 4; ++k) out.push_back(segment(p.screen[k], p.screen[(k + 1) % 4], colour));
  return out;
}

OverlayGeometry build_overlays(const OverlayOptions& o, const std::vector<Camera>& cameras,
                               const std::vector<Projector>& projectors,
                               const std::vector<HeadMarker>& heads) {
  OverlayGeometry g;
  if (o.camera_frusta)
    for (const Camera& c : cameras) {
      if (c.width <= 0 || c.height <= 0 || !c.centre_in_world().allFinite()) continue;
      for (auto& s : camera_frustum(c, o.camera_frustum_m)) g.lines.push_back(s);
    }
  for (const Projector& p : projectors) {
    if (!finite_projector(p)) continue;
    if (o.projector_frusta)
      for (auto& s : projector_frustum(p)) g.lines.push_back(s);
    if (o.projector_screens) g.screens.push_back({p.camera.id, p.screen, p.camera});
  }
  if (o.head)
    for (const HeadMarker& h : heads) {
      if (!h.position.allFinite()) continue;
      g.spheres.push_back({h.position.cast<float>(), float(o.head_radius_m), overlay_colour::head});
      if (h.velocity.allFinite() && h.velocity.norm() * o.velocity_lead_s > 1e-3)
        g.lines.push_back(segment(h.position, h.position + o.velocity_lead_s * h.velocity,
                                  overlay_colour::velocity));
      for (const Projector& p : projectors) {
        if (!finite_projector(p)) continue;
        const Eigen::Vector3d centre =
            0.25 * (p.screen[0] + p.screen[1] + p.screen[2] + p.screen[3]);
        g.lines.push_back(segment(h.position, centre, overlay_colour::sight));
      }
    }
  return g;
}

Expected<void> parse_overlay_list(const std::string& list, OverlayOptions& o) {
  OverlayOptions r = o;
  r.head = r.camera_frusta = r.projector_frusta = r.projector_screens = false;
  std::istringstream in(list);
  for (std::string word; std::getline(in, word, ',');) {
    if (word == "head") {
      r.head = true;
    } else if (word == "cameras") {
      r.camera_frusta = true;
    } else if (word == "projectors") {
      r.projector_frusta = true;
    } else if (word == "screens") {
      r.projector_screens = true;
    } else if (word == "all") {
      r.head = r.camera_frusta = r.projector_frusta = r.projector_screens = true;
    } else if (word != "none") {
      return fail("overlays: unknown '" + word +
                  "' (expected head, cameras, projectors, screens, all or none)");
    }
  }
  o = r;
  return {};
}

}  // namespace studio::preview
