#include "scene_testing/random_commands.h"

#include <cmath>
#include <iterator>

namespace studio::scene::testing {

NodeId RandomCommandSource::some_node(const Scene& scene, bool allow_unknown) {
  const auto& nodes = scene.nodes();
  if (nodes.empty() || (allow_unknown && rng_() % 12 == 0)) return "ghost" + std::to_string(rng_() % 5);
  auto it = nodes.begin();
  std::advance(it, static_cast<long>(rng_() % nodes.size()));
  return it->first;
}

std::string RandomCommandSource::some_animation(const Scene& scene) {
  const auto& anims = scene.animations();
  const auto r = rng_() % 10;
  if (r == 0) return "";                        // all
  if (r == 1 || anims.empty()) return "nosuch";  // unknown
  auto it = anims.begin();
  std::advance(it, static_cast<long>(rng_() % anims.size()));
  return it->first;
}

Transform RandomCommandSource::some_transform(bool allow_bad) {
  std::uniform_real_distribution<double> u(-3, 3);
  Transform t;
  t.translation = {u(rng_), u(rng_), u(rng_)};
  t.rotation = Eigen::Quaterniond(u(rng_), u(rng_), u(rng_), u(rng_) + 0.1);
  t.scale = Eigen::Vector3d::Constant(0.5 + std::abs(u(rng_)));
  if (allow_bad && rng_() % 10 == 0) {
    switch (rng_() % 4) {
      case 0: t.translation.y() = NAN; break;
      case 1: t.rotation.coeffs().setZero(); break;
      case 2: t.scale.x() = 0; break;
      default: t.translation.x() = INFINITY; break;
    }
  }
  return t;
}

Node RandomCommandSource::some_node_to_add(const Scene& scene) {
  Node n;
  n.id = rng_() % 15 == 0 ? some_node(scene, false) : "n" + std::to_string(serial_++);
  if (rng_() % 20 == 0) n.id = "";
  n.parent = rng_() % 3 == 0 ? "" : some_node(scene);
  n.local = some_transform(true);
  switch (rng_() % 4) {
    case 0: n.kind = NodeKind::group; break;
    case 1:
      n.kind = NodeKind::model;
      n.asset = {rng_() % 10 ? "set.glb" : "", "00ff", {static_cast<std::uint32_t>(rng_() % 4)}};
      n.material.colour = {0.1f, 0.5f, 0.9f, 1.0f};
      break;
    case 2:
      n.kind = NodeKind::light;
      n.light.intensity = rng_() % 10 ? 5.0f : -1.0f;
      break;
    default:
      n.kind = NodeKind::actor;
      n.actor_id = "actor0";
  }
  return n;
}

Animation RandomCommandSource::some_animation_to_add(const Scene& scene) {
  Animation a;
  a.name = rng_() % 8 == 0 ? some_animation(scene) : "a" + std::to_string(serial_++);
  a.mode = static_cast<PlayMode>(rng_() % 3);
  const int tracks = 1 + static_cast<int>(rng_() % 3);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int k = 0; k < tracks; ++k) {
    Track t;
    t.node = some_node(scene);
    t.path = static_cast<TrackPath>(rng_() % 3);
    t.interpolation = static_cast<Interpolation>(rng_() % 2);
    const int keys = 1 + static_cast<int>(rng_() % 5);
    double time = 0;
    for (int j = 0; j < keys; ++j) {
      t.times.push_back(time);
      time += 0.1 + std::abs(u(rng_));
      Eigen::Vector4d v(u(rng_), u(rng_), u(rng_), u(rng_));
      if (t.path == TrackPath::scale) v.head<3>() = v.head<3>().cwiseAbs().array() + 0.2;
      if (t.path == TrackPath::rotation) v[3] += 0.1 * (v[3] >= 0 ? 1 : -1);
      t.values.push_back(v);
    }
    if (rng_() % 15 == 0) t.times.back() = -1;  // unsorted / negative: refused
    a.tracks.push_back(t);
  }
  return a;
}

Command RandomCommandSource::make(const Scene& scene, int depth) {
  Command c;
  frame_ += static_cast<std::int64_t>(rng_() % 3);
  c.frame = rng_() % 200 == 0 ? -1 : frame_;
  std::uniform_real_distribution<double> u(-3, 3);
  const auto pick = rng_() % 100;
  if (pick < 22) {
    c.op = AddNode{some_node_to_add(scene)};
  } else if (pick < 27) {
    c.op = RemoveNode{some_node(scene)};
  } else if (pick < 42) {
    c.op = SetTransform{some_node(scene), some_transform(true)};
  } else if (pick < 50) {
    c.op = SetParent{some_node(scene), rng_() % 4 == 0 ? "" : some_node(scene)};
  } else if (pick < 54) {
    Material m;
    m.colour = {0.2f, 0.3f, rng_() % 8 ? 0.4f : 1.5f, 1.0f};
    m.high_contrast = rng_() % 2;
    c.op = SetMaterial{some_node(scene), m};
  } else if (pick < 58) {
    c.op = SetVisible{some_node(scene), rng_() % 2 == 0};
  } else if (pick < 66) {
    c.op = AddAnimation{some_animation_to_add(scene)};
  } else if (pick < 69) {
    c.op = RemoveAnimation{some_animation(scene)};
  } else if (pick < 74) {
    Play p;
    p.animation = some_animation(scene);
    if (rng_() % 2) p.from_time = rng_() % 10 ? u(rng_) : NAN;
    if (rng_() % 2) p.mode = static_cast<PlayMode>(rng_() % 3);
    c.op = p;
  } else if (pick < 77) {
    c.op = Pause{some_animation(scene)};
  } else if (pick < 80) {
    c.op = Seek{some_animation(scene), rng_() % 10 ? u(rng_) : INFINITY};
  } else if (pick < 83) {
    c.op = SetSpeed{some_animation(scene), rng_() % 10 ? u(rng_) : 5000.0};
  } else if (pick < 96 || depth > 0) {
    c.op = Tick{};
  } else {
    Batch b;
    const int n = 1 + static_cast<int>(rng_() % 4);
    for (int i = 0; i < n; ++i) b.commands.push_back(make(scene, depth + 1));
    c.op = b;
  }
  return c;
}

Command RandomCommandSource::next(const Scene& scene) { return make(scene, 0); }

}  // namespace studio::scene::testing
