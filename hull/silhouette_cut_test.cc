#include "hull/silhouette_cut.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "support/cameras.h"
#include "testing/synthetic.h"

namespace studio::hull {
namespace {

using testing::Scene;

struct Rig {
  std::vector<Camera> cameras;
  std::vector<RunMask> masks;
  std::vector<View> views() const {
    std::vector<View> v;
    for (std::size_t k = 0; k < cameras.size(); ++k) v.push_back({&cameras[k], &masks[k]});
    return v;
  }
};

// Distant cameras on the +x, +y, +z axes looking at the origin: nearly orthographic views.
Rig axis_rig(const Scene& scene, double r, std::initializer_list<int> axes) {
  Rig rig;
  const double D = 200, f = 450 * D / r;
  for (int a : axes) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    c[a] = D;
    const Eigen::Vector3d up = a == 1 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    rig.cameras.push_back(support::look_at_camera("axis" + std::to_string(a), c, Eigen::Vector3d::Zero(),
                                           up, 1000, 1000, f));
  }
  for (const Camera& c : rig.cameras) rig.masks.push_back(testing::render_mask(c, scene));
  return rig;
}

// The benchmark's scene: the synthetic actor seen by 8 cameras 704x576 on a 4 m ring.
Rig actor_ring() {
  Rig rig;
  rig.cameras = support::camera_ring(8, 704, 576, 4.0, 1.6, {0, 1, 0}, 600);
  const Scene s = testing::actor();
  for (const Camera& c : rig.cameras) rig.masks.push_back(testing::render_mask(c, s));
  return rig;
}

// 128x128 columns along y over the actor's 2 m box.
GridSpec actor_grid() {
  GridSpec g;
  g.box_min = {-1, 0, -1};
  g.box_max = {1, 2, 1};
  g.cells_u = g.cells_v = 128;
  return g;
}

GridSpec cube_grid(double half, int n, Axis axis = Axis::y) {
  GridSpec g;
  g.box_min = Eigen::Vector3d::Constant(-half);
  g.box_max = Eigen::Vector3d::Constant(half);
  g.axis = axis;
  g.cells_u = g.cells_v = n;
  return g;
}

TEST(SilhouetteCut, SphereFromThreeAxisViewsIsTheTricylinder) {
  const double r = 0.5;
  Scene s;
  s.ellipsoids.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(r)});
  const Rig rig = axis_rig(s, r, {0, 1, 2});
  const double expected = 8 * (2 - std::sqrt(2.0)) * r * r * r;
  for (Axis axis : {Axis::x, Axis::y, Axis::z}) {
    for (bool pencil : {true, false}) {
      CutOptions o;
      o.allow_pencil = pencil;
      auto hull = visual_hull(cube_grid(0.55, 200, axis), rig.views(), o);
      ASSERT_TRUE(hull) << hull.error().message;
      EXPECT_TRUE(hull->valid());
      EXPECT_NEAR(hull->volume() / expected, 1.0, 0.01)
          << "axis " << axis_name(axis) << " pencil " << pencil;
    }
  }
}

TEST(SilhouetteCut, SphereFromTwoViewsIsTheBicylinder) {
  const double r = 0.5;
  Scene s;
  s.ellipsoids.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(r)});
  const Rig rig = axis_rig(s, r, {0, 2});
  auto hull = visual_hull(cube_grid(0.55, 200), rig.views());
  ASSERT_TRUE(hull);
  EXPECT_NEAR(hull->volume() / (16.0 / 3.0 * r * r * r), 1.0, 0.01);
}

TEST(SilhouetteCut, CubeGivesTheCube) {
  Scene s;
  s.boxes.push_back({Eigen::Vector3d::Constant(-0.4), Eigen::Vector3d::Constant(0.4)});
  const Rig rig = axis_rig(s, 0.5, {0, 1, 2});
  auto hull = visual_hull(cube_grid(0.55, 110), rig.views());
  ASSERT_TRUE(hull);
  EXPECT_NEAR(hull->volume() / (0.8 * 0.8 * 0.8), 1.0, 0.01);
  EXPECT_TRUE(hull->contains({0.39, 0.39, 0.39}));
  EXPECT_FALSE(hull->contains({0.45, 0, 0}));
  EXPECT_FALSE(hull->contains({0, 0.45, 0}));
}

// Random studio scenes: the hull contains the object (every true surface point inside or
// within one cell), and adding a view never grows the volume.
TEST(SilhouetteCut, RandomScenesContainTheObjectAndViewsOnlyShrink) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.6, 0.6), R(0.08, 0.3);
  for (int trial = 0; trial < 4; ++trial) {
    Scene s;
    for (int k = 0; k < 4; ++k) {
      s.ellipsoids.push_back(
          {Eigen::Vector3d(U(rng), 1.0 + U(rng), U(rng)), Eigen::Vector3d(R(rng), R(rng), R(rng))});
    }
    s.boxes.push_back({Eigen::Vector3d(U(rng), 0.2, U(rng)), Eigen::Vector3d::Zero()});
    s.boxes.back().max = s.boxes.back().min + Eigen::Vector3d(0.2, 0.3, 0.15);
    const Distortion dist = trial % 2 ? Distortion::radial(-0.08, 0.01) : Distortion::none();
    auto cams = support::camera_ring(6, 352, 288, 3.5, 1.0 + 0.3 * trial, {0, 1, 0}, 300, dist);
    GridSpec g;
    g.box_min = {-1.2, -0.1, -1.2};
    g.box_max = {1.2, 2.2, 1.2};
    g.cells_u = g.cells_v = 96;
    std::vector<RunMask> masks;
    for (const Camera& c : cams) masks.push_back(testing::render_mask(c, s));
    std::vector<View> views;
    double previous = SegmentSet::full(g).volume();
    SegmentSet hull = SegmentSet::full(g);
    CutOptions one_at_a_time;  // one view per call: what it does not see stays for the next
    one_at_a_time.min_views = 0;
    for (std::size_t k = 0; k < cams.size(); ++k) {
      ASSERT_TRUE(cut(hull,
                      std::span<const View>(&views.emplace_back(View{&cams[k], &masks[k]}), 1),
                      one_at_a_time));
      EXPECT_LE(hull.volume(), previous + 1e-12) << "view " << k;
      previous = hull.volume();
    }
    EXPECT_TRUE(hull.valid());
    const Eigen::Vector3d cell(g.du(), 0.0, g.dv());
    int missed = 0, total = 0;
    for (const Eigen::Vector3d& p : s.surface_samples(400, rng)) {
      bool found = false;
      for (int a = -1; a <= 1 && !found; ++a)
        for (int b = -1; b <= 1 && !found; ++b)
          for (int c = -1; c <= 1 && !found; ++c)
            found = hull.contains(
                p + Eigen::Vector3d(a * g.dv() * 0.999, b * g.du() * 0.999, c * g.du() * 0.999));
      missed += !found;
      ++total;
    }
    EXPECT_EQ(missed, 0) << "of " << total << " surface points, trial " << trial;
    // The hull is tight, not the whole box.
    EXPECT_LT(hull.volume(), 3 * s.volume_estimate(g.box_min, g.box_max, 60));
  }
}

TEST(SilhouetteCut, PencilAndRowWalkerAgree) {
  const Rig rig = actor_ring();
  const auto& cams = rig.cameras;
  const auto& masks = rig.masks;
  const std::vector<View> views = rig.views();
  const GridSpec g = actor_grid();
  CutOptions fast, exact;
  exact.allow_pencil = false;
  fast.threads = 2;
  auto a = visual_hull(g, views, fast);
  auto b = visual_hull(g, views, exact);
  ASSERT_TRUE(a && b);
  EXPECT_NEAR(a->volume() / b->volume(), 1.0, 0.01);
  auto p = PreparedView::create(cams[0], masks[0], Eigen::Vector4d(0, 1, 0, 0), fast);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->uses_pencil());
  // Same result with one thread.
  fast.threads = 1;
  auto c = visual_hull(g, views, fast);
  EXPECT_EQ(*a, *c);
}

// The grid fast path of cut() (bin and run ends affine in the column index, row spans of the
// occupied bins) against PreparedView::cut_line on every column, view after view: the same
// intervals up to float rounding, except where a column's pencil coordinate lies on a bin border
// and the two roundings pick neighbouring half-pixel bins.
TEST(SilhouetteCut, GridFastPathMatchesPerLineCut) {
  const Rig rig = actor_ring();
  const std::vector<View> views = rig.views();
  const GridSpec g = actor_grid();
  auto fast = visual_hull(g, views);
  ASSERT_TRUE(fast);
  const Eigen::AlignedBox3d domain(g.box_min, g.box_max);
  std::vector<PreparedView> prepared;
  for (const View& v : views) {
    auto p = PreparedView::create(*v.camera, *v.mask, Eigen::Vector4d(0, 1, 0, 0), CutOptions{},
                                  &domain);
    ASSERT_TRUE(p);
    ASSERT_TRUE(p->uses_pencil() && p->domain_inside_image());
    prepared.push_back(std::move(*p));
  }
  const Eigen::Vector3d d(0, 1, 0);
  CutScratch scratch;
  int nonempty = 0, differ = 0;
  for (int j = 0; j < g.cells_v; ++j)
    for (int i = 0; i < g.cells_u; ++i) {
      std::vector<Interval> cur{{float(g.t_min()), float(g.t_max())}}, next;
      const Eigen::Vector3d o = g.point(i, j, 0);
      for (const PreparedView& p : prepared) {
        next.clear();
        if (!cur.empty()) p.cut_line(o, d, cur, &next, &scratch);
        std::swap(cur, next);
      }
      const auto got = fast->column(i, j);
      nonempty += !cur.empty() || !got.empty();
      bool same = got.size() == cur.size();
      for (std::size_t k = 0; same && k < cur.size(); ++k) {
        same = std::abs(got[k].lo - cur[k].lo) <= 1e-5f && std::abs(got[k].hi - cur[k].hi) <= 1e-5f;
      }
      differ += !same;
    }
  EXPECT_GT(nonempty, 500);
  EXPECT_LE(differ, nonempty / 100) << differ << " of " << nonempty << " columns differ";
}

// The visibility policy's two extremes with one camera: min_views 0 keeps what it does not see,
// min_views all (= 1 here) cuts it.
TEST(SilhouetteCut, OutsideImageKeptOrCut) {
  Scene s;
  s.ellipsoids.push_back({Eigen::Vector3d(0, 1, 0), Eigen::Vector3d::Constant(0.3)});
  // A camera close enough that the top and bottom of the box leave its image.
  Camera cam =
      support::look_at_camera("c", {0, 1, 2.0}, {0, 1, 0}, Eigen::Vector3d::UnitY(), 320, 240, 300);
  RunMask mask = testing::render_mask(cam, s);
  View v{&cam, &mask};
  GridSpec g;
  g.box_min = {-0.5, -1, -0.5};
  g.box_max = {0.5, 3, 0.5};
  g.cells_u = g.cells_v = 40;
  CutOptions keep, drop;
  keep.min_views = 0;
  drop.min_views = kAllViews;
  auto a = visual_hull(g, std::span<const View>(&v, 1), keep);
  auto b = visual_hull(g, std::span<const View>(&v, 1), drop);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->contains({0, -0.9, 0}));   // below the image: kept
  EXPECT_FALSE(b->contains({0, -0.9, 0}));  // ... or cut
  EXPECT_TRUE(b->contains({0, 1, 0}));
  EXPECT_GT(a->volume(), b->volume());
}

TEST(SilhouetteCut, RejectsMaskOfWrongSize) {
  Camera cam =
      support::look_at_camera("cam3", {0, 1, 4}, {0, 1, 0}, Eigen::Vector3d::UnitY(), 320, 240, 300);
  RunMask mask(100, 100);
  mask.finish();
  View v{&cam, &mask};
  GridSpec g;
  auto r = visual_hull(g, std::span<const View>(&v, 1));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("cam3"), std::string::npos);
}

TEST(SilhouetteCut, TwoActorsAreTwoComponents) {
  Scene s = testing::actor(-0.7, 0);
  Scene other = testing::actor(0.7, 0.2);
  s.ellipsoids.insert(s.ellipsoids.end(), other.ellipsoids.begin(), other.ellipsoids.end());
  auto cams = support::camera_ring(8, 704, 576, 4.0, 2.2, {0, 1, 0}, 500);
  std::vector<RunMask> masks;
  std::vector<View> views;
  for (const Camera& c : cams) masks.push_back(testing::render_mask(c, s));
  for (std::size_t k = 0; k < cams.size(); ++k) views.push_back({&cams[k], &masks[k]});
  GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2, 1.5};
  g.cells_u = g.cells_v = 128;
  auto hull = visual_hull(g, views);
  ASSERT_TRUE(hull);
  const auto all = connected_components(*hull);
  std::string sizes;
  for (const auto& p : all) sizes += std::to_string(p.volume()) + " ";
  // Two actors seen by 8 cameras leave small phantom volumes (a visual-hull property, ~3 L
  // here); a 10 L threshold keeps the actors.
  const auto parts = connected_components(*hull, 0.01);
  ASSERT_EQ(parts.size(), 2u) << sizes;
  EXPECT_GT(parts[1].volume(), 0.05);
  EXPECT_NEAR(parts[0].volume() + parts[1].volume(), hull->volume(), 0.01);
  EXPECT_NE(parts[0].contains({-0.7, 1.25, 0}), parts[1].contains({-0.7, 1.25, 0}));
}

}  // namespace
}  // namespace studio::hull
