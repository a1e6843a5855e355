#include "capture_config.h"

#include <algorithm>
#include <array>
#include <optional>
#include <set>

#include "capture/aravis_source.h"
#include "capture/file_source.h"
#include "capture/sim_source.h"
#include "keyer/config/keyer_yaml.h"
#include "sim/cameras.h"
#include "tracking_config.h"
#include "yaml_io/options.h"
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
    "                                    studio-keyer --config keys image: {rate: 1000, raw: "
    "true})\n"
    "  plate_dir: DIR                    difference key: keep plates captured on command\n"
    "                                    (KeyerPlate) as DIR/<camera>.png, load them at start\n"
    "  recorder: {queue_frames: N, sync_interval_ms: 1000, disk_mb_s: 0}\n"
    "                                    frames buffered before the disk (default 50);\n"
    "                                    frames.raw fdatasync'ed at least this often (a power\n"
    "                                    cut loses at most that; verify-take rebuilds the rest);\n"
    "                                    the disk's sustained MB/s (BENCHMARKS.md, 0: measured\n"
    "                                    at start): a warning when the cameras need more\n"
    "  state_period: S                   seconds between CameraState samples (default 1)\n"
    "  cameras:                          one entry per camera:\n"
    "    - id: cam0\n"
    "      source: {type: sim, ring: 6, index: 0, width: 704, height: 576, paced: true,\n"
    "               frame_code: false, stamp: false, offset_us: 0, jitter_us: 0, drop_every: 0,\n"
    "               readout_us: -1, motion: sequence, swing_peak_speed: 1.5,\n"
    "               costume: plain, response: [1, 1, 1], gamma: 0, buffers: 16}\n"
    "                                    readout_us: exposure instant -> frame on the host (the\n"
    "                                    rest of the exposure, read-out, transfer); -1 (default):\n"
    "                                    a GigE camera's, half the exposure + 8 bits a pixel at\n"
    "                                    1 Gbit/s (8.2 ms at 704x576); 0: an ideal camera\n"
    "                                    motion: the simulated actor's (idle, walk, turn,\n"
    "                                    raise_hand, crouch, sequence, arm_swing: the fast arm\n"
    "                                    swing, fingertips at swing_peak_speed m/s); every camera\n"
    "                                    of a studio must give the same\n"
    "                                    stamp: frame number as a corner code in the pixels;\n"
    "                                    offset/jitter/drop_every: a real camera's imperfections\n"
    "                                    buffers: frames the camera holds for a late consumer\n"
    "                                    (older ones are lost, counted as drops), as an aravis\n"
    "                                    source's buffers (default 16: a 600 ms stall at 25 fps)\n"
    "                                    frame_code: the actor wears the frame number (preview "
    "tests)\n"
    "                                    costume: plain (evenly coloured clothing) or patterned\n"
    "                                    (a fixed pattern on the clothing's surface, the same "
    "from\n"
    "                                    every camera: what photo-consistency needs to work on);\n"
    "                                    every camera of a studio must give the same\n"
    "                                    response: the camera's linear gains on R, G, B, each in\n"
    "                                    [0.25, 4] (exposure and white balance: a real rig's\n"
    "                                    cameras differ by a few percent; what studio-hull\n"
    "                                    offline's --colour-balance corrects)\n"
    "                                    gamma: 0 (default) or 0.1..4: the camera publishes\n"
    "                                    GenICam Gamma (read-only) and its Gain, exposure and\n"
    "                                    white balance act before it (a factor f scales the\n"
    "                                    delivered values by f^gamma), as a real camera's do\n"
    "      source: {type: files, path: DIR, fps: 25, loop: false, paced: true}\n"
    "      source: {type: aravis, device: ID, pixel_format: BayerRG8, width: W, height: H,\n"
    "               fps: 25, trigger: free_run|software|line, line: Line0, buffers: 16,\n"
    "               interfaces: [GigEVision, USB3Vision], clock_trigger: true,\n"
    "               camera_time: true}\n";

namespace {

// The keys as written; read_capture_config() turns them into CaptureNodeOptions.
struct ClockKeys {
  double fps = 0;  // 0: not given
  int64_t period_ns = 0;
  int64_t epoch_ns = 0;
  Expected<void> validate() const {
    if (fps > 0 && period_ns > 0) return fail("give fps or period_ns, not both");
    return {};
  }
  FrameClock clock() const {
    FrameClock c;
    c.period_ns = period_ns > 0 ? period_ns : int64_t(1e9 / (fps > 0 ? fps : 25.0) + 0.5);
    c.epoch_ns = epoch_ns;
    return c;
  }
};
struct ImageKeys {
  double rate = 5;
  int quality = 85;
  bool raw = false;
};
struct RecorderKeys {
  int queue_frames = 50;
  int sync_interval_ms = 1000;
  double disk_mb_s = 0;
};
struct SimKeys {
  int ring = 6, index = 0, width = 704, height = 576;
  bool paced = true;
  bool frame_code = false;  // sim/frame_code.h
  bool patterned_costume = false;  // sim::StudioOptions::patterned_costume
  bool stamp = false;
  double offset_us = 0, jitter_us = 0;
  double readout_us = -1;  // -1: a GigE camera's (see kUsage)
  int drop_every = 0;
  int buffers = SimSourceOptions{}.buffer_frames;
  sim::Motion motion = sim::Motion::sequence;  // the simulated actor's motion (sim/actor.h)
  double swing_peak_speed = 1.5;               // arm_swing: fingertip peak speed, m/s
  std::array<double, 3> response{1, 1, 1};     // sim::StudioOptions::camera_response
  double gamma = 0;                            // SimSourceOptions::gamma
  Expected<void> validate() const {
    if (index >= ring) return fail("index: must be below ring");
    if (readout_us < 0 && readout_us != -1) return fail("readout_us: -1 (auto) or >= 0");
    return {};
  }
};
// One camera of `cameras:`; its source is opened once the whole file has been read.
struct CameraKeys {
  std::string id;
  std::optional<yaml::Node> source;  // the source mapping (for errors while opening)
  std::string type;
  SimKeys sim;
  FileSourceOptions files;
  AravisOptions aravis;
  std::optional<TrackingKeys> tracking;
  std::optional<LensTableFile> lens_table;  // a fixed camera's zoom/focus -> intrinsics
};
struct CaptureKeys {
  ClockKeys clock;
  std::string takes_dir, rig, plate_dir;
  keyer::KeyerOptions keyer;
  ImageKeys image;
  bool masks = true;
  RecorderKeys recorder;
  double state_period = 1.0;
  std::vector<CameraKeys> cameras;
  Expected<void> validate() const {
    if (!plate_dir.empty() && (!masks || keyer.mode != keyer::KeyMode::kDifference))
      return fail(
          "plate_dir: clean plates need in-process keying (masks: true) with the difference key");
    return {};
  }
};

const yaml::Schema<SimKeys> kSim{
    yaml::field("ring", &SimKeys::ring).range(1, 64),
    yaml::field("index", &SimKeys::index).range(0, 63),
    yaml::field("width", &SimKeys::width).range(16, 8192),
    yaml::field("height", &SimKeys::height).range(16, 8192),
    yaml::field("paced", &SimKeys::paced),
    yaml::field("frame_code", &SimKeys::frame_code),
    yaml::enum_field("costume", &SimKeys::patterned_costume,
                     {{"plain", false}, {"patterned", true}}),
    yaml::field("stamp", &SimKeys::stamp),
    yaml::field("offset_us", &SimKeys::offset_us).range(-5e5, 5e5),
    yaml::field("jitter_us", &SimKeys::jitter_us).range(0, 1e6),
    yaml::field("readout_us", &SimKeys::readout_us).range(-1, 1e6),
    yaml::field("drop_every", &SimKeys::drop_every).range(0, 1e9),
    yaml::field("buffers", &SimKeys::buffers).range(1, 64),
    yaml::field("motion", &SimKeys::motion,
                [](const yaml::Node& n) -> Expected<sim::Motion> {
                  auto s = n.as_string();
                  if (!s) return std::unexpected(s.error());
                  auto m = sim::parse_motion(*s);
                  if (!m) return n.fail("motion: " + m.error().message);
                  return m;
                }),
    yaml::field("swing_peak_speed", &SimKeys::swing_peak_speed).range(0.05, 10),
    yaml::field("gamma", &SimKeys::gamma).range(0, 4),
    yaml::field("response", &SimKeys::response,
                [](const yaml::Node& n) -> Expected<std::array<double, 3>> {
                  auto v = n.as_doubles(3);
                  if (!v) return std::unexpected(v.error());
                  for (double g : *v)
                    if (!(g >= 0.25 && g <= 4)) return n.fail("each gain must lie in [0.25, 4]");
                  return std::array<double, 3>{(*v)[0], (*v)[1], (*v)[2]};
                }),
};
const yaml::Schema<FileSourceOptions> kFiles{
    yaml::field("path", &FileSourceOptions::path).required().relative_path(),
    yaml::field("fps", &FileSourceOptions::fps).range(1e-3, 1000),
    yaml::field("loop", &FileSourceOptions::loop),
    yaml::field("paced", &FileSourceOptions::paced),
};
const yaml::Schema<AravisOptions> kAravis{
    yaml::field("device", &AravisOptions::device_id),
    yaml::field("pixel_format", &AravisOptions::pixel_format,
                [](const yaml::Node& n) -> Expected<CameraPixelFormat> {
                  auto s = n.as_string();
                  if (!s) return std::unexpected(s.error());
                  auto pf = parse_pixel_format(*s);
                  if (!pf) return n.fail(pf.error().message);
                  return pf;
                }),
    yaml::field("width", &AravisOptions::width).range(0, 32768),
    yaml::field("height", &AravisOptions::height).range(0, 32768),
    yaml::field("fps", &AravisOptions::frame_rate).range(0, 1000),
    yaml::enum_field("trigger", &AravisOptions::trigger,
                     {{"free_run", TriggerMode::free_run},
                      {"software", TriggerMode::software},
                      {"line", TriggerMode::line}}),
    yaml::field("line", &AravisOptions::trigger_line),
    yaml::field("clock_trigger", &AravisOptions::clock_trigger),
    yaml::field("camera_time", &AravisOptions::camera_time),
    yaml::field("buffers", &AravisOptions::buffers).range(2, 256),
    yaml::field("interfaces", &AravisOptions::interfaces),
};

// The source mapping's keys after `type`, by type.
Expected<void> read_source(const yaml::Node& node, CameraKeys& c) {
  auto m = yaml::MapReader::from(node);
  if (!m) return std::unexpected(m.error());
  auto type_node = m->required("type");
  if (!type_node) return std::unexpected(type_node.error());
  auto type = type_node->as_string();
  if (!type) return std::unexpected(type.error());
  c.type = *type;
  c.source = node;
  auto done = [](const auto& keys, auto& out) -> Expected<void> {
    if (!keys) return std::unexpected(keys.error());
    out = *keys;
    return {};
  };
  if (c.type == "sim") return done(kSim.read_fields(*m, {}, true), c.sim);
  if (c.type == "files") return done(kFiles.read_fields(*m, {}, true), c.files);
  if (c.type == "aravis") return done(kAravis.read_fields(*m, {}, true), c.aravis);
  return type_node->fail("unknown source type '" + c.type + "' (expected sim, files or aravis)");
}

Expected<std::vector<CameraKeys>> read_cameras(const yaml::Node& n) {
  auto elements = n.elements();
  if (!elements) return std::unexpected(elements.error());
  if (elements->empty()) return n.fail("expected at least one camera");
  std::vector<CameraKeys> cameras;
  for (const auto& e : *elements) {
    static const yaml::Schema<CameraKeys> kCamera{
        yaml::field("id", &CameraKeys::id).required(),
    };
    auto m = yaml::MapReader::from(e);
    if (!m) return std::unexpected(m.error());
    auto c = kCamera.read_fields(*m);
    if (!c) return std::unexpected(c.error());
    if (c->id.empty() || c->id.size() > 63) return e.fail("id: expected 1..63 characters");
    auto source = m->required("source");
    if (!source) return std::unexpected(source.error());
    if (auto r = read_source(*source, *c); !r) return std::unexpected(r.error());
    if (auto tracking = m->optional("tracking")) {
      auto t = read_tracking(*tracking);
      if (!t) return std::unexpected(t.error());
      c->tracking = std::move(*t);
    }
    if (auto lens = m->optional("lens_table")) {
      auto path = lens->as_string();
      if (!path) return std::unexpected(path.error());
      auto table = read_lens_table(yaml::resolve_path(*lens, *path));
      if (!table) return lens->fail("lens_table: " + table.error().message);
      if (c->tracking) return lens->fail("lens_table: a tracked camera's goes under tracking:");
      c->lens_table = std::move(*table);
    }
    if (auto r = m->finish(); !r) return std::unexpected(r.error());
    for (const auto& other : cameras)
      if (other.id == c->id) return e.fail("duplicate camera id " + c->id);
    cameras.push_back(std::move(*c));
  }
  return cameras;
}

// The camera's source, opened with the studio clock; errors name the source mapping.
Expected<CameraSetup> open_camera(const CameraKeys& c, const FrameClock& clock,
                                  Listeners& listeners) {
  CameraSetup setup;
  setup.id = c.id;
  const yaml::Node& at = *c.source;
  Expected<std::unique_ptr<FrameSource>> src = fail("unknown source type");
  if (c.type == "sim") {
    sim::RingOptions ring;
    ring.count = c.sim.ring;
    ring.width = c.sim.width;
    ring.height = c.sim.height;
    ring.focal_px *= double(ring.width) / 704.0;  // keep the field of view at any size
    SimSourceOptions so;
    so.paced = c.sim.paced;
    so.studio.frame_code = c.sim.frame_code;
    so.studio.patterned_costume = c.sim.patterned_costume;
    if (c.sim.response != std::array<double, 3>{1, 1, 1})
      so.studio.camera_response = {c.sim.response};  // the source's one camera
    so.studio.actor.motion = c.sim.motion;
    so.studio.actor.swing_peak_speed = c.sim.swing_peak_speed;
    so.gamma = c.sim.gamma;
    so.stamp = c.sim.stamp;
    so.offset_ns = int64_t(c.sim.offset_us * 1000);
    so.jitter_ns = int64_t(c.sim.jitter_us * 1000);
    so.drop_every = uint64_t(c.sim.drop_every);
    so.buffer_frames = c.sim.buffers;
    so.camera = sim::ring_cameras(ring)[std::size_t(c.sim.index)];
    so.camera.id = c.id;
    so.clock = clock;
    so.exposure_us = std::min(so.exposure_us, double(clock.period_ns) / 1000.0);
    // A GigE camera unless told: the second half of the exposure, then 8-bit pixels (Bayer) at
    // 1 Gbit/s = 1000 bits per microsecond.
    const double readout_us =
        c.sim.readout_us >= 0 ? c.sim.readout_us
                              : so.exposure_us / 2 + double(c.sim.width) * c.sim.height * 8 / 1000;
    so.readout_ns = c.sim.readout_us >= 0 ? int64_t(readout_us * 1000)
                                          : std::min(int64_t(readout_us * 1000), clock.period_ns);
    setup.calibration = so.camera;
    setup.modelled_readout_ns = so.readout_ns;
    src = SimFrameSource::create(so);
  } else if (c.type == "files") {
    FileSourceOptions fo = c.files;
    fo.id = c.id;
    fo.clock = clock;
    src = FileSource::create(fo);
  } else {
    AravisOptions ao = c.aravis;
    if (ao.trigger == TriggerMode::software && !ao.clock_trigger)
      return at.fail("trigger: software with clock_trigger: false: nothing in the capture "
                     "service would fire the trigger (use clock_trigger: true, or line)");
    ao.camera_id = c.id;
    ao.clock = clock;
    src = AravisSource::open(ao);
  }
  if (!src) return at.fail(src.error().message);
  setup.source = std::move(*src);
  if (c.tracking) {
    // A tracked camera's calibration is per frame; a simulated one renders from it.
    const int w = c.type == "sim" ? c.sim.width : c.type == "aravis" ? c.aravis.width : 0;
    const int h = c.type == "sim" ? c.sim.height : c.type == "aravis" ? c.aravis.height : 0;
    auto tracked = make_tracked_source(std::move(setup.source), *c.tracking, c.id, w, h,
                                       setup.calibration, clock, listeners);
    if (!tracked) return at.fail(tracked.error().message);
    setup.tracked = tracked->get();
    setup.source = std::move(*tracked);
    setup.calibration.reset();
  }
  if (c.lens_table) setup.lens_table = LensTableOptions{c.lens_table->table, c.lens_table->feature_scale};
  return setup;
}

}  // namespace

Expected<CaptureNodeOptions> read_capture_config(yaml::MapReader& config) {
  static const yaml::Schema<CaptureKeys> schema{
      yaml::field("clock", &CaptureKeys::clock,
                  yaml::Schema<ClockKeys>{
                      yaml::field("fps", &ClockKeys::fps).range(0.1, 1000),
                      yaml::field("period_ns", &ClockKeys::period_ns).range(1e6, 1e10),
                      yaml::field("epoch_ns", &ClockKeys::epoch_ns).range(0, 9.2e18),
                  }),
      yaml::field("takes_dir", &CaptureKeys::takes_dir).relative_path(),
      yaml::field("rig", &CaptureKeys::rig).relative_path(),
      yaml::field("keyer", &CaptureKeys::keyer,
                  [](const yaml::Node& n) -> Expected<keyer::KeyerOptions> {
                    auto path = n.as_string();
                    if (!path) return std::unexpected(path.error());
                    return keyer::load_keyer_options(yaml::resolve_path(n, *path));
                  }),
      yaml::field("image", &CaptureKeys::image,
                  yaml::Schema<ImageKeys>{
                      yaml::field("rate", &ImageKeys::rate).range(0, 1000),
                      yaml::field("quality", &ImageKeys::quality).range(1, 100),
                      yaml::field("raw", &ImageKeys::raw),
                  }),
      yaml::field("masks", &CaptureKeys::masks),
      yaml::field("plate_dir", &CaptureKeys::plate_dir).relative_path(),
      yaml::field("recorder", &CaptureKeys::recorder,
                  yaml::Schema<RecorderKeys>{
                      yaml::field("queue_frames", &RecorderKeys::queue_frames).range(1, 10000),
                      yaml::field("sync_interval_ms", &RecorderKeys::sync_interval_ms)
                          .range(1, 60000),
                      yaml::field("disk_mb_s", &RecorderKeys::disk_mb_s).range(0, 1e6),
                  }),
      yaml::field("state_period", &CaptureKeys::state_period).range(0.05, 60),
      yaml::field("cameras", &CaptureKeys::cameras, read_cameras).required(),
  };
  auto keys = schema.read_fields(config);
  if (!keys) return std::unexpected(keys.error());
  CaptureNodeOptions o;
  o.clock = keys->clock.clock();
  o.takes_dir =
      yaml::resolve_path(config.node(), keys->takes_dir.empty() ? "takes" : keys->takes_dir);
  o.queue_frames = std::size_t(keys->recorder.queue_frames);
  o.sync_interval_ms = keys->recorder.sync_interval_ms;
  o.disk_mb_s = keys->recorder.disk_mb_s;
  o.keyer = keys->keyer;
  o.image_rate = keys->image.rate;
  o.jpeg_quality = keys->image.quality;
  o.image_raw = keys->image.raw;
  o.publish_masks = keys->masks;
  o.plate_dir = keys->plate_dir;
  o.state_period = keys->state_period;
  Listeners listeners;
  std::set<const FreeDListener*> reported;
  for (const CameraKeys& c : keys->cameras) {
    auto setup = open_camera(c, o.clock, listeners);
    if (!setup) return std::unexpected(setup.error());
    // One camera per listener reports its counters.
    if (setup->tracked) setup->report_tracker = reported.insert(&setup->tracked->listener()).second;
    o.cameras.push_back(std::move(*setup));
  }
  if (!keys->rig.empty()) {
    auto rig = yaml::read_rig(keys->rig);
    if (!rig) return std::unexpected(rig.error());
    for (auto& c : o.cameras)
      if (const Camera* rc = rig->find_camera(c.id); rc && !c.tracked) c.calibration = *rc;
  }
  return o;
}

runtime::ServiceDefinition capture_service_definition() {
  runtime::ServiceDefinition d;
  d.name = "capture";
  d.summary =
      "Capture server: per camera publishes alpha masks, images and state, applies camera "
      "control and records takes on command. Also: studio-capture verify-take DIR.";
  d.config_help = std::string(kConfigHelp) + kTrackingHelp;
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& ctx) -> Expected<std::unique_ptr<runtime::Node>> {
    auto options = read_capture_config(config);
    if (!options) return std::unexpected(options.error());
    return make_capture_node(std::move(*options), ctx);
  };
  return d;
}

}  // namespace studio::capture::node
