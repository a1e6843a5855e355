#include "core/rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace studio {
namespace {

Camera camera(const std::string& id) {
  Camera c;
  c.id = id;
  c.width = 640;
  c.height = 480;
  c.intrinsics = Intrinsics{500, 500, 320, 240, 0};
  c.cam_from_world = Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 3));
  return c;
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const Expected<Rig>& r) { return r ? std::string("<ok>") : r.error().message; }

TEST(Rig, FindByIdAndValidate) {
  Rig rig;
  rig.cameras = {camera("a"), camera("b")};
  Projector p;
  p.camera = camera("p");
  p.screen = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 0),
              Eigen::Vector3d(0, 1, 0)};
  rig.projectors.push_back(p);
  ASSERT_TRUE(rig.validate());
  EXPECT_EQ(rig.find_camera("b"), &rig.cameras[1]);
  EXPECT_EQ(rig.find_camera("p"), nullptr);
  EXPECT_EQ(rig.find_projector("p"), &rig.projectors[0]);
  rig.find_camera("a")->width = 0;
  EXPECT_EQ(rig.validate().error().message,
            "cameras[0] (a): image size must be positive, got 0x480");
  rig.cameras[0].width = 640;
  rig.projectors[0].camera.id = "a";
  EXPECT_EQ(rig.validate().error().message, "projectors[0] (a): duplicate id");
  rig.projectors[0].camera.id = "p";
  rig.projectors[0].screen[2].z() = 0.5;
  EXPECT_EQ(rig.validate().error().message, "projectors[0] (p): screen: corners are not coplanar");
  rig.projectors[0].screen[2].z() = 0;
  rig.cameras[1].intrinsics.fy = std::nan("");
  EXPECT_EQ(rig.validate().error().message, "cameras[1] (b): non-finite intrinsics");
}

TEST(Rig, CheckedConversions) {
  EXPECT_TRUE(rigid_from_matrix(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()));
  EXPECT_FALSE(rigid_from_matrix(-Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()));
  EXPECT_FALSE(rigid_from_matrix(2 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()));
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  Expected<Intrinsics> k = intrinsics_from_matrix(2 * K);
  ASSERT_TRUE(k);
  EXPECT_EQ(k->fx, 500);
  K(2, 2) = 0;
  EXPECT_FALSE(intrinsics_from_matrix(K));
}

TEST(RigImport, ProjectionMatrixLists) {
  const Camera c = camera("x");
  const Eigen::Matrix<double, 3, 4> P = c.projection_matrix();
  std::ostringstream text;
  text.precision(17);
  text << "# two cameras\n";
  for (int k = 0; k < 2; ++k) {
    for (int r = 0; r < 3; ++r)
      text << P(r, 0) << ", " << P(r, 1) << ", " << P(r, 2) << ", " << P(r, 3) << "\n";
  }
  Expected<Rig> rig = import_projection_matrices(write_temp("p2.txt", text.str()), 640, 480, "v");
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 2u);
  EXPECT_EQ(rig->cameras[1].id, "v1");
  EXPECT_LT((rig->cameras[1].projection_matrix() - P).cwiseAbs().maxCoeff(), 1e-9);

  const std::string dir = testing::TempDir();
  EXPECT_EQ(error_of(import_projection_matrices("/nonexistent/p.txt", 640, 480)),
            "/nonexistent/p.txt: cannot open file");
  EXPECT_EQ(
      error_of(import_projection_matrices(write_temp("p_empty.txt", "# nothing\n"), 640, 480)),
      dir + "/p_empty.txt: no projection matrices (empty file)");
  EXPECT_EQ(error_of(import_projection_matrices(write_temp("p11.txt", "1 0 0 0\n0 1 0 0\n0 0 1\n"),
                                                640, 480)),
            dir + "/p11.txt:3: expected 12 numbers per camera, got 11 numbers in total");
  EXPECT_EQ(error_of(import_projection_matrices(
                write_temp("pnan.txt", "1 0 0 0\n0 nan 0 0\n0 0 1 0\n"), 640, 480)),
            dir + "/pnan.txt:2: non-finite number 'nan'");
  EXPECT_EQ(error_of(import_projection_matrices(
                write_temp("pword.txt", "1 0 0 0\n0 1 0 0\n0 0 one 0\n"), 640, 480)),
            dir + "/pword.txt:3: expected a number, got 'one'");
  EXPECT_EQ(error_of(import_projection_matrices(
                write_temp("prank.txt", "1 0 0 0\n1 0 0 0\n0 0 1 0\n"), 640, 480)),
            dir +
                "/prank.txt:1: camera 0: P: left 3x3 block is rank-deficient (not a finite "
                "projective camera)");
}

TEST(RigImport, MiddleburyParFiles) {
  const std::string line = "view1.png 500 0 320 0 500 240 0 0 1 1 0 0 0 1 0 0 0 1 0.1 0.2 3\n";
  Expected<Rig> rig = import_middlebury(
      write_temp("ok_par.txt",
                 "2\n" + line + "view2.png 500 0 320 0 500 240 0 0 1 1 0 0 0 1 0 0 0 1 0 0 3\n"),
      640, 480);
  ASSERT_TRUE(rig) << rig.error().message;
  EXPECT_EQ(rig->cameras[0].id, "view1");
  EXPECT_EQ(rig->cameras[0].cam_from_world.translation, Eigen::Vector3d(0.1, 0.2, 3));

  const std::string dir = testing::TempDir();
  EXPECT_EQ(error_of(import_middlebury(write_temp("m0.txt", ""), 640, 480)),
            dir + "/m0.txt: empty file");
  EXPECT_EQ(error_of(import_middlebury(write_temp("m1.txt", "two\n" + line), 640, 480)),
            dir + "/m1.txt:1: expected the camera count on the first line");
  EXPECT_EQ(error_of(import_middlebury(write_temp("m2.txt", "2\n" + line), 640, 480)),
            dir + "/m2.txt:2: expected 2 cameras, got 1");
  EXPECT_EQ(error_of(import_middlebury(write_temp("m3.txt", "1\n" + line + line), 640, 480)),
            dir + "/m3.txt:3: more camera lines than the count 1");
  EXPECT_EQ(error_of(import_middlebury(write_temp("m4.txt", "1\nview1.png 500 0 320\n"), 640, 480)),
            dir + "/m4.txt:2: expected a name and 21 numbers, got 4 fields");
  EXPECT_EQ(
      error_of(import_middlebury(
          write_temp("m5.txt", "1\nview1.png 500 0 320 0 500 240 0 0 1 1 0 0 0 1 0 0 0 -1 0 0 3\n"),
          640, 480)),
      dir + "/m5.txt:2: R: not a rotation matrix (max |R^T R - I| = 0, det = -1)");
  EXPECT_EQ(error_of(import_middlebury(
                write_temp("m6.txt",
                           "1\nview1.png 500 0 320 0 500 240 0 0 1 1 0 0 0 1 0 0 0 1 0 inf 3\n"),
                640, 480)),
            dir + "/m6.txt:2: non-finite number 'inf'");
  EXPECT_EQ(error_of(import_middlebury(write_temp("m7.txt", "2\n" + line + line), 640, 480)),
            dir + "/m7.txt:3: duplicate camera 'view1'");
  EXPECT_EQ(error_of(import_middlebury("/nonexistent/x_par.txt", 640, 480)),
            "/nonexistent/x_par.txt: cannot open file");
}

}  // namespace
}  // namespace studio
