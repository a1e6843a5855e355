// The scene thread's triple buffer (projector/scene_handoff.h): the reader gets the newest image,
// keeps it while the writer goes on, and images nobody took are counted.
#include "projector/scene_handoff.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace studio::projector {
namespace {

using namespace std::chrono_literals;

void write(SceneHandoff& h, std::uint8_t value) {
  SceneImage& img = h.back();
  img.rgba.assign(16, value);
  img.eye = Eigen::Vector3d(value, 0, 0);
  h.publish();
}

TEST(SceneHandoff, TheReaderGetsTheNewestAndKeepsItWhileTheWriterGoesOn) {
  SceneHandoff h;
  EXPECT_EQ(h.take(), nullptr);  // nothing published yet
  write(h, 1);
  bool fresh = false;
  const SceneImage* a = h.take(&fresh);
  ASSERT_NE(a, nullptr);
  EXPECT_TRUE(fresh);
  EXPECT_EQ(a->rgba[0], 1);
  EXPECT_EQ(a->sequence, 1u);
  // Nothing newer: the same image again, not fresh.
  EXPECT_EQ(h.take(&fresh), a);
  EXPECT_FALSE(fresh);
  // The writer publishes twice: the reader's image is untouched, the second is the newest and
  // the first of the two was never taken (skipped).
  write(h, 2);
  write(h, 3);
  EXPECT_EQ(a->rgba[0], 1);
  EXPECT_EQ(a->eye.x(), 1);
  EXPECT_EQ(h.skipped(), 1u);
  const SceneImage* b = h.take(&fresh);
  ASSERT_NE(b, nullptr);
  EXPECT_TRUE(fresh);
  EXPECT_EQ(b->rgba[0], 3);
  EXPECT_EQ(b->sequence, 3u);
  EXPECT_EQ(h.published(), 3u);
  // Many images while the reader holds one: never its slot.
  for (int k = 4; k < 40; ++k) {
    write(h, std::uint8_t(k));
    EXPECT_EQ(b->rgba[0], 3);
  }
  EXPECT_EQ(h.take()->rgba[0], 39);
  EXPECT_EQ(h.skipped(), 1u + 35u);
}

TEST(SceneHandoff, WaitFirstReturnsOnTheFirstImageOrOnStop) {
  SceneHandoff h;
  EXPECT_FALSE(h.wait_first(10ms));  // nothing: times out
  std::thread writer([&] {
    std::this_thread::sleep_for(30ms);
    write(h, 7);
  });
  EXPECT_TRUE(h.wait_first(5s));
  writer.join();
  EXPECT_EQ(h.take()->rgba[0], 7);

  SceneHandoff stopped;
  std::thread stopper([&] {
    std::this_thread::sleep_for(30ms);
    stopped.stop();
  });
  const auto t = std::chrono::steady_clock::now();
  EXPECT_FALSE(stopped.wait_first(10s));  // woken by stop(), no image
  EXPECT_LT(std::chrono::steady_clock::now() - t, 5s);
  stopper.join();
}

// A writer and a reader on two threads: every image the reader gets is whole (all its bytes
// from one write), and the sequence never goes back.
TEST(SceneHandoff, ImagesAreWholeAndInOrderAcrossThreads) {
  SceneHandoff h;
  std::atomic<bool> done{false};
  std::atomic<long> written{0};
  std::thread writer([&] {
    for (int k = 1; !done; ++k) {
      SceneImage& img = h.back();
      img.rgba.assign(4096, std::uint8_t(k & 0xff));
      img.eye = Eigen::Vector3d(k, k, k);
      h.publish();
      written = k;
    }
  });
  std::uint64_t last = 0;
  long torn = 0, backwards = 0, fresh_taken = 0;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (fresh_taken < 2000 && std::chrono::steady_clock::now() < until) {
    bool fresh = false;
    const SceneImage* img = h.take(&fresh);
    if (!img) continue;
    fresh_taken += fresh;
    if (img->sequence < last) ++backwards;
    last = img->sequence;
    const std::uint8_t v = img->rgba[0];
    for (std::uint8_t b : img->rgba) torn += b != v;
    torn += img->eye.x() != double(img->sequence) || (img->sequence & 0xff) != v;
  }
  done = true;
  writer.join();
  std::printf("%ld images written, %ld taken fresh, %llu skipped\n", written.load(), fresh_taken,
              static_cast<unsigned long long>(h.skipped()));
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(fresh_taken, 2000);
  EXPECT_EQ(h.take()->sequence, std::uint64_t(written.load()));
}

}  // namespace
}  // namespace studio::projector
