#pragma once
// Which studio cameras texture the live actor in the director's preview, and how much each
// contributes (issue 16; TCSVT 2004 §II: "the camera nearest in angle to the virtual camera").
//
// Angles are measured at the actor (`target`, e.g. its mesh centre) between the ray to the
// virtual eye and the ray to each studio camera's centre.
//   nearest():  the paper's choice, the camera with the smallest angle (weight 1).
//   blend():    beyond the paper, the k nearest cameras with the angle penalty of unstructured
//               lumigraph rendering (Buehler et al., SIGGRAPH 2001, §4.4):
//                 w_i = (1 - a_i / a_thr) / a_i,   a_thr = the angle of the (k+1)-th camera,
//               normalised to sum 1 (a camera at the threshold fades to 0, so the blend changes
//               continuously as the viewpoint moves; a camera at a_i = 0 takes everything).
// Visibility is per surface point and is the renderer's part: a camera that cannot see a
// point does not colour it and the remaining weights are renormalised there.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::preview {

struct StudioCameraPose {
  std::string id;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // world, metres
};

struct CameraWeight {
  int index = -1;     // into the cameras given
  double angle = 0;   // radians, at the target
  double weight = 0;  // sums to 1 over the result
};

struct BlendOptions {
  int cameras = 3;  // k, 1..8
  Expected<void> validate() const;
};

// The centre of the points' bounding box (the actor's target above); zero when there are none.
Eigen::Vector3d bounds_centre(const std::vector<Eigen::Vector3f>& points);

// Angle at `target` between (eye - target) and (centre - target); pi when either is degenerate.
double view_angle(const Eigen::Vector3d& eye, const Eigen::Vector3d& centre,
                  const Eigen::Vector3d& target);

// Empty when there are no cameras.
std::vector<CameraWeight> nearest(const std::vector<StudioCameraPose>& cameras,
                                  const Eigen::Vector3d& eye, const Eigen::Vector3d& target);
// Up to options.cameras entries with weight > 0, sorted by angle.
std::vector<CameraWeight> blend(const std::vector<StudioCameraPose>& cameras,
                                const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                                const BlendOptions& options = {});
// The blend's threshold angle a_thr (radians): the (k+1)-th camera's angle at the target, pi
// when there are at most k cameras. The renderer evaluates the same penalty per surface point.
double blend_threshold(const std::vector<StudioCameraPose>& cameras, const Eigen::Vector3d& eye,
                       const Eigen::Vector3d& target, const BlendOptions& options = {});

}  // namespace studio::preview
