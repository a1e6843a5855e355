#pragma once
// A studio rig: the calibrated cameras and projectors (DESIGN §4). Pure data; reading and writing
// rig.yaml lives in core/yaml (yaml_io/rig_yaml.h), text importers are declared here.
//
// Units are metres, studio frame: y up, floor = xz-plane.

#include <Eigen/Core>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/camera.h"
#include "core/error.h"

namespace studio {

// A data projector is an inverse camera (same model: K, distortion, cam_from_world, size in
// pixels) plus the screen it lights, as four corners in the studio frame, in the order
// lower-left, lower-right, upper-right, upper-left (as seen from the front of the screen).
struct Projector {
  Camera camera;
  std::array<Eigen::Vector3d, 4> screen = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                           Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
};

struct Rig {
  std::vector<Camera> cameras;
  std::vector<Projector> projectors;

  // nullptr when no camera / projector has that id.
  const Camera* find_camera(std::string_view id) const;
  Camera* find_camera(std::string_view id);
  const Projector* find_projector(std::string_view id) const;
  Projector* find_projector(std::string_view id);

  // Ids non-empty and unique (cameras and projectors together), sizes positive, every number
  // finite, focal lengths positive; screens non-degenerate (four distinct, nearly coplanar
  // corners). The message names the device: "cameras[2] (cam2): duplicate id".
  Expected<void> validate() const;
};

// Checks one camera as Rig::validate does; `where` prefixes the message ("cameras[2]").
Expected<void> validate_camera(const Camera& camera, std::string_view where);

// Checked conversions shared by the rig readers and importers (messages without location; the
// caller prefixes file, line and field):
// - a rotation matrix must satisfy |R^T R - I| <= 1e-4 (max entry; real files such as
//   Middlebury's print R to ~1e-6) and det R > 0; it is then
//   re-orthonormalised (Rigid3 stores a unit quaternion);
// - a camera matrix K must be finite and upper triangular with K(2,2) != 0 and positive fx, fy
//   after normalisation by K(2,2).
Expected<Rigid3> rigid_from_matrix(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
Expected<Intrinsics> intrinsics_from_matrix(const Eigen::Matrix3d& K);

// Plain 3x4 projection-matrix lists: a text file of numbers separated by white space or commas,
// 12 per camera (row-major P ~ K [R | t]); '#' starts a comment. Cameras get ids
// <id_prefix>0, <id_prefix>1, ... and the given image size. Errors name the file and line.
Expected<Rig> import_projection_matrices(const std::string& path, int width, int height,
                                         std::string_view id_prefix = "cam");

// Middlebury multi-view `*_par.txt`: the first line is the camera count, then one line per
// camera: `name k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3`
// with x_in_cam = R x_in_world + t. Camera ids are the image names without extension.
Expected<Rig> import_middlebury(const std::string& path, int width, int height);

// The same importers on text already in memory; `name` stands for the file in messages.
Expected<Rig> parse_projection_matrices(std::string_view text, const std::string& name, int width,
                                        int height, std::string_view id_prefix = "cam");
Expected<Rig> parse_middlebury(std::string_view text, const std::string& name, int width,
                               int height);

}  // namespace studio
