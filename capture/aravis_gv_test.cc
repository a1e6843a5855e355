// AravisSource against a real GigE Vision stack: Aravis' arv-fake-gv-camera-0.8 serving GVCP /
// GVSP on 127.0.0.1, inside a private network namespace (run by ctest through
// run_in_netns.sh, which does `unshare -n` and brings lo up), so discovery broadcasts never
// leave the machine. Proves discovery and open by id, streaming with the requested format and
// size, one frame per software trigger, and the disappear → retry with back-off → resume path.
// Every test runs under a watchdog (55 s) besides ctest's timeout.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>

#include "capture/aravis_source.h"
#include "capture/freed.h"
#include "capture/freed_listener.h"
#include "core/clock.h"
#include "testing/private_netns.h"

namespace studio::capture {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
constexpr char kDeviceId[] = "Aravis-Fake-GV01";

// arv-fake-gv-camera-0.8 -i 127.0.0.1 as a child process, killed with the test (PDEATHSIG).
class FakeGvCamera {
 public:
  ~FakeGvCamera() { kill(); }
  void start() {
    ASSERT_LT(pid_, 0);
    pid_ = fork();
    ASSERT_GE(pid_, 0);
    if (pid_ == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      std::freopen("/dev/null", "w", stdout);
      std::freopen("/dev/null", "w", stderr);
      execlp("arv-fake-gv-camera-0.8", "arv-fake-gv-camera-0.8", "-i", "127.0.0.1", nullptr);
      _exit(127);
    }
  }
  void kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

bool wait_for_device(milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    const auto ids = list_aravis_devices({"GigEVision"});
    if (std::find(ids.begin(), ids.end(), kDeviceId) != ids.end()) return true;
    std::this_thread::sleep_for(milliseconds(100));
  }
  return false;
}

class AravisGv : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!only_loopback()) {
      GTEST_SKIP() << "not in a private network namespace (interfaces besides lo exist); run "
                      "through ctest, which wraps this binary in run_in_netns.sh";
    }
    watchdog_ = std::thread([this] {
      std::unique_lock lock(mutex_);
      if (!done_cv_.wait_for(lock, std::chrono::seconds(55), [this] { return done_; })) {
        std::fprintf(stderr, "watchdog: test exceeded 55 s\n");
        std::_Exit(3);
      }
    });
    camera_.start();
    ASSERT_TRUE(wait_for_device(milliseconds(10000))) << kDeviceId << " not discovered on lo";
  }
  void TearDown() override {
    camera_.kill();
    if (watchdog_.joinable()) {
      {
        std::lock_guard lock(mutex_);
        done_ = true;
      }
      done_cv_.notify_all();
      watchdog_.join();
    }
  }
  static AravisOptions options() {
    AravisOptions o;
    o.device_id = kDeviceId;
    o.camera_id = "gv0";
    o.interfaces = {"GigEVision"};
    o.pixel_format = CameraPixelFormat::bayer_rg8;
    o.width = 320;
    o.height = 240;
    o.frame_rate = 25;
    return o;
  }

  FakeGvCamera camera_;

 private:
  std::thread watchdog_;
  std::mutex mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
};

std::optional<Frame> grab(AravisSource& source, milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    auto f = source.next(milliseconds(200));
    EXPECT_TRUE(f) << (f ? "" : f.error().message);
    if (!f) return std::nullopt;
    if (*f) return std::move(**f);
  }
  return std::nullopt;
}

TEST_F(AravisGv, DiscoversOpensByIdAndStreams) {
  auto source = AravisSource::open(options());
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ((*source)->id(), "gv0");
  EXPECT_EQ((*source)->config().serial, "GV01");
  EXPECT_EQ((*source)->config().pixel_format, "BayerRG8");
  ASSERT_TRUE((*source)->start());
  uint64_t last_frame = 0;
  for (int i = 0; i < 10; ++i) {
    auto f = grab(**source, milliseconds(5000));
    ASSERT_TRUE(f) << "frame " << i;
    EXPECT_EQ(f->image.width(), 320);
    EXPECT_EQ(f->image.height(), 240);
    EXPECT_GE(f->frame, last_frame);
    last_frame = f->frame;
  }
  EXPECT_EQ((*source)->stats().frames, 10u);
  EXPECT_TRUE((*source)->stats().connected);
  auto gain = (*source)->set_feature("Gain", 3);
  ASSERT_TRUE(gain) << gain.error().message;
  EXPECT_DOUBLE_EQ(*gain, 3);
}

TEST_F(AravisGv, SoftwareTriggerGivesOneFramePerTrigger) {
  AravisOptions o = options();
  o.trigger = TriggerMode::software;
  o.clock_trigger = false;  // this test fires the triggers itself
  auto source = AravisSource::open(o);
  ASSERT_TRUE(source) << source.error().message;
  ASSERT_TRUE((*source)->start());
  auto idle = (*source)->next(milliseconds(500));
  ASSERT_TRUE(idle);
  EXPECT_FALSE(*idle) << "a frame arrived without a trigger";
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE((*source)->software_trigger());
    ASSERT_TRUE(grab(**source, milliseconds(5000))) << "no frame for trigger " << i;
    auto extra = (*source)->next(milliseconds(300));
    ASSERT_TRUE(extra);
    EXPECT_FALSE(*extra) << "more than one frame for trigger " << i;
  }
  EXPECT_EQ((*source)->stats().frames, 3u);
}

// The capture service's software trigger: fired at every studio frame (10 fps here), mid-frame;
// one frame per studio frame, numbered by the camera's own time latched to the host clock.
TEST_F(AravisGv, ClockTriggerDeliversOneFramePerStudioFrame) {
  AravisOptions o = options();
  o.trigger = TriggerMode::software;
  o.clock.period_ns = 100'000'000;
  auto source = AravisSource::open(o);
  ASSERT_TRUE(source) << source.error().message;
  ASSERT_TRUE((*source)->start());
  std::vector<uint64_t> frames;
  const auto start = Clock::now();
  while (Clock::now() - start < std::chrono::seconds(4)) {
    auto f = (*source)->next(milliseconds(200));
    ASSERT_TRUE(f) << f.error().message;
    if (*f) frames.push_back((*f)->frame);
  }
  const uint64_t triggers = (*source)->triggers();
  (*source)->stop();
  ASSERT_GE(frames.size(), 30u) << "4 s at 10 fps";
  EXPECT_LE(frames.size(), 41u);
  // Every trigger gave one frame (the last may still be in flight) ...
  EXPECT_GE(frames.size() + 1, triggers);
  EXPECT_LE(frames.size(), triggers);
  // ... numbered in step with the studio clock: each studio frame once, none skipped but for a
  // wake-up the loaded host made late (counted: at most 2 here).
  uint64_t gaps = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    ASSERT_GT(frames[i], frames[i - 1]) << "frame " << frames[i] << " twice";
    gaps += frames[i] - frames[i - 1] - 1;
  }
  EXPECT_LE(gaps, 2u);
  std::printf("clock trigger: %zu frames, %lu triggers, %lu skipped, time source %s\n",
              frames.size(), (unsigned long)triggers, (unsigned long)gaps,
              (*source)->time_source() == TimeSource::camera ? "camera" : "host arrival");
}

// Frame time from the camera's timestamp latched to the host clock; host arrival when told not
// to (the positive control of the reported source).
TEST_F(AravisGv, CameraTimeIsUsedAndReported) {
  for (bool camera_time : {true, false}) {
    AravisOptions o = options();
    o.camera_time = camera_time;
    auto source = AravisSource::open(o);
    ASSERT_TRUE(source) << source.error().message;
    ASSERT_TRUE((*source)->start());
    int64_t last = 0;
    for (int i = 0; i < 15; ++i) {
      auto f = grab(**source, milliseconds(5000));
      ASSERT_TRUE(f);
      const int64_t now = realtime_ns();
      EXPECT_LE(f->capture_ns, now);  // latched: never later than its arrival
      EXPECT_GT(f->capture_ns, now - 1'000'000'000);
      EXPECT_GT(f->capture_ns, last);
      EXPECT_EQ(f->frame, o.clock.frame_at(f->capture_ns));
      last = f->capture_ns;
    }
    EXPECT_EQ((*source)->time_source(),
              camera_time ? TimeSource::camera : TimeSource::host_arrival);
    (*source)->stop();
  }
}

TEST_F(AravisGv, DisappearsRetriesWithBackOffAndResumes) {
  AravisOptions o = options();
  o.retry_initial = milliseconds(200);
  o.retry_max = milliseconds(1000);
  o.lost_after = milliseconds(1000);
  std::mutex m;
  std::vector<bool> transitions;
  o.on_state = [&](const SourceStats& s) {
    std::lock_guard lock(m);
    transitions.push_back(s.connected);
  };
  auto source = AravisSource::open(o);
  ASSERT_TRUE(source) << source.error().message;
  ASSERT_TRUE((*source)->start());
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(grab(**source, milliseconds(5000)));

  camera_.kill();  // the camera disappears
  const auto lost_at = Clock::now();
  while ((*source)->stats().connected && Clock::now() - lost_at < std::chrono::seconds(20)) {
    auto f = (*source)->next(milliseconds(200));
    ASSERT_TRUE(f) << "a lost camera is not an error: " << f.error().message;
  }
  ASSERT_FALSE((*source)->stats().connected) << "loss not detected within 20 s";
  const double detect_s = std::chrono::duration<double>(Clock::now() - lost_at).count();
  // While it is gone: no frames, no errors, retries in the background.
  const auto gone_until = Clock::now() + milliseconds(2500);
  while (Clock::now() < gone_until) {
    auto f = (*source)->next(milliseconds(200));
    ASSERT_TRUE(f);
    EXPECT_FALSE(*f);
  }
  EXPECT_TRUE((*source)->features().empty());
  EXPECT_FALSE((*source)->set_feature("Gain", 1));

  camera_.start();  // it comes back
  const auto back_at = Clock::now();
  auto resumed = grab(**source, milliseconds(25000));
  ASSERT_TRUE(resumed) << "frames did not resume";
  const double resume_s = std::chrono::duration<double>(Clock::now() - back_at).count();
  EXPECT_EQ(resumed->image.width(), 320);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(grab(**source, milliseconds(5000)));
  const SourceStats s = (*source)->stats();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.reconnects, 1u);
  EXPECT_EQ(s.frames, 9u);
  {
    std::lock_guard lock(m);
    EXPECT_EQ(transitions, (std::vector<bool>{false, true}));
  }
  std::printf("loss detected after %.2f s, frames resumed %.2f s after the camera restarted\n",
              detect_s, resume_s);
}

}  // namespace
// A tracked GigE camera (Aravis's fake camera behind TrackedSource, as studio-capture wires a
// `tracking: freed:` entry): before any Free-D packet the tracker is silent; while packets of its
// id arrive every frame it is not, and the frames keep flowing; when the packets stop, the state
// says silent within one second of the last one (the node copies this into CameraState).
TEST_F(AravisGv, TrackerFallingSilentShowsInTheState) {
  AravisOptions o = options();
  FreeDListenerOptions lo{"127.0.0.1", 0, 64};
  lo.clock = o.clock;
  auto created = FreeDListener::create(lo);
  ASSERT_TRUE(created) << created.error().message;
  std::shared_ptr<FreeDListener> listener = std::move(*created);
  TrackedSourceOptions to;
  to.camera.camera_id = o.camera_id;
  to.camera.freed_id = 5;
  to.camera.width = o.width;
  to.camera.height = o.height;
  to.camera.lens = LensTable{{LensSample{0, 0, 400, 400, 160, 120, 0, 0}}};
  to.clock = o.clock;
  ASSERT_TRUE(to.validate());
  auto inner = AravisSource::open(o);
  ASSERT_TRUE(inner) << inner.error().message;
  TrackedSource source(std::move(*inner), listener, to);
  ASSERT_TRUE(source.start());
  EXPECT_TRUE(source.status(realtime_ns()).silent) << "no packet yet";

  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in to_addr{};
  to_addr.sin_family = AF_INET;
  to_addr.sin_port = htons(listener->port());
  to_addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::atomic<bool> sending{true};
  std::atomic<int64_t> last_sent_ns{0};
  std::thread tracker([&] {
    FreeDPacket p;
    p.camera_id = 5;
    while (sending) {
      p.pan_deg += 0.5;
      const auto bytes = encode_freed(p);
      if (::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to_addr),
                   sizeof to_addr) == ssize_t(bytes.size()))
        last_sent_ns = realtime_ns();
      std::this_thread::sleep_for(milliseconds(40));
    }
  });
  // Tracked: frames flow and the state is not silent.
  int frames = 0;
  bool tracked = false;
  const auto until = Clock::now() + std::chrono::seconds(3);
  while (Clock::now() < until && (frames < 25 || !tracked)) {
    auto f = source.next(milliseconds(200));
    ASSERT_TRUE(f) << f.error().message;
    if (*f) ++frames;
    tracked = tracked || !source.status(realtime_ns()).silent;
  }
  EXPECT_GE(frames, 25);
  EXPECT_TRUE(tracked) << "packets arrived but the tracker stayed silent";
  // Silent: stop the packets; the state follows within one second of the last one.
  sending = false;
  tracker.join();
  ::close(fd);
  int64_t silent_after_ns = -1;
  while (realtime_ns() - last_sent_ns < 3'000'000'000) {
    (void)source.next(milliseconds(50));  // the camera keeps streaming meanwhile
    if (source.status(realtime_ns()).silent) {
      silent_after_ns = realtime_ns() - last_sent_ns;
      break;
    }
  }
  source.stop();
  ASSERT_GE(silent_after_ns, 0) << "still not silent 3 s after the last packet";
  EXPECT_LE(silent_after_ns, 1'000'000'000);
  std::printf(
      "tracked GigE camera: %d frames while tracked; silent %.0f ms after the last packet\n",
      frames, silent_after_ns / 1e6);
}

}  // namespace studio::capture
