#include "scene_assets/scene_description.h"

#include <Eigen/Geometry>

namespace studio::scene_assets {
namespace {

Expected<scene::Track> to_track(const TrackSpec& s) {
  scene::Track t;
  t.node = s.node;
  t.path = s.path;
  t.interpolation = s.interpolation;
  t.times = s.times;
  const std::size_t width = s.path == scene::TrackPath::rotation ? 4 : 3;
  if (s.values.size() != s.times.size() * width)
    return fail("track of '" + s.node + "': " + std::to_string(s.times.size()) + " times need " +
                std::to_string(s.times.size() * width) + " values, got " +
                std::to_string(s.values.size()));
  for (std::size_t k = 0; k < s.times.size(); ++k) {
    Eigen::Vector4d v = Eigen::Vector4d::Zero();
    for (std::size_t j = 0; j < width; ++j) v[static_cast<int>(j)] = s.values[k * width + j];
    t.values.push_back(v);
  }
  return t;
}

}  // namespace

Expected<scene::Scene> build_scene(const SceneDescription& d, AssetCache& cache,
                                   std::int64_t frame) {
  scene::SceneOptions options;
  options.frame_period = 1.0 / d.fps;
  if (auto ok = options.validate(); !ok) return fail(d.file + ": fps: " + ok.error().message);
  scene::Scene s(options);
  auto run = [&](const scene::Command& c, const std::string& section) -> Expected<void> {
    if (auto ok = s.apply(c); !ok) return fail(d.file + ": " + section + ": " + ok.error().message);
    return {};
  };
  if (!d.set.empty()) {
    auto set = cache.load(d.set);
    if (!set) return fail(d.file + ": set: " + set.error().message);
    const Instance inst = instantiate(**set, d.set_id, "", frame);
    if (auto ok = run({frame, scene::Batch{inst.commands}}, "set"); !ok) return std::unexpected(ok.error());
  }
  for (const NodeSpec& ns : d.nodes) {
    if (ns.translation.size() != 3 || ns.rotation.size() != 4 || ns.scale.size() != 3 ||
        ns.colour.size() != 4)
      return fail(d.file + ": nodes: '" + ns.id + "': translation, rotation, scale, colour need 3, 4, 3, 4 numbers");
    scene::Node n;
    n.id = ns.id;
    n.parent = ns.parent;
    n.local.translation = Eigen::Vector3d(ns.translation[0], ns.translation[1], ns.translation[2]);
    n.local.rotation = Eigen::Quaterniond(ns.rotation[3], ns.rotation[0], ns.rotation[1], ns.rotation[2]);
    n.local.scale = Eigen::Vector3d(ns.scale[0], ns.scale[1], ns.scale[2]);
    n.material.colour = Eigen::Vector4d(ns.colour[0], ns.colour[1], ns.colour[2], ns.colour[3]).cast<float>();
    n.material.texture = ns.texture;
    n.material.high_contrast = ns.high_contrast;
    n.visible = ns.visible;
    if (!ns.actor.empty()) {
      n.kind = scene::NodeKind::actor;
      n.actor_id = ns.actor;
    } else if (!ns.asset.empty()) {
      auto a = cache.load(ns.asset);
      if (!a) return fail(d.file + ": nodes: '" + ns.id + "': " + a.error().message);
      n.kind = scene::NodeKind::model;
      n.asset = {ns.asset, (*a)->sha256, {}};
    }
    if (auto ok = run({frame, scene::AddNode{n}}, "nodes"); !ok) return std::unexpected(ok.error());
  }
  for (const AnimationSpec& as : d.animations) {
    scene::Animation a;
    a.name = as.name;
    a.mode = as.mode;
    for (const TrackSpec& ts : as.tracks) {
      auto t = to_track(ts);
      if (!t) return fail(d.file + ": animations: '" + as.name + "': " + t.error().message);
      a.tracks.push_back(std::move(*t));
    }
    if (auto ok = run({frame, scene::AddAnimation{a}}, "animations"); !ok) return std::unexpected(ok.error());
  }
  for (const std::string& id : d.high_contrast) {
    const scene::Node* n = s.find(id);
    if (!n) return fail(d.file + ": high_contrast: unknown node '" + id + "'");
    scene::Material m = n->material;
    m.high_contrast = true;
    if (auto ok = run({frame, scene::SetMaterial{id, m}}, "high_contrast"); !ok) return std::unexpected(ok.error());
  }
  for (const PlaySpec& p : d.play) {
    scene::Play play;
    play.animation = p.animation;
    play.mode = p.mode;
    if (auto ok = run({p.at_frame, scene::SetSpeed{p.animation, p.speed}}, "play"); !ok) return std::unexpected(ok.error());
    if (auto ok = run({p.at_frame, play}, "play"); !ok) return std::unexpected(ok.error());
  }
  if (auto ok = run({frame, scene::Tick{}}, "tick"); !ok) return std::unexpected(ok.error());
  return s;
}

}  // namespace studio::scene_assets
