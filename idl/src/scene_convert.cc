#include "wire/scene_convert.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

#include "wire/sample.h"

namespace studio::wire {
namespace {

template <class... F>
struct Overload : F... {
  using F::operator()...;
};
template <class... F>
Overload(F...) -> Overload<F...>;

template <std::size_t N>
Expected<void> put(char (&dst)[N], const std::string& value, const char* what) {
  if (value.size() >= N)
    return fail(std::string(what) + " '" + value.substr(0, 40) + "...' is longer than " +
                std::to_string(N - 1) + " characters");
  set(dst, value);
  return {};
}

scene::Transform trs_of(const studio_SceneNode& s) {
  scene::Transform t;
  t.translation = {s.translation[0], s.translation[1], s.translation[2]};
  t.rotation.coeffs() << s.rotation[0], s.rotation[1], s.rotation[2], s.rotation[3];
  t.scale = {s.scale[0], s.scale[1], s.scale[2]};
  return t;
}

void put_trs(const scene::Transform& t, studio_SceneNode& s) {
  for (int i = 0; i < 3; ++i) {
    s.translation[i] = t.translation[i];
    s.scale[i] = t.scale[i];
  }
  for (int i = 0; i < 4; ++i) s.rotation[i] = t.rotation.coeffs()[i];
}

scene::Material material_of(const studio_SceneNode& s) {
  scene::Material m;
  m.colour = {s.colour[0], s.colour[1], s.colour[2], s.colour[3]};
  m.texture = s.texture;
  m.high_contrast = (s.flags & studio_SCENE_NODE_HIGH_CONTRAST) != 0;
  return m;
}

Expected<void> put_material(const scene::Material& m, studio_SceneNode& s) {
  for (int i = 0; i < 4; ++i) s.colour[i] = m.colour[i];
  if (m.high_contrast) s.flags |= studio_SCENE_NODE_HIGH_CONTRAST;
  return put(s.texture, m.texture, "texture");
}

// A 4x4 (row-major) without shear as TRS: scale = column norms (the sign of the determinant on
// x), rotation = the orthonormalised rest.
scene::Transform decompose(const double (&m)[16]) {
  Eigen::Matrix4d a;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a(r, c) = m[4 * r + c];
  scene::Transform t;
  t.translation = a.block<3, 1>(0, 3);
  Eigen::Matrix3d rs = a.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) t.scale[c] = rs.col(c).norm();
  if (rs.determinant() < 0) t.scale[0] = -t.scale[0];
  Eigen::Matrix3d r = rs;
  for (int c = 0; c < 3; ++c)
    if (t.scale[c] != 0) r.col(c) /= t.scale[c];
  // Nearest rotation (polar decomposition through the SVD), so the quaternion is well defined.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d q = svd.matrixU() * svd.matrixV().transpose();
  if (q.determinant() < 0) q = -q;  // only for degenerate input; the library judges the scale
  t.rotation = Eigen::Quaterniond(q);
  return t;
}

}  // namespace

Expected<void> from_core(const scene::Node& n, studio_SceneNode& s) {
  if (auto ok = put(s.node_id, n.id, "node id"); !ok) return ok;
  if (auto ok = put(s.parent, n.parent, "parent"); !ok) return ok;
  if (auto ok = put(s.asset, n.asset.path, "asset"); !ok) return ok;
  if (auto ok = put(s.asset_sha256, n.asset.sha256, "asset_sha256"); !ok) return ok;
  if (auto ok = put(s.actor_id, n.actor_id, "actor_id"); !ok) return ok;
  if (n.asset.meshes.size() > 1024) return fail("node '" + n.id + "': more than 1024 meshes");
  set(s.material, "");
  s.frame = n.frame >= 0 ? uint64_t(n.frame) : 0;
  const Eigen::Matrix4d m = n.local.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) s.parent_from_node[4 * r + c] = m(r, c);
  for (int c = 0; c < 3; ++c) s.parent_from_node[12 + c] = 0;  // exactly rigid-affine
  s.parent_from_node[15] = 1;
  s.flags = (n.visible ? studio_SCENE_NODE_VISIBLE : 0u) |
            (n.kind == scene::NodeKind::actor ? studio_SCENE_NODE_ACTOR : 0u);
  s.kind = static_cast<studio_SceneNodeKind>(n.kind);
  put_trs(n.local, s);
  if (auto ok = put_material(n.material, s); !ok) return ok;
  assign(s.asset_meshes, n.asset.meshes);
  s.light_type = static_cast<studio_SceneLightType>(n.light.type);
  for (int i = 0; i < 3; ++i) s.light_colour[i] = n.light.colour[i];
  s.light_intensity = n.light.intensity;
  s.light_range = n.light.range;
  s.light_inner_cone = n.light.inner_cone;
  s.light_outer_cone = n.light.outer_cone;
  return {};
}

Expected<scene::Node> to_core(const studio_SceneNode& s) {
  scene::Node n;
  n.id = s.node_id;
  n.parent = s.parent;
  const auto kind = static_cast<uint32_t>(s.kind);
  if (kind > 3) return fail("node '" + n.id + "': unknown kind " + std::to_string(kind));
  n.kind = static_cast<scene::NodeKind>(kind);
  n.local = trs_of(s);
  n.visible = (s.flags & studio_SCENE_NODE_VISIBLE) != 0;
  n.asset.path = s.asset;
  n.asset.sha256 = s.asset_sha256;
  const auto meshes = view(s.asset_meshes);
  n.asset.meshes.assign(meshes.begin(), meshes.end());
  n.material = material_of(s);
  const auto light = static_cast<uint32_t>(s.light_type);
  if (light > 2) return fail("node '" + n.id + "': unknown light type " + std::to_string(light));
  n.light.type = static_cast<scene::LightType>(light);
  n.light.colour = {s.light_colour[0], s.light_colour[1], s.light_colour[2]};
  n.light.intensity = s.light_intensity;
  n.light.range = s.light_range;
  n.light.inner_cone = s.light_inner_cone;
  n.light.outer_cone = s.light_outer_cone;
  n.actor_id = s.actor_id;
  n.frame = static_cast<std::int64_t>(s.frame);
  return n;
}

Expected<scene::Command> to_core(const studio_SceneCommand& s, std::int64_t now_frame) {
  scene::Command c;
  c.frame = s.at_frame == studio_SCENE_AT_NOW ? now_frame : s.at_frame;
  const std::string target = s.target;
  const auto mode = static_cast<uint32_t>(s.mode);
  if (mode > studio_SCENE_MODE_PING_PONG) return fail("unknown play mode " + std::to_string(mode));
  std::optional<scene::PlayMode> play_mode;
  if (mode != studio_SCENE_MODE_KEEP) play_mode = static_cast<scene::PlayMode>(mode - 1);
  switch (static_cast<uint32_t>(s.verb)) {
    case studio_SCENE_LOAD_SET:
      return fail("load_set: loading a set is the server's work, not a library command");
    case studio_SCENE_ADD_NODE: {
      auto n = to_core(s.node);
      if (!n) return std::unexpected(n.error());
      n->frame = 0;  // stamped by the scene with the command's frame
      c.op = scene::AddNode{std::move(*n)};
      break;
    }
    case studio_SCENE_REMOVE_NODE:
      c.op = scene::RemoveNode{target};
      break;
    case studio_SCENE_SET_TRANSFORM:
      c.op = scene::SetTransform{target, trs_of(s.node)};
      break;
    case studio_SCENE_MOVE_NODE:
      c.op = scene::SetTransform{target, decompose(s.transform)};
      break;
    case studio_SCENE_SET_PARENT:
      c.op = scene::SetParent{target, s.node.parent};
      break;
    case studio_SCENE_SET_MATERIAL:
      c.op = scene::SetMaterial{target, material_of(s.node)};
      break;
    case studio_SCENE_SET_VISIBLE:
      c.op = scene::SetVisible{target, (s.node.flags & studio_SCENE_NODE_VISIBLE) != 0};
      break;
    case studio_SCENE_ADD_ANIMATION: {
      if (!play_mode) return fail("add_animation: '" + target + "' needs a play mode, not KEEP");
      scene::Animation a;
      a.name = target;
      a.mode = *play_mode;
      for (const studio_SceneTrack& t : view(s.tracks)) {
        scene::Track track;
        track.node = t.node;
        if (t.path > 2 || t.interpolation > 1)
          return fail("add_animation: '" + target + "': bad track path or interpolation");
        track.path = static_cast<scene::TrackPath>(t.path);
        track.interpolation = static_cast<scene::Interpolation>(t.interpolation);
        const auto times = view(t.times), values = view(t.values);
        if (values.size() != 4 * times.size())
          return fail("add_animation: '" + target + "': values are not 4 per key");
        track.times.assign(times.begin(), times.end());
        for (std::size_t k = 0; k < times.size(); ++k)
          track.values.emplace_back(values[4 * k], values[4 * k + 1], values[4 * k + 2],
                                    values[4 * k + 3]);
        a.tracks.push_back(std::move(track));
      }
      c.op = scene::AddAnimation{std::move(a)};
      break;
    }
    case studio_SCENE_REMOVE_ANIMATION:
      c.op = scene::RemoveAnimation{target};
      break;
    case studio_SCENE_PLAY: {
      scene::Play p;
      p.animation = target;
      if (s.has_value) p.from_time = s.value;
      p.mode = play_mode;
      c.op = p;
      break;
    }
    case studio_SCENE_PAUSE:
      c.op = scene::Pause{target};
      break;
    case studio_SCENE_SEEK:
      c.op = scene::Seek{target, s.value};
      break;
    case studio_SCENE_SPEED:
      c.op = scene::SetSpeed{target, s.value};
      break;
    case studio_SCENE_TICK:
      c.op = scene::Tick{};
      break;
    default:
      return fail("unknown verb " + std::to_string(static_cast<uint32_t>(s.verb)));
  }
  return c;
}

Expected<void> from_core(const scene::Command& c, studio_SceneCommand& s) {
  s.at_frame = c.frame;
  s.mode = studio_SCENE_MODE_KEEP;
  s.has_value = false;
  s.value = 0;
  set(s.target, "");
  set(s.path, "");
  resize(s.tracks, 0);
  auto target = [&](const std::string& id) { return put(s.target, id, "target"); };
  return std::visit(
      Overload{
          [&](const scene::AddNode& x) -> Expected<void> {
            s.verb = studio_SCENE_ADD_NODE;
            return from_core(x.node, s.node);
          },
          [&](const scene::RemoveNode& x) -> Expected<void> {
            s.verb = studio_SCENE_REMOVE_NODE;
            return target(x.id);
          },
          [&](const scene::SetTransform& x) -> Expected<void> {
            s.verb = studio_SCENE_SET_TRANSFORM;
            put_trs(x.local, s.node);
            return target(x.id);
          },
          [&](const scene::SetParent& x) -> Expected<void> {
            s.verb = studio_SCENE_SET_PARENT;
            if (auto ok = put(s.node.parent, x.parent, "parent"); !ok) return ok;
            return target(x.id);
          },
          [&](const scene::SetMaterial& x) -> Expected<void> {
            s.verb = studio_SCENE_SET_MATERIAL;
            s.node.flags = 0;
            if (auto ok = put_material(x.material, s.node); !ok) return ok;
            return target(x.id);
          },
          [&](const scene::SetVisible& x) -> Expected<void> {
            s.verb = studio_SCENE_SET_VISIBLE;
            s.node.flags = x.visible ? studio_SCENE_NODE_VISIBLE : 0u;
            return target(x.id);
          },
          [&](const scene::AddAnimation& x) -> Expected<void> {
            s.verb = studio_SCENE_ADD_ANIMATION;
            s.mode = static_cast<studio_ScenePlayMode>(static_cast<uint32_t>(x.animation.mode) + 1);
            if (x.animation.tracks.size() > 1024)
              return fail("add_animation: more than 1024 tracks");
            resize(s.tracks, static_cast<uint32_t>(x.animation.tracks.size()));
            auto tracks = view(s.tracks);
            for (std::size_t i = 0; i < tracks.size(); ++i) {
              const scene::Track& t = x.animation.tracks[i];
              if (auto ok = put(tracks[i].node, t.node, "track node"); !ok) return ok;
              tracks[i].path = static_cast<uint8_t>(t.path);
              tracks[i].interpolation = static_cast<uint8_t>(t.interpolation);
              assign(tracks[i].times, t.times);
              std::vector<double> values;
              for (const auto& v : t.values) values.insert(values.end(), v.data(), v.data() + 4);
              assign(tracks[i].values, values);
            }
            return target(x.animation.name);
          },
          [&](const scene::RemoveAnimation& x) -> Expected<void> {
            s.verb = studio_SCENE_REMOVE_ANIMATION;
            return target(x.name);
          },
          [&](const scene::Play& x) -> Expected<void> {
            s.verb = studio_SCENE_PLAY;
            if (x.from_time) {
              s.has_value = true;
              s.value = *x.from_time;
            }
            if (x.mode)
              s.mode = static_cast<studio_ScenePlayMode>(static_cast<uint32_t>(*x.mode) + 1);
            return target(x.animation);
          },
          [&](const scene::Pause& x) -> Expected<void> {
            s.verb = studio_SCENE_PAUSE;
            return target(x.animation);
          },
          [&](const scene::Seek& x) -> Expected<void> {
            s.verb = studio_SCENE_SEEK;
            s.value = x.time;
            return target(x.animation);
          },
          [&](const scene::SetSpeed& x) -> Expected<void> {
            s.verb = studio_SCENE_SPEED;
            s.value = x.speed;
            return target(x.animation);
          },
          [&](const scene::Tick&) -> Expected<void> {
            s.verb = studio_SCENE_TICK;
            return {};
          },
          [&](const scene::Batch&) -> Expected<void> {
            return fail("batch: no wire form (send the commands one by one)");
          },
      },
      c.op);
}

}  // namespace studio::wire
