#pragma once
// rig.yaml (DESIGN §4), read strictly and written losslessly.
//
//   units: metres                     # optional; if present must be metres
//   cameras:
//     - id: cam0
//       width: 704
//       height: 576
//       K: [fx, skew, cx, 0, fy, cy, 0, 0, 1]   # or cahv: {C, A, H, V} or P: [12 row-major]
//       radial: [rd3, rd5]                     # optional; or opencv: [k1, k2, p1, p2, k3]
//       cam_from_world: {R: [9 row-major], t: [3]}   # with K only (cahv and P carry the pose)
//   projectors:
//     - id: proj0
//       ... the camera keys ...
//       screen: {corners: [[x, y, z] x 4]}     # lower-left, lower-right, upper-right, upper-left
//
// Reading checks every field (types, lengths, finite numbers, R a rotation, K upper triangular
// with positive focal lengths, unique ids, positive sizes); errors name file, line and field.
// Writing always uses K + cam_from_world and the shortest decimal form that reads back to the
// same double, so intrinsics, distortion, t, sizes and screen corners round-trip bit-exactly and
// R to within the quaternion <-> matrix conversion (~1e-16).

#include <string>
#include <string_view>

#include "core/camera.h"
#include "core/error.h"
#include "core/rig.h"
#include "yaml_io/node.h"

namespace studio::yaml {

Expected<Rig> read_rig(const std::string& path);
Expected<Rig> parse_rig(std::string_view text, const std::string& name);
Expected<Rig> read_rig(const Node& root);

// One camera mapping, as an element of `cameras` (strict: no other keys).
Expected<Camera> read_camera(const Node& node);

std::string format_rig(const Rig& rig);
Expected<void> write_rig(const Rig& rig, const std::string& path);
// The body of one camera mapping as block YAML, each line prefixed by `indent` spaces
// (for embedding, e.g. in take.yaml's calibration).
std::string format_camera(const Camera& camera, int indent);

// A YAML scalar for `text`: plain when that reads back verbatim, double-quoted otherwise.
std::string quote(std::string_view text);

}  // namespace studio::yaml
