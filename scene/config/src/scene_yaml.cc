#include "scene_config/scene_yaml.h"

#include "yaml_io/options.h"

namespace studio::scene_config {
namespace {

using namespace studio::scene_assets;
using studio::yaml::enum_field;
using studio::yaml::field;
using studio::yaml::Node;
using studio::yaml::Schema;

const std::vector<std::pair<std::string, scene::PlayMode>> kModes{
    {"once", scene::PlayMode::once},
    {"loop", scene::PlayMode::loop},
    {"ping_pong", scene::PlayMode::ping_pong}};

template <class T>
auto list_of(const Schema<T>& schema) {
  return [schema](const Node& n) -> Expected<std::vector<T>> {
    auto elements = n.elements();
    if (!elements) return std::unexpected(elements.error());
    std::vector<T> out;
    for (const Node& e : *elements) {
      auto v = schema.read(e);
      if (!v) return std::unexpected(v.error());
      out.push_back(std::move(*v));
    }
    return out;
  };
}

const Schema<NodeSpec>& node_schema() {
  static const Schema<NodeSpec> s{
      field("id", &NodeSpec::id).required(),
      field("parent", &NodeSpec::parent),
      field("asset", &NodeSpec::asset).relative_path(),
      field("actor", &NodeSpec::actor),
      field("translation", &NodeSpec::translation).size(3),
      field("rotation", &NodeSpec::rotation).size(4),
      field("scale", &NodeSpec::scale).size(3),
      field("colour", &NodeSpec::colour).size(4).range(0, 1),
      field("texture", &NodeSpec::texture).relative_path(),
      field("high_contrast", &NodeSpec::high_contrast),
      field("visible", &NodeSpec::visible),
  };
  return s;
}

const Schema<TrackSpec>& track_schema() {
  static const Schema<TrackSpec> s{
      field("node", &TrackSpec::node).required(),
      enum_field("path", &TrackSpec::path,
                 {{"translation", scene::TrackPath::translation},
                  {"rotation", scene::TrackPath::rotation},
                  {"scale", scene::TrackPath::scale}}),
      enum_field("interpolation", &TrackSpec::interpolation,
                 {{"linear", scene::Interpolation::linear}, {"step", scene::Interpolation::step}}),
      field("times", &TrackSpec::times).required().min(0),
      field("values", &TrackSpec::values).required(),
  };
  return s;
}

const Schema<AnimationSpec>& animation_schema() {
  static const Schema<AnimationSpec> s{
      field("name", &AnimationSpec::name).required(),
      enum_field("mode", &AnimationSpec::mode, kModes),
      field("tracks", &AnimationSpec::tracks, list_of(track_schema())),
  };
  return s;
}

const Schema<PlaySpec>& play_schema() {
  static const Schema<PlaySpec> s{
      field("animation", &PlaySpec::animation),
      field("at_frame", &PlaySpec::at_frame).min(0),
      field("mode", &PlaySpec::mode,
            [](const Node& n) -> Expected<std::optional<scene::PlayMode>> {
              auto text = n.as_string();
              if (!text) return std::unexpected(text.error());
              for (const auto& [name, mode] : kModes)
                if (name == *text) return mode;
              return n.fail("expected one of once, loop, ping_pong, got '" + *text + "'");
            }),
      field("speed", &PlaySpec::speed).range(-1000, 1000),
  };
  return s;
}

const Schema<ViewSpec>& view_schema() {
  static const Schema<ViewSpec> s{
      field("eye", &ViewSpec::eye).required().size(3),
      field("at", &ViewSpec::at).required().size(3),
      field("fov", &ViewSpec::fov_deg).range(1, 179),
  };
  return s;
}

const Schema<SceneDescription>& scene_schema() {
  static const Schema<SceneDescription> s{
      field("set", &SceneDescription::set).relative_path(),
      field("set_id", &SceneDescription::set_id),
      field("fps", &SceneDescription::fps).range(1, 1000),
      field("nodes", &SceneDescription::nodes, list_of(node_schema())),
      field("animations", &SceneDescription::animations, list_of(animation_schema())),
      field("high_contrast", &SceneDescription::high_contrast),
      field("play", &SceneDescription::play, list_of(play_schema())),
      field("view", &SceneDescription::view,
            [](const Node& n) -> Expected<std::optional<ViewSpec>> {
              auto v = view_schema().read(n);
              if (!v) return std::unexpected(v.error());
              return std::optional<ViewSpec>(std::move(*v));
            }),
  };
  return s;
}

}  // namespace

Expected<SceneDescription> read_scene_file(const std::string& path) {
  auto d = scene_schema().read_file(path);
  if (!d) return std::unexpected(d.error());
  d->file = path;
  return d;
}

Expected<SceneDescription> parse_scene_text(const std::string& text, const std::string& name) {
  auto root = yaml::parse(text, name);
  if (!root) return std::unexpected(root.error());
  auto d = scene_schema().read(*root);
  if (!d) return std::unexpected(d.error());
  d->file = name;
  return d;
}

}  // namespace studio::scene_config
