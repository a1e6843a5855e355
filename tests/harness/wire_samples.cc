#include "harness/wire_samples.h"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace studio::testing {
namespace {

using wire::assign;
using wire::set;
using wire::str;
using wire::view;

std::string id(const char* prefix, int seed) { return prefix + std::to_string(seed % 4); }

void stamp(uint64_t& frame, int64_t& capture_ns, int seed) {
  frame = 1000 + uint64_t(seed);
  capture_ns = 1'700'000'000'000'000'000 + int64_t(seed) * 40'000'000;
}

// A rotation about y by angle a (row-major), as a rig would hold.
void rot_y(double (&R)[9], double a) {
  const double c = std::cos(a), s = std::sin(a);
  const double r[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
  std::memcpy(R, r, sizeof r);
}
void K_of(double (&K)[9], int seed) {
  const double k[9] = {800.0 + seed, 0, 352, 0, 800.0 + seed, 288, 0, 0, 1};
  std::memcpy(K, k, sizeof k);
}
void identity4(double (&m)[16], double tx) {
  std::memset(m, 0, sizeof m);
  m[0] = m[5] = m[10] = m[15] = 1;
  m[3] = tx;
}

template <class Seq>
bool seq_same(const Seq& a, const Seq& b) {
  auto x = view(a), y = view(b);
  return x.size() == y.size() &&
         (x.empty() || std::memcmp(x.data(), y.data(), x.size_bytes()) == 0);
}
template <std::size_t N>
bool str_same(const char (&a)[N], const char (&b)[N]) {
  return str(a) == str(b);
}
template <class A>
bool arr_same(const A& a, const A& b) {
  return std::memcmp(&a, &b, sizeof(A)) == 0;
}

}  // namespace

void fill(studio_CameraCalibration& s, int seed) {
  set(s.camera_id, id("cam", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.width = 704;
  s.height = 576;
  K_of(s.K, seed);
  s.rd3 = -0.01 * seed;
  s.rd5 = 0.001;
  rot_y(s.R, 0.1 * seed);
  s.t[0] = 0.5;
  s.t[1] = -1.2;
  s.t[2] = 4.0 + seed;
  s.tracked = seed % 2;
}

void fill(studio_AlphaMask& s, int seed) {
  set(s.camera_id, id("cam", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.width = 64;
  s.height = 48;
  s.encoding = studio_MASK_RUNS;
  std::vector<uint32_t> row_start{0}, runs;
  for (uint32_t y = 0; y < s.height; ++y) {
    if (y >= 10 && y < 40) {  // a body: one run, plus a second (an arm) on some rows
      runs.insert(runs.end(), {20u + seed % 5, 30u + y % 7});
      if (y % 3 == 0) runs.insert(runs.end(), {40u, 44u + seed % 3});
    }
    row_start.push_back(uint32_t(runs.size() / 2));
  }
  assign(s.row_start, row_start);
  assign(s.runs, runs);
  wire::resize(s.data, 0);
}

void fill(studio_CameraImage& s, int seed) {
  set(s.camera_id, id("cam", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.width = 32;
  s.height = 24;
  s.format = studio_IMAGE_RGB8;
  std::vector<uint8_t> px(size_t(s.width) * s.height * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(i * 7 + seed);
  assign(s.data, px);
}

void fill(studio_CameraState& s, int seed) {
  set(s.camera_id, id("cam", seed));
  stamp(s.frame, s.capture_ns, seed);
  std::vector<studio_CameraFeature> f(3);
  std::memset(f.data(), 0, f.size() * sizeof f[0]);
  const char* names[3] = {"ExposureTime", "Gain", "Iris"};
  for (int i = 0; i < 3; ++i) {
    set(f[i].name, names[i]);
    f[i].min = 0;
    f[i].max = 100 * (i + 1);
    f[i].value = 10 + i + seed;
  }
  assign(s.features, f);
  s.fps = 25;
  s.drops = seed;
  s.recording = seed % 2;
  set(s.take, "take" + std::to_string(seed));
  s.state = studio_CAMERA_STREAMING;
  set(s.error, "");
  s.calibration_valid = seed % 3 != 0;
  s.time_source = studio_TIME_CAMERA;
}

void fill(studio_CameraControl& s, int seed) {
  set(s.camera_id, id("cam", seed));
  set(s.feature, "Gain");
  stamp(s.frame, s.capture_ns, seed);
  s.value = 6.5 + seed;
}

void fill(studio_CaptureCommand& s, int seed) {
  set(s.take, "take" + std::to_string(seed));
  stamp(s.frame, s.capture_ns, seed);
  s.action = seed % 2 ? studio_CAPTURE_STOP : studio_CAPTURE_START;
  s.at_frame = s.frame + 50;
}

void fill(studio_SegmentSet& s, int seed) {
  set(s.actor_id, id("actor", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.nu = 8;
  s.nv = 6;
  const float lo[3] = {-1.5f, 0.f, -1.5f}, hi[3] = {1.5f, 2.5f, 1.5f};
  std::memcpy(s.box_min, lo, sizeof lo);
  std::memcpy(s.box_max, hi, sizeof hi);
  s.axis = 1;
  std::vector<uint32_t> start{0};
  std::vector<float> iv;
  for (uint32_t c = 0; c < s.nu * s.nv; ++c) {
    if ((c + seed) % 3 != 0) iv.insert(iv.end(), {0.1f * (c % 4), 1.0f + 0.01f * c});
    if (c % 5 == 0) iv.insert(iv.end(), {2.0f, 2.2f});
    start.push_back(uint32_t(iv.size() / 2));
  }
  assign(s.interval_start, start);
  assign(s.intervals, iv);
}

void fill(studio_ActorMesh& s, int seed) {
  set(s.actor_id, id("actor", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.source_frame = s.frame - 2;
  std::vector<float> v, n;
  std::vector<uint32_t> t;
  for (int i = 0; i < 20; ++i) {
    v.insert(v.end(), {float(i % 5), float(i / 5) + 0.01f * seed, 0.5f});
    n.insert(n.end(), {0.f, 0.f, 1.f});
  }
  for (uint32_t i = 0; i + 6 < 20; ++i) t.insert(t.end(), {i, i + 1, i + 5});
  assign(s.vertices, v);
  assign(s.normals, n);
  assign(s.triangles, t);
}

void fill(studio_HeadPose& s, int seed) {
  set(s.actor_id, id("actor", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.position[0] = 0.1 * seed;
  s.position[1] = 1.7;
  s.position[2] = -0.2;
  s.velocity[0] = 0.5;
  s.confidence = 0.9;
}

void fill(studio_SceneNode& s, int seed) {
  set(s.node_id, id("node", seed));
  stamp(s.frame, s.capture_ns, seed);
  set(s.parent, seed % 4 ? "node0" : "");
  identity4(s.parent_from_node, 0.25 * seed);
  set(s.asset, "sets/studio_" + std::to_string(seed) + ".glb");
  set(s.material, "matte");
  s.flags = studio_SCENE_NODE_VISIBLE;
}

void fill(studio_SceneCommand& s, int seed) {
  stamp(s.frame, s.capture_ns, seed);
  s.verb = studio_SCENE_MOVE_NODE;
  set(s.target, id("node", seed));
  set(s.path, "");
  s.value = 0.5 * seed;
  identity4(s.transform, 1.0 + seed);
}

void fill(studio_ProjectorCalibration& s, int seed) {
  set(s.projector_id, id("proj", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.width = 1920;
  s.height = 1080;
  K_of(s.K, seed);
  rot_y(s.R, -0.2 * seed);
  s.t[2] = 3;
  const double corners[12] = {-2, 0, -3, 2, 0, -3, 2, 2.5, -3, -2, 2.5, -3};
  std::memcpy(s.screen_corners, corners, sizeof corners);
  const double h[9] = {1, 0.01 * seed, 3, 0, 1, -2, 0, 0.0001, 1};
  std::memcpy(s.homography, h, sizeof h);
}

void fill(studio_ServiceStatus& s, int seed) {
  set(s.service, "hull");
  set(s.instance, id("host", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.state = studio_SERVICE_RUNNING;
  set(s.host, "studio-rack-1");
  s.pid = 4242 + seed;
  s.input_hz = 25;
  s.output_hz = 24.5;
  s.latency_ms = 31.5;
  std::vector<studio_Counter> c(2);
  std::memset(c.data(), 0, c.size() * sizeof c[0]);
  set(c[0].name, "masks_missed");
  c[0].value = seed;
  set(c[1].name, "rejected");
  c[1].value = 0;
  assign(s.counters, c);
}

void fill(studio_SceneState& s, int seed) {
  set(s.instance, id("scene", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.state_hash = 0x9e3779b97f4a7c15ull * uint64_t(seed + 1);
  s.nodes_hash = 0xc2b2ae3d27d4eb4full * uint64_t(seed + 3);
  s.node_count = 500 + seed;
  s.animation_count = 2;
  s.commands_accepted = 100 + seed;
  s.commands_rejected = seed;
  s.commands_lost = 0;
  set(s.last_sender, "studioctl");
  s.last_command_id = 7 + seed;
  s.last_accepted = seed % 2 == 0;
  set(s.last_error, seed % 2 == 0 ? "" : "set_parent: 'a' -> 'b' would make a cycle");
}

void fill(studio_ProjectorMask& s, int seed) {
  set(s.projector_id, id("proj", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.width = 96;
  s.height = 54;
  s.step = 1 + seed % 4;
  std::vector<uint32_t> row_start{0}, runs;
  for (uint32_t y = 0; y < s.height; ++y) {
    if (y >= 8 && y < 50) runs.insert(runs.end(), {30u + seed % 7, 44u + y % 5});  // an actor
    if (y >= 20 && y < 26) runs.insert(runs.end(), {60u, 70u + seed % 3});         // an arm
    row_start.push_back(uint32_t(runs.size() / 2));
  }
  assign(s.row_start, row_start);
  assign(s.runs, runs);
}

void fill(studio_ImageRequest& s, int seed) {
  set(s.requester, id("preview", seed));
  stamp(s.frame, s.capture_ns, seed);
  set(s.camera_id, id("cam", seed));
  s.request_id = 40 + uint64_t(seed);
}

void fill(studio_ImageReply& s, int seed) {
  set(s.requester, id("preview", seed));
  set(s.camera_id, id("cam", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.request_id = 40 + uint64_t(seed);
  s.status = studio_IMAGE_REPLY_OK;
  s.width = 16;
  s.height = 12;
  s.format = studio_IMAGE_RGB8;
  std::vector<uint8_t> px(size_t(s.width) * s.height * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(i * 5 + seed);
  assign(s.data, px);
}

bool same(const studio_CameraCalibration& a, const studio_CameraCalibration& b) {
  return str_same(a.camera_id, b.camera_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.width == b.width && a.height == b.height && arr_same(a.K, b.K) && a.rd3 == b.rd3 &&
         a.rd5 == b.rd5 && arr_same(a.R, b.R) && arr_same(a.t, b.t) && a.tracked == b.tracked;
}
bool same(const studio_AlphaMask& a, const studio_AlphaMask& b) {
  return str_same(a.camera_id, b.camera_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.width == b.width && a.height == b.height && a.encoding == b.encoding &&
         seq_same(a.row_start, b.row_start) && seq_same(a.runs, b.runs) && seq_same(a.data, b.data);
}
bool same(const studio_CameraImage& a, const studio_CameraImage& b) {
  return str_same(a.camera_id, b.camera_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.width == b.width && a.height == b.height && a.format == b.format &&
         seq_same(a.data, b.data);
}
bool same(const studio_CameraState& a, const studio_CameraState& b) {
  auto fa = view(a.features), fb = view(b.features);
  if (fa.size() != fb.size()) return false;
  for (size_t i = 0; i < fa.size(); ++i)
    if (!str_same(fa[i].name, fb[i].name) || fa[i].value != fb[i].value || fa[i].min != fb[i].min ||
        fa[i].max != fb[i].max)
      return false;
  return str_same(a.camera_id, b.camera_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.fps == b.fps && a.drops == b.drops && a.recording == b.recording &&
         str_same(a.take, b.take) && a.state == b.state && str_same(a.error, b.error) &&
         a.calibration_valid == b.calibration_valid && a.time_source == b.time_source;
}
bool same(const studio_CameraControl& a, const studio_CameraControl& b) {
  return str_same(a.camera_id, b.camera_id) && str_same(a.feature, b.feature) &&
         a.frame == b.frame && a.capture_ns == b.capture_ns && a.value == b.value;
}
bool same(const studio_CaptureCommand& a, const studio_CaptureCommand& b) {
  return str_same(a.take, b.take) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.action == b.action && a.at_frame == b.at_frame;
}
bool same(const studio_SegmentSet& a, const studio_SegmentSet& b) {
  return str_same(a.actor_id, b.actor_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.nu == b.nu && a.nv == b.nv && arr_same(a.box_min, b.box_min) &&
         arr_same(a.box_max, b.box_max) && a.axis == b.axis &&
         seq_same(a.interval_start, b.interval_start) && seq_same(a.intervals, b.intervals);
}
bool same(const studio_ActorMesh& a, const studio_ActorMesh& b) {
  return str_same(a.actor_id, b.actor_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.source_frame == b.source_frame && seq_same(a.vertices, b.vertices) &&
         seq_same(a.normals, b.normals) && seq_same(a.triangles, b.triangles);
}
bool same(const studio_HeadPose& a, const studio_HeadPose& b) {
  return str_same(a.actor_id, b.actor_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         arr_same(a.position, b.position) && arr_same(a.velocity, b.velocity) &&
         a.confidence == b.confidence;
}
bool same(const studio_SceneNode& a, const studio_SceneNode& b) {
  return str_same(a.node_id, b.node_id) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         str_same(a.parent, b.parent) && arr_same(a.parent_from_node, b.parent_from_node) &&
         str_same(a.asset, b.asset) && str_same(a.material, b.material) && a.flags == b.flags;
}
bool same(const studio_SceneCommand& a, const studio_SceneCommand& b) {
  return a.frame == b.frame && a.capture_ns == b.capture_ns && a.verb == b.verb &&
         str_same(a.target, b.target) && str_same(a.path, b.path) && a.value == b.value &&
         arr_same(a.transform, b.transform);
}
bool same(const studio_ProjectorCalibration& a, const studio_ProjectorCalibration& b) {
  return str_same(a.projector_id, b.projector_id) && a.frame == b.frame &&
         a.capture_ns == b.capture_ns && a.width == b.width && a.height == b.height &&
         arr_same(a.K, b.K) && arr_same(a.R, b.R) && arr_same(a.t, b.t) &&
         arr_same(a.screen_corners, b.screen_corners) && arr_same(a.homography, b.homography);
}
bool same(const studio_ServiceStatus& a, const studio_ServiceStatus& b) {
  auto ca = view(a.counters), cb = view(b.counters);
  if (ca.size() != cb.size()) return false;
  for (size_t i = 0; i < ca.size(); ++i)
    if (!str_same(ca[i].name, cb[i].name) || ca[i].value != cb[i].value) return false;
  return str_same(a.service, b.service) && str_same(a.instance, b.instance) && a.frame == b.frame &&
         a.capture_ns == b.capture_ns && a.state == b.state && str_same(a.host, b.host) &&
         a.pid == b.pid && a.input_hz == b.input_hz && a.output_hz == b.output_hz &&
         a.latency_ms == b.latency_ms;
}

bool same(const studio_ProjectorMask& a, const studio_ProjectorMask& b) {
  return str_same(a.projector_id, b.projector_id) && a.frame == b.frame &&
         a.capture_ns == b.capture_ns && a.width == b.width && a.height == b.height &&
         a.step == b.step && seq_same(a.row_start, b.row_start) && seq_same(a.runs, b.runs);
}

bool same(const studio_SceneState& a, const studio_SceneState& b) {
  return str_same(a.instance, b.instance) && a.frame == b.frame && a.capture_ns == b.capture_ns &&
         a.state_hash == b.state_hash && a.nodes_hash == b.nodes_hash &&
         a.node_count == b.node_count &&
         a.animation_count == b.animation_count && a.commands_accepted == b.commands_accepted &&
         a.commands_rejected == b.commands_rejected && a.commands_lost == b.commands_lost &&
         str_same(a.last_sender, b.last_sender) && a.last_command_id == b.last_command_id &&
         a.last_accepted == b.last_accepted && str_same(a.last_error, b.last_error);
}

void fill(studio_ProjectorFrame& s, int seed) {
  set(s.projector_id, id("proj", seed));
  stamp(s.frame, s.capture_ns, seed);
  s.render_frame = 7 + uint64_t(seed);
  s.render_done_ns = s.capture_ns + 31'000'000;
  s.latency_ms = 31.0;
  s.margin_m = 0.02 + 0.001 * seed;
  s.predicted = seed % 2;
  s.actors = 1 + uint32_t(seed % 2);
  s.eye[0] = 0.1 * seed;
  s.eye[1] = 1.7;
  s.eye[2] = 1.0;
  s.two_pass = seed % 3 == 0;
  s.width = 96;
  s.height = 54;
  std::vector<uint32_t> row_start{0}, runs;
  for (uint32_t y = 0; y < s.height; ++y) {
    if (y >= 8 && y < 50) runs.insert(runs.end(), {40u + seed % 5, 52u + y % 5});
    row_start.push_back(uint32_t(runs.size() / 2));
  }
  assign(s.mask_row_start, row_start);
  assign(s.mask_runs, runs);
  s.thumb_width = 16;
  s.thumb_height = 9;
  std::vector<uint8_t> rgb(16 * 9 * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 7 + seed);
  assign(s.thumbnail, rgb);
}

bool same(const studio_ProjectorFrame& a, const studio_ProjectorFrame& b) {
  return str_same(a.projector_id, b.projector_id) && a.frame == b.frame &&
         a.capture_ns == b.capture_ns && a.render_frame == b.render_frame &&
         a.render_done_ns == b.render_done_ns && a.latency_ms == b.latency_ms &&
         a.margin_m == b.margin_m && a.predicted == b.predicted && a.actors == b.actors &&
         arr_same(a.eye, b.eye) && a.two_pass == b.two_pass && a.width == b.width &&
         a.height == b.height && seq_same(a.mask_row_start, b.mask_row_start) &&
         seq_same(a.mask_runs, b.mask_runs) && a.thumb_width == b.thumb_width &&
         a.thumb_height == b.thumb_height && seq_same(a.thumbnail, b.thumbnail);
}

bool same(const studio_ImageRequest& a, const studio_ImageRequest& b) {
  return str_same(a.requester, b.requester) && a.frame == b.frame &&
         a.capture_ns == b.capture_ns && str_same(a.camera_id, b.camera_id) &&
         a.request_id == b.request_id;
}

bool same(const studio_ImageReply& a, const studio_ImageReply& b) {
  return str_same(a.requester, b.requester) && str_same(a.camera_id, b.camera_id) &&
         a.frame == b.frame && a.capture_ns == b.capture_ns && a.request_id == b.request_id &&
         a.status == b.status && a.width == b.width && a.height == b.height &&
         a.format == b.format && seq_same(a.data, b.data);
}

}  // namespace studio::testing
