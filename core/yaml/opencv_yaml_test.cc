#include "yaml_io/opencv_yaml.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace studio::yaml {
namespace {

Camera sample_camera() {
  Camera c;
  c.id = "cam0";
  c.width = 1280;
  c.height = 720;
  c.intrinsics = Intrinsics{1012.123456789, 1009.87654321, 641.25, 359.75, 0.125};
  c.distortion = Distortion::opencv(-0.2345, 0.0789, 0.00123, -0.00045, -0.0123);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1, 0.2).normalized()).toRotationMatrix();
  c.cam_from_world = Rigid3(R, Eigen::Vector3d(0.25, -1.5, 3.75));
  return c;
}

cv::Mat to_cv(const Eigen::MatrixXd& m) {
  cv::Mat out(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_64F);
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c) out.at<double>(r, c) = m(r, c);
  return out;
}

double max_diff(const cv::Mat& a, const Eigen::MatrixXd& b) {
  double worst = 0;
  for (int r = 0; r < a.rows; ++r)
    for (int c = 0; c < a.cols; ++c)
      worst = std::max(worst, std::abs(a.at<double>(r, c) - b(r, c)));
  return worst;
}

TEST(OpenCvYaml, ExportIsReadByCvFileStorage) {
  const Camera cam = sample_camera();
  const std::string path = testing::TempDir() + "/cam_export.yaml";
  ASSERT_TRUE(export_opencv_yaml(cam, path));
  cv::FileStorage fs(path, cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  cv::Mat K, D, R, T;
  int w = 0, h = 0;
  fs["image_width"] >> w;
  fs["image_height"] >> h;
  fs["camera_matrix"] >> K;
  fs["distortion_coefficients"] >> D;
  fs["R"] >> R;
  fs["T"] >> T;
  EXPECT_EQ(w, 1280);
  EXPECT_EQ(h, 720);
  ASSERT_EQ(D.total(), 5u);
  const double eK = max_diff(K, cam.intrinsics.K());
  const double eR = max_diff(R, cam.cam_from_world.R());
  const double eT = max_diff(T, cam.cam_from_world.translation);
  const Distortion& d = cam.distortion;
  const double eD =
      max_diff(D.reshape(1, 5), Eigen::Matrix<double, 5, 1>(d.k1, d.k2, d.p1, d.p2, d.k3));
  std::printf("[ measured ] export -> cv::FileStorage: max diff K %.3g, D %.3g, R %.3g, T %.3g\n",
              eK, eD, eR, eT);
  EXPECT_EQ(eK, 0);
  EXPECT_EQ(eD, 0);
  EXPECT_EQ(eR, 0);
  EXPECT_EQ(eT, 0);
  // and back through our importer
  Expected<Rig> back = import_opencv_yaml(path);
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->cameras.size(), 1u);
  EXPECT_EQ((back->cameras[0].intrinsics.K() - cam.intrinsics.K()).cwiseAbs().maxCoeff(), 0);
  EXPECT_LT((back->cameras[0].cam_from_world.R() - cam.cam_from_world.R()).cwiseAbs().maxCoeff(),
            1e-15);
}

TEST(OpenCvYaml, ImportsFilesWrittenByCvFileStorage) {
  const Camera cam = sample_camera();
  const Distortion& d = cam.distortion;
  const std::string single = testing::TempDir() + "/cv_single.yaml";
  {
    cv::FileStorage fs(single, cv::FileStorage::WRITE);
    fs << "K" << to_cv(cam.intrinsics.K());
    fs << "distCoeffs" << (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
    cv::Mat rvec;
    cv::Rodrigues(to_cv(cam.cam_from_world.R()), rvec);
    fs << "R" << rvec;  // a Rodrigues vector is accepted too
    fs << "T" << to_cv(cam.cam_from_world.translation);
    fs << "rms" << 0.21;
  }
  Expected<Rig> rig = import_opencv_yaml(single, 1280, 720);
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 1u);
  const Camera& c = rig->cameras[0];
  EXPECT_EQ(c.id, "cam0");
  EXPECT_EQ(c.width, 1280);
  EXPECT_EQ(c.distortion.k3, d.k3);
  const double eP = (c.projection_matrix() - cam.projection_matrix()).cwiseAbs().maxCoeff();
  std::printf("[ measured ] cv::FileStorage (Rodrigues R) -> import: max |dP| %.3g\n", eP);
  EXPECT_LT(eP, 1e-9);

  const std::string stereo = testing::TempDir() + "/cv_stereo.yaml";
  {
    cv::FileStorage fs(stereo, cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480;
    fs << "K1" << to_cv(cam.intrinsics.K()) << "D1" << cv::Mat::zeros(1, 8, CV_64F);
    fs << "K2" << to_cv(cam.intrinsics.K()) << "D2"
       << (cv::Mat_<double>(5, 1) << -0.1, 0.01, 0, 0, 0);
    fs << "R" << to_cv(cam.cam_from_world.R()) << "T" << to_cv(cam.cam_from_world.translation);
    fs << "E" << cv::Mat::eye(3, 3, CV_64F) << "F" << cv::Mat::eye(3, 3, CV_64F);
  }
  Expected<Rig> pair = import_opencv_yaml(stereo, 0, 0, "stereo");
  ASSERT_TRUE(pair) << pair.error().message;
  ASSERT_EQ(pair->cameras.size(), 2u);
  EXPECT_EQ(pair->cameras[1].id, "stereo1");
  EXPECT_EQ(pair->cameras[0].width, 640);
  EXPECT_LT(pair->cameras[0].centre_in_world().norm(), 1e-15);
  EXPECT_LT((pair->cameras[1].cam_from_world.R() - cam.cam_from_world.R()).cwiseAbs().maxCoeff(),
            1e-15);
  EXPECT_EQ(pair->cameras[1].distortion.k1, -0.1);
}

// A file written by cv::FileStorage with distortion `coefficients` (k1 k2 p1 p2 k3).
std::string write_cv_file(const Camera& cam, const cv::Mat& coefficients, const std::string& name) {
  const std::string path = testing::TempDir() + "/" + name;
  cv::FileStorage fs(path, cv::FileStorage::WRITE);
  fs << "image_width" << cam.width << "image_height" << cam.height;
  fs << "camera_matrix" << to_cv(cam.intrinsics.K()) << "distortion_coefficients" << coefficients;
  fs << "R" << to_cv(cam.cam_from_world.R()) << "T" << to_cv(cam.cam_from_world.translation);
  return path;
}

// Worst pixel distance between cv::projectPoints (the file's model, as OpenCV applies it) and the
// imported camera, over points in front of the camera that land in the image.
double worst_vs_opencv(const Camera& imported, const cv::Mat& coefficients) {
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 25; ++i)
    for (int j = 0; j < 25; ++j) {
      // Rays through a grid beyond the image corners, at 2 to 5 m.
      const Eigen::Vector3d n((i - 12) * 0.06, (j - 12) * 0.05, 1.0);
      const Eigen::Vector3d x_in_cam = n * (2.0 + 0.12 * i);
      const Eigen::Vector3d x = imported.cam_from_world.inverse() * x_in_cam;
      points.emplace_back(x.x(), x.y(), x.z());
    }
  cv::Mat rvec;
  cv::Rodrigues(to_cv(imported.cam_from_world.R()), rvec);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, rvec, to_cv(imported.cam_from_world.translation),
                    to_cv(imported.intrinsics.K()), coefficients, expected);
  double worst = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (expected[k].x < 0 || expected[k].y < 0 || expected[k].x > imported.width - 1 ||
        expected[k].y > imported.height - 1)
      continue;
    Eigen::Vector2d px;
    EXPECT_TRUE(imported.project({points[k].x, points[k].y, points[k].z}, &px));
    worst = std::max(worst, (px - Eigen::Vector2d(expected[k].x, expected[k].y)).norm());
  }
  return worst;
}

TEST(OpenCvYaml, PaperModelImportFitsOrRefusesNeverRenames) {
  Camera cam = sample_camera();
  cam.intrinsics.skew = 0;  // cv::projectPoints has no skew
  // Radial-only k1, k2: the paper's model holds it exactly (both map ideal -> observed).
  const cv::Mat radial = (cv::Mat_<double>(1, 5) << -0.2345, 0.0789, 0, 0, 0);
  std::vector<PaperModelFit> fits;
  Expected<Rig> rig = import_opencv_yaml(write_cv_file(cam, radial, "cv_radial.yaml"), 0, 0, "cam",
                                         {.paper_model = true, .fits = &fits});
  ASSERT_TRUE(rig) << rig.error().message;
  const Camera& c = rig->cameras[0];
  EXPECT_EQ(c.distortion.model, Distortion::Model::radial);
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_TRUE(fits[0].fitted);
  EXPECT_LT(fits[0].max_residual_px, 1e-6);
  const double exact = worst_vs_opencv(c, radial);
  std::printf("[ measured ] k1 k2 only -> paper model: fit max %.3g px, vs cv::projectPoints %.3g px\n",
              fits[0].max_residual_px, exact);
  EXPECT_LT(exact, 1e-6);

  // A small k3: fitted, residual reported and within tolerance; OpenCV agrees within it.
  const cv::Mat k3 = (cv::Mat_<double>(1, 5) << -0.2345, 0.0789, 0, 0, -0.004);
  fits.clear();
  rig = import_opencv_yaml(write_cv_file(cam, k3, "cv_k3.yaml"), 0, 0, "cam",
                           {.paper_model = true, .fits = &fits});
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(fits.size(), 1u);
  const double fitted = worst_vs_opencv(rig->cameras[0], k3);
  std::printf("[ measured ] k3 -0.004 -> paper model: fit max %.3g px RMS %.3g px, vs "
              "cv::projectPoints %.3g px\n",
              fits[0].max_residual_px, fits[0].rms_residual_px, fitted);
  EXPECT_GT(fits[0].max_residual_px, 1e-4);
  EXPECT_LE(fitted, fits[0].max_residual_px * 1.05 + 1e-9);

  // Strong tangential terms: refused, naming the file and the camera.
  const cv::Mat tangential = (cv::Mat_<double>(1, 5) << -0.2345, 0.0789, 0.004, -0.003, 0);
  const std::string path = write_cv_file(cam, tangential, "cv_tangential.yaml");
  rig = import_opencv_yaml(path, 0, 0, "cam", {.paper_model = true});
  ASSERT_FALSE(rig);
  EXPECT_NE(rig.error().message.find(path + ": camera cam0"), std::string::npos)
      << rig.error().message;
  EXPECT_NE(rig.error().message.find("does not fit the paper's radial model"), std::string::npos);
  // Without paper_model the same file keeps OpenCV's model exactly.
  rig = import_opencv_yaml(path);
  ASSERT_TRUE(rig) << rig.error().message;
  EXPECT_EQ(rig->cameras[0].distortion.model, Distortion::Model::opencv);
  EXPECT_LT(worst_vs_opencv(rig->cameras[0], tangential), 1e-6);
}

std::string error_of(const std::string& text, int w = 640, int h = 480) {
  Expected<Rig> rig = parse_opencv_yaml(text, "cv.yaml", w, h);
  return rig ? std::string("<ok>") : rig.error().message;
}

const char* kMatrix =
    "%YAML:1.0\n---\nK: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., "
    "320., 0., 500., 240., 0., 0., 1. ]\n";

TEST(OpenCvYaml, BadInputNamesFileLineAndField) {
  EXPECT_EQ(error_of(kMatrix), "<ok>");
  EXPECT_EQ(error_of(std::string(kMatrix) + "T: [1, 2, 3]\n"),
            "cv.yaml:3: R and T must be given together");
  std::string s = kMatrix;
  s.replace(s.find(" 1. ]"), 5, " ]");
  EXPECT_EQ(error_of(s), "cv.yaml:7: K.data: expected 9 numbers (3x3), got 8");
  s = kMatrix;
  s.replace(s.find("dt: d"), 5, "dt: q");
  EXPECT_EQ(error_of(s),
            "cv.yaml:6: K.dt: unsupported element type 'q' (expected one of d f i s u w c)");
  s = kMatrix;
  s.replace(s.find("rows: 3"), 7, "rows: x");
  EXPECT_EQ(error_of(s), "cv.yaml:4: K.rows: expected an integer, got 'x'");
  EXPECT_EQ(error_of(kMatrix, 0, 0),
            "cv.yaml:3: image size unknown: the file has no image_width/image_height; pass it");
  EXPECT_EQ(error_of("%YAML:1.0\n---\nfoo: 1\n"),
            "cv.yaml:3: no camera matrix (expected K, camera_matrix or K1/K2)");
  EXPECT_EQ(error_of(std::string(kMatrix) + "distCoeffs: [0.1, 0, 0, 0, 0, 0.5, 0, 0]\n"),
            "cv.yaml:8: distCoeffs: only k1 k2 p1 p2 k3 are supported; coefficient 5 (rational / "
            "thin-prism / tilt) is not zero");
  EXPECT_EQ(error_of(std::string(kMatrix) + "distCoeffs: [0.1, 0, 0]\n"),
            "cv.yaml:8: distCoeffs: expected 4, 5, 8, 12 or 14 distortion coefficients, got 3");
  EXPECT_EQ(error_of(std::string(kMatrix) + "R: [1, 0, 0, 1]\nT: [0, 0, 0]\n"),
            "cv.yaml:8: R: expected a 3x3 rotation matrix or a 3-vector, got 4x1");
  EXPECT_EQ(
      error_of(std::string(kMatrix) + "R: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   "
                                      "data: [1, 0, 0, 0, 1, 0, 0, 0, 2]\nT: [0, 0, .nan]\n"),
      "cv.yaml:13: T[2]: non-finite number '.nan'");
  EXPECT_EQ(
      error_of(std::string(kMatrix) + "R: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   "
                                      "data: [1, 0, 0, 0, 1, 0, 0, 0, 2]\nT: [0, 0, 0]\n"),
      "cv.yaml:8: R: not a rotation matrix (max |R^T R - I| = 3, det = 2)");
  EXPECT_EQ(error_of("%YAML:1.0\n---\nK: [1, 2\n").substr(0, 8), "cv.yaml:");
  Expected<Rig> missing = import_opencv_yaml("/nonexistent/calib.yml");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "/nonexistent/calib.yml: cannot open file");
}

}  // namespace
}  // namespace studio::yaml
