// The keyer service (studio-keyer --config) as a real process on loopback:
//  - a studio-capture process (simulated cameras, masks: false, every frame raw) sends
//    CameraImages; the node's AlphaMasks decode to exactly the masks of keying those images
//    in-process, with the images' frame and capture time;
//  - malformed, unsupported-format, surplus-camera and plate-size-mismatch samples are rejected
//    and counted in studio/service/status while the node keeps keying;
//  - difference key: a clean plate from a file and one captured on command (CameraControl
//    KeyerPlate), each giving the in-process keyer's masks exactly;
//  - bad config is one line and exit status 1.
#include <gtest/gtest.h>

#include <fstream>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <thread>

#include "core/clock.h"
#include "harness/fixture.h"
#include "keyer/config/image_io.h"
#include "keyer/keyer.h"
#include "keyer/config/keyer_yaml.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/sample.h"

namespace studio::keyer {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using Key = std::pair<std::string, uint64_t>;  // camera id, frame

// A blue-backing frame with noise and an actor rectangle (skin, dark cloth) moving with `frame`.
Image<Rgb8> chroma_frame(int w, int h, uint64_t frame) {
  Image<Rgb8> img(w, h);
  std::mt19937 rng(uint32_t(frame) * 7919u + 1);
  std::uniform_int_distribution<int> noise(-6, 6);
  const int x0 = 20 + int(frame % 40), y0 = 30, x1 = x0 + w / 3, y1 = h - 20;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Rgb8 p{uint8_t(30 + noise(rng)), uint8_t(50 + noise(rng)), uint8_t(190 + noise(rng))};
      if (x >= x0 && x < x1 && y >= y0 && y < y1)
        p = y < y0 + 30 ? Rgb8{200, 150, 120} : Rgb8{uint8_t(40 + noise(rng) + 6), 40, 45};
      img(x, y) = p;
    }
  return img;
}

// A textured backing (the clean plate) and the same with an actor rectangle.
Image<Rgb8> plate_image(int w, int h) {
  Image<Rgb8> img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img(x, y) = Rgb8{uint8_t(x % 200), uint8_t(60 + y % 100), uint8_t((x + y) % 160)};
  return img;
}
Image<Rgb8> actor_on(const Image<Rgb8>& plate, uint64_t frame) {
  Image<Rgb8> img = plate;
  const int x0 = 30 + int(frame % 30), x1 = x0 + plate.width() / 4;
  for (int y = 40; y < plate.height() - 30; ++y)
    for (int x = x0; x < x1; ++x) img(x, y) = Rgb8{uint8_t(230 - x % 30), 220, 20};
  return img;
}

RunMask key_in_process(Keyer& keyer, const Image<Rgb8>& image) {
  RunMask m;
  auto r = keyer.key(image.view(), m);
  EXPECT_TRUE(r.has_value()) << r.error().message;
  return m;
}

class KeyerNodeTest : public testing::ProcessTest {
 protected:
  void SetUp() override {
    ProcessTest::SetUp();
    participant_.emplace(wire::Participant::create().value());
  }

  std::string write_file(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  template <class T>
  wire::Writer<T> writer() {
    return wire::Writer<T>::create(*participant_, wire::Topic<T>::create(*participant_).value())
        .value();
  }
  template <class T>
  wire::Reader<T> reader() {
    return wire::Reader<T>::create(*participant_, wire::Topic<T>::create(*participant_).value())
        .value();
  }

  static void send_image(wire::Writer<studio_CameraImage>& w, const std::string& cam,
                         uint64_t frame, const Image<Rgb8>& img) {
    wire::Owned<studio_CameraImage> s;
    wire::set(s->camera_id, cam);
    s->frame = frame;
    s->capture_ns = realtime_ns();
    s->width = uint32_t(img.width());
    s->height = uint32_t(img.height());
    s->format = studio_IMAGE_RGB8;
    const auto* p = reinterpret_cast<const uint8_t*>(img.data());
    wire::assign(s->data, std::span<const uint8_t>(p, std::size_t(img.width()) * img.height() * 3));
    ASSERT_TRUE(w.write(*s).has_value());
  }

  // Newest keyer status counters (name -> value), merged into `out`; latency into *latency_ms.
  void poll_status(wire::Reader<studio_ServiceStatus>& r, std::map<std::string, double>& out,
                   double* latency_ms = nullptr) {
    for (auto& s : r.take()) {
      if (!s.meta.valid_data || wire::str(s.data->service) != "keyer") continue;
      for (const auto& c : wire::view(s.data->counters))
        out[std::string(wire::str(c.name))] = c.value;
      if (latency_ms && s.data->latency_ms > 0) *latency_ms = s.data->latency_ms;
    }
  }

  // Masks received, by camera and frame.
  void poll_masks(wire::Reader<studio_AlphaMask>& r,
                  std::map<Key, wire::Owned<studio_AlphaMask>>& out) {
    for (auto& s : r.take())
      if (s.meta.valid_data)
        out[{std::string(wire::str(s.data->camera_id)), s.data->frame}] = std::move(s.data);
  }

  std::optional<wire::Participant> participant_;
};

TEST_F(KeyerNodeTest, CaptureImagesKeyedExactlyAsInProcess) {
  constexpr int kW = 352, kH = 288;
  const std::string capture_cfg = write_file(
      "capture.yaml",
      "instance: cap\nclock: {fps: 25}\ntakes_dir: takes\nmasks: false\nimage: {rate: 1000, raw: "
      "true}\ncameras:\n"
      "  - id: cam0\n    source: {type: sim, ring: 6, index: 0, width: 352, height: 288}\n"
      "  - id: cam1\n    source: {type: sim, ring: 6, index: 3, width: 352, height: 288}\n");
  const std::string keyer_cfg =
      write_file("keyer.yaml",
                 "instance: keyer-test\nstatus_period: 0.2\ncameras: [cam0, cam1]\nthreads: 2\n"
                 "keyer:\n  key: blue\n  clip_black: 22\n  clip_white: 100\n  cleanup: "
                 "{min_component_area: 32, max_hole_area: 200}\n");
  auto options = load_keyer_options(keyer_cfg);
  ASSERT_TRUE(options.has_value()) << options.error().message;
  ASSERT_EQ(options->clip_black, 22.0f);

  auto images = reader<studio_CameraImage>();
  auto masks = reader<studio_AlphaMask>();
  auto status = reader<studio_ServiceStatus>();
  auto& keyer_node = spawn("keyer", "keyer/studio-keyer", {"--config", keyer_cfg});
  ASSERT_TRUE(keyer_node.wait_ready(20s)) << keyer_node.log();
  auto& capture = spawn("capture", "capture/studio-capture", {"--config", capture_cfg});
  ASSERT_TRUE(capture.wait_ready(20s)) << capture.log();

  // Collect images and masks until 10 (camera, frame) pairs per camera have both.
  std::map<Key, Image<Rgb8>> seen_images;
  std::map<Key, wire::Owned<studio_AlphaMask>> seen_masks;
  std::map<Key, int64_t> image_capture_ns;
  auto pairs = [&](const std::string& cam) {
    int n = 0;
    for (const auto& [k, img] : seen_images)
      if (k.first == cam && seen_masks.count(k)) ++n;
    return n;
  };
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < 25s &&
         (pairs("cam0") < 10 || pairs("cam1") < 10)) {
    for (auto& s : images.take()) {
      if (!s.meta.valid_data) continue;
      ASSERT_EQ(s.data->format, studio_IMAGE_RGB8);
      Image<Rgb8> img(int(s.data->width), int(s.data->height));
      const auto d = wire::view(s.data->data);
      ASSERT_EQ(d.size(), img.pixels().size() * 3);
      std::memcpy(img.data(), d.data(), d.size());
      const Key k{std::string(wire::str(s.data->camera_id)), s.data->frame};
      image_capture_ns[k] = s.data->capture_ns;
      seen_images.emplace(k, std::move(img));
    }
    poll_masks(masks, seen_masks);
    std::this_thread::sleep_for(3ms);
  }
  ASSERT_GE(pairs("cam0"), 10) << keyer_node.log();
  ASSERT_GE(pairs("cam1"), 10) << keyer_node.log();

  // Exact equality with the in-process keyer (one per camera, as in the node), and identity.
  std::map<std::string, Keyer> keyers;
  int compared = 0;
  for (const auto& [k, img] : seen_images) {
    auto m = seen_masks.find(k);
    if (m == seen_masks.end()) continue;
    if (!keyers.count(k.first)) keyers.emplace(k.first, Keyer::create(*options).value());
    EXPECT_EQ(m->second->capture_ns, image_capture_ns[k]);
    EXPECT_EQ(m->second->encoding, studio_MASK_CODEC);
    auto decoded = wire::to_core(*m->second);
    ASSERT_TRUE(decoded.has_value()) << decoded.error().message;
    ASSERT_EQ(decoded->width(), kW);
    ASSERT_EQ(decoded->height(), kH);
    const RunMask expected = key_in_process(keyers.at(k.first), img);
    EXPECT_EQ(*decoded, expected) << k.first << " frame " << k.second;
    EXPECT_GT(decoded->area(), 500u) << "the simulated actor is in view";
    ++compared;
  }
  EXPECT_GE(compared, 20);

  // Every frame of the capture node is keyed: the masks' frame numbers are (nearly) contiguous.
  for (const std::string cam : {"cam0", "cam1"}) {
    uint64_t lo = UINT64_MAX, hi = 0, n = 0;
    for (const auto& [k, m] : seen_masks)
      if (k.first == cam) lo = std::min(lo, k.second), hi = std::max(hi, k.second), ++n;
    std::printf("%s: %llu masks over frames %llu..%llu\n", cam.c_str(), (unsigned long long)n,
                (unsigned long long)lo, (unsigned long long)hi);
    EXPECT_GE(double(n), 0.5 * double(hi - lo + 1)) << cam;
  }

  // The status reports what was keyed, nothing rejected, and the capture -> publish latency.
  // Once the capture node has stopped, every image that reached the node was either keyed or
  // dropped for a newer one: nothing waits in a queue.
  EXPECT_EQ(capture.stop(), 0);
  std::map<std::string, double> counters;
  double latency_ms = 0;
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < until &&
         !(counters["masks_published"] >= compared && latency_ms > 0)) {
    poll_status(status, counters, &latency_ms);
    std::this_thread::sleep_for(50ms);
  }
  std::this_thread::sleep_for(700ms);  // > 3 status periods after the last image
  poll_status(status, counters);
  EXPECT_EQ(counters["images_in"], counters["masks_published"] + counters["frames_dropped"]);
  EXPECT_GE(counters["masks_published"], compared);
  EXPECT_EQ(counters["images_rejected"], 0);
  EXPECT_GT(latency_ms, 0);
  EXPECT_LT(latency_ms, 1000);
  std::printf("keyer status: masks_published %.0f, frames_dropped %.0f, latency %.2f ms\n",
              counters["masks_published"], counters["frames_dropped"], latency_ms);
  EXPECT_EQ(keyer_node.stop(), 0) << keyer_node.log();
}

TEST_F(KeyerNodeTest, BadSamplesAreCountedAndTheNodeKeepsKeying) {
  constexpr int kW = 176, kH = 144;
  const std::string cfg = write_file("keyer.yaml", "status_period: 0.2\nmax_cameras: 2\n");
  auto images = writer<studio_CameraImage>();
  auto masks = reader<studio_AlphaMask>();
  auto status = reader<studio_ServiceStatus>();
  auto& node = spawn("keyer", "keyer/studio-keyer", {"--config", cfg});
  ASSERT_TRUE(node.wait_ready(20s)) << node.log();
  ASSERT_TRUE(images.wait_for_readers(1, 10s));

  auto raw = [&](const std::string& cam, uint32_t w, uint32_t h, studio_ImageFormat f,
                 std::size_t bytes) {
    wire::Owned<studio_CameraImage> s;
    wire::set(s->camera_id, cam);
    s->frame = 1;
    s->width = w;
    s->height = h;
    s->format = f;
    std::vector<uint8_t> data(bytes, 0x5A);
    if (f == studio_IMAGE_JPEG && bytes >= 2)
      data[0] = 0xFF, data[1] = 0xD8;  // passes the SOI check
    wire::assign(s->data, data);
    ASSERT_TRUE(images.write(*s).has_value());
  };
  std::map<std::string, double> counters;
  std::map<Key, wire::Owned<studio_AlphaMask>> got;
  const Image<Rgb8> good = chroma_frame(kW, kH, 5);
  const auto t0 = std::chrono::steady_clock::now();
  // camA and camB take the node's two camera slots (resent until both are keyed: best effort).
  while (std::chrono::steady_clock::now() - t0 < 15s &&
         !(got.count({"camA", 5}) && got.count({"camB", 5}))) {
    send_image(images, "camA", 5, good);
    send_image(images, "camB", 5, good);
    std::this_thread::sleep_for(100ms);
    poll_masks(masks, got);
  }
  ASSERT_TRUE(got.count({"camA", 5}) && got.count({"camB", 5})) << node.log();
  auto done = [&] {
    return counters["rejected_malformed"] >= 3 && counters["rejected_format"] >= 2 &&
           counters["rejected_cameras"] >= 1;
  };
  while (std::chrono::steady_clock::now() - t0 < 25s && !done()) {
    // One instance (camera id) per bad sample, so none replaces another in the keep-last-1 cache.
    raw("short", kW, kH, studio_IMAGE_RGB8, kW * kH * 3 - 1);  // data shorter than w*h*3
    raw("zero", 0, kH, studio_IMAGE_RGB8, 0);                  // no pixels
    raw("huge", 70000, 70000, studio_IMAGE_RGB8, 16);          // absurd size
    raw("mono", kW, kH, studio_IMAGE_MONO8, kW * kH);          // valid MONO8: unsupported
    raw("jpeg", kW, kH, studio_IMAGE_JPEG, 4000);              // JPEG: unsupported
    send_image(images, "camC", 5, good);                       // beyond max_cameras 2
    std::this_thread::sleep_for(150ms);
    poll_masks(masks, got);
    poll_status(status, counters);
  }
  EXPECT_GE(counters["rejected_malformed"], 3);
  EXPECT_GE(counters["rejected_format"], 2);
  EXPECT_GE(counters["rejected_cameras"], 1);
  EXPECT_GE(
      counters["images_rejected"],
      counters["rejected_malformed"] + counters["rejected_format"] + counters["rejected_cameras"]);
  ASSERT_TRUE(got.count({"camA", 5})) << node.log();
  EXPECT_FALSE(got.count({"camC", 5}));
  EXPECT_FALSE(got.count({"mono", 1}));

  // The node kept running and its masks are the in-process keyer's (default options).
  EXPECT_TRUE(node.running());
  auto keyer = Keyer::create(KeyerOptions{}).value();
  auto decoded = wire::to_core(*got.at({"camA", 5}));
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(*decoded, key_in_process(keyer, good));
  EXPECT_GT(decoded->area(), 1000u);
  EXPECT_EQ(node.stop(), 0) << node.log();
}

TEST_F(KeyerNodeTest, DifferenceKeyWithPlateFromFileAndOnCommand) {
  constexpr int kW = 320, kH = 240;
  const Image<Rgb8> plate = plate_image(kW, kH);
  {
    cv::Mat rgb(kH, kW, CV_8UC3, const_cast<Rgb8*>(plate.data())), bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    ASSERT_TRUE(cv::imwrite((dir_ / "plate0.png").string(), bgr));
  }
  const std::string cfg = write_file("keyer.yaml",
                                     "status_period: 0.2\ncameras: [cam0, cam1]\nplates: {cam0: "
                                     "plate0.png}\nkeyer: {key: difference, diff_low: 10, "
                                     "diff_high: 30}\n");
  auto options = load_keyer_options(cfg);
  ASSERT_TRUE(options.has_value()) << options.error().message;
  auto file_plate = read_rgb((dir_ / "plate0.png").string());
  ASSERT_TRUE(file_plate.has_value());

  auto images = writer<studio_CameraImage>();
  auto controls = writer<studio_CameraControl>();
  auto masks = reader<studio_AlphaMask>();
  auto status = reader<studio_ServiceStatus>();
  auto& node = spawn("keyer", "keyer/studio-keyer", {"--config", cfg});
  ASSERT_TRUE(node.wait_ready(20s)) << node.log();
  ASSERT_TRUE(images.wait_for_readers(1, 10s));
  ASSERT_TRUE(controls.wait_for_readers(1, 10s));

  std::map<std::string, double> counters;
  std::map<Key, wire::Owned<studio_AlphaMask>> got;
  const Image<Rgb8> small = plate_image(kW / 2, kH / 2);
  // cam0: plate from the file. cam1: no plate yet, frames go unkeyed. A frame of the wrong size
  // for cam0's plate is rejected.
  auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < 20s &&
         !(got.count({"cam0", 100}) && counters["frames_unkeyed"] >= 1 &&
           counters["rejected_keyer"] >= 1)) {
    send_image(images, "cam0", 99, small);
    std::this_thread::sleep_for(60ms);
    send_image(images, "cam0", 100, actor_on(plate, 100));
    send_image(images, "cam1", 100, actor_on(plate, 100));
    std::this_thread::sleep_for(100ms);
    poll_masks(masks, got);
    poll_status(status, counters);
  }
  ASSERT_TRUE(got.count({"cam0", 100})) << node.log();
  EXPECT_FALSE(got.count({"cam0", 99}));
  EXPECT_FALSE(got.count({"cam1", 100}));
  EXPECT_GE(counters["frames_unkeyed"], 1);
  EXPECT_GE(counters["rejected_keyer"], 1);
  auto keyer0 = Keyer::create(*options).value();
  ASSERT_TRUE(keyer0.capture_plate(file_plate->view()).has_value());
  const RunMask expect100 = key_in_process(keyer0, actor_on(plate, 100));
  EXPECT_EQ(wire::to_core(*got.at({"cam0", 100})).value(), expect100);
  EXPECT_GT(expect100.area(), 5000u);

  // cam1: clean plate on command (3 frames averaged), then keyed like the in-process keyer.
  wire::Owned<studio_CameraControl> c;
  wire::set(c->camera_id, "cam1");
  wire::set(c->feature, "KeyerPlate");
  c->value = 2.5;  // not a frame count: rejected and counted
  ASSERT_TRUE(controls.write(*c).has_value());
  c->value = 3;
  ASSERT_TRUE(controls.write(*c).has_value());
  t0 = std::chrono::steady_clock::now();
  uint64_t f = 200;
  while (std::chrono::steady_clock::now() - t0 < 20s && counters["plates_captured"] < 1) {
    send_image(images, "cam1", f++, plate);
    std::this_thread::sleep_for(60ms);
    poll_status(status, counters);
  }
  ASSERT_GE(counters["plates_captured"], 1) << node.log();
  EXPECT_EQ(counters["controls_rejected"], 1);
  auto keyer1 = Keyer::create(*options).value();
  ASSERT_TRUE(keyer1.capture_plate(plate.view()).has_value());
  got.clear();
  t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < 20s && !got.count({"cam1", 500})) {
    send_image(images, "cam1", 500, actor_on(plate, 500));
    std::this_thread::sleep_for(100ms);
    poll_masks(masks, got);
  }
  ASSERT_TRUE(got.count({"cam1", 500})) << node.log();
  EXPECT_EQ(wire::to_core(*got.at({"cam1", 500})).value(),
            key_in_process(keyer1, actor_on(plate, 500)));
  EXPECT_EQ(node.stop(), 0) << node.log();
}

// With plate_dir a plate captured on command survives a restart of the node (with the actor on
// set it could not be shot again): the restarted node keys its first frame with it. KeyerPlate 0
// removes the kept file.
TEST_F(KeyerNodeTest, PlateCapturedOnCommandIsKeptAcrossARestart) {
  constexpr int kW = 320, kH = 240;
  const Image<Rgb8> plate = plate_image(kW, kH);
  const std::string cfg =
      write_file("keyer.yaml",
                 "status_period: 0.2\ncameras: [cam0]\nplate_dir: plates\nkeyer: {key: "
                 "difference, diff_low: 10, diff_high: 30}\n");
  auto options = load_keyer_options(cfg);
  ASSERT_TRUE(options.has_value()) << options.error().message;
  const fs::path kept = dir_ / "plates" / "cam0.png";

  auto images = writer<studio_CameraImage>();
  auto controls = writer<studio_CameraControl>();
  auto masks = reader<studio_AlphaMask>();
  auto status = reader<studio_ServiceStatus>();
  {
    auto& node = spawn("keyer", "keyer/studio-keyer", {"--config", cfg});
    ASSERT_TRUE(node.wait_ready(20s)) << node.log();
    ASSERT_TRUE(images.wait_for_readers(1, 10s));
    ASSERT_TRUE(controls.wait_for_readers(1, 10s));
    wire::Owned<studio_CameraControl> c;
    wire::set(c->camera_id, "cam0");
    wire::set(c->feature, "KeyerPlate");
    c->value = 3;
    ASSERT_TRUE(controls.write(*c).has_value());
    std::map<std::string, double> counters;
    const auto t0 = std::chrono::steady_clock::now();
    uint64_t f = 200;
    while (std::chrono::steady_clock::now() - t0 < 20s &&
           !(counters["plates_captured"] >= 1 && fs::exists(kept))) {
      send_image(images, "cam0", f++, plate);
      std::this_thread::sleep_for(60ms);
      poll_status(status, counters);
    }
    ASSERT_TRUE(fs::exists(kept)) << node.log();
    EXPECT_EQ(counters["plate_saves_failed"], 0);
    EXPECT_EQ(node.stop(), 0) << node.log();
  }
  auto file = read_rgb(kept.string());
  ASSERT_TRUE(file.has_value()) << file.error().message;
  EXPECT_EQ(file->pixels(), plate.pixels());  // 3 equal frames average to the frame itself
  EXPECT_FALSE(fs::exists(kept.string() + ".part.png"));

  auto& node = spawn("keyer-restarted", "keyer/studio-keyer", {"--config", cfg});
  ASSERT_TRUE(node.wait_ready(20s)) << node.log();
  ASSERT_TRUE(images.wait_for_readers(1, 10s));
  std::map<Key, wire::Owned<studio_AlphaMask>> got;
  auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < 20s && !got.count({"cam0", 600})) {
    send_image(images, "cam0", 600, actor_on(plate, 600));
    std::this_thread::sleep_for(100ms);
    poll_masks(masks, got);
  }
  ASSERT_TRUE(got.count({"cam0", 600})) << node.log();
  auto keyer = Keyer::create(*options).value();
  ASSERT_TRUE(keyer.capture_plate(plate.view()).has_value());
  EXPECT_EQ(wire::to_core(*got.at({"cam0", 600})).value(),
            key_in_process(keyer, actor_on(plate, 600)));

  ASSERT_TRUE(controls.wait_for_readers(1, 10s));
  wire::Owned<studio_CameraControl> clear;
  wire::set(clear->camera_id, "cam0");
  wire::set(clear->feature, "KeyerPlate");
  clear->value = 0;
  ASSERT_TRUE(controls.write(*clear).has_value());
  t0 = std::chrono::steady_clock::now();
  uint64_t f = 700;
  while (std::chrono::steady_clock::now() - t0 < 20s && fs::exists(kept)) {
    send_image(images, "cam0", f++, actor_on(plate, 700));  // the clear applies with a frame
    std::this_thread::sleep_for(60ms);
  }
  EXPECT_FALSE(fs::exists(kept)) << node.log();
  EXPECT_EQ(node.stop(), 0) << node.log();
}

TEST_F(KeyerNodeTest, ExampleConfigRuns) {
  auto& node = spawn("keyer", "keyer/studio-keyer",
                     {"--config", STUDIO_SOURCE_DIR "/keyer/node/keyer-node.example.yaml"});
  ASSERT_TRUE(node.wait_ready(20s)) << node.log();
  EXPECT_EQ(node.stop(), 0) << node.log();
}

TEST_F(KeyerNodeTest, BadConfigIsOneLine) {
  struct Case {
    std::string yaml, expect;
  } cases[] = {
      {"colour: red\n", "colour: unknown key"},
      {"keyer: {clip_black: 120, clip_white: 100}\n", "clip"},
      {"keyer: {key: purple}\n", "purple"},
      {"keyer: {shade: 3}\n", "unknown key 'shade'"},
      {"keyer: {edge: {threshold: 1.5}}\n", "edge.threshold"},
      {"keyer: {edge: {width: 2}}\n", "unknown key 'width'"},
      {"keyer: {edge_refine: maybe}\n", "edge_refine"},
      {"keyer: missing-keyer.yaml\n", "missing-keyer.yaml"},
      {"threads: 0\n", "threads"},
      {"cameras: []\n", "cameras"},
      {"cameras: [a, a]\n", "duplicate camera id a"},
      {"plates: {cam0: p.png}\n", "difference key"},
      {"plate_dir: plates\n", "difference key"},
      {"keyer: {key: difference}\nplates: {cam0: nowhere.png}\n", "nowhere.png"},
      {"keyer: {key: difference}\ncameras: [cam1]\nplates: {cam0: nowhere.png}\n",
       "not in cameras"},
      {"cameras: [cam0\n", "keyer.yaml:"},
  };
  for (const auto& c : cases) {
    auto& p = spawn("keyer", "keyer/studio-keyer", {"--config", write_file("keyer.yaml", c.yaml)});
    EXPECT_EQ(p.wait_exit(10s), 1) << c.yaml;
    const std::string log = p.log();
    EXPECT_NE(log.find(c.expect), std::string::npos) << c.yaml << " -> " << log;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  }
}

}  // namespace
}  // namespace studio::keyer
