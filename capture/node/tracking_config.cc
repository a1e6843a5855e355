#include "tracking_config.h"

#include <cmath>

#include "yaml_io/options.h"

namespace studio::capture::node {

const char kTrackingHelp[] =
    "      aravis trigger: software fires the camera's TriggerSoftware\n"
    "                                    at every studio frame (mid-frame, on the studio clock;\n"
    "                                    clock_trigger: false leaves it to nobody: refused);\n"
    "                                    frame numbers come from the camera's timestamp latched\n"
    "                                    to the host clock (GenICam TimestampLatch when present,\n"
    "                                    else the fastest arrivals), host arrival time only when\n"
    "                                    the camera stamps nothing or camera_time: false;\n"
    "                                    CameraState time_source says which\n"
    "      lens_table: FILE               a fixed camera with remote zoom/focus: its intrinsics\n"
    "                                    follow the Zoom/Focus features through the table\n"
    "                                    (format under tracking:, counts = feature value x\n"
    "                                    feature_scale) and are republished; without one a\n"
    "                                    Zoom/Focus change marks the calibration invalid\n"
    "                                    (CameraState calibration_valid false; the hull leaves\n"
    "                                    the camera out) until the values return\n"
    "      tracking:                     a Free-D (D1) tracked camera: per-frame calibration\n"
    "        freed: {port: 40000, bind: 0.0.0.0, id: 1, shared: false, group: ADDR}\n"
    "                                    UDP port and address, D1 camera id byte; shared: true\n"
    "                                    lets several processes bind the port (the tracker must\n"
    "                                    send broadcast or multicast; group: joins a multicast\n"
    "                                    group), each keeping its own ids\n"
    "        world_from_tracker: {R: [9 row-major], t: [3]}   default identity\n"
    "        head_from_lens: {R: [9], t: [3]}                 default identity\n"
    "        lens: {K: [9], radial: [rd3, rd5]}   a fixed lens, or\n"
    "        lens_table: FILE.yaml        zoom/focus counts -> intrinsics, interpolated:\n"
    "                                    {width, height, samples: [{zoom, focus, fx, fy, cx, cy,\n"
    "                                    rd3, rd5}]} (a simulated camera defaults to its own)\n"
    "        delay_frames: 0             the tracker's data for frame f arrives in frame f+N\n"
    "      Packets are matched to frames by arrival time; each frame publishes CameraCalibration\n"
    "      (tracked: true) and takes record it (calibration file). Malformed, unknown-id,\n"
    "      too-late and duplicate packets are counted (freed_rejected_<reason>); a tracker silent\n"
    "      for 0.5 s makes CameraState say so (calibration_valid false, error text).\n";

namespace {

struct RigidKeys {
  std::vector<double> R{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::vector<double> t{0, 0, 0};
};
struct LensKeys {
  std::vector<double> K;
  std::vector<double> radial{0, 0};
};
struct FreeDKeys {
  int port = kFreeDDefaultPort;
  std::string bind = "0.0.0.0";
  int id = 0;
  bool shared = false;
  std::string group;
};
struct Keys {
  FreeDKeys freed;
  RigidKeys world_from_tracker, head_from_lens;
  std::optional<LensKeys> lens;
  std::string lens_table;
  int delay_frames = 0;
};

const yaml::Schema<RigidKeys> kRigid{
    yaml::field("R", &RigidKeys::R).size(9),
    yaml::field("t", &RigidKeys::t).size(3),
};

Expected<Rigid3> to_rigid(const RigidKeys& k, const yaml::Node& at, const char* what) {
  Eigen::Matrix3d R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = k.R[std::size_t(i)];
  if (!R.allFinite() || (R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      R.determinant() < 0)
    return at.fail(std::string(what) + ".R: not a rotation matrix");
  return Rigid3(R, Eigen::Vector3d(k.t[0], k.t[1], k.t[2]));
}

}  // namespace

Expected<TrackingKeys> read_tracking(const yaml::Node& node) {
  static const yaml::Schema<Keys> schema{
      yaml::field("freed", &Keys::freed,
                  yaml::Schema<FreeDKeys>{
                      yaml::field("port", &FreeDKeys::port).range(0, 65535),
                      yaml::field("bind", &FreeDKeys::bind),
                      yaml::field("id", &FreeDKeys::id).range(0, 255),
                      yaml::field("shared", &FreeDKeys::shared),
                      yaml::field("group", &FreeDKeys::group),
                  }),
      yaml::field("world_from_tracker", &Keys::world_from_tracker, kRigid),
      yaml::field("head_from_lens", &Keys::head_from_lens, kRigid),
      yaml::field("lens", &Keys::lens,
                  [](const yaml::Node& n) -> Expected<std::optional<LensKeys>> {
                    static const yaml::Schema<LensKeys> s{
                        yaml::field("K", &LensKeys::K).required().size(9),
                        yaml::field("radial", &LensKeys::radial).size(2),
                    };
                    auto k = s.read(n);
                    if (!k) return std::unexpected(k.error());
                    return std::optional<LensKeys>(*k);
                  }),
      yaml::field("lens_table", &Keys::lens_table).relative_path(),
      yaml::field("delay_frames", &Keys::delay_frames).range(0, 50),
  };
  auto k = schema.read(node);
  if (!k) return std::unexpected(k.error());
  if (k->lens && !k->lens_table.empty())
    return node.fail("tracking: give lens or lens_table, not both");
  TrackingKeys t;
  t.listener.port = uint16_t(k->freed.port);
  t.listener.bind_address = k->freed.bind;
  t.listener.shared = k->freed.shared;
  t.listener.group = k->freed.group;
  if (auto v = t.listener.validate(); !v) return node.fail("tracking.freed: " + v.error().message);
  t.freed_id = k->freed.id;
  auto w = to_rigid(k->world_from_tracker, node, "world_from_tracker");
  if (!w) return std::unexpected(w.error());
  auto h = to_rigid(k->head_from_lens, node, "head_from_lens");
  if (!h) return std::unexpected(h.error());
  t.world_from_tracker = *w;
  t.head_from_lens = *h;
  t.delay_frames = k->delay_frames;
  if (k->lens) {
    const auto& K = k->lens->K;
    LensSample s;
    s.fx = K[0], s.fy = K[4], s.cx = K[2], s.cy = K[5];
    s.rd3 = k->lens->radial[0], s.rd5 = k->lens->radial[1];
    t.lens = LensTable{{s}};
  } else if (!k->lens_table.empty()) {
    auto table = read_lens_table(k->lens_table);
    if (!table) return node.fail("tracking.lens_table: " + table.error().message);
    t.lens = table->table;
    t.lens_width = table->width;
    t.lens_height = table->height;
  }
  if (t.lens)
    if (auto v = t.lens->validate(); !v) return node.fail("tracking: " + v.error().message);
  return t;
}

Expected<LensTableFile> read_lens_table(const std::string& path) {
  struct File {
    int width = 0, height = 0;
    double feature_scale = 1;
    std::vector<LensSample> samples;
  };
  static const yaml::Schema<LensSample> kSample{
      yaml::field("zoom", &LensSample::zoom).required(),
      yaml::field("focus", &LensSample::focus).required(),
      yaml::field("fx", &LensSample::fx).required().min(1e-6),
      yaml::field("fy", &LensSample::fy).required().min(1e-6),
      yaml::field("cx", &LensSample::cx).required(),
      yaml::field("cy", &LensSample::cy).required(),
      yaml::field("rd3", &LensSample::rd3),
      yaml::field("rd5", &LensSample::rd5),
  };
  static const yaml::Schema<File> kFile{
      yaml::field("width", &File::width).required().range(1, 32768),
      yaml::field("height", &File::height).required().range(1, 32768),
      yaml::field("feature_scale", &File::feature_scale).range(1e-9, 1e9),
      yaml::field("samples", &File::samples,
                  [](const yaml::Node& n) -> Expected<std::vector<LensSample>> {
                    auto elements = n.elements();
                    if (!elements) return std::unexpected(elements.error());
                    if (elements->empty()) return n.fail("expected at least one sample");
                    std::vector<LensSample> out;
                    for (const auto& e : *elements) {
                      auto s = kSample.read(e);
                      if (!s) return std::unexpected(s.error());
                      out.push_back(*s);
                    }
                    return out;
                  })
          .required(),
  };
  auto f = kFile.read_file(path);
  if (!f) return std::unexpected(f.error());
  LensTableFile out{LensTable{f->samples}, f->width, f->height, f->feature_scale};
  if (auto v = out.table.validate(); !v) return fail(path + ": " + v.error().message);
  return out;
}

Expected<std::shared_ptr<FreeDListener>> Listeners::get(FreeDListenerOptions options) {
  const auto key = std::make_pair(options.bind_address, options.port);
  if (auto it = by_port_.find(key); it != by_port_.end()) {
    const auto& have = it->second->options();
    if (have.shared != options.shared || have.group != options.group)
      return fail("free-d " + options.bind_address + ":" + std::to_string(options.port) +
                  ": cameras on one port must agree on shared and group");
    return it->second;
  }
  auto l = FreeDListener::create(options);
  if (!l) return std::unexpected(l.error());
  std::shared_ptr<FreeDListener> shared = std::move(*l);
  by_port_[key] = shared;
  return shared;
}

Expected<std::unique_ptr<TrackedSource>> make_tracked_source(
    std::unique_ptr<FrameSource> inner, const TrackingKeys& keys, const std::string& camera_id,
    int width, int height, const std::optional<Camera>& default_lens, const FrameClock& clock,
    Listeners& listeners) {
  TrackedSourceOptions o;
  o.clock = clock;
  o.delay_frames = keys.delay_frames;
  o.camera.camera_id = camera_id;
  o.camera.freed_id = uint8_t(keys.freed_id);
  o.camera.world_from_tracker = keys.world_from_tracker;
  o.camera.head_from_lens = keys.head_from_lens;
  o.camera.width = keys.lens_width > 0 ? keys.lens_width : width;
  o.camera.height = keys.lens_height > 0 ? keys.lens_height : height;
  if (keys.lens) {
    o.camera.lens = *keys.lens;
  } else if (default_lens) {
    LensSample s;
    const Intrinsics& in = default_lens->intrinsics;
    s.fx = in.fx, s.fy = in.fy, s.cx = in.cx, s.cy = in.cy;
    if (default_lens->distortion.model == Distortion::Model::radial)
      s.rd3 = default_lens->distortion.rd3, s.rd5 = default_lens->distortion.rd5;
    o.camera.lens = LensTable{{s}};
  } else {
    return fail("tracking: lens or lens_table is required for this source");
  }
  if (o.camera.width <= 0 || o.camera.height <= 0)
    return fail(
        "tracking: the image size is unknown: give the source's width and height or a "
        "lens_table");
  if (auto v = o.validate(); !v) return fail("tracking: " + v.error().message);
  FreeDListenerOptions lo = keys.listener;
  lo.clock = clock;
  auto listener = listeners.get(lo);
  if (!listener) return fail("tracking: " + listener.error().message);
  if ((*listener)->tracks(o.camera.freed_id))
    return fail("tracking: free-d id " + std::to_string(keys.freed_id) +
                " is already taken by another camera on this port");
  return std::make_unique<TrackedSource>(std::move(inner), *listener, o);
}

}  // namespace studio::capture::node
