#include "calibrate/synthetic.h"

#include <cmath>
#include "calibrate/text.h"
#include <random>

#include "calibrate/bundle.h"
#include "core/look_at.h"

namespace studio::calibrate {

SyntheticStudio make_synthetic_studio(const SyntheticStudioOptions& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> u01(0, 1);
  auto uniform = [&](double a, double b) { return a + (b - a) * u01(rng); };
  std::normal_distribution<double> noise(0, o.noise_rms_px / std::sqrt(2.0));

  SyntheticStudio s;
  s.target_points = o.target.points();
  const Eigen::Vector3d middle = 0.5 * (s.target_points.front() + s.target_points.back());
  const Eigen::Vector3d look(middle.x(), 0.8, middle.y());
  for (int c = 0; c < o.cameras; ++c) {
    const double a = 2 * M_PI * c / o.cameras + uniform(-0.15, 0.15);
    const Eigen::Vector3d centre = look + Eigen::Vector3d(o.ring_radius_m * std::cos(a),
                                                          uniform(1.2, 2.0),
                                                          o.ring_radius_m * std::sin(a));
    Camera cam;
    cam.id = format("cam{}", c);
    cam.width = o.width;
    cam.height = o.height;
    const double f = uniform(700, 900);
    cam.intrinsics = Intrinsics{f, f * uniform(0.995, 1.005), (o.width - 1) / 2.0 + uniform(-8, 8),
                                (o.height - 1) / 2.0 + uniform(-8, 8), 0};
    cam.distortion = Distortion::radial(uniform(-0.2, -0.05), uniform(0.0, 0.08));
    cam.cam_from_world = look_at(centre, look + Eigen::Vector3d(uniform(-0.2, 0.2), uniform(-0.4, 0),
                                                                uniform(-0.2, 0.2)));
    s.cameras.push_back(cam);
    s.observations.cameras.push_back({cam.id, o.width, o.height});
  }

  const int total = o.frames + o.heldout_frames;
  for (int f = 0; f < total; ++f) {
    FrameObservations frame;
    Rigid3 world_from_target;
    // Draw poses until at least 3 cameras see the whole target (2 for floor frames far out).
    for (int attempt = 0; attempt < 200; ++attempt) {
      frame = FrameObservations{};
      frame.id = format("{}", f);
      if (f == 0) {
        frame.placement = Placement::origin;
        world_from_target = floor_pose(0, 0, 0);
      } else if (f <= o.floor_frames || (f == o.frames && o.heldout_floor_frame)) {
        frame.placement = Placement::floor;
        frame.holdout = f >= o.frames;
        world_from_target =
            floor_pose(uniform(-M_PI, M_PI), uniform(-1.2, 0.6), uniform(-1.2, 0.6));
      } else {
        frame.placement = Placement::free;
        frame.holdout = f >= o.frames;
        // Face (−z of the target) towards a random heading, tilted up by 20-65°.
        const double heading = uniform(-M_PI, M_PI), tilt = uniform(0.35, 1.15);
        const double roll = uniform(-M_PI, M_PI);
        const Eigen::Vector3d face(std::cos(heading) * std::cos(tilt), std::sin(tilt),
                                   std::sin(heading) * std::cos(tilt));
        const Eigen::Vector3d z = -face;
        Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
        x = Eigen::AngleAxisd(roll, z) * x;
        const Eigen::Vector3d y = z.cross(x);
        Eigen::Matrix3d r;
        r << x, y, z;
        const Eigen::Vector3d centre(uniform(-0.6, 0.6), uniform(0.5, 1.6), uniform(-0.6, 0.6));
        world_from_target = Rigid3(r, centre - r * middle);
      }
      const Eigen::Vector3d board_centre = world_from_target * middle;
      const Eigen::Vector3d normal = -(world_from_target.rotation * Eigen::Vector3d::UnitZ());
      for (const Camera& cam : s.cameras) {
        const Eigen::Vector3d to_cam = (cam.centre_in_world() - board_centre).normalized();
        if (to_cam.dot(normal) < std::cos(75 * M_PI / 180)) continue;
        View view{cam.id, {}};
        bool inside = true;
        for (size_t i = 0; i < s.target_points.size() && inside; ++i) {
          Eigen::Vector2d px;
          inside = cam.project(world_from_target * s.target_points[i], &px) && cam.in_image(px);
          view.points.push_back({static_cast<int>(i), px + Eigen::Vector2d(noise(rng), noise(rng))});
        }
        if (inside) frame.views.push_back(std::move(view));
      }
      if (frame.views.size() >= 3 || f == 0) break;
    }
    s.world_from_target.push_back(world_from_target);
    s.observations.frames.push_back(std::move(frame));
  }
  for (int k = 0; k < o.outliers; ++k) {
    auto& frame = s.observations.frames[static_cast<size_t>(uniform(0, o.frames - 0.001))];
    if (frame.views.empty()) continue;
    auto& view = frame.views[static_cast<size_t>(uniform(0, frame.views.size() - 0.001))];
    auto& p = view.points[static_cast<size_t>(uniform(0, view.points.size() - 0.001))];
    const double a = uniform(0, 2 * M_PI), d = uniform(5, 20);
    p.pixel += d * Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  return s;
}

}  // namespace studio::calibrate
