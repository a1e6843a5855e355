// The mask's outline form (projector/mask_geometry.h grow_outline, GrowOptions::projector),
// checked against geometry computed here, independently of the library (ray casting):
// - conservative: for a 1280x720 projector at several places looking at the actor, every point
//   within the margin of the actor (a random surface point plus a random offset shorter than the
//   margin) that the projector images lies on a ray from its centre that meets the mask.
//   Controls: the ungrown mesh and (at 0.2 m) the outline of a quarter of the margin miss such rays (the
//   samples do probe the margin);
// - tight: seen from the viewpoint, the outline mask covers every ray that passes within the
//   margin of the surface (the ideal mask) and at most 1.3x as many; fewer than the vertex push
//   (grow_mask without a viewpoint) of the same margin on shapes with edges and corners (a hull
//   mesh's), within 25 % of it on a smooth sphere (the band's cell slack);
// - whole: the outline form grows the mesh as it is (a dense one too: tighter than from its
//   simplification), and its push fallback simplifies it first.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

#include "core/look_at.h"
#include "projector/mask_geometry.h"
#include "testing/shapes.h"

namespace studio::projector {
namespace {

using testing::box;
using testing::merge;
using testing::random_rotation;
using testing::sphere;

// Whether the ray from o along d meets any triangle of m (either side, t > 0; Moller-Trumbore).
bool hits(const ActorMesh& m, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[t[0]].cast<double>();
    const Eigen::Vector3d e1 = m.vertices[t[1]].cast<double>() - a;
    const Eigen::Vector3d e2 = m.vertices[t[2]].cast<double>() - a;
    const Eigen::Vector3d p = d.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-15) continue;
    const Eigen::Vector3d s = o - a;
    const double u = s.dot(p) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    if (e2.dot(q) / det > 0) return true;
  }
  return false;
}

// Distance from the ray (o, unit d) to the segment ab (sampled finely: the test's own reference).
double ray_to_point(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& p) {
  const double t = std::max(0.0, d.dot(p - o));
  return (o + t * d - p).norm();
}

// A random point on the surface (triangles by area).
struct SurfaceSampler {
  explicit SurfaceSampler(const ActorMesh& m) : mesh(m) {
    double total = 0;
    for (const auto& t : m.triangles) {
      const Eigen::Vector3d a = m.vertices[t[0]].cast<double>();
      total += 0.5 * (m.vertices[t[1]].cast<double>() - a)
                         .cross(m.vertices[t[2]].cast<double>() - a)
                         .norm();
      cumulative.push_back(total);
    }
  }
  Eigen::Vector3d operator()(std::mt19937& rng) const {
    std::uniform_real_distribution<double> u(0, 1);
    const double x = u(rng) * cumulative.back();
    const size_t k = std::lower_bound(cumulative.begin(), cumulative.end(), x) - cumulative.begin();
    const auto& t = mesh.triangles[std::min(k, mesh.triangles.size() - 1)];
    double r1 = u(rng), r2 = u(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    return a + r1 * (mesh.vertices[t[1]].cast<double>() - a) +
           r2 * (mesh.vertices[t[2]].cast<double>() - a);
  }
  const ActorMesh& mesh;
  std::vector<double> cumulative;
};

struct Case {
  const char* name;
  ActorMesh mesh;
};

std::vector<Case> cases() {
  std::mt19937 rng(5);
  std::vector<Case> c;
  c.push_back({"box", box({0, 1, 0}, {0.2, 0.3, 0.1}, 6)});
  c.push_back({"sphere", sphere({0, 1.2, 0}, 0.3, random_rotation(rng), 16, 32)});
  c.push_back({"torso and hand", merge(box({-0.05, 1.2, 0}, {0.17, 0.3, 0.1}, 12),
                                       sphere({0.45, 1.0, 0.2}, 0.06, random_rotation(rng), 16, 32))});
  return c;
}

const std::vector<Eigen::Vector3d> kViewpoints = {
    {0, 1.6, 4.0}, {3.0, 2.5, 2.0}, {-2.5, 0.8, -3.0}, {0.3, 4.0, 1.5}};

// A 1280x720 projector at `eye` looking at `target`, aimed off-centre (the actor near a corner
// of its image: the pinhole's stretch there).
Camera projector_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  Camera c;
  c.width = 1280;
  c.height = 720;
  c.intrinsics = {1100, 1080, 639.5 + 300, 359.5 - 120, 0};
  c.cam_from_world = look_at(eye, target);
  return c;
}

Eigen::Vector3d centre_of(const ActorMesh& m) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& v : m.vertices) c += v.cast<double>();
  return c / double(m.vertices.size());
}

TEST(MaskOutline, EveryRayWithinTheMarginOfTheActorMeetsTheMask) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  for (const Case& c : cases()) {
    const SurfaceSampler sample(c.mesh);
    for (double margin : {0.02, 0.2}) {
      for (const Eigen::Vector3d& eye : kViewpoints) {
        const Camera cam = projector_at(eye, centre_of(c.mesh));
        auto mask = grow_outline(c.mesh, margin, cam);
        ASSERT_TRUE(mask) << mask.error().message;
        auto quarter = grow_outline(c.mesh, margin / 4, cam);
        ASSERT_TRUE(quarter);
        int missed = 0, bare_missed = 0, quarter_missed = 0;
        for (int k = 0; k < 600; ++k) {
          const Eigen::Vector3d w = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
          // Offsets mostly near the margin's edge, where a thin band would fail first.
          const Eigen::Vector3d q = sample(rng) + 0.999 * margin * std::cbrt(u(rng)) * w;
          Eigen::Vector2d pixel;
          if (!cam.project(q, &pixel) || !cam.in_image(pixel)) continue;  // not its business
          const Eigen::Vector3d d = (q - eye).normalized();
          missed += !hits(*mask, eye, d);
          bare_missed += !hits(c.mesh, eye, d);
          quarter_missed += !hits(*quarter, eye, d);
        }
        EXPECT_EQ(missed, 0) << c.name << " margin " << margin << " eye " << eye.transpose();
        EXPECT_GT(bare_missed, 0) << c.name << " margin " << margin;
        // (At 2 cm the band's cell slack, ~5 px, is most of a quarter margin.)
        if (margin > 0.1) {
          EXPECT_GT(quarter_missed, 0) << c.name << " margin " << margin;
        }
      }
    }
  }
}

TEST(MaskOutline, CoversLessThanTheVertexPushAndCloseToTheIdealMask) {
  for (const Case& c : cases()) {
    for (double margin : {0.05, 0.2}) {
      const Eigen::Vector3d eye = kViewpoints[1];
      const Eigen::Vector3d centre = centre_of(c.mesh);
      Camera cam = projector_at(eye, centre);
      cam.intrinsics.cx = 639.5;  // the actor in the middle of the image: nothing clipped
      cam.intrinsics.cy = 359.5;
      auto outline = grow_outline(c.mesh, margin, cam);
      auto push = grow_mask(MaskBase{c.mesh, 0, {}}, margin);
      ASSERT_TRUE(outline && push);
      // Rays on an angular grid round the mesh's centre, wide enough for the push's spikes.
      const Eigen::Vector3d z = (centre - eye).normalized(), x = z.unitOrthogonal(),
                            y = z.cross(x);
      const double half_angle = std::atan(1.6 / (centre - eye).norm());
      const int n = 60;
      int in_outline = 0, in_push = 0, in_ideal = 0, ideal_not_outline = 0;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const double a = half_angle * (2.0 * (i + 0.5) / n - 1),
                       b = half_angle * (2.0 * (j + 0.5) / n - 1);
          const Eigen::Vector3d d = (z + std::tan(a) * x + std::tan(b) * y).normalized();
          Eigen::Vector2d pixel;
          if (!cam.project(eye + d, &pixel) || !cam.in_image(pixel)) continue;
          const bool o = hits(*outline, eye, d), p = hits(*push, eye, d);
          // Ideal: the ray passes within the margin of the surface (of a vertex, or crosses it).
          bool ideal = hits(c.mesh, eye, d);
          for (size_t v = 0; !ideal && v < c.mesh.vertices.size(); ++v)
            ideal = ray_to_point(eye, d, c.mesh.vertices[v].cast<double>()) < margin;
          in_outline += o;
          in_push += p;
          in_ideal += ideal;
          ideal_not_outline += ideal && !o;
        }
      std::printf("%-15s margin %.2f m: rays covered: outline %d, vertex push %d, ideal %d\n",
                  c.name, margin, in_outline, in_push, in_ideal);
      EXPECT_EQ(ideal_not_outline, 0) << c.name;
      // Edges and corners (a hull mesh's facets, a box): the push's spikes cover more. A smooth
      // sphere: the push is near the ideal and the outline's band (the nearest point's angle
      // everywhere, a pinhole's stretch bound, ~2 cells of raster slack) a little wider.
      if (std::string(c.name) == "sphere")
        EXPECT_LE(in_outline, 1.25 * in_push) << c.name;
      else
        EXPECT_LT(in_outline, in_push) << c.name;
      EXPECT_LE(in_outline, 1.3 * in_ideal + 20) << c.name;
    }
  }
}

TEST(MaskOutline, RefusesWhatItCannotMaskAndGrowMaskFallsBackToThePush) {
  const ActorMesh b = box({0, 1, 0}, {0.2, 0.3, 0.1}, 2);
  const Camera cam = projector_at({0, 1, 3}, {0, 1, 0});
  EXPECT_TRUE(grow_outline(b, 0.1, cam));  // positive control
  EXPECT_FALSE(grow_outline(b, -0.1, cam));
  EXPECT_FALSE(grow_outline(ActorMesh{}, 0.1, cam));
  Camera no_size = cam;
  no_size.width = 0;
  EXPECT_FALSE(grow_outline(b, 0.1, no_size));
  // A vertex behind the projector, or the projector within the margin: refused by the outline,
  // and grow_mask() then gives the vertex push, never no mask.
  const Camera inside = projector_at({0, 1, 0.15}, {0, 1, -1});
  EXPECT_FALSE(grow_outline(b, 0.1, inside));
  GrowOptions o;
  o.projector = inside;
  auto fallback = grow_mask(MaskBase{b, 0, {}}, 0.1, o);
  ASSERT_TRUE(fallback);
  auto push = grow_mask(MaskBase{b, 0, {}}, 0.1);
  ASSERT_TRUE(push);
  EXPECT_EQ(fallback->vertices, push->vertices);
  // A mesh the projector does not image: an empty mask.
  const Camera away = projector_at({0, 1, 3}, {0, 1, 6});
  auto none = grow_outline(box({0, 1, 0}, {0.2, 0.3, 0.1}, 2), 0.05, away);
  EXPECT_FALSE(none);  // behind its near plane
}

TEST(MaskOutline, GrowsTheWholeMeshAndTheFallbackPushSimplifiesIt) {
  // A hull-like dense mesh: the outline form keeps every triangle (no simplifier error in the
  // margin), so its mask is tighter than the outline of the simplified mesh and still covers
  // every ray within the margin; simplify_outline restores the simplification.
  const ActorMesh dense = sphere({0, 1.2, 0}, 0.3, Eigen::Matrix3d::Identity(), 72, 144);
  ASSERT_GT(dense.triangles.size(), 4 * GrowOptions{}.max_triangles);
  const Eigen::Vector3d eye = kViewpoints[0];
  Camera cam = projector_at(eye, {0, 1.2, 0});
  cam.intrinsics.cx = 639.5;
  cam.intrinsics.cy = 359.5;
  GrowOptions whole, simplified;
  whole.projector = simplified.projector = cam;
  simplified.simplify_outline = true;
  auto a = simplify_for_mask(dense, whole);
  auto b = simplify_for_mask(dense, simplified);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->mesh.triangles, dense.triangles);
  EXPECT_EQ(a->mesh.vertices, dense.vertices);
  EXPECT_EQ(a->error_m, 0);
  EXPECT_LE(b->mesh.triangles.size(), GrowOptions{}.max_triangles);
  EXPECT_GT(b->error_m, 0);
  const double margin = 0.03;
  auto mask_whole = grow_mask(*a, margin, whole);
  auto mask_simplified = grow_mask(*b, margin, simplified);
  ASSERT_TRUE(mask_whole && mask_simplified);
  const Eigen::Vector3d z = (Eigen::Vector3d(0, 1.2, 0) - eye).normalized(),
                        x = z.unitOrthogonal(), y = z.cross(x);
  const double half_angle = std::atan(0.45 / (Eigen::Vector3d(0, 1.2, 0) - eye).norm());
  const int n = 40;
  int in_whole = 0, in_simplified = 0, ideal_missed = 0, ideal = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d d = (z + std::tan(half_angle * (2.0 * (i + 0.5) / n - 1)) * x +
                                 std::tan(half_angle * (2.0 * (j + 0.5) / n - 1)) * y)
                                    .normalized();
      const bool w = hits(*mask_whole, eye, d);
      in_whole += w;
      in_simplified += hits(*mask_simplified, eye, d);
      // The sphere grown by the margin, exactly: the ray passes within 0.33 m of the centre.
      if (ray_to_point(eye, d, {0, 1.2, 0}) < 0.3 + margin) {
        ++ideal;
        ideal_missed += !w;
      }
    }
  std::printf("rays covered: whole mesh %d, simplified %d, ideal %d\n", in_whole, in_simplified,
              ideal);
  EXPECT_EQ(ideal_missed, 0);
  EXPECT_LT(in_whole, in_simplified);
  // A mesh above outline_max_triangles is clustered to about that many, its error in the margin:
  // it still covers every ray of the grown sphere.
  GrowOptions bounded = whole;
  bounded.outline_max_triangles = 5000;
  auto clustered = simplify_for_mask(dense, bounded);
  ASSERT_TRUE(clustered);
  EXPECT_LE(clustered->mesh.triangles.size(), 5000u);
  EXPECT_GT(clustered->error_m, 0);
  auto mask_clustered = grow_mask(*clustered, margin, bounded);
  ASSERT_TRUE(mask_clustered);
  int clustered_missed = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d d = (z + std::tan(half_angle * (2.0 * (i + 0.5) / n - 1)) * x +
                                 std::tan(half_angle * (2.0 * (j + 0.5) / n - 1)) * y)
                                    .normalized();
      if (ray_to_point(eye, d, {0, 1.2, 0}) < 0.3 + margin)
        clustered_missed += !hits(*mask_clustered, eye, d);
    }
  EXPECT_EQ(clustered_missed, 0);
  // Where the outline cannot be made (the projector inside the margin), the push falls back to
  // the simplified mesh, exactly as grow_mask() without a projector would draw it.
  const Camera inside = projector_at({0, 1.2, 0.32}, {0, 1.2, -1});
  GrowOptions fallback = whole;
  fallback.projector = inside;
  auto c = simplify_for_mask(dense, fallback);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->mesh.triangles.size(), dense.triangles.size());
  auto pushed = grow_mask(*c, 0.05, fallback);
  auto reference = grow_mesh(dense, 0.05);
  ASSERT_TRUE(pushed && reference);
  EXPECT_LE(pushed->triangles.size(), GrowOptions{}.max_triangles);
  EXPECT_EQ(pushed->vertices, reference->vertices);
  EXPECT_EQ(pushed->triangles, reference->triangles);
}

}  // namespace
}  // namespace studio::projector
