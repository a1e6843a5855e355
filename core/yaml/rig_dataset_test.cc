// Real data: the Middlebury dino camera set (/work/shared/data/middlebury_dino/dinoSR_par.txt,
// 16 views, 640x480). Skipped with a message when the shared data is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/rig.h"
#include "yaml_io/opencv_yaml.h"
#include "yaml_io/rig_yaml.h"

namespace studio {
namespace {

const std::string kPar = std::string(STUDIO_SHARED_DATA) + "/middlebury_dino/dinoSR_par.txt";

TEST(MiddleburyDino, CamerasLookAtOneObject) {
  if (!std::filesystem::exists(kPar)) GTEST_SKIP() << "no Middlebury dino data at " << kPar;
  Expected<Rig> rig = import_middlebury(kPar, 640, 480);
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 16u);
  EXPECT_EQ(rig->cameras[0].id, "dinoSR0001");
  Expected<void> valid = rig->validate();
  ASSERT_TRUE(valid) << valid.error().message;

  // The centroid of the nearest points of every pair of optical axes: the object.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int pairs = 0;
  for (std::size_t i = 0; i < rig->cameras.size(); ++i) {
    for (std::size_t j = i + 1; j < rig->cameras.size(); ++j) {
      const Eigen::Vector3d c1 = rig->cameras[i].centre_in_world(),
                            d1 = rig->cameras[i].axis_in_world();
      const Eigen::Vector3d c2 = rig->cameras[j].centre_in_world(),
                            d2 = rig->cameras[j].axis_in_world();
      const Eigen::Vector3d w = c1 - c2;
      const double b = d1.dot(d2), d = d1.dot(w), e = d2.dot(w), denom = 1 - b * b;
      if (denom < 1e-6) continue;  // nearly parallel axes: no stable nearest point
      const double s = (b * e - d) / denom, t = (e - b * d) / denom;
      sum += 0.5 * ((c1 + s * d1) + (c2 + t * d2));
      ++pairs;
    }
  }
  ASSERT_GT(pairs, 0);
  const Eigen::Vector3d object = sum / pairs;
  double dmin = 1e9, dmax = 0;
  for (const Camera& cam : rig->cameras) {
    const double distance = (cam.centre_in_world() - object).norm();
    dmin = std::min(dmin, distance);
    dmax = std::max(dmax, distance);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(cam.project(object, &pixel)) << cam.id << ": object behind the camera";
    EXPECT_TRUE(cam.in_image(pixel)) << cam.id << ": object projects to " << pixel.transpose();
  }
  std::printf(
      "[ measured ] dino: object point (%.4f, %.4f, %.4f) m, camera distances %.4f..%.4f m\n",
      object.x(), object.y(), object.z(), dmin, dmax);
  EXPECT_LT(dmax / dmin, 1.1);  // the views lie on a ring (hemisphere) around the dino

  // rig.yaml and OpenCV YAML of real cameras round-trip.
  const std::string path = testing::TempDir() + "/dino_rig.yaml";
  ASSERT_TRUE(yaml::write_rig(*rig, path));
  Expected<Rig> back = yaml::read_rig(path);
  ASSERT_TRUE(back) << back.error().message;
  double worst = 0;
  for (std::size_t i = 0; i < 16; ++i) {
    worst =
        std::max(worst, (back->cameras[i].projection_matrix() - rig->cameras[i].projection_matrix())
                            .cwiseAbs()
                            .maxCoeff());
  }
  std::printf("[ measured ] dino rig.yaml round trip: max |dP| = %.3g (P entries up to ~3e3)\n",
              worst);
  EXPECT_LT(worst, 1e-9);

  // P-matrix list export/import.
  const std::string plist = testing::TempDir() + "/dino_P.txt";
  {
    std::ofstream out(plist);
    out.precision(17);
    out << "# 16 projection matrices, row-major\n";
    for (const Camera& c : rig->cameras) {
      const Eigen::Matrix<double, 3, 4> P = c.projection_matrix();
      for (int r = 0; r < 3; ++r)
        out << P(r, 0) << ' ' << P(r, 1) << ' ' << P(r, 2) << ' ' << P(r, 3) << '\n';
    }
  }
  Expected<Rig> from_p = import_projection_matrices(plist, 640, 480);
  ASSERT_TRUE(from_p) << from_p.error().message;
  double worst_k = 0, worst_c = 0;
  for (std::size_t i = 0; i < 16; ++i) {
    worst_k = std::max(
        worst_k,
        (from_p->cameras[i].intrinsics.K() - rig->cameras[i].intrinsics.K()).cwiseAbs().maxCoeff());
    worst_c = std::max(
        worst_c, (from_p->cameras[i].centre_in_world() - rig->cameras[i].centre_in_world()).norm());
  }
  std::printf("[ measured ] dino P-list import: max |dK| = %.3g px, max centre error %.3g m\n",
              worst_k, worst_c);
  EXPECT_LT(worst_k, 1e-6);
  EXPECT_LT(worst_c, 1e-9);
}

}  // namespace
}  // namespace studio
