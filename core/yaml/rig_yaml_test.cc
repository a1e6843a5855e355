#include "yaml_io/rig_yaml.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace studio::yaml {
namespace {

const char* kGood = R"(units: metres
cameras:
  - id: cam0
    width: 704
    height: 576
    K: [700, 0, 352, 0, 700, 288, 0, 0, 1]
    radial: [-0.1, 0.01]
    cam_from_world: {R: [1, 0, 0, 0, 1, 0, 0, 0, 1], t: [0, 0, 4]}
  - id: cam1
    width: 704
    height: 576
    K: [700, 0, 352, 0, 700, 288, 0, 0, 1]
    cam_from_world: {R: [0, 0, -1, 0, 1, 0, 1, 0, 0], t: [0, -1, 4]}
projectors:
  - id: proj0
    width: 1920
    height: 1080
    K: [1500, 0, 960, 0, 1500, 540, 0, 0, 1]
    cam_from_world: {R: [1, 0, 0, 0, 1, 0, 0, 0, 1], t: [0, 0, 5]}
    screen: {corners: [[-2, 0, -1], [2, 0, -1], [2, 2.25, -1], [-2, 2.25, -1]]}
)";

// kGood with one substring replaced (the replacement must apply).
std::string with(const std::string& from, const std::string& to) {
  std::string s = kGood;
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

std::string error_of(const std::string& text) {
  Expected<Rig> rig = parse_rig(text, "rig.yaml");
  return rig ? std::string("<ok>") : rig.error().message;
}

Camera make_camera(const std::string& id, double angle, const Distortion& d) {
  Camera c;
  c.id = id;
  c.width = 704;
  c.height = 576;
  c.intrinsics = Intrinsics{712.3456789, 708.91, 351.123, 287.987, 0.4321};
  c.distortion = d;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.1 * angle + 0.05, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  c.cam_from_world = Rigid3(R, Eigen::Vector3d(0.1 * angle, -1.3, 4.0 + angle / 7));
  return c;
}

Rig make_rig() {
  Rig rig;
  rig.cameras.push_back(make_camera("cam0", 0.3, Distortion::radial(-0.123456789, 0.0123)));
  rig.cameras.push_back(
      make_camera("cam1", 1.7, Distortion::opencv(-0.2, 0.05, 1e-3, -2e-4, -0.01)));
  rig.cameras.push_back(make_camera("studio cam: \"left\"", -2.9, Distortion::none()));
  Projector p;
  p.camera = make_camera("proj0", 3.1, Distortion::none());
  p.camera.width = 1920;
  p.camera.height = 1080;
  p.screen = {Eigen::Vector3d(-2, 0, -1.1), Eigen::Vector3d(2, 0, -1.1),
              Eigen::Vector3d(2, 2.25, -1.1), Eigen::Vector3d(-2, 2.25, -1.1)};
  rig.projectors.push_back(p);
  return rig;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(RigYaml, ReadsTheDesignExample) {
  Expected<Rig> rig = parse_rig(kGood, "rig.yaml");
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 2u);
  ASSERT_EQ(rig->projectors.size(), 1u);
  const Camera* cam1 = rig->find_camera("cam1");
  ASSERT_NE(cam1, nullptr);
  EXPECT_NEAR((cam1->centre_in_world() - Eigen::Vector3d(-4, 1, 0)).norm(), 0, 1e-12);
  EXPECT_EQ(rig->cameras[0].distortion.model, Distortion::Model::radial);
  EXPECT_EQ(rig->cameras[0].distortion.rd3, -0.1);
  EXPECT_EQ(rig->projectors[0].screen[2], Eigen::Vector3d(2, 2.25, -1));
  EXPECT_EQ(rig->find_projector("proj0"), &rig->projectors[0]);
  EXPECT_EQ(rig->find_camera("proj0"), nullptr);
}

TEST(RigYaml, WriteReadRoundTripsExactly) {
  const Rig rig = make_rig();
  const std::string path = testing::TempDir() + "/rig_roundtrip.yaml";
  ASSERT_TRUE(write_rig(rig, path));
  Expected<Rig> back = read_rig(path);
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->cameras.size(), rig.cameras.size());
  ASSERT_EQ(back->projectors.size(), 1u);
  double worst_R = 0;
  std::vector<std::pair<const Camera*, const Camera*>> pairs;
  for (std::size_t i = 0; i < rig.cameras.size(); ++i)
    pairs.emplace_back(&rig.cameras[i], &back->cameras[i]);
  pairs.emplace_back(&rig.projectors[0].camera, &back->projectors[0].camera);
  for (auto [a, b] : pairs) {
    EXPECT_EQ(a->id, b->id);
    EXPECT_EQ(a->width, b->width);
    EXPECT_EQ(a->height, b->height);
    const Intrinsics &ka = a->intrinsics, &kb = b->intrinsics;
    EXPECT_TRUE(same_bits(ka.fx, kb.fx) && same_bits(ka.fy, kb.fy) && same_bits(ka.cx, kb.cx) &&
                same_bits(ka.cy, kb.cy) && same_bits(ka.skew, kb.skew));
    const Distortion &da = a->distortion, &db = b->distortion;
    EXPECT_EQ(da.model, db.model);
    EXPECT_TRUE(same_bits(da.rd3, db.rd3) && same_bits(da.rd5, db.rd5) && same_bits(da.k1, db.k1) &&
                same_bits(da.k2, db.k2) && same_bits(da.p1, db.p1) && same_bits(da.p2, db.p2) &&
                same_bits(da.k3, db.k3));
    for (int j = 0; j < 3; ++j) {
      EXPECT_TRUE(same_bits(a->cam_from_world.translation(j), b->cam_from_world.translation(j)));
    }
    worst_R =
        std::max(worst_R, (a->cam_from_world.R() - b->cam_from_world.R()).cwiseAbs().maxCoeff());
  }
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rig.projectors[0].screen[i], back->projectors[0].screen[i]);
  std::printf(
      "[ measured ] rig.yaml write->read: K, distortion, t, sizes, screen bit-exact; max |dR| = "
      "%.3g\n",
      worst_R);
  EXPECT_LT(worst_R, 1e-15);
  // Rigid3 keeps a quaternion, so R may move by an ulp per cycle; it does not drift.
  Rig cycled = *back;
  for (int cycle = 0; cycle < 10; ++cycle) {
    Expected<Rig> again = parse_rig(format_rig(cycled), "again.yaml");
    ASSERT_TRUE(again);
    cycled = *again;
  }
  double drift = 0;
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    drift =
        std::max(drift, (cycled.cameras[i].cam_from_world.R() - rig.cameras[i].cam_from_world.R())
                            .cwiseAbs()
                            .maxCoeff());
  }
  std::printf("[ measured ] after 10 more write/read cycles max |dR| = %.3g\n", drift);
  EXPECT_LT(drift, 1e-15);
}

TEST(RigYaml, CahvAndProjectionMatrixFormsDescribeTheSameCamera) {
  const Camera cam = make_camera("c", 0.8, Distortion::none());
  const Cahv cahv = to_cahv(cam);
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> P = -2.5 * cam.projection_matrix();
  auto vec = [](const double* v, int n) {
    std::string s = "[";
    for (int i = 0; i < n; ++i) s += (i ? ", " : "") + format_double(v[i]);
    return s + "]";
  };
  const std::string head = "cameras:\n  - id: c\n    width: 704\n    height: 576\n";
  const std::string cahv_text = head + "    cahv: {C: " + vec(cahv.C.data(), 3) +
                                ", A: " + vec(cahv.A.data(), 3) + ", H: " + vec(cahv.H.data(), 3) +
                                ", V: " + vec(cahv.V.data(), 3) + "}\n";
  const std::string p_text =
      head + "    P: " + vec(P.data(), 12) + "\n    opencv: [0.1, 0, 0, 0, 0]\n";
  Expected<Rig> a = parse_rig(cahv_text, "cahv.yaml");
  ASSERT_TRUE(a) << a.error().message;
  Expected<Rig> b = parse_rig(p_text, "p.yaml");
  ASSERT_TRUE(b) << b.error().message;
  const double ea =
      (a->cameras[0].projection_matrix() - cam.projection_matrix()).cwiseAbs().maxCoeff();
  const double eb =
      (b->cameras[0].projection_matrix() - cam.projection_matrix()).cwiseAbs().maxCoeff();
  std::printf("[ measured ] rig.yaml cahv form vs K form: %.3g; P form: %.3g (max |dP|)\n", ea, eb);
  EXPECT_LT(ea, 1e-9);
  EXPECT_LT(eb, 1e-9);
  EXPECT_EQ(b->cameras[0].distortion.model, Distortion::Model::opencv);
  EXPECT_EQ(
      error_of(cahv_text + "    cam_from_world: {R: [1, 0, 0, 0, 1, 0, 0, 0, 1], t: [0, 0, 0]}\n"),
      "rig.yaml:6: cameras[0].cam_from_world: not allowed with cahv (it already holds the pose)");
}

TEST(RigYaml, BadInputNamesFileLineAndField) {
  EXPECT_EQ(error_of(kGood), "<ok>");
  Expected<Rig> missing = read_rig("/nonexistent/rig.yaml");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "/nonexistent/rig.yaml: cannot open file");
  // not YAML / not a rig
  EXPECT_NE(error_of("cameras: [\n  - id: {\n").find("rig.yaml:"), std::string::npos);
  EXPECT_NE(error_of("cameras: [\n  - id: {\n").find("not valid YAML"), std::string::npos);
  EXPECT_EQ(error_of("%PDF-1.4 binary junk"), "rig.yaml: empty YAML document");
  EXPECT_EQ(error_of("just some text"), "rig.yaml:1: expected a mapping");
  EXPECT_EQ(error_of("cameras: 3\n"), "rig.yaml:1: cameras: expected a sequence");
  // wrong type
  EXPECT_EQ(error_of(with("width: 704", "width: wide")),
            "rig.yaml:4: cameras[0].width: expected an integer, got 'wide'");
  EXPECT_EQ(error_of(with("width: 704", "width: -704")),
            "rig.yaml:4: cameras[0].width: must be a positive pixel count, got -704");
  EXPECT_EQ(error_of(with("K: [700, 0, 352, 0, 700, 288, 0, 0, 1]", "K: {fx: 700}")),
            "rig.yaml:6: cameras[0].K: expected 9 numbers, got a mapping");
  EXPECT_EQ(error_of(with("K: [700, 0, 352, 0, 700, 288, 0, 0, 1]",
                          "K: [700, 0, 352, 0, 700, 288, 0, 0, one]")),
            "rig.yaml:6: cameras[0].K[8]: expected a number, got 'one'");
  // wrong length
  EXPECT_EQ(error_of(with("    K: [700, 0, 352, 0, 700, 288, 0, 0, 1]\n    cam",
                          "    K: [700, 0, 352, 0, 700, 288, 0, 0]\n    cam")),
            "rig.yaml:12: cameras[1].K: expected 9 numbers, got 8");
  EXPECT_EQ(error_of(with("radial: [-0.1, 0.01]", "radial: [-0.1]")),
            "rig.yaml:7: cameras[0].radial: expected 2 numbers, got 1");
  EXPECT_EQ(error_of(with("t: [0, 0, 4]", "t: [0, 0]")),
            "rig.yaml:8: cameras[0].cam_from_world.t: expected 3 numbers, got 2");
  EXPECT_EQ(error_of(with("[2, 2.25, -1], [-2, 2.25, -1]]", "[2, 2.25, -1]]")),
            "rig.yaml:20: projectors[0].screen.corners: expected 4 corners [x, y, z] (lower-left, "
            "lower-right, "
            "upper-right, upper-left), got 3");
  // unknown key
  EXPECT_EQ(error_of(with("    radial:", "    foo: 1\n    radial:")),
            "rig.yaml:7: cameras[0].foo: unknown key");
  EXPECT_EQ(error_of(with("units: metres", "units: metres\nrigs: []")),
            "rig.yaml:2: rigs: unknown key");
  EXPECT_EQ(error_of(with("t: [0, 0, 4]", "t: [0, 0, 4], q: [1, 0, 0, 0]")),
            "rig.yaml:8: cameras[0].cam_from_world.q: unknown key");
  // missing key
  EXPECT_EQ(error_of(with("    height: 576\n    K: [700, 0, 352, 0, 700, 288, 0, 0, 1]\n    radial",
                          "    K: [700, 0, 352, 0, 700, 288, 0, 0, 1]\n    radial")),
            "rig.yaml:3: cameras[0].height: missing required key");
  EXPECT_EQ(
      error_of(with(
          "    screen: {corners: [[-2, 0, -1], [2, 0, -1], [2, 2.25, -1], [-2, 2.25, -1]]}\n", "")),
      "rig.yaml:15: projectors[0].screen: missing required key");
  EXPECT_EQ(error_of(with("    K: [700, 0, 352, 0, 700, 288, 0, 0, 1]\n    radial", "    radial")),
            "rig.yaml:3: cameras[0]: expected one of K, cahv, P");
  EXPECT_EQ(
      error_of(with("    radial:", "    P: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0]\n    radial:")),
      "rig.yaml:3: cameras[0]: expected exactly one of K, cahv, P, got both K and P");
  // non-finite numbers
  EXPECT_EQ(error_of(with("K: [700, 0, 352,", "K: [.inf, 0, 352,")),
            "rig.yaml:6: cameras[0].K[0]: non-finite number '.inf'");
  EXPECT_EQ(error_of(with("t: [0, 0, 4]", "t: [0, .nan, 4]")),
            "rig.yaml:8: cameras[0].cam_from_world.t[1]: non-finite number '.nan'");
  // non-rotation R
  EXPECT_EQ(error_of(with("R: [0, 0, -1, 0, 1, 0, 1, 0, 0]", "R: [0, 0, 1, 0, 1, 0, 1, 0, 0]")),
            "rig.yaml:13: cameras[1].cam_from_world.R: not a rotation matrix (max |R^T R - I| = 0, "
            "det = -1)");
  EXPECT_EQ(error_of(with("R: [0, 0, -1, 0, 1, 0, 1, 0, 0]", "R: [0, 0, -1, 0, 1.1, 0, 1, 0, 0]")),
            "rig.yaml:13: cameras[1].cam_from_world.R: not a rotation matrix (max |R^T R - I| = "
            "0.21, det = 1.1)");
  // bad K, duplicate ids, units
  EXPECT_EQ(
      error_of(with("K: [700, 0, 352, 0, 700, 288, 0, 0, 1]",
                    "K: [700, 0, 352, 0, -700, 288, 0, 0, 1]")),
      "rig.yaml:6: cameras[0].K: camera matrix needs positive focal lengths, got fx 700, fy -700");
  EXPECT_EQ(error_of(with("K: [700, 0, 352, 0, 700, 288, 0, 0, 1]",
                          "K: [700, 0, 352, 3, 700, 288, 0, 0, 1]")),
            "rig.yaml:6: cameras[0].K: camera matrix is not upper triangular");
  EXPECT_EQ(error_of(with("id: cam1", "id: cam0")), "rig.yaml:1: cameras[1] (cam0): duplicate id");
  EXPECT_EQ(error_of(with("units: metres", "units: feet")),
            "rig.yaml:1: units: only metres are supported, got 'feet'");
  EXPECT_EQ(error_of(with("[2, 2.25, -1], [-2, 2.25, -1]]", "[2, 0, -1], [-2, 0, -1]]")),
            "rig.yaml:1: projectors[0] (proj0): screen: corners are degenerate (zero area)");
}

TEST(RigYaml, WriterRefusesAnInvalidRig) {
  Rig rig = make_rig();
  rig.cameras[1].id = "cam0";
  Expected<void> ok = write_rig(rig, testing::TempDir() + "/bad_rig.yaml");
  ASSERT_FALSE(ok);
  EXPECT_NE(ok.error().message.find("duplicate id"), std::string::npos);
  EXPECT_FALSE(write_rig(make_rig(), "/nonexistent/dir/rig.yaml"));
}

TEST(RigYaml, QuoteReadsBackVerbatim) {
  for (std::string id :
       {"cam0", "null", "true", "-x", "a: b", "tab\there", "quote\"back\\slash", "#x", "0"}) {
    Camera c = make_camera(id, 0.2, Distortion::none());
    Rig rig;
    rig.cameras.push_back(c);
    Expected<Rig> back = parse_rig(format_rig(rig), "q.yaml");
    ASSERT_TRUE(back) << id << ": " << back.error().message;
    EXPECT_EQ(back->cameras[0].id, id);
  }
}

}  // namespace
}  // namespace studio::yaml
