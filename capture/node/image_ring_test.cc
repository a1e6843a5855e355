// Frame-exact images on request (image_ring.h): the ring itself, and studio-capture answering
// studio/camera/image_request over real DDS with the image of exactly the requested frame
// (compared byte for byte with the simulated camera's own rendering of that frame).
#include "image_ring.h"

#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "harness/fixture.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "wire/endpoint.h"

namespace studio::capture::node {
namespace {

using namespace std::chrono_literals;

Image<Rgb8> filled(int w, int h, uint8_t v) {
  Image<Rgb8> img(w, h);
  for (auto& p : img.pixels()) p = {v, uint8_t(v + 1), uint8_t(v + 2)};
  return img;
}

TEST(ImageRing, PushByMoveKeepsTheImageAndGivesBackTheOldestBuffer) {
  ImageRing ring(2);
  ImageRing::Image3 out;
  for (uint64_t f = 1; f <= 4; ++f) {
    Image<Rgb8> img = filled(3, 2, uint8_t(10 * f));
    ring.push(f, int64_t(f) * 40, std::move(img));
    // From the third push on, the caller's image holds the evicted frame's buffer.
    if (f >= 3) {
      EXPECT_EQ(img.pixels(), filled(3, 2, uint8_t(10 * (f - 2))).pixels());
    }
  }
  ASSERT_EQ(ring.find(4, out), ImageRing::Found::ok);
  EXPECT_EQ(out.capture_ns, 160);
  EXPECT_EQ(out.rgb.size(), 18u);
  EXPECT_EQ(out.rgb[0], 40);
  EXPECT_EQ(ring.find(3, out), ImageRing::Found::ok);
  EXPECT_EQ(out.rgb[1], 31);
  EXPECT_EQ(ring.find(2, out), ImageRing::Found::evicted);
  ring.push(5, 200, filled(3, 2, 50));  // a copy into the reused slot
  ASSERT_EQ(ring.find(5, out), ImageRing::Found::ok);
  EXPECT_EQ(out.rgb[2], 52);
}

TEST(ImageRing, KeepsTheLastFramesAndSaysWhyOthersAreMissing) {
  ImageRing ring(4);
  ImageRing::Image3 out;
  EXPECT_EQ(ring.find(0, out), ImageRing::Found::not_yet);  // empty
  for (uint64_t f = 10; f < 16; ++f) ring.push(f, int64_t(f) * 40, filled(3, 2, uint8_t(f)));
  ASSERT_EQ(ring.find(13, out), ImageRing::Found::ok);
  EXPECT_EQ(out.width, 3);
  EXPECT_EQ(out.height, 2);
  EXPECT_EQ(out.capture_ns, 13 * 40);
  ASSERT_EQ(out.rgb.size(), 18u);
  EXPECT_EQ(out.rgb[0], 13);
  EXPECT_EQ(out.rgb[1], 14);
  EXPECT_EQ(ring.find(11, out), ImageRing::Found::evicted);  // 12..15 kept
  EXPECT_EQ(ring.find(16, out), ImageRing::Found::not_yet);
  EXPECT_EQ(ring.find(15, out), ImageRing::Found::ok);
  EXPECT_EQ(out.rgb[0], 15);
}

class ImageRequestTest : public testing::ProcessTest {};

TEST_F(ImageRequestTest, CaptureAnswersWithExactlyTheRequestedFrame) {
  const auto config = dir_ / "capture.yaml";
  std::ofstream(config) << "clock: {fps: 25}\ntakes_dir: takes\nstate_period: 0.2\n"
                           "image: {rate: 0}\ncameras:\n"
                           "  - id: cam2\n    source: {type: sim, ring: 4, index: 2, width: 160, "
                           "height: 128, frame_code: true}\n";
  testing::Process& capture = spawn("capture", "capture/studio-capture", {"--config", config.string()});
  ASSERT_TRUE(capture.wait_ready(30s));
  auto p = wire::Participant::create().value();
  auto req_topic = wire::Topic<studio_ImageRequest>::create(p).value();
  auto rep_topic = wire::Topic<studio_ImageReply>::create(p).value();
  auto st_topic = wire::Topic<studio_CameraState>::create(p).value();
  auto requests = wire::Writer<studio_ImageRequest>::create(p, req_topic).value();
  auto replies = wire::Reader<studio_ImageReply>::create(p, rep_topic).value();
  auto states = wire::Reader<studio_CameraState>::create(p, st_topic).value();
  ASSERT_TRUE(requests.wait_for_readers(1, 20s));
  // The newest frame captured, from the camera's state.
  uint64_t newest = 0;
  for (auto deadline = std::chrono::steady_clock::now() + 20s;
       newest < 30 && std::chrono::steady_clock::now() < deadline;) {
    for (auto& s : states.take())
      if (s.meta.valid_data) newest = std::max<uint64_t>(newest, s.data->frame);
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_GT(newest, 30u);
  auto ask = [&](const std::string& camera, uint64_t frame, uint64_t id) {
    wire::Owned<studio_ImageRequest> r;
    wire::set(r->requester, "test");
    wire::set(r->camera_id, camera);
    r->frame = frame;
    r->request_id = id;
    ASSERT_TRUE(requests.write(*r));
  };
  ask("cam2", newest - 2, 1);        // in the ring
  ask("cam2", newest - 1000, 2);     // long gone
  ask("cam2", newest + 100000, 3);   // not yet
  ask("cam7", newest - 2, 4);        // not this server's camera: no reply
  std::map<uint64_t, wire::Owned<studio_ImageReply>> got;
  for (auto deadline = std::chrono::steady_clock::now() + 10s;
       got.size() < 3 && std::chrono::steady_clock::now() < deadline;) {
    for (auto& r : replies.take())
      if (r.meta.valid_data) got[r.data->request_id] = std::move(r.data);
    std::this_thread::sleep_for(10ms);
  }
  std::this_thread::sleep_for(300ms);
  for (auto& r : replies.take())
    if (r.meta.valid_data) got[r.data->request_id] = std::move(r.data);
  ASSERT_EQ(got.size(), 3u) << "one reply per request for its own camera, none for cam7";
  EXPECT_EQ(got[2]->status, studio_IMAGE_REPLY_EVICTED);
  EXPECT_EQ(got[3]->status, studio_IMAGE_REPLY_NOT_YET);
  EXPECT_EQ(wire::view(got[2]->data).size(), 0u);
  const auto& ok = *got[1];
  ASSERT_EQ(ok.status, studio_IMAGE_REPLY_OK);
  EXPECT_EQ(ok.frame, newest - 2);
  EXPECT_EQ(wire::str(ok.requester), "test");
  ASSERT_EQ(ok.width, 160u);
  ASSERT_EQ(ok.height, 128u);
  // The same camera and frame rendered here: byte for byte what the server replied.
  sim::RingOptions ring;
  ring.count = 4;
  ring.width = 160;
  ring.height = 128;
  ring.focal_px *= 160.0 / 704.0;
  Camera cam = sim::ring_cameras(ring)[2];
  cam.id = "cam2";
  sim::StudioOptions so;
  so.threads = 1;
  so.frame_code = true;
  auto studio = sim::SimulatedStudio::create({cam}, so).value();
  Image<Rgb8> truth;
  studio.render(0, int64_t(ok.frame), &truth, nullptr);
  const auto data = wire::view(ok.data);
  ASSERT_EQ(data.size(), truth.pixels().size() * 3);
  EXPECT_EQ(std::memcmp(data.data(), truth.data(), data.size()), 0);
  Image<Rgb8> other;
  studio.render(0, int64_t(ok.frame) + 1, &other, nullptr);
  EXPECT_NE(std::memcmp(data.data(), other.data(), data.size()), 0) << "positive control";
}

}  // namespace
}  // namespace studio::capture::node
