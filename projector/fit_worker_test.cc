// FitWorker (projector/fit_worker.h): the motion fits of late latching on a thread of their own
// give the velocities the tracker gives on the caller's thread, in order; the newest mesh wins
// while the thread is busy and the last mesh is always fitted; remove() starts an actor afresh;
// a refused mesh is a result with its error, not a crash; the thread runs at its nice value,
// real-time priority 1 under a real-time caller; a priority it cannot lower (setpriority denied
// by a seccomp filter, as a unit's hardening would) is said in one line and the fits go on.
#include "projector/fit_worker.h"
#include "projector/thread_priority.h"

#include <gtest/gtest.h>

#include <dirent.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <sstream>
#include <thread>

#include "testing/shapes.h"

namespace studio::projector {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000'000, kDt = 40'000'000;  // 25 fps

// A sphere moving at 1 m/s along x, re-tessellated (rotated) every frame.
ActorMesh moving(int k) {
  const double a = 0.3 * k;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(a, Eigen::Vector3d(0.3, 1, 0.2).normalized())
                                .toRotationMatrix();
  ActorMesh m = testing::sphere(Eigen::Vector3d(0.04 * k, 1.2, 0), 0.2, r);
  m.capture_ns = kT0 + k * kDt;
  return m;
}

std::unique_ptr<FitWorker> worker(int nice = 0, bool realtime = false) {
  auto w = FitWorker::create({MotionOptions{}, nice, realtime});
  EXPECT_TRUE(w) << (w ? "" : w.error().message);
  return w ? std::move(*w) : nullptr;
}

TEST(FitWorker, GivesTheTrackersVelocitiesInOrder) {
  auto w = worker();
  ASSERT_TRUE(w);
  MotionTracker reference;
  std::vector<FitResult> got;
  for (int k = 0; k < 5; ++k) {
    EXPECT_FALSE(w->submit("a", moving(k)));
    w->drain();
    for (auto& r : w->take()) got.push_back(std::move(r));
  }
  ASSERT_EQ(got.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    const FitResult want = fit_motion(reference, "a", moving(k), MotionOptions{}.region_size_m);
    EXPECT_EQ(got[k].actor, "a");
    EXPECT_EQ(got[k].capture_ns, moving(k).capture_ns);
    ASSERT_EQ(got[k].motion.has_value(), want.motion.has_value()) << k;
    EXPECT_EQ(got[k].field.has_value(), want.field.has_value()) << k;
    EXPECT_TRUE(got[k].error.empty()) << got[k].error;
    if (!want.motion) continue;
    ASSERT_EQ(got[k].motion->regions.size(), want.motion->regions.size());
    for (std::size_t i = 0; i < want.motion->regions.size(); ++i)
      EXPECT_EQ(got[k].motion->regions[i].velocity, want.motion->regions[i].velocity);
    // The fitted motion itself: ~1 m/s along x.
    EXPECT_NEAR(got[k].motion->global_velocity.x(), 1.0, 0.05);
  }
  EXPECT_FALSE(got[0].motion);  // the first mesh has nothing to be fitted against
  EXPECT_EQ(w->fitted(), 5u);
  EXPECT_EQ(w->dropped(), 0u);
}

TEST(FitWorker, NewestMeshWinsWhileBusyAndTheLastIsFitted) {
  auto w = worker();
  ASSERT_TRUE(w);
  int replaced = 0;
  const int n = 12;
  for (int k = 0; k < n; ++k) replaced += w->submit("a", moving(k)) ? 1 : 0;
  w->drain();
  auto results = w->take();
  EXPECT_EQ(w->dropped(), uint64_t(replaced));
  EXPECT_EQ(w->fitted() + w->dropped(), uint64_t(n));
  ASSERT_FALSE(results.empty());
  EXPECT_EQ(results.size(), w->fitted());
  EXPECT_EQ(results.back().capture_ns, moving(n - 1).capture_ns);
  for (std::size_t i = 1; i < results.size(); ++i)
    EXPECT_LT(results[i - 1].capture_ns, results[i].capture_ns);
  // Over a skipped mesh the fit spans two intervals and still finds the motion.
  if (results.size() >= 2) {
    ASSERT_TRUE(results.back().motion);
    EXPECT_NEAR(results.back().motion->global_velocity.x(), 1.0, 0.05);
  }
  EXPECT_TRUE(w->take().empty());  // taken once
}

TEST(FitWorker, RemovedActorStartsAfresh) {
  auto w = worker();
  ASSERT_TRUE(w);
  w->submit("a", moving(0));
  w->submit("b", moving(0));
  w->drain();
  EXPECT_EQ(w->take().size(), 2u);
  // Positive control: the next mesh of a kept actor is fitted against its previous one.
  w->submit("b", moving(1));
  w->drain();
  auto kept = w->take();
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_TRUE(kept[0].motion);
  // Removed: a result not taken yet goes, and the next mesh is a first mesh again.
  w->submit("a", moving(1));
  w->drain();
  w->remove("a");
  EXPECT_TRUE(w->take().empty());
  w->submit("a", moving(2));
  w->drain();
  auto fresh = w->take();
  ASSERT_EQ(fresh.size(), 1u);
  EXPECT_EQ(fresh[0].actor, "a");
  EXPECT_FALSE(fresh[0].motion);
  EXPECT_TRUE(fresh[0].error.empty());
}

TEST(FitWorker, RefusedMeshIsAResultWithItsError) {
  auto w = worker();
  ASSERT_TRUE(w);
  w->submit("a", moving(0));
  w->drain();
  ActorMesh bad = moving(1);
  bad.vertices[3].x() = NAN;
  w->submit("a", std::move(bad));
  w->drain();
  w->submit("a", moving(2));  // after a refusal: a first mesh (the tracker was reset)
  w->submit("a", moving(2));  // replaces the waiting one or comes after it: refused as not newer
  w->drain();
  w->submit("a", moving(3));  // positive control: fitted against mesh 2
  w->drain();
  auto r = w->take();
  ASSERT_GE(r.size(), 4u);
  EXPECT_FALSE(r[1].motion);
  EXPECT_NE(r[1].error.find("finite"), std::string::npos) << r[1].error;
  EXPECT_FALSE(r[2].motion);
  ASSERT_TRUE(r.back().motion);
  EXPECT_EQ(r.back().capture_ns, moving(3).capture_ns);
  EXPECT_NEAR(r.back().motion->global_velocity.x(), 1.0, 0.05);
}

// The nice value, real-time priority and scheduling policy of every thread of this process
// (Linux: /proc/self/task/*/stat, fields 19, 40 and 41).
struct ThreadSched {
  int nice = 0, rt_priority = 0, policy = 0;
  bool operator==(const ThreadSched&) const = default;
};
std::vector<ThreadSched> threads_sched() {
  std::vector<ThreadSched> out;
  DIR* d = opendir("/proc/self/task");
  if (!d) return out;
  while (dirent* e = readdir(d)) {
    if (e->d_name[0] == '.') continue;
    std::ifstream f(std::string("/proc/self/task/") + e->d_name + "/stat");
    std::string line;
    std::getline(f, line);
    const auto close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    ThreadSched t;
    for (int i = 3; i <= 41 && rest >> field; ++i) {
      if (i == 19) t.nice = std::stoi(field);
      if (i == 40) t.rt_priority = std::stoi(field);
      if (i == 41) t.policy = std::stoi(field);
    }
    out.push_back(t);
  }
  closedir(d);
  return out;
}

long count(const std::vector<ThreadSched>& threads, const ThreadSched& want) {
  return std::count(threads.begin(), threads.end(), want);
}

TEST(FitWorker, ThreadRunsAtItsNiceValue) {
  EXPECT_FALSE(FitWorker::create({MotionOptions{}, 20}));
  EXPECT_FALSE(FitWorker::create({MotionOptions{}, -1}));
  const int base = getpriority(PRIO_PROCESS, 0);
  auto w = worker(5);
  ASSERT_TRUE(w);
  w->submit("a", moving(0));
  w->drain();  // the thread has run (and set its priority) by now
  EXPECT_EQ(w->priority_note(), "");
  const auto threads = threads_sched();
  EXPECT_EQ(count(threads, {std::min(19, base + 5), 0, SCHED_OTHER}), 1) << "base " << base;
  EXPECT_GE(count(threads, {base, 0, SCHED_OTHER}), 1);  // this thread unchanged
}

// A thread whose setpriority is denied (what the hardening's SystemCallFilter=~@resources does to
// a unit that does not allow it back, deploy/systemd): the worker says why in one line and still
// fits. The filter (seccomp, EPERM for setpriority only) is installed on a thread of its own, so
// that only it and the worker it creates carry it.
TEST(FitWorker, PriorityNotLoweredIsReportedAndTheFitsGoOn) {
  std::string note;
  bool motion = false, filtered = false;
  std::thread([&] {
    sock_filter code[] = {
        BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, nr)),
        BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, __NR_setpriority, 0, 1),
        BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_ERRNO | (EPERM & SECCOMP_RET_DATA)),
        BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_ALLOW),
    };
    sock_fprog prog{static_cast<unsigned short>(std::size(code)), code};
    filtered = prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) == 0 &&
               syscall(SYS_seccomp, SECCOMP_SET_MODE_FILTER, 0, &prog) == 0;
    if (!filtered) return;
    auto w = worker(5);
    if (!w) return;
    note = w->priority_note();
    w->submit("a", moving(0));
    w->drain();
    w->submit("a", moving(1));
    w->drain();
    auto r = w->take();
    motion = !r.empty() && r.back().motion.has_value();
  }).join();
  ASSERT_TRUE(filtered) << "seccomp filter not installed";
  EXPECT_NE(note.find("setpriority: Operation not permitted"), std::string::npos) << note;
  EXPECT_EQ(note.find('\n'), std::string::npos);
  EXPECT_TRUE(motion);
  // The control, ThreadRunsAtItsNiceValue: unfiltered, the note is empty.
}

// A real-time caller (the projector's masks' path at SCHED_FIFO): by default the fit thread goes
// time-sharing at the caller's nice value + the increment; `realtime`, to real-time priority 1,
// below the caller and above all time-sharing work; with no increment it keeps the caller's
// priority (the control).
TEST(FitWorker, RealTimeCallersFitThreadGoesTimeSharingOrToTheLowestRealTimePriority) {
  sched_param rt{};
  rt.sched_priority = 2;
  ASSERT_EQ(pthread_setschedparam(pthread_self(), SCHED_FIFO, &rt), 0)
      << "SCHED_FIFO not permitted: this test needs CAP_SYS_NICE (root, as ./studio test runs)";
  const int base = getpriority(PRIO_PROCESS, 0);
  {
    auto shared = worker(5);
    auto lowered = worker(5, true);
    auto same = worker(0);
    ASSERT_TRUE(shared && lowered && same);
    for (auto* w : {shared.get(), lowered.get(), same.get()}) w->submit("a", moving(0));
    for (auto* w : {shared.get(), lowered.get(), same.get()}) w->drain();
    EXPECT_EQ(shared->priority_note(), "");
    const auto threads = threads_sched();
    EXPECT_EQ(count(threads, {std::min(19, base + 5), 0, SCHED_OTHER}), 1) << "base " << base;
    EXPECT_EQ(count(threads, {base, 1, SCHED_FIFO}), 1);
    EXPECT_GE(count(threads, {base, 2, SCHED_FIFO}), 2);  // this thread and `same`
  }
  sched_param normal{};
  EXPECT_EQ(pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal), 0);
}

// The helper itself, as the scene thread calls it: a real-time thread goes time-sharing even
// with no nice increment; asked to keep real time, it goes to priority 1 of its policy.
TEST(LowerThisThread, RealTimeThreadGoesTimeSharingOrToPriorityOne) {
  int shared = -1, kept = -1, kept_priority = -1;
  std::string shared_note = "unset", kept_note = "unset";
  for (const bool keep : {false, true})
    std::thread([&] {
      sched_param rt{};
      rt.sched_priority = 2;
      if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &rt) != 0) return;
      const std::string note = lower_this_thread(0, keep);
      sched_param now{};
      (keep ? kept : shared) = sched_getscheduler(0);
      (keep ? kept_note : shared_note) = note;
      if (keep && sched_getparam(0, &now) == 0) kept_priority = now.sched_priority;
    }).join();
  EXPECT_EQ(shared_note, "");
  EXPECT_EQ(shared, SCHED_OTHER);
  EXPECT_EQ(kept_note, "");
  EXPECT_EQ(kept, SCHED_FIFO);
  EXPECT_EQ(kept_priority, 1);
}

}  // namespace
}  // namespace studio::projector
