// The simulated actor: determinism, motions, containment in the acting area, true surface.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "sim/actor.h"

namespace studio::sim {
namespace {

Actor make(Motion m, uint64_t seed = 1) {
  Actor::Options o;
  o.motion = m;
  o.seed = seed;
  return Actor(o);
}

double top_of(const Part& p) {
  Eigen::Vector3d lo, hi;
  p.bounds(&lo, &hi);
  return hi.y();
}

TEST(SimActor, HasAllBodyPartsInOrder) {
  const ActorBody body = make(Motion::idle).body_at(0);
  ASSERT_EQ(body.parts.size(), static_cast<std::size_t>(PartId::count));
  for (int i = 0; i < static_cast<int>(PartId::count); ++i) {
    EXPECT_EQ(static_cast<int>(body.parts[i].id), i) << part_name(PartId(i));
  }
}

TEST(SimActor, DeterministicForSeedAndTime) {
  const Actor a = make(Motion::sequence, 7), b = make(Motion::sequence, 7), c = make(Motion::sequence, 8);
  bool differs = false;
  for (double t : {0.0, 1.3, 6.1, 9.7, 14.2, 33.3}) {
    const ActorBody ba = a.body_at(t), bb = b.body_at(t), bc = c.body_at(t);
    for (std::size_t i = 0; i < ba.parts.size(); ++i) {
      EXPECT_EQ(ba.parts[i].a, bb.parts[i].a);
      EXPECT_EQ(ba.parts[i].b, bb.parts[i].b);
      EXPECT_EQ(ba.parts[i].centre, bb.parts[i].centre);
      EXPECT_EQ(ba.parts[i].axes, bb.parts[i].axes);
      differs |= (ba.parts[i].centre - bc.parts[i].centre).norm() > 1e-3 ||
                 (ba.parts[i].a - bc.parts[i].a).norm() > 1e-3;
    }
  }
  EXPECT_TRUE(differs) << "another seed must give another actor or path";
}

TEST(SimActor, HeadCentreInsideHeadPart) {
  for (Motion m : {Motion::idle, Motion::walk, Motion::crouch, Motion::sequence}) {
    const Actor actor = make(m, 3);
    for (double t = 0; t < 16; t += 0.7) {
      const ActorBody body = actor.body_at(t);
      EXPECT_TRUE(body.part(PartId::head).inside(body.head_centre())) << motion_name(m) << " t=" << t;
      EXPECT_TRUE(body.inside(body.head_centre()));
      const double height = body.head_centre().y();
      EXPECT_GT(height, 0.8);
      EXPECT_LT(height, 1.9);
    }
  }
}

TEST(SimActor, RaisedHandRisesAboveTheHead) {
  const Actor actor = make(Motion::raise_hand, 2);
  const ActorBody rest = actor.body_at(0.0), raised = actor.body_at(1.8);
  const double head_top = std::max(top_of(raised.part(PartId::head)), top_of(raised.part(PartId::hair)));
  const double hand_top = top_of(raised.part(PartId::hand_r));
  EXPECT_GT(hand_top, head_top + 0.2) << "hand " << hand_top << " head " << head_top;
  EXPECT_LT(top_of(rest.part(PartId::hand_r)), rest.head_centre().y() - 0.5);
  // The other hand stays down.
  EXPECT_LT(top_of(raised.part(PartId::hand_l)), raised.head_centre().y() - 0.5);
}

TEST(SimActor, CrouchLowersTheHeadByMoreThan30cm) {
  const Actor actor = make(Motion::crouch, 4);
  const double standing = actor.body_at(0.0).head_centre().y();
  const double crouched = actor.body_at(1.8).head_centre().y();
  EXPECT_GT(standing - crouched, 0.3) << standing << " -> " << crouched;
  // Back up at the end of the cycle.
  EXPECT_NEAR(actor.body_at(3.95).head_centre().y(), standing, 0.03);
}

TEST(SimActor, WalksAtTheRequestedSpeedOnTheFloor) {
  const Actor actor = make(Motion::walk, 5);
  const Eigen::Vector2d p0 = actor.pose_at(1.0).root_xz, p1 = actor.pose_at(2.0).root_xz;
  // Chord of a 0.8 m circle for an arc of 0.9 m.
  const double arc = 0.9, r = 0.8;
  EXPECT_NEAR((p1 - p0).norm(), 2 * r * std::sin(arc / (2 * r)), 1e-6);
  for (double t = 0; t < 3; t += 0.05) {
    Eigen::Vector3d lo, hi;
    actor.body_at(t).bounds(&lo, &hi);
    EXPECT_NEAR(lo.y(), 0.0, 1e-9) << "the lowest point touches the floor";
  }
}

TEST(SimActor, StaysInsideTheActingArea) {
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    for (Motion m : {Motion::sequence, Motion::walk, Motion::turn, Motion::raise_hand, Motion::crouch}) {
      const Actor actor = make(m, seed);
      for (double t = 0; t < 40; t += 0.1) {
        Eigen::Vector3d lo, hi;
        actor.body_at(t).bounds(&lo, &hi);
        ASSERT_GE(lo.minCoeff(), -1.5) << motion_name(m) << " seed " << seed << " t " << t;
        ASSERT_LE(hi.x(), 1.5);
        ASSERT_LE(hi.z(), 1.5);
        ASSERT_LE(hi.y(), 3.0);
        ASSERT_GE(lo.y(), -1e-9);
      }
    }
  }
}

TEST(SimActor, SequenceIsContinuous) {
  const Actor actor = make(Motion::sequence, 9);
  const double dt = 0.01;
  ActorBody prev = actor.body_at(0);
  for (double t = dt; t < 33; t += dt) {
    const ActorBody body = actor.body_at(t);
    for (std::size_t i = 0; i < body.parts.size(); ++i) {
      const Eigen::Vector3d a = body.parts[i].shape == PartShape::capsule ? body.parts[i].b : body.parts[i].centre;
      const Eigen::Vector3d b = prev.parts[i].shape == PartShape::capsule ? prev.parts[i].b : prev.parts[i].centre;
      // 6 m/s is far above any limb speed of these motions; a jump would exceed it.
      ASSERT_LT((a - b).norm(), 6 * dt) << part_name(PartId(i)) << " at t=" << t;
    }
    prev = body;
  }
}

TEST(SimActor, SurfaceSamplesLieOnTheTrueSurface) {
  const ActorBody body = make(Motion::sequence, 11).body_at(10.0);
  const auto samples = body.surface_samples(3000, 5);
  ASSERT_EQ(samples.size(), 3000u);
  for (const Eigen::Vector3d& x : samples) {
    // Some part has x on its surface; x is inside the union but just outside along the normal.
    bool on_some = false;
    for (const Part& p : body.parts) {
      const Eigen::Vector3d n = p.normal(x);
      if (p.inside(x - 1e-6 * n) && !p.inside(x + 1e-6 * n)) {
        on_some = true;
        EXPECT_FALSE(body.inside(x + 1e-5 * n)) << "sample covered by another part";
        break;
      }
    }
    EXPECT_TRUE(on_some);
  }
  EXPECT_EQ(body.surface_samples(100, 5), body.surface_samples(100, 5));
}

TEST(SimActor, RayHitsTheSurfaceOfTheUnion) {
  const ActorBody body = make(Motion::sequence, 12).body_at(3.0);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uni(-1, 1);
  int hits = 0;
  for (int k = 0; k < 4000; ++k) {
    const Eigen::Vector3d origin(4 * uni(rng), 1 + uni(rng), 4 * uni(rng));
    Eigen::Vector3d target(0.9 * uni(rng), 0.9 + 0.9 * uni(rng), 0.9 * uni(rng));
    const Eigen::Vector3d dir = (target - origin).normalized();
    if (body.inside(origin)) continue;
    const auto hit = body.ray_hit(origin, dir);
    if (!hit) continue;
    ++hits;
    EXPECT_FALSE(body.inside(hit->point - 1e-7 * dir));
    EXPECT_TRUE(body.inside(hit->point + 1e-7 * dir));
    EXPECT_NEAR(hit->normal.norm(), 1.0, 1e-9);
    EXPECT_LT(hit->normal.dot(dir), 1e-9) << "the ray enters against the normal";
  }
  EXPECT_GT(hits, 300);
}

TEST(SimActor, MeshVerticesLieOnParts) {
  const ActorBody body = make(Motion::idle).body_at(0);
  const TriangleMesh mesh = body.mesh(12);
  ASSERT_FALSE(mesh.triangles.empty());
  for (const auto& tri : mesh.triangles) {
    for (uint32_t i : tri) ASSERT_LT(i, mesh.vertices.size());
  }
  // Every vertex is on the surface of some part (within float precision).
  for (const Eigen::Vector3f& v : mesh.vertices) {
    const Eigen::Vector3d x = v.cast<double>();
    bool on = false;
    for (const Part& p : body.parts) {
      const Eigen::Vector3d n = p.normal(x);
      on |= p.inside(x - 1e-5 * n) && !p.inside(x + 1e-5 * n);
    }
    ASSERT_TRUE(on);
  }
  // Outward winding: the signed volume of the closed mesh is positive.
  double volume = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6;
  }
  EXPECT_GT(volume, 0.03);
  EXPECT_LT(volume, 0.15);
}

TEST(SimActor, OptionsAndMotionNamesAreValidated) {
  Actor::Options o;
  o.walk_radius = 1.4;
  ASSERT_FALSE(o.validate());
  EXPECT_NE(o.validate().error().message.find("walk_radius"), std::string::npos);
  EXPECT_THROW(Actor{o}, std::invalid_argument);
  EXPECT_EQ(parse_motion("crouch").value(), Motion::crouch);
  EXPECT_FALSE(parse_motion("dance"));
}

}  // namespace
}  // namespace studio::sim
