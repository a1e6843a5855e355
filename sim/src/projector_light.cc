// Projector light truth of the simulated studio (sim/projector_light.h). Own maths throughout:
// the projector is a plain pinhole (K, R, t read from the core Camera's numbers), the cyclorama
// and boards are intersected here, the actor through its analytic solids.
#include "sim/projector_light.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/look_at.h"
#include "message.h"
#include "projector_light_impl.h"

namespace studio::sim {
namespace {

// A pinhole projector: x_cam = R X + t, u = fx x/z + s y/z + cx, v = fy y/z + cy.
struct Pinhole {
  Eigen::Matrix3d R;
  Eigen::Vector3d t, centre;
  double fx, fy, cx, cy, skew;
  int W, H;
  explicit Pinhole(const Camera& c)
      : R(c.cam_from_world.rotation.normalized().toRotationMatrix()),
        t(c.cam_from_world.translation),
        centre(-R.transpose() * t),
        fx(c.intrinsics.fx),
        fy(c.intrinsics.fy),
        cx(c.intrinsics.cx),
        cy(c.intrinsics.cy),
        skew(c.intrinsics.skew),
        W(c.width),
        H(c.height) {}
  // Pixel index holding the projection of X, if X is in front and inside the image.
  bool pixel(const Eigen::Vector3d& X, int* u, int* v) const {
    const Eigen::Vector3d x = R * X + t;
    if (!(x.z() > 1e-9)) return false;
    const double a = x.x() / x.z(), b = x.y() / x.z();
    const double uf = fx * a + skew * b + cx, vf = fy * b + cy;
    const double iu = std::floor(uf + 0.5), iv = std::floor(vf + 0.5);
    if (!(iu >= 0 && iv >= 0 && iu < W && iv < H)) return false;
    *u = static_cast<int>(iu);
    *v = static_cast<int>(iv);
    return true;
  }
  // World direction (not unit) of the ray through sub-pixel (u, v).
  Eigen::Vector3d ray(double u, double v) const {
    const double b = (v - cy) / fy;
    const double a = (u - cx - skew * b) / fx;
    return R.transpose() * Eigen::Vector3d(a, b, 1);
  }
};

std::optional<double> hit_board(const Board& b, const Eigen::Vector3d& o,
                                const Eigen::Vector3d& d) {
  const Eigen::Vector3d n = b.x_axis.cross(b.y_axis);
  const double dn = d.dot(n);
  if (std::abs(dn) < 1e-12) return std::nullopt;
  const double t = (b.centre - o).dot(n) / dn;
  if (!(t > 1e-9)) return std::nullopt;
  const Eigen::Vector3d q = o + t * d - b.centre;
  if (std::abs(q.dot(b.x_axis)) > b.half_width || std::abs(q.dot(b.y_axis)) > b.half_height) {
    return std::nullopt;
  }
  return t;
}

bool finite3(const Eigen::Vector3d& v) { return v.allFinite(); }

uint8_t quantise(double x) { return static_cast<uint8_t>(std::clamp(x + 0.5, 0.0, 255.0)); }

}  // namespace

Expected<void> ProjectorLight::validate() const {
  for (std::size_t i = 0; i < projectors.size(); ++i) {
    const Camera& c = projectors[i].projector.camera;
    const auto& k = c.intrinsics;
    if (c.width < 1 || c.height < 1 || c.width > 8192 || c.height > 8192) {
      return fail(detail::cat("projector_light.projectors[", i, "]: size ", c.width, "x", c.height,
                              " outside [1, 8192]"));
    }
    if (!(k.fx > 0 && k.fy > 0 && std::isfinite(k.fx) && std::isfinite(k.fy) &&
          std::isfinite(k.cx) && std::isfinite(k.cy) && std::isfinite(k.skew))) {
      return fail(detail::cat("projector_light.projectors[", i,
                              "]: focal lengths must be positive and finite"));
    }
    if (!c.distortion.is_identity()) {
      return fail(
          detail::cat("projector_light.projectors[", i, "]: lens distortion is not modelled"));
    }
    if (!finite3(c.cam_from_world.translation) || !c.cam_from_world.rotation.coeffs().allFinite()) {
      return fail(detail::cat("projector_light.projectors[", i, "]: cam_from_world is not finite"));
    }
    const Image<Rgb8>& f = projectors[i].frame;
    if (!f.pixels().empty() && (f.width() != c.width || f.height() != c.height)) {
      return fail(detail::cat("projector_light.projectors[", i, "]: frame ", f.width(), "x",
                              f.height(), " differs from the projector's ", c.width, "x",
                              c.height));
    }
  }
  for (std::size_t i = 0; i < boards.size(); ++i) {
    const Board& b = boards[i];
    if (!finite3(b.centre) || std::abs(b.x_axis.norm() - 1) > 1e-6 ||
        std::abs(b.y_axis.norm() - 1) > 1e-6 || std::abs(b.x_axis.dot(b.y_axis)) > 1e-6) {
      return fail(detail::cat("projector_light.boards[", i,
                              "]: centre must be finite and the axes unit and orthogonal"));
    }
    if (!(b.half_width > 0 && b.half_height > 0 && b.albedo >= 0 && b.albedo <= 1)) {
      return fail(detail::cat("projector_light.boards[", i,
                              "]: half sizes must be positive, albedo in [0, 1]"));
    }
  }
  auto unit = [](double v) { return v >= 0 && v <= 1; };
  if (!unit(ring_level) || !unit(cloth_gain) || !unit(board_gain) || !unit(board_ambient) ||
      !(eye_gain >= 0 && eye_gain <= 4)) {
    return fail(
        "projector_light: ring_level, cloth_gain, board_gain, board_ambient must lie in [0, 1], "
        "eye_gain in [0, 4]");
  }
  if (!(exposure > 0 && exposure <= 16)) {
    return fail(detail::cat("projector_light.exposure ", exposure, " outside (0, 16]"));
  }
  if (samples < 1 || samples > 8)
    return fail(detail::cat("projector_light.samples ", samples, " outside [1, 8]"));
  return {};
}

Expected<void> DisplayOptions::validate() const {
  if (!(display_lag_s > 0 && display_lag_s < 1)) {
    return fail(
        detail::cat("display_lag_s ", display_lag_s, " outside (0, 1) s (a display always lags)"));
  }
  return {};
}

std::optional<SurfaceHit> hit_surface(const Cyclorama& cyc, const std::vector<Board>& boards,
                                      const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  std::optional<SurfaceHit> best;
  auto consider = [&](double t, const Eigen::Vector3d& n, int board, bool floor) {
    if (!(t > 1e-9) || (best && t >= best->t)) return;
    const Eigen::Vector3d x = o + t * d;
    if (board < 0) {
      const double eps = 1e-9;
      if (std::abs(x.x()) > cyc.half_width + eps || std::abs(x.z()) > cyc.half_width + eps ||
          x.y() < -eps || x.y() > cyc.height + eps) {
        return;
      }
    }
    best = SurfaceHit{t, x, n.dot(d) > 0 ? Eigen::Vector3d(-n) : n, board, floor};
  };
  if (d.y() != 0) consider(-o.y() / d.y(), Eigen::Vector3d::UnitY(), -1, true);
  for (int axis : {0, 2}) {
    if (d[axis] == 0) continue;
    for (double side : {-cyc.half_width, cyc.half_width}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = 1;
      consider((side - o[axis]) / d[axis], n, -1, false);
    }
  }
  for (std::size_t i = 0; i < boards.size(); ++i) {
    if (auto t = hit_board(boards[i], o, d)) {
      consider(*t, boards[i].x_axis.cross(boards[i].y_axis), static_cast<int>(i), false);
    }
  }
  return best;
}

namespace {

// projected_light() with the projectors' pinholes prepared once.
std::array<double, 3> light_at(const ProjectorLight& light, const std::vector<Pinhole>& pinholes,
                               const Eigen::Vector3d& X, int board, const ActorBody* occluder) {
  std::array<double, 3> sum{0, 0, 0};
  for (std::size_t k = 0; k < light.projectors.size(); ++k) {
    const SimProjector& p = light.projectors[k];
    if (p.frame.pixels().empty()) continue;
    const Pinhole& ph = pinholes[k];
    int u, v;
    if (!ph.pixel(X, &u, &v)) continue;
    const Eigen::Vector3d d = X - ph.centre;  // t in (0, 1) is between projector and X
    bool blocked = false;
    for (std::size_t i = 0; i < light.boards.size() && !blocked; ++i) {
      if (static_cast<int>(i) == board) continue;
      if (auto t = hit_board(light.boards[i], ph.centre, d)) blocked = *t < 1 - 1e-9;
    }
    if (!blocked && occluder) {
      if (auto h = occluder->ray_hit(ph.centre, d)) blocked = h->t < 1 - 1e-9;
    }
    if (blocked) continue;
    const Rgb8& c = p.frame(u, v);
    sum[0] += c.r;
    sum[1] += c.g;
    sum[2] += c.b;
  }
  return sum;
}

std::vector<Pinhole> pinholes_of(const ProjectorLight& light) {
  std::vector<Pinhole> out;
  for (const SimProjector& p : light.projectors) out.emplace_back(p.projector.camera);
  return out;
}

}  // namespace

std::array<double, 3> projected_light(const ProjectorLight& light, const Eigen::Vector3d& X,
                                      int board, const ActorBody* occluder) {
  return light_at(light, pinholes_of(light), X, board, occluder);
}

EyeView eye_view(const ProjectorLight& light, const Cyclorama& cyc, const Camera& eye,
                 const ActorBody* occluder) {
  EyeView out;
  out.image = Image<Rgb8>(eye.width, eye.height, Rgb8{0, 0, 0});
  out.lit = Mask(eye.width, eye.height, 0);
  const Eigen::Vector3d C = eye.centre_in_world();
  const int n = light.samples;
  const std::vector<Pinhole> pinholes = pinholes_of(light);
  for (int v = 0; v < eye.height; ++v) {
    for (int u = 0; u < eye.width; ++u) {
      double acc[3] = {0, 0, 0};
      bool lit = false;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const Eigen::Vector2d px(u - 0.5 + (i + 0.5) / n, v - 0.5 + (j + 0.5) / n);
          const Eigen::Vector3d d = eye.pixel_ray_in_world(px);
          const auto hit = hit_surface(cyc, light.boards, C, d);
          if (!hit) continue;
          const auto l = light_at(light, pinholes, hit->point, hit->board, occluder);
          if (l[0] + l[1] + l[2] > 0) lit = true;
          for (int k = 0; k < 3; ++k) acc[k] += l[k];
        }
      }
      const double s = light.eye_gain / (n * n);
      out.image(u, v) = {quantise(acc[0] * s), quantise(acc[1] * s), quantise(acc[2] * s)};
      out.lit(u, v) = lit ? 255 : 0;
    }
  }
  return out;
}

namespace detail {

void light_background(const ProjectorLight& light, const Cyclorama& cyc, const Camera& cam,
                      Image<Rgb8>* background, Image<uint8_t>* surface) {
  const std::vector<Pinhole> pinholes = pinholes_of(light);
  const bool any_frame =
      std::any_of(light.projectors.begin(), light.projectors.end(),
                  [](const SimProjector& p) { return !p.frame.pixels().empty(); });
  const Eigen::Vector3d C = cam.centre_in_world();
  const int n = light.samples;
  const double ring = light.ring_level * light.exposure;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      Rgb8& px = (*background)(u, v);
      // The cloth's colour is the ring light's retro-reflection; the dark studio beyond it is not.
      const double base_gain = (*surface)(u, v) == kSurfaceNone ? light.exposure : ring;
      double rgb[3] = {px.r * base_gain, px.g * base_gain, px.b * base_gain};
      std::optional<SurfaceHit> centre_hit;
      if (!light.boards.empty()) {
        centre_hit =
            hit_surface(cyc, light.boards, C, cam.pixel_ray_in_world(Eigen::Vector2d(u, v)));
        if (centre_hit && centre_hit->board >= 0) {
          const double g =
              255 * light.board_ambient * light.boards[centre_hit->board].albedo * light.exposure;
          rgb[0] = rgb[1] = rgb[2] = g;
          (*surface)(u, v) = kSurfaceBoard;
        }
      }
      if (any_frame) {
        double acc[3] = {0, 0, 0};
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < n; ++i) {
            const Eigen::Vector2d q(u - 0.5 + (i + 0.5) / n, v - 0.5 + (j + 0.5) / n);
            const auto hit = hit_surface(cyc, light.boards, C, cam.pixel_ray_in_world(q));
            if (!hit) continue;
            const auto l = light_at(light, pinholes, hit->point, hit->board, nullptr);
            const double g = hit->board >= 0 ? light.board_gain * light.boards[hit->board].albedo
                                             : light.cloth_gain;
            for (int k = 0; k < 3; ++k) acc[k] += g * l[k];
          }
        }
        for (int k = 0; k < 3; ++k) rgb[k] += light.exposure * acc[k] / (n * n);
      }
      px = {quantise(rgb[0]), quantise(rgb[1]), quantise(rgb[2])};
    }
  }
}

}  // namespace detail

Mask actor_in_projector(const Camera& projector, const ActorBody& body) {
  const Pinhole ph(projector);
  Mask mask(ph.W, ph.H, 0);
  // Per part: the pixel rectangle of its bounding box's projection (whole image if a corner is
  // behind or very near the projector), then exact ray casting inside it.
  for (const Part& part : body.parts) {
    Eigen::Vector3d lo, hi;
    part.bounds(&lo, &hi);
    double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
    bool whole = false;
    for (int k = 0; k < 8 && !whole; ++k) {
      const Eigen::Vector3d X(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(),
                              k & 4 ? hi.z() : lo.z());
      const Eigen::Vector3d x = ph.R * X + ph.t;
      if (!(x.z() > 0.05)) {
        whole = true;
        break;
      }
      const double a = x.x() / x.z(), b = x.y() / x.z();
      const double uf = ph.fx * a + ph.skew * b + ph.cx, vf = ph.fy * b + ph.cy;
      umin = std::min(umin, uf);
      umax = std::max(umax, uf);
      vmin = std::min(vmin, vf);
      vmax = std::max(vmax, vf);
    }
    // A convex solid lies inside its box, the box's image inside the hull of its corners'.
    const int x0 = whole ? 0 : std::clamp(static_cast<int>(std::floor(umin)) - 1, 0, ph.W);
    const int x1 = whole ? ph.W : std::clamp(static_cast<int>(std::ceil(umax)) + 2, 0, ph.W);
    const int y0 = whole ? 0 : std::clamp(static_cast<int>(std::floor(vmin)) - 1, 0, ph.H);
    const int y1 = whole ? ph.H : std::clamp(static_cast<int>(std::ceil(vmax)) + 2, 0, ph.H);
    for (int v = y0; v < y1; ++v) {
      uint8_t* row = &mask(0, v);
      for (int u = x0; u < x1; ++u) {
        if (row[u]) continue;
        if (part.intersect(ph.centre, ph.ray(u, v))) row[u] = 255;
      }
    }
  }
  return mask;
}

Mask actor_at_display(const Actor& actor, const Camera& projector, double render_time_s,
                      const DisplayOptions& options) {
  if (auto ok = options.validate(); !ok) throw std::invalid_argument(ok.error().message);
  return actor_in_projector(projector, actor.body_at(render_time_s + options.display_lag_s));
}

LitCount count_lit(const Mask& actor, const RunMask& blackout) {
  if (actor.width() != blackout.width() || actor.height() != blackout.height()) {
    throw std::invalid_argument(detail::cat("count_lit: actor mask ", actor.width(), "x",
                                            actor.height(), " and blackout ", blackout.width(), "x",
                                            blackout.height(), " differ"));
  }
  LitCount c;
  for (int y = 0; y < actor.height(); ++y) {
    const uint8_t* row = &actor(0, y);
    int x = 0;
    uint64_t on_actor_in_runs = 0;
    for (const Run& r : blackout.row(y)) {
      for (; x < r.begin; ++x) c.lit_actor += row[x] != 0;
      for (; x < r.end; ++x) on_actor_in_runs += row[x] != 0;
      c.blackout += static_cast<uint64_t>(r.end - r.begin);
      c.wasted += static_cast<uint64_t>(r.end - r.begin);
    }
    for (; x < actor.width(); ++x) c.lit_actor += row[x] != 0;
    c.wasted -= on_actor_in_runs;
    for (int u = 0; u < actor.width(); ++u) c.actor += row[u] != 0;
  }
  return c;
}

Projector studio_projector(const Cyclorama& cyc, const Eigen::Vector3d& centre, double wall_width_m,
                           int width, int height, const Eigen::Vector3d& target,
                           const std::string& id) {
  Projector p;
  Camera& c = p.camera;
  c.id = id;
  c.width = width;
  c.height = height;
  const double distance = (target - centre).norm();
  const double f = 0.5 * width * distance / (0.5 * wall_width_m);
  c.intrinsics.fx = c.intrinsics.fy = f;
  c.intrinsics.cx = 0.5 * (width - 1);
  c.intrinsics.cy = 0.5 * (height - 1);
  c.cam_from_world = look_at(centre, target, Eigen::Vector3d::UnitY());
  // Corner rays of the image (pixel edges) meet the wall the target is on: the plane
  // x = target.x or z = target.z, whichever coordinate is larger in magnitude.
  const int axis = std::abs(target.x()) > std::abs(target.z()) ? 0 : 2;
  const Pinhole ph(c);
  const Eigen::Vector2d corners[4] = {
      {-0.5, height - 0.5}, {width - 0.5, height - 0.5}, {width - 0.5, -0.5}, {-0.5, -0.5}};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d d = ph.ray(corners[k].x(), corners[k].y());
    const double t = (target[axis] - ph.centre[axis]) / d[axis];
    Eigen::Vector3d X = ph.centre + t * d;
    X.y() = std::clamp(X.y(), 0.0, cyc.height);
    p.screen[static_cast<std::size_t>(k)] = X;
  }
  return p;
}

}  // namespace studio::sim
