#include "capture_config.h"

#include <filesystem>

#include "../../keyer/cli/keyer_yaml.h"
#include "capture/aravis_source.h"
#include "capture/file_source.h"
#include "capture/sim_source.h"
#include "sim/cameras.h"
#include "yaml_io/rig_yaml.h"

namespace studio::capture::node {

const char kConfigHelp[] =
    "  clock: {fps: 25, epoch_ns: 0}     studio clock (or period_ns instead of fps)\n"
    "  takes_dir: DIR                    where takes/<take>/<camera>/ go (default takes)\n"
    "  rig: FILE                         rig.yaml with the calibrations to publish (optional);\n"
    "                                    OpenCV distortion is fitted to the paper's model, and\n"
    "                                    refused when the fit is off by more than 0.5 px\n"
    "  keyer: FILE                       keyer options, see keyer.example.yaml (optional)\n"
    "  image: {rate: HZ, quality: Q, raw: BOOL}   latest-image service (default 5, 85, false)\n"
    "  masks: BOOL                       key and publish masks here (default true; false when\n"
    "                                    studio-keyer --config keys image: {rate: 1000, raw: true})\n"
    "  plate_dir: DIR                    difference key: keep plates captured on command\n"
    "                                    (KeyerPlate) as DIR/<camera>.png, load them at start\n"
    "  recorder: {queue_frames: N}       frames buffered before the disk (default 50)\n"
    "  state_period: S                   seconds between CameraState samples (default 1)\n"
    "  cameras:                          one entry per camera:\n"
    "    - id: cam0\n"
    "      source: {type: sim, ring: 6, index: 0, width: 704, height: 576, paced: true}\n"
    "      source: {type: files, path: DIR, fps: 25, loop: false, paced: true}\n"
    "      source: {type: aravis, device: ID, pixel_format: BayerRG8, width: W, height: H,\n"
    "               fps: 25, trigger: free_run|software|line, line: Line0, buffers: 8,\n"
    "               interfaces: [GigEVision, USB3Vision]}\n";

namespace {

using Fail = std::unexpected<Error>;

std::string resolve(const yaml::Node& n, const std::string& path) {
  if (path.empty() || path.front() == '/') return path;
  return (std::filesystem::path(n.file()).parent_path() / path).string();
}

template <class T, class F>
Expected<void> number(yaml::MapReader& m, std::string_view key, T& out, double lo, double hi,
                      F convert) {
  auto n = m.optional(key);
  if (!n) return {};
  auto v = convert(*n);
  if (!v) return Fail(v.error());
  if (double(*v) < lo || double(*v) > hi)
    return n->fail("must be in [" + yaml::format_double(lo) + ", " + yaml::format_double(hi) + "]");
  out = T(*v);
  return {};
}
auto as_double = [](const yaml::Node& n) { return n.as_double(); };
auto as_int = [](const yaml::Node& n) { return n.as_int(); };

Expected<void> boolean(yaml::MapReader& m, std::string_view key, bool& out) {
  auto n = m.optional(key);
  if (!n) return {};
  auto v = n->as_bool();
  if (!v) return Fail(v.error());
  out = *v;
  return {};
}

Expected<void> string(yaml::MapReader& m, std::string_view key, std::string& out, bool path) {
  auto n = m.optional(key);
  if (!n) return {};
  auto v = n->as_string();
  if (!v) return Fail(v.error());
  if (v->empty()) return n->fail("must not be empty");
  out = path ? resolve(*n, *v) : *v;
  return {};
}

#define TRY(expr)                                       \
  do {                                                  \
    if (auto _r = (expr); !_r) return Fail(_r.error()); \
  } while (0)

Expected<CameraSetup> read_camera(const yaml::Node& node, const CaptureNodeOptions& o) {
  auto m = yaml::MapReader::from(node);
  if (!m) return Fail(m.error());
  CameraSetup setup;
  auto id_node = m->required("id");
  if (!id_node) return Fail(id_node.error());
  auto id = id_node->as_string();
  if (!id) return Fail(id.error());
  if (id->empty() || id->size() > 63) return id_node->fail("expected 1..63 characters");
  setup.id = *id;
  auto src_node = m->required("source");
  if (!src_node) return Fail(src_node.error());
  auto s = yaml::MapReader::from(*src_node);
  if (!s) return Fail(s.error());
  auto type_node = s->required("type");
  if (!type_node) return Fail(type_node.error());
  auto type = type_node->as_string();
  if (!type) return Fail(type.error());
  if (*type == "sim") {
    sim::RingOptions ring;
    int index = 0;
    SimSourceOptions so;
    TRY(number(*s, "ring", ring.count, 1, 64, as_int));
    TRY(number(*s, "index", index, 0, 63, as_int));
    TRY(number(*s, "width", ring.width, 16, 8192, as_int));
    TRY(number(*s, "height", ring.height, 16, 8192, as_int));
    TRY(boolean(*s, "paced", so.paced));
    TRY(s->finish());
    if (index >= ring.count) return src_node->fail("index: must be below ring");
    ring.focal_px *= double(ring.width) / 704.0;  // keep the field of view at any size
    so.camera = sim::ring_cameras(ring)[std::size_t(index)];
    so.camera.id = setup.id;
    so.clock = o.clock;
    so.exposure_us = std::min(so.exposure_us, double(o.clock.period_ns) / 1000.0);
    setup.calibration = so.camera;
    auto src = SimFrameSource::create(so);
    if (!src) return src_node->fail(src.error().message);
    setup.source = std::move(*src);
  } else if (*type == "files") {
    FileSourceOptions fo;
    fo.id = setup.id;
    fo.clock = o.clock;
    auto path = s->required("path");
    if (!path) return Fail(path.error());
    auto p = path->as_string();
    if (!p) return Fail(p.error());
    fo.path = resolve(*path, *p);
    TRY(number(*s, "fps", fo.fps, 1e-3, 1000, as_double));
    TRY(boolean(*s, "loop", fo.loop));
    TRY(boolean(*s, "paced", fo.paced));
    TRY(s->finish());
    auto src = FileSource::create(fo);
    if (!src) return src_node->fail(src.error().message);
    setup.source = std::move(*src);
  } else if (*type == "aravis") {
    AravisOptions ao;
    ao.camera_id = setup.id;
    ao.clock = o.clock;
    std::string pixel_format, trigger = "free_run";
    TRY(string(*s, "device", ao.device_id, false));
    TRY(string(*s, "pixel_format", pixel_format, false));
    TRY(number(*s, "width", ao.width, 0, 32768, as_int));
    TRY(number(*s, "height", ao.height, 0, 32768, as_int));
    TRY(number(*s, "fps", ao.frame_rate, 0, 1000, as_double));
    TRY(string(*s, "trigger", trigger, false));
    TRY(string(*s, "line", ao.trigger_line, false));
    TRY(number(*s, "buffers", ao.buffers, 2, 256, as_int));
    if (auto n = s->optional("interfaces")) {
      auto v = n->elements();
      if (!v) return Fail(v.error());
      for (const auto& e : *v) {
        auto name = e.as_string();
        if (!name) return Fail(name.error());
        ao.interfaces.push_back(*name);
      }
    }
    TRY(s->finish());
    if (!pixel_format.empty()) {
      auto pf = parse_pixel_format(pixel_format);
      if (!pf) return src_node->fail(pf.error().message);
      ao.pixel_format = *pf;
    }
    if (trigger == "free_run")
      ao.trigger = TriggerMode::free_run;
    else if (trigger == "software")
      ao.trigger = TriggerMode::software;
    else if (trigger == "line")
      ao.trigger = TriggerMode::line;
    else
      return src_node->fail("trigger: expected free_run, software or line");
    auto src = AravisSource::open(ao);
    if (!src) return src_node->fail(src.error().message);
    setup.source = std::move(*src);
  } else {
    return type_node->fail("unknown source type '" + *type + "' (expected sim, files or aravis)");
  }
  TRY(m->finish());
  return setup;
}

}  // namespace

Expected<CaptureNodeOptions> read_capture_config(yaml::MapReader& config) {
  CaptureNodeOptions o;
  if (auto n = config.optional("clock")) {
    auto c = yaml::MapReader::from(*n);
    if (!c) return Fail(c.error());
    if (c->has("fps") && c->has("period_ns")) return n->fail("give fps or period_ns, not both");
    double fps = 25;
    TRY(number(*c, "fps", fps, 0.1, 1000, as_double));
    o.clock.period_ns = int64_t(1e9 / fps + 0.5);
    TRY(number(*c, "period_ns", o.clock.period_ns, 1e6, 1e10, as_int));
    TRY(number(*c, "epoch_ns", o.clock.epoch_ns, 0, 9.2e18, as_int));
    TRY(c->finish());
  }
  o.takes_dir = resolve(config.node(), "takes");
  TRY(string(config, "takes_dir", o.takes_dir, true));
  std::string rig_path, keyer_path;
  TRY(string(config, "rig", rig_path, true));
  TRY(string(config, "keyer", keyer_path, true));
  if (auto n = config.optional("image")) {
    auto c = yaml::MapReader::from(*n);
    if (!c) return Fail(c.error());
    TRY(number(*c, "rate", o.image_rate, 0, 1000, as_double));
    TRY(number(*c, "quality", o.jpeg_quality, 1, 100, as_int));
    TRY(boolean(*c, "raw", o.image_raw));
    TRY(c->finish());
  }
  if (auto n = config.optional("recorder")) {
    auto c = yaml::MapReader::from(*n);
    if (!c) return Fail(c.error());
    TRY(number(*c, "queue_frames", o.queue_frames, 1, 10000, as_int));
    TRY(c->finish());
  }
  TRY(number(config, "state_period", o.state_period, 0.05, 60, as_double));
  TRY(boolean(config, "masks", o.publish_masks));
  if (!keyer_path.empty()) {
    auto k = keyer::load_keyer_options(keyer_path);
    if (!k) return Fail(k.error());
    o.keyer = *k;
  }
  if (auto n = config.optional("plate_dir")) {
    auto dir = n->as_string();
    if (!dir) return Fail(dir.error());
    if (dir->empty()) return n->fail("expected a folder");
    if (!o.publish_masks || o.keyer.mode != keyer::KeyMode::kDifference)
      return n->fail("clean plates need in-process keying (masks: true) with the difference key");
    o.plate_dir = resolve(*n, *dir);
  }
  auto cams = config.required("cameras");
  if (!cams) return Fail(cams.error());
  auto elements = cams->elements();
  if (!elements) return Fail(elements.error());
  if (elements->empty()) return cams->fail("expected at least one camera");
  for (const auto& e : *elements) {
    auto c = read_camera(e, o);
    if (!c) return Fail(c.error());
    for (const auto& other : o.cameras)
      if (other.id == c->id) return e.fail("duplicate camera id " + c->id);
    o.cameras.push_back(std::move(*c));
  }
  if (!rig_path.empty()) {
    auto rig = yaml::read_rig(rig_path);
    if (!rig) return Fail(rig.error());
    for (auto& c : o.cameras)
      if (const Camera* rc = rig->find_camera(c.id)) c.calibration = *rc;
  }
  return o;
}

}  // namespace studio::capture::node
