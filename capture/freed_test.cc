// Free-D D1 decoding (the issue's test vector, exact), rejection reasons, the pose and lens
// mapping to studio::Camera, the UDP listener on loopback and the per-frame calibration
// decorator.
#include "capture/freed.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <deque>
#include <vector>

#include "capture/freed_listener.h"
#include "core/clock.h"

namespace studio::capture {
namespace {

const std::vector<uint8_t> kVector = {0xd1, 0x00, 0xdf, 0x78, 0xaa, 0x00, 0x47, 0xef, 0x00, 0x00,
                                      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                      0x00, 0x40, 0x00, 0x00, 0x15, 0x01, 0xd1, 0xff, 0x12};

TEST(FreeD, DecodesTheIssueTestVectorExactly) {
  ASSERT_EQ(kVector.size(), kFreeDD1Size);
  auto p = decode_freed(kVector);
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_EQ(p->camera_id, 0);
  EXPECT_EQ(p->pan_deg, -2131798.0 / 32768.0);  // 0xdf78aa as int24
  EXPECT_NEAR(p->pan_deg, -65.0573, 5e-5);
  EXPECT_EQ(p->tilt_deg, 18415.0 / 32768.0);
  EXPECT_NEAR(p->tilt_deg, 0.56198, 5e-6);
  EXPECT_EQ(p->roll_deg, 0.0);
  EXPECT_EQ(p->x_mm, 0.0);
  EXPECT_EQ(p->y_mm, 0.0);
  EXPECT_EQ(p->z_mm, 0.0);
  EXPECT_EQ(p->zoom, 16384u);
  EXPECT_EQ(p->focus, 5377u);
  EXPECT_EQ(p->spare, 0xd1ff);
  EXPECT_EQ(freed_checksum(std::span(kVector).first(28)), 0x12);
}

TEST(FreeD, EncodeRoundTripsAndReproducesTheVector) {
  auto p = decode_freed(kVector);
  ASSERT_TRUE(p);
  const auto bytes = encode_freed(*p);
  EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), kVector.begin()));

  FreeDPacket q;
  q.camera_id = 7;
  q.pan_deg = 179.5;
  q.tilt_deg = -89.25;
  q.roll_deg = 12.0 / 32768.0;
  q.x_mm = -131072.0;  // int24 minimum in 1/64 mm
  q.y_mm = 1234.5;
  q.z_mm = 1.0 / 64.0;
  q.zoom = 0xFFFFFF;
  q.focus = 1;
  q.spare = 0xBEEF;
  auto r = decode_freed(encode_freed(q));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->camera_id, 7);
  EXPECT_EQ(r->pan_deg, q.pan_deg);
  EXPECT_EQ(r->tilt_deg, q.tilt_deg);
  EXPECT_EQ(r->roll_deg, q.roll_deg);
  EXPECT_EQ(r->x_mm, q.x_mm);
  EXPECT_EQ(r->y_mm, q.y_mm);
  EXPECT_EQ(r->z_mm, q.z_mm);
  EXPECT_EQ(r->zoom, q.zoom);
  EXPECT_EQ(r->focus, q.focus);
  EXPECT_EQ(r->spare, q.spare);
  // Out-of-range values saturate instead of wrapping.
  q.x_mm = 1e9;
  q.pan_deg = NAN;
  r = decode_freed(encode_freed(q));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->x_mm, 8388607.0 / 64.0);
  EXPECT_EQ(r->pan_deg, 0.0);
}

TEST(FreeD, RejectsWithAReason) {
  FreeDReject reason{};
  for (std::size_t n : {0, 1, 28, 30, 64}) {
    std::vector<uint8_t> bytes(n, 0xd1);
    auto p = decode_freed(bytes, &reason);
    ASSERT_FALSE(p) << n;
    EXPECT_EQ(reason, FreeDReject::wrong_length) << n;
    EXPECT_NE(p.error().message.find("29"), std::string::npos);
  }
  auto d2 = kVector;
  d2[0] = 0xd2;
  d2[28] = freed_checksum(std::span(d2).first(28));  // valid checksum, wrong type
  EXPECT_FALSE(decode_freed(d2, &reason));
  EXPECT_EQ(reason, FreeDReject::unknown_type);
  EXPECT_NE(decode_freed(d2).error().message.find("0xD2"), std::string::npos);
  // Any single corrupted byte after the type breaks the checksum.
  for (std::size_t i = 1; i < kFreeDD1Size; ++i) {
    auto bad = kVector;
    bad[i] ^= 0x20;
    EXPECT_FALSE(decode_freed(bad, &reason)) << i;
    EXPECT_EQ(reason, FreeDReject::bad_checksum) << i;
  }
  EXPECT_STREQ(to_string(FreeDReject::bad_checksum), "bad_checksum");
}

LensTable fixed_lens() { return LensTable{{LensSample{0, 0, 800, 800, 352, 288, 0, 0}}}; }

FreeDCameraOptions camera_options() {
  FreeDCameraOptions o;
  o.camera_id = "tracked0";
  o.freed_id = 3;
  o.width = 704;
  o.height = 576;
  o.lens = fixed_lens();
  return o;
}

Camera camera_at(double pan, double tilt, double roll, double x = 0, double y = 0, double z = 0,
                 const FreeDCameraOptions& options = camera_options()) {
  FreeDPacket p;
  p.camera_id = options.freed_id;
  p.pan_deg = pan;
  p.tilt_deg = tilt;
  p.roll_deg = roll;
  p.x_mm = x;
  p.y_mm = y;
  p.z_mm = z;
  return freed_to_camera(p, options);
}

// Camera +x (image right) in the world frame.
Eigen::Vector3d right_in_world(const Camera& c) {
  return c.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitX();
}

TEST(FreeD, PoseFollowsTheDocumentedAxisMapping) {
  ASSERT_TRUE(camera_options().validate());
  const double eps = 1e-12;
  // Rest: looking along studio -z (Free-D +Y), image right = +x, image down = -y.
  Camera c = camera_at(0, 0, 0);
  EXPECT_TRUE(c.axis_in_world().isApprox(Eigen::Vector3d(0, 0, -1), eps));
  EXPECT_TRUE(right_in_world(c).isApprox(Eigen::Vector3d(1, 0, 0), eps));
  EXPECT_LT(c.cam_from_world.R().determinant(), 1 + eps);
  EXPECT_GT(c.cam_from_world.R().determinant(), 1 - eps);
  // Pan +90 (clockwise from above) turns to +x; tilt +90 looks up; roll +90 (clockwise from
  // behind) turns image right to studio down.
  EXPECT_TRUE(camera_at(90, 0, 0).axis_in_world().isApprox(Eigen::Vector3d(1, 0, 0), eps));
  EXPECT_TRUE(camera_at(-90, 0, 0).axis_in_world().isApprox(Eigen::Vector3d(-1, 0, 0), eps));
  EXPECT_TRUE(camera_at(0, 90, 0).axis_in_world().isApprox(Eigen::Vector3d(0, 1, 0), eps));
  EXPECT_TRUE(right_in_world(camera_at(0, 0, 90)).isApprox(Eigen::Vector3d(0, -1, 0), eps));
  // Pan then tilt: pan 90 + tilt 45 looks right and up.
  EXPECT_TRUE(camera_at(90, 45, 0).axis_in_world().isApprox(
      Eigen::Vector3d(std::sqrt(0.5), std::sqrt(0.5), 0), eps));
  // Position: X → x, Y → -z, Z (height) → y, millimetres → metres.
  c = camera_at(0, 0, 0, 1000, 2000, 1500);
  EXPECT_TRUE(c.centre_in_world().isApprox(Eigen::Vector3d(1, 1.5, -2), eps));
  // A point 3 m straight ahead projects to the principal point.
  Eigen::Vector2d px;
  ASSERT_TRUE(c.project(Eigen::Vector3d(1, 1.5, -5), &px));
  EXPECT_NEAR(px.x(), 352, 1e-9);
  EXPECT_NEAR(px.y(), 288, 1e-9);
  // A point above the axis appears higher in the image (smaller v).
  ASSERT_TRUE(c.project(Eigen::Vector3d(1, 2.5, -5), &px));
  EXPECT_NEAR(px.y(), 288 - 800.0 / 3.0, 1e-9);
}

TEST(FreeD, MountingOffsetAndTrackerPlacement) {
  FreeDCameraOptions o = camera_options();
  // Entrance pupil 20 cm in front of and 10 cm above the tracked point (head axes: z backward).
  o.head_from_lens = Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0.1, -0.2));
  Camera c = camera_at(90, 0, 0, 0, 0, 1000, o);  // panned to +x, 1 m high
  EXPECT_TRUE(c.centre_in_world().isApprox(Eigen::Vector3d(0.2, 1.1, 0), 1e-12));
  EXPECT_TRUE(c.axis_in_world().isApprox(Eigen::Vector3d(1, 0, 0), 1e-12));
  // Tracker origin surveyed at (5, 0, -3) and turned 90° about the vertical.
  o.head_from_lens = Rigid3();
  o.world_from_tracker =
      Rigid3(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix(),
             Eigen::Vector3d(5, 0, -3));
  c = camera_at(0, 0, 0, 1000, 0, 0, o);  // tracker x = 1 m → studio -z after the 90° turn
  EXPECT_TRUE(c.centre_in_world().isApprox(Eigen::Vector3d(5, 0, -4), 1e-12));
  EXPECT_TRUE(c.axis_in_world().isApprox(Eigen::Vector3d(-1, 0, 0), 1e-12));
}

TEST(FreeD, LensTableInterpolatesZoomAndFocus) {
  LensTable t;
  // Two zoom levels: wide (zoom 0) with two focus samples, tele (zoom 1000) with three.
  t.samples = {{0, 0, 500, 510, 350, 290, -0.1, 0.01},
               {0, 1000, 520, 530, 350, 290, -0.12, 0.01},
               {1000, 0, 1500, 1510, 354, 286, 0.0, 0.0},
               {1000, 400, 1540, 1550, 354, 286, 0.0, 0.0},
               {1000, 1000, 1600, 1610, 354, 286, 0.02, 0.0}};
  ASSERT_TRUE(t.validate());
  LensSample s = t.at(0, 500);
  EXPECT_DOUBLE_EQ(s.fx, 510);
  EXPECT_DOUBLE_EQ(s.rd3, -0.11);
  s = t.at(1000, 200);
  EXPECT_DOUBLE_EQ(s.fx, 1520);
  s = t.at(1000, 700);
  EXPECT_DOUBLE_EQ(s.fx, 1570);
  // Between zoom levels: focus first within each level, then zoom.
  s = t.at(250, 500);  // wide: 510, tele at focus 500: 1540 + 60/6 = 1550
  EXPECT_DOUBLE_EQ(s.fx, 510 + 0.25 * (1550 - 510));
  EXPECT_DOUBLE_EQ(s.cx, 351);
  EXPECT_DOUBLE_EQ(s.cy, 289);
  EXPECT_EQ(s.zoom, 250u);
  // Clamped outside the table.
  EXPECT_DOUBLE_EQ(t.at(5000, 5000).fx, 1600);
  EXPECT_DOUBLE_EQ(t.at(0, 0).fy, 510);
  // A fixed lens.
  EXPECT_DOUBLE_EQ(fixed_lens().at(123, 456).fx, 800);

  // The test vector's zoom (16384) and focus (5377) through a table reaching further.
  LensTable wide_tele{{{0, 0, 600, 600, 352, 288, 0, 0}, {32768, 0, 2600, 2600, 352, 288, 0, 0}}};
  FreeDCameraOptions o = camera_options();
  o.lens = wide_tele;
  auto p = decode_freed(kVector);
  Camera c = freed_to_camera(*p, o);
  EXPECT_DOUBLE_EQ(c.intrinsics.fx, 1600);
  EXPECT_NEAR(c.axis_in_world().y(), std::sin(p->tilt_deg * M_PI / 180), 1e-12);
  EXPECT_EQ(c.distortion.model, Distortion::Model::none);
  EXPECT_EQ(freed_to_camera(decode_freed(encode_freed(FreeDPacket{})).value(),
                            [&] {
                              auto q = camera_options();
                              q.lens = t;
                              return q;
                            }())
                .distortion.model,
            Distortion::Model::radial);
}

TEST(FreeD, LensTableAndOptionsValidation) {
  EXPECT_FALSE(LensTable{}.validate());
  LensTable t = fixed_lens();
  t.samples[0].fx = 0;
  EXPECT_NE(t.validate().error().message.find("positive"), std::string::npos);
  t = fixed_lens();
  t.samples[0].rd3 = NAN;
  EXPECT_FALSE(t.validate());
  t = fixed_lens();
  t.samples.push_back(t.samples[0]);
  EXPECT_NE(t.validate().error().message.find("same zoom"), std::string::npos);
  FreeDCameraOptions o = camera_options();
  o.width = 0;
  EXPECT_FALSE(o.validate());
  o = camera_options();
  o.camera_id.clear();
  EXPECT_FALSE(o.validate());
  o = camera_options();
  o.head_from_lens.translation.x() = INFINITY;
  EXPECT_FALSE(o.validate());
  EXPECT_FALSE((FreeDListenerOptions{"not-an-address", 0, 64}).validate());
  EXPECT_FALSE((FreeDListenerOptions{"127.0.0.1", 0, 0}).validate());
}

// Sends datagrams to 127.0.0.1:port from a plain UDP socket.
class Sender {
 public:
  explicit Sender(uint16_t port) : fd_(socket(AF_INET, SOCK_DGRAM, 0)) {
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    inet_pton(AF_INET, "127.0.0.1", &to_.sin_addr);
  }
  ~Sender() { close(fd_); }
  void send(std::span<const uint8_t> bytes) {
    ASSERT_EQ(
        sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to_), sizeof to_),
        ssize_t(bytes.size()));
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

TEST(FreeDListener, CountsRejectionsAndKeepsTheNewestPerCamera) {
  auto listener = FreeDListener::create({"127.0.0.1", 0, 8});
  ASSERT_TRUE(listener) << listener.error().message;
  ASSERT_NE((*listener)->port(), 0);
  Sender sender((*listener)->port());

  sender.send(kVector);  // camera 0
  FreeDPacket p;
  p.camera_id = 3;
  for (int i = 0; i < 20; ++i) {  // camera 3: pans 0..19, history keeps 8
    p.pan_deg = i;
    sender.send(encode_freed(p));
  }
  std::vector<uint8_t> too_long(3000, 0xd1), too_short(28, 0xd1), empty;
  sender.send(too_long);
  sender.send(too_short);
  sender.send(empty);
  auto wrong_type = kVector;
  wrong_type[0] = 0xd0;
  sender.send(wrong_type);
  auto bad_sum = kVector;
  bad_sum[28] ^= 1;
  sender.send(bad_sum);
  sender.send(bad_sum);

  ASSERT_TRUE((*listener)->wait_for_datagrams(27, std::chrono::seconds(10)));
  const FreeDListenerStats s = (*listener)->stats();
  EXPECT_EQ(s.datagrams, 27u);
  EXPECT_EQ(s.accepted, 21u);
  EXPECT_EQ(s.rejected[size_t(FreeDReject::wrong_length)], 3u);
  EXPECT_EQ(s.rejected[size_t(FreeDReject::unknown_type)], 1u);
  EXPECT_EQ(s.rejected[size_t(FreeDReject::bad_checksum)], 2u);
  EXPECT_EQ(s.rejected_total(), 6u);

  auto cam0 = (*listener)->latest(0);
  ASSERT_TRUE(cam0);
  EXPECT_EQ(cam0->packet.zoom, 16384u);
  auto cam3 = (*listener)->latest(3);
  ASSERT_TRUE(cam3);
  EXPECT_EQ(cam3->packet.pan_deg, 19.0);
  EXPECT_GT(cam3->arrival_ns, 1'600'000'000'000'000'000);  // CLOCK_REALTIME, after 2020
  EXPECT_FALSE((*listener)->latest(1));
}

TEST(FreeDListener, ReportsAPortInUse) {
  auto first = FreeDListener::create({"127.0.0.1", 0, 8});
  ASSERT_TRUE(first);
  auto second = FreeDListener::create({"127.0.0.1", (*first)->port(), 8});
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("bind 127.0.0.1"), std::string::npos);
}

// A scripted inner source: frames at given capture times.
class ScriptedSource : public FrameSource {
 public:
  explicit ScriptedSource(std::deque<int64_t> times, int w = 704, int h = 576)
      : times_(std::move(times)), w_(w), h_(h) {}
  const std::string& id() const override { return id_; }
  Expected<void> start() override { return {}; }
  void stop() override {}
  Expected<std::optional<Frame>> next(std::chrono::milliseconds) override {
    if (times_.empty()) return std::optional<Frame>();
    Frame f;
    f.capture_ns = times_.front();
    f.frame = uint64_t(times_.front() / 40'000'000);
    f.image = Image<Rgb8>(w_, h_);
    times_.pop_front();
    return std::optional<Frame>(std::move(f));
  }
  SourceStats stats() const override { return {}; }

 private:
  std::string id_ = "scripted";
  std::deque<int64_t> times_;
  int w_, h_;
};

TEST(TrackedSource, AttachesThePacketOfItsFrameByArrivalTimeAndCountsTheRest) {
  FreeDListenerOptions lo{"127.0.0.1", 0, 64};
  lo.clock.period_ns = 40'000'000;
  auto created = FreeDListener::create(lo);
  ASSERT_TRUE(created);
  std::shared_ptr<FreeDListener> listener = std::move(*created);
  TrackedSourceOptions options;
  options.camera = camera_options();
  options.clock = lo.clock;
  options.delay_frames = 1;
  ASSERT_TRUE(options.validate());
  // Frames 2, 3, 5 and 6 (the scripted source numbers frames by 40 ms).
  TrackedSource source(std::make_unique<ScriptedSource>(std::deque<int64_t>{
                           80'000'000, 121'000'000, 205'000'000, 250'000'000}),
                       listener, options);
  ASSERT_TRUE(source.start());
  // The tracker lags one frame: the packet of frame i (pan = i) arrives 5 ms into frame i + 1.
  FreeDPacket p;
  p.camera_id = 3;
  auto send = [&](double pan, int64_t arrival) {
    p.pan_deg = pan;
    listener->handle_datagram(encode_freed(p), arrival);
  };
  for (int i : {2, 3, 6}) send(i, int64_t(i + 1) * 40'000'000 + 5'000'000);
  send(99, 3 * 40'000'000 + 30'000'000);  // a second packet for frame 2: the first counts
  p.camera_id = 4;
  send(50, 3 * 40'000'000 + 31'000'000);  // no camera takes id 4
  p.camera_id = 3;
  std::vector<std::optional<Camera>> calibrations;
  for (int i = 0; i < 4; ++i) {
    auto f = source.next(std::chrono::milliseconds(10));
    ASSERT_TRUE(f && *f);
    calibrations.push_back((*f)->calibration);
    if (i == 1) send(77, 4 * 40'000'000 + 1'000'000);  // for frame 3, after it was delivered
  }
  auto axis = [](double deg) {
    return Eigen::Vector3d(std::sin(deg * M_PI / 180), 0, -std::cos(deg * M_PI / 180));
  };
  ASSERT_TRUE(calibrations[0]);
  EXPECT_EQ(calibrations[0]->id, "tracked0");
  EXPECT_TRUE(calibrations[0]->axis_in_world().isApprox(axis(2), 1e-9));
  ASSERT_TRUE(calibrations[1]);
  EXPECT_TRUE(calibrations[1]->axis_in_world().isApprox(axis(3), 1e-9));
  EXPECT_FALSE(calibrations[2]);  // frame 5: no packet
  ASSERT_TRUE(calibrations[3]);
  EXPECT_TRUE(calibrations[3]->axis_in_world().isApprox(axis(6), 1e-9));
  EXPECT_EQ(source.untracked(), 1u);
  const FreeDListenerStats s = listener->stats();
  EXPECT_EQ(s.accepted, 3u);
  EXPECT_EQ(s.rejected[size_t(FreeDReject::duplicate)], 1u);
  EXPECT_EQ(s.rejected[size_t(FreeDReject::unknown_id)], 1u);
  EXPECT_EQ(s.rejected[size_t(FreeDReject::too_late)], 1u);
  // Silence: the last packet arrived at 285 ms (1970): long silent now; fresh just after it.
  EXPECT_TRUE(source.status(realtime_ns()).silent);
  EXPECT_FALSE(source.status(7 * 40'000'000 + 5'000'000 + 100'000'000).silent);

  // A frame of another size than the lens table's is refused with one line.
  TrackedSource wrong(std::make_unique<ScriptedSource>(std::deque<int64_t>{40'000'000}, 640, 480),
                      listener, options);
  auto f = wrong.next(std::chrono::milliseconds(10));
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("640x480"), std::string::npos);
}

TEST(FreeDListener, SharedPortGivesEveryListenerEachBroadcast) {
  FreeDListenerOptions lo{"0.0.0.0", 0, 8};
  lo.shared = true;
  auto a = FreeDListener::create(lo);
  ASSERT_TRUE(a) << a.error().message;
  lo.port = (*a)->port();
  auto b = FreeDListener::create(lo);
  ASSERT_TRUE(b) << b.error().message;
  (*a)->track(1, 0);
  (*b)->track(2, 0);
  // Unshared, the same port is refused (positive control of the sharing).
  FreeDListenerOptions unshared{"0.0.0.0", lo.port, 8};
  EXPECT_FALSE(FreeDListener::create(unshared));

  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  const int one = 1;
  ASSERT_EQ(setsockopt(fd, SOL_SOCKET, SO_BROADCAST, &one, sizeof one), 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(lo.port);
  inet_pton(AF_INET, "127.255.255.255", &to.sin_addr);
  for (uint8_t id : {1, 2}) {
    FreeDPacket p;
    p.camera_id = id;
    p.pan_deg = id;
    const auto bytes = encode_freed(p);
    ASSERT_EQ(sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to),
                     sizeof to),
              ssize_t(bytes.size()));
  }
  close(fd);
  ASSERT_TRUE((*a)->wait_for_datagrams(2, std::chrono::seconds(10)));
  ASSERT_TRUE((*b)->wait_for_datagrams(2, std::chrono::seconds(10)));
  for (auto* l : {a->get(), b->get()}) {
    const auto s = l->stats();
    EXPECT_EQ(s.accepted, 1u);
    EXPECT_EQ(s.rejected[size_t(FreeDReject::unknown_id)], 1u);
  }
  ASSERT_TRUE((*a)->latest(1));
  EXPECT_FALSE((*a)->latest(2));
  ASSERT_TRUE((*b)->latest(2));
  EXPECT_FALSE((*b)->latest(1));
}

}  // namespace
}  // namespace studio::capture
