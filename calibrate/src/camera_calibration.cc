#include "calibrate/camera_calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include "calibrate/text.h"

#include "calibrate/geometry.h"
#include "calibrate/pose_graph.h"

namespace studio::calibrate {
namespace {

using Points = std::vector<Eigen::Vector3d>;

struct Solved {
  std::vector<BundleCamera> cameras;
  std::vector<BundleFrame> frames;  // one per Observations frame; meaningful where solved
  std::vector<BundleObservation> inliers;
  std::vector<BundleObservation> outliers;
  int iterations = 0;
  std::string gauge;
};

void say(const CalibrationOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::vector<CameraInfo> with_sizes(const Observations& obs) {
  std::vector<CameraInfo> cams = obs.cameras;
  for (size_t c = 0; c < cams.size(); ++c) {
    if (cams[c].width > 0 && cams[c].height > 0) continue;
    double umax = 1, vmax = 1;  // the extent of what the camera saw
    for (const auto& f : obs.frames)
      for (const auto& v : f.views)
        if (v.camera_id == cams[c].id)
          for (const auto& p : v.points) {
            umax = std::max(umax, p.pixel.x());
            vmax = std::max(vmax, p.pixel.y());
          }
    cams[c].width = static_cast<int>(std::ceil(umax)) + 1;
    cams[c].height = static_cast<int>(std::ceil(vmax)) + 1;
  }
  return cams;
}

// Per camera: Zhang's focal length, planar poses, a single-camera refinement. Returns the edges
// (camera_from_target per view) for chaining and fills the initial intrinsics.
Expected<std::vector<PoseEdge>> initialise_cameras(const Observations& obs, const Points& pts,
                                                   const std::vector<bool>& use,
                                                   const CalibrationOptions& o,
                                                   std::vector<BundleCamera>* cameras) {
  std::vector<PoseEdge> edges;
  const std::vector<CameraInfo> infos = with_sizes(obs);
  for (size_t c = 0; c < infos.size(); ++c) {
    BundleCamera& bc = (*cameras)[c];
    bc.camera.id = infos[c].id;
    bc.camera.width = infos[c].width;
    bc.camera.height = infos[c].height;
    bc.fixed = o.fixed;
    struct ViewRef {
      int frame;
      std::vector<int> ids;
      std::vector<Eigen::Vector3d> object;
      std::vector<Eigen::Vector2d> pixels;
    };
    std::vector<ViewRef> views;
    for (size_t f = 0; f < obs.frames.size(); ++f) {
      if (!use[f]) continue;
      for (const auto& v : obs.frames[f].views) {
        if (v.camera_id != infos[c].id ||
            static_cast<int>(v.points.size()) < o.min_points_per_view)
          continue;
        ViewRef ref{static_cast<int>(f), {}, {}, {}};
        for (const auto& p : v.points) {
          ref.ids.push_back(p.id);
          ref.object.push_back(pts[p.id]);
          ref.pixels.push_back(p.pixel);
        }
        views.push_back(std::move(ref));
      }
    }
    if (views.empty())
      return fail(format("camera {}: the target is seen with >= {} points in none of its frames",
                              infos[c].id, o.min_points_per_view));
    const double cx = (infos[c].width - 1) / 2.0, cy = (infos[c].height - 1) / 2.0;
    std::vector<Eigen::Matrix3d> hs;
    for (const auto& v : views) {
      std::vector<Eigen::Vector2d> xy;
      for (const auto& p : v.object) xy.push_back(p.head<2>());
      if (auto h = fit_homography(xy, v.pixels)) hs.push_back(*h);
    }
    Eigen::Vector2d focal(std::max(infos[c].width, infos[c].height),
                          std::max(infos[c].width, infos[c].height));
    if (auto f = focal_from_homographies(hs, cx, cy)) focal = *f;
    else say(o, format("camera {}: {}; starting from f = {:.0f} px", infos[c].id,
                            f.error().message, focal.x()));
    bc.camera.intrinsics = Intrinsics{focal.x(), focal.y(), cx, cy, 0};
    bc.camera.distortion = Distortion::radial(0, 0);
    bc.camera.cam_from_world = Rigid3::identity();

    // Single-camera refinement: the camera is the world, each view a free frame.
    std::vector<BundleCamera> single{bc};
    single[0].fix_pose = true;
    if (views.size() < 3) {
      single[0].fixed.principal_point = true;
      single[0].fixed.aspect = true;
      single[0].fixed.rd3 = single[0].fixed.rd5 = true;
    }
    std::vector<BundleFrame> frames;
    std::vector<BundleObservation> bobs;
    std::vector<int> frame_of;
    for (const auto& v : views) {
      auto pose = planar_pose(bc.camera, v.object, v.pixels);
      if (!pose) continue;
      const int fi = static_cast<int>(frames.size());
      frames.push_back({Placement::free, *pose});
      frame_of.push_back(v.frame);
      for (size_t i = 0; i < v.pixels.size(); ++i) bobs.push_back({0, fi, v.ids[i], v.pixels[i]});
    }
    if (frames.empty()) return fail("camera " + infos[c].id + ": no view gives a target pose");
    BundleOptions bo = o.bundle;
    bo.on_iteration = nullptr;
    auto s = solve_bundle(pts, bobs, &single, &frames, bo);
    if (!s) return fail("camera " + infos[c].id + ": " + s.error().message);
    bc.camera.intrinsics = single[0].camera.intrinsics;
    bc.camera.distortion = single[0].camera.distortion;
    say(o, format("camera {}: {} views, f = {:.1f} px, single-camera rms {:.3f} px",
                       infos[c].id, frames.size(), bc.camera.intrinsics.fx, s->final_rms_px));
    for (size_t i = 0; i < frames.size(); ++i) {
      double count = 0;
      for (const auto& b : bobs) count += b.frame == static_cast<int>(i);
      edges.push_back({static_cast<int>(c), frame_of[i], frames[i].world_from_target, count});
    }
  }
  return edges;
}

double robust_sigma(std::vector<double> norms) {
  if (norms.empty()) return 0;
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  return norms[norms.size() / 2] / 1.1774;  // median of a 2-D Gaussian's norm = 1.1774 σ
}

Expected<Solved> solve_frames(const Observations& obs, const Points& pts, const std::vector<bool>& use,
                              const CalibrationOptions& o) {
  Solved out;
  out.cameras.resize(obs.cameras.size());
  out.frames.resize(obs.frames.size());
  auto edges = initialise_cameras(obs, pts, use, o, &out.cameras);
  if (!edges) return std::unexpected(edges.error());

  int origin = -1;
  bool any_floor = false;
  for (size_t f = 0; f < obs.frames.size(); ++f) {
    if (!use[f]) continue;
    if (obs.frames[f].placement == Placement::origin) origin = static_cast<int>(f);
    if (obs.frames[f].placement == Placement::floor) any_floor = true;
  }
  if (any_floor && origin < 0)
    return fail("floor frames need an origin frame to fix the studio frame");
  PoseGauge gauge;
  if (origin >= 0) {
    gauge = {true, origin, floor_pose(0, 0, 0)};
    out.gauge = "origin frame " + obs.frames[origin].id;
  } else {
    gauge = {false, 0, Rigid3::identity()};
    out.gauge = "camera " + obs.cameras[0].id + " (free gauge)";
  }
  const ChainedPoses chained =
      chain_poses(static_cast<int>(obs.cameras.size()), static_cast<int>(obs.frames.size()), *edges,
                  gauge);
  std::vector<std::string> lost, kept;
  for (size_t c = 0; c < obs.cameras.size(); ++c)
    (chained.sensor_from_world[c] ? kept : lost).push_back(obs.cameras[c].id);
  if (!lost.empty())
    return fail(format("camera{} {} share{} no frame with the cameras connected to {} ({})",
                            lost.size() > 1 ? "s" : "", join(lost), lost.size() > 1 ? "" : "s",
                            out.gauge, kept.empty() ? "none" : join(kept)));
  for (size_t c = 0; c < obs.cameras.size(); ++c) {
    out.cameras[c].camera.cam_from_world = *chained.sensor_from_world[c];
    out.cameras[c].fix_pose = origin < 0 && c == 0;
  }
  std::vector<BundleObservation> all;
  for (size_t f = 0; f < obs.frames.size(); ++f) {
    if (!use[f] || !chained.world_from_frame[f]) continue;
    out.frames[f] = {obs.frames[f].placement, *chained.world_from_frame[f]};
    if (obs.frames[f].placement == Placement::origin) out.frames[f].world_from_target = gauge.pose;
    for (const auto& v : obs.frames[f].views) {
      const int c = obs.camera_index(v.camera_id);
      for (const auto& p : v.points) all.push_back({c, static_cast<int>(f), p.id, p.pixel});
    }
  }

  BundleOptions bo = o.bundle;
  bo.on_iteration = [&](int it, double rms) {
    say(o, format("  iteration {:3d}  rms {:.4f} px", it, rms));
  };
  out.inliers = all;
  for (int round = 0; round <= o.outlier_rounds; ++round) {
    say(o, format("solve: {} cameras, {} observations (robust)", obs.cameras.size(),
                       out.inliers.size()));
    auto s = solve_bundle(pts, out.inliers, &out.cameras, &out.frames, bo);
    if (!s) return std::unexpected(s.error());
    out.iterations += s->iterations;
    std::vector<double> norms;
    for (const auto& b : out.inliers)
      norms.push_back(reprojection_residual(pts, b, out.cameras, out.frames).norm());
    const double threshold = std::max(o.outlier_min_px, o.outlier_sigmas * robust_sigma(norms));
    std::vector<BundleObservation> keep;
    size_t dropped = 0;
    for (size_t i = 0; i < out.inliers.size(); ++i) {
      if (norms[i] > threshold) {
        out.outliers.push_back(out.inliers[i]);
        ++dropped;
      } else {
        keep.push_back(out.inliers[i]);
      }
    }
    out.inliers = std::move(keep);
    say(o, format("solve: rms {:.4f} px, {} outliers over {:.3f} px dropped", s->final_rms_px,
                       dropped, threshold));
    if (dropped == 0) break;
  }
  if (o.final_least_squares && o.bundle.loss != BundleOptions::Loss::none) {
    bo.loss = BundleOptions::Loss::none;
    say(o, "solve: least squares on the inliers");
    auto s = solve_bundle(pts, out.inliers, &out.cameras, &out.frames, bo);
    if (!s) return std::unexpected(s.error());
    out.iterations += s->iterations;
  }
  return out;
}

// Fits the target pose of one frame with every camera fixed; returns its observations scored.
Expected<std::vector<BundleObservation>> fit_frame(const Observations& obs, const Points& pts,
                                                   int frame, const CalibrationOptions& o,
                                                   Solved* solved) {
  const FrameObservations& f = obs.frames[frame];
  std::optional<Rigid3> start;
  size_t best = 0;
  std::vector<BundleObservation> bobs;
  for (const auto& v : f.views) {
    const int c = obs.camera_index(v.camera_id);
    std::vector<Eigen::Vector3d> object;
    std::vector<Eigen::Vector2d> pixels;
    for (const auto& p : v.points) {
      object.push_back(pts[p.id]);
      pixels.push_back(p.pixel);
      bobs.push_back({c, frame, p.id, p.pixel});
    }
    if (v.points.size() < 4 || v.points.size() <= best) continue;
    const Camera& cam = solved->cameras[c].camera;
    if (auto pose = planar_pose(cam, object, pixels)) {
      start = cam.cam_from_world.inverse() * *pose;
      best = v.points.size();
    }
  }
  if (!start) {
    say(o, "held-out frame " + f.id + ": no view gives a target pose; not scored");
    return std::vector<BundleObservation>{};
  }
  std::vector<BundleCamera> fixed = solved->cameras;
  for (auto& c : fixed) {
    c.fix_pose = true;
    c.fixed = IntrinsicsFixed{true, true, true, true, true};
  }
  BundleFrame& bf = solved->frames[frame];
  bf = {f.placement == Placement::floor ? Placement::floor : Placement::free, *start};
  BundleOptions bo = o.bundle;
  bo.on_iteration = nullptr;
  auto s = solve_bundle(pts, bobs, &fixed, &solved->frames, bo);
  if (!s) return fail("held-out frame " + f.id + ": " + s.error().message);
  return bobs;
}

ScoredObservation score(const Observations& obs, const Points& pts, const BundleObservation& b,
                        const Solved& s) {
  return {obs.cameras[b.camera].id, obs.frames[b.frame].id, b.point, b.pixel,
          reprojection_residual(pts, b, s.cameras, s.frames)};
}

double rms(const std::vector<ScoredObservation>& v) {
  if (v.empty()) return 0;
  double sum = 0;
  for (const auto& s : v) sum += s.residual.squaredNorm();
  return std::sqrt(sum / v.size());
}

}  // namespace

Expected<void> CalibrationOptions::validate() const {
  if (auto v = bundle.validate(); !v) return v;
  if (!(outlier_sigmas > 0) || !(outlier_min_px > 0))
    return fail("calibration: outlier thresholds must be > 0");
  if (outlier_rounds < 0) return fail("calibration: outlier_rounds must be >= 0");
  if (k_fold < 0 || k_fold == 1) return fail("calibration: k_fold must be 0 or >= 2");
  if (min_points_per_view < 4) return fail("calibration: min_points_per_view must be >= 4");
  return {};
}

Expected<CalibrationResult> calibrate_cameras(const Observations& obs, const Points& pts,
                                              const CalibrationOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  if (auto v = o.validate(); !v) return std::unexpected(v.error());
  if (auto v = obs.validate(static_cast<int>(pts.size())); !v) return std::unexpected(v.error());

  std::vector<bool> use(obs.frames.size());
  for (size_t f = 0; f < obs.frames.size(); ++f) use[f] = !obs.frames[f].holdout;
  auto solved = solve_frames(obs, pts, use, o);
  if (!solved) return std::unexpected(solved.error());

  CalibrationResult r;
  r.gauge = solved->gauge;
  r.iterations = solved->iterations;
  for (const auto& b : solved->inliers) r.inliers.push_back(score(obs, pts, b, *solved));
  for (const auto& b : solved->outliers) r.outliers.push_back(score(obs, pts, b, *solved));
  r.rms_px = rms(r.inliers);
  r.observations = static_cast<int>(r.inliers.size());

  for (size_t f = 0; f < obs.frames.size(); ++f) {
    if (use[f]) continue;
    auto scored = fit_frame(obs, pts, static_cast<int>(f), o, &*solved);
    if (!scored) return std::unexpected(scored.error());
    for (const auto& b : *scored) r.heldout.push_back(score(obs, pts, b, *solved));
  }
  r.heldout_rms_px = rms(r.heldout);
  r.heldout_observations = static_cast<int>(r.heldout.size());

  if (o.k_fold > 1) {
    std::vector<int> eligible;
    for (size_t f = 0; f < obs.frames.size(); ++f)
      if (use[f] && obs.frames[f].placement != Placement::origin) eligible.push_back(f);
    if (static_cast<int>(eligible.size()) < o.k_fold)
      return fail(format("k-fold: {} folds but only {} frames to leave out", o.k_fold,
                              eligible.size()));
    CalibrationOptions quiet = o;
    quiet.progress = nullptr;
    std::vector<ScoredObservation> pooled;
    for (int k = 0; k < o.k_fold; ++k) {
      say(o, format("k-fold: fold {}/{}", k + 1, o.k_fold));
      std::vector<bool> fold_use = use;
      for (size_t j = k; j < eligible.size(); j += o.k_fold) fold_use[eligible[j]] = false;
      auto fold = solve_frames(obs, pts, fold_use, quiet);
      if (!fold) return fail(format("k-fold: fold {}: {}", k + 1, fold.error().message));
      for (size_t j = k; j < eligible.size(); j += o.k_fold) {
        auto scored = fit_frame(obs, pts, eligible[j], quiet, &*fold);
        if (!scored) return std::unexpected(scored.error());
        for (const auto& b : *scored) pooled.push_back(score(obs, pts, b, *fold));
      }
    }
    r.kfold_rms_px = rms(pooled);
    r.kfold_observations = static_cast<int>(pooled.size());
  }

  for (size_t c = 0; c < obs.cameras.size(); ++c) {
    r.cameras.push_back(solved->cameras[c].camera);
    CameraStats st;
    st.id = obs.cameras[c].id;
    std::vector<ScoredObservation> mine, held;
    for (const auto& s : r.inliers)
      if (s.camera_id == st.id) mine.push_back(s);
    for (const auto& s : r.heldout)
      if (s.camera_id == st.id) held.push_back(s);
    for (const auto& s : r.outliers) st.outliers += s.camera_id == st.id;
    st.observations = static_cast<int>(mine.size());
    st.rms_px = rms(mine);
    st.heldout_observations = static_cast<int>(held.size());
    st.heldout_rms_px = rms(held);
    r.per_camera.push_back(st);
  }
  for (size_t f = 0; f < obs.frames.size(); ++f) {
    FrameStats st;
    st.id = obs.frames[f].id;
    st.placement = obs.frames[f].placement;
    st.held_out = !use[f];
    st.world_from_target = solved->frames[f].world_from_target;
    std::vector<ScoredObservation> mine;
    for (const auto& s : st.held_out ? r.heldout : r.inliers)
      if (s.frame_id == st.id) mine.push_back(s);
    st.observations = static_cast<int>(mine.size());
    st.rms_px = rms(mine);
    r.per_frame.push_back(st);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace studio::calibrate
