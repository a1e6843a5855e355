#pragma once
// Per-frame calibration of a tracked camera in a take (DESIGN §4): takes/<take>/<camera>/
// calibration holds one text line per recorded frame that had one, in frame order, written by the
// recorder right after the frame itself:
//
//   <frame> <model> fx fy cx cy skew d1 d2 d3 d4 d5 r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz
//
// model 0 = no distortion, 1 = the paper's radial model (d1 = rd3, d2 = rd5, rest 0), 2 = OpenCV
// (d = k1 k2 p1 p2 k3); R | t = cam_from_world (metres); every number with 17 significant
// digits, so a camera read back is the camera written. A torn last line (power cut) is ignored.

#include <cstdint>
#include <map>
#include <string>

#include "core/camera.h"
#include "core/error.h"

namespace studio::capture {

inline constexpr char kCalibrationFile[] = "calibration";

// One line (with its '\n').
std::string format_calibration_line(uint64_t frame, const Camera& camera);

// The per-frame cameras of one camera's take folder, keyed by frame; id, width and height come
// from `base` (the take's camera). Empty when the take has no calibration file (a fixed camera).
// Error with file:line on a malformed complete line.
Expected<std::map<uint64_t, Camera>> read_take_calibration(const std::string& take_dir,
                                                           const Camera& base);

}  // namespace studio::capture
