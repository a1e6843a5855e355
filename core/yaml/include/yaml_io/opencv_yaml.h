#pragma once
// OpenCV FileStorage YAML import / export (DESIGN §4 importers).
//
// Import accepts what cv::FileStorage writes: the `%YAML:1.0` header, `!!opencv-matrix` nodes
// (rows, cols, dt, data; rows * cols must equal the data length) or plain number lists.
// - one camera per file: camera matrix `K` or `camera_matrix`; distortion `distCoeffs`, `D` or
//   `distortion_coefficients` (4 or 5 values k1 k2 p1 p2 [k3]; longer vectors only if the extra
//   rational/thin-prism/tilt terms are zero); optional pose `R` (3x3 rotation, or a 3-vector
//   Rodrigues rotation) and `T` / `t` (3x1), x_in_cam = R x_in_world + T; identity when absent.
// - a stereo file: K1, D1, K2, D2, R, T (as cv::stereoCalibrate: x_in_cam1 = R x_in_cam0 + T);
//   camera 0 defines the world frame.
// The image size comes from `image_width`/`image_height` (or `width`/`height`) when present,
// otherwise from the arguments; without either the import fails. Other keys are ignored (the
// format carries many: E, F, rms, ...). Cameras get ids <id_prefix>0, <id_prefix>1.
//
// Distortion: imported cameras keep OpenCV's model exactly (Distortion::opencv; core/camera.h
// implements it). With OpencvImport::paper_model each camera is converted explicitly to the
// paper's radial model by to_paper_model (core/distortion_fit.h: least-squares fit over the
// image, residual in pixels reported through `fits`), and the import fails, naming the file and
// the camera, when a fit's residual exceeds the tolerance. Never a rename of k1/k2.
//
// Export writes one camera as cv::FileStorage would: image_width, image_height, camera_matrix,
// distortion_coefficients (k1 k2 p1 p2 k3; the paper's radial model is exactly k1 = rd3,
// k2 = rd5, both models mapping ideal to observed coordinates), R, T.

#include <string>
#include <string_view>
#include <vector>

#include "core/camera.h"
#include "core/distortion_fit.h"
#include "core/error.h"
#include "core/rig.h"

namespace studio::yaml {

struct OpencvImport {
  bool paper_model = false;  // convert every camera to the paper's model (or fail)
  PaperModelOptions fit;     // tolerance and sampling of that conversion
  std::vector<PaperModelFit>* fits = nullptr;  // optional: one entry per camera, in order
};

Expected<Rig> import_opencv_yaml(const std::string& path, int width = 0, int height = 0,
                                 std::string_view id_prefix = "cam",
                                 const OpencvImport& options = {});
Expected<Rig> parse_opencv_yaml(std::string_view text, const std::string& name, int width = 0,
                                int height = 0, std::string_view id_prefix = "cam",
                                const OpencvImport& options = {});

std::string format_opencv_yaml(const Camera& camera);
Expected<void> export_opencv_yaml(const Camera& camera, const std::string& path);

}  // namespace studio::yaml
