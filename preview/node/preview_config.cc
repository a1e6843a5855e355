#include "preview_config.h"

#include "yaml_io/options.h"

namespace studio::preview {
namespace {

struct Keys {
  std::string instance = "preview";
  int64_t domain = -1;
  std::string dds_config, log, viewpoint, texturing = "blend", asset_root, take = "take";
  std::vector<int> size{1280, 720};
  int blend_cameras = 3, wait_ms = 200;
  bool carve_masks = true, colour_balance = true;
  int colour_balance_every = 4;
  double colour_balance_rig_s = 0.5;
  bool head_marker = true, camera_frusta = true, projector_frusta = true, projector_screens = true;
  double camera_frustum_m = 0.5;
};

const yaml::Schema<Keys> kSchema{
    yaml::field("instance", &Keys::instance),
    yaml::field("domain", &Keys::domain).range(0, 232),
    yaml::field("dds_config", &Keys::dds_config).relative_path(),
    yaml::field("log", &Keys::log),
    yaml::field("viewpoint", &Keys::viewpoint),
    yaml::field("size", &Keys::size).size(2).range(16, 8192),
    yaml::field("texturing", &Keys::texturing).one_of({"blend", "nearest"}),
    yaml::field("blend_cameras", &Keys::blend_cameras).range(1, 3),
    yaml::field("wait_ms", &Keys::wait_ms).range(0, 10000),
    yaml::field("asset_root", &Keys::asset_root).relative_path(),
    yaml::field("take", &Keys::take),
    yaml::field("carve_masks", &Keys::carve_masks),
    yaml::field("colour_balance", &Keys::colour_balance),
    yaml::field("colour_balance_every", &Keys::colour_balance_every).range(1, 1000),
    yaml::field("colour_balance_rig_s", &Keys::colour_balance_rig_s).range(0, 60),
    yaml::field("head_marker", &Keys::head_marker),
    yaml::field("camera_frusta", &Keys::camera_frusta),
    yaml::field("camera_frustum_m", &Keys::camera_frustum_m).range(0.01, 20),
    yaml::field("projector_frusta", &Keys::projector_frusta),
    yaml::field("projector_screens", &Keys::projector_screens),
};

}  // namespace

Expected<void> PreviewConfig::validate() const {
  if (instance.empty() || instance.size() > 40) return fail("instance: 1..40 characters");
  if (auto ok = viewpoint.validate(); !ok) return ok;
  return overlays.validate();
}

Expected<PreviewConfig> read_preview_config(const std::string& path) {
  PreviewConfig c;
  if (path.empty()) return c;
  auto k = kSchema.read_file(path);
  if (!k) return std::unexpected(k.error());
  c.instance = k->instance;
  c.domain = k->domain;
  c.dds_config = k->dds_config;
  c.log = k->log;
  if (!k->viewpoint.empty()) {
    auto v = parse_viewpoint(k->viewpoint);
    if (!v) return fail(path + ": viewpoint: " + v.error().message);
    c.viewpoint = *v;
  }
  c.width = k->size[0];
  c.height = k->size[1];
  c.blend = k->texturing == "blend";
  c.blend_cameras = k->blend_cameras;
  c.wait_ms = k->wait_ms;
  c.asset_root = k->asset_root;
  c.take = k->take;
  c.carve_masks = k->carve_masks;
  c.colour_balance = k->colour_balance;
  c.colour_balance_every = k->colour_balance_every;
  c.colour_balance_rig_s = k->colour_balance_rig_s;
  c.overlays.head = k->head_marker;
  c.overlays.camera_frusta = k->camera_frusta;
  c.overlays.camera_frustum_m = k->camera_frustum_m;
  c.overlays.projector_frusta = k->projector_frusta;
  c.overlays.projector_screens = k->projector_screens;
  if (auto ok = c.validate(); !ok) return fail(path + ": " + ok.error().message);
  return c;
}

}  // namespace studio::preview
