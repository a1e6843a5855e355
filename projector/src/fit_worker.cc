#include "projector/fit_worker.h"

#include <algorithm>
#include <system_error>

#include "projector/thread_priority.h"

namespace studio::projector {

Expected<void> FitWorkerOptions::validate() const {
  if (auto ok = motion.validate(); !ok) return ok;
  if (nice_increment < 0 || nice_increment > 19) return fail("nice_increment: 0..19");
  return {};
}

Expected<std::unique_ptr<FitWorker>> FitWorker::create(const FitWorkerOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  std::unique_ptr<FitWorker> w(new FitWorker(options));
  try {
    w->thread_ = std::thread([p = w.get()] { p->run(); });
  } catch (const std::system_error& e) {
    return fail(std::string("motion fit thread: ") + e.what());
  }
  std::unique_lock lock(w->mutex_);  // until the thread has set its priority
  w->idle_.wait(lock, [&] { return w->started_; });
  return w;
}

FitWorker::FitWorker(const FitWorkerOptions& options) : options_(options) {}

FitWorker::~FitWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool FitWorker::submit(const std::string& actor, ActorMesh mesh) {
  bool replaced = false;
  {
    std::lock_guard lock(mutex_);
    const std::uint64_t epoch = epochs_[actor];
    auto it = std::find_if(jobs_.begin(), jobs_.end(), [&](const Job& j) { return j.actor == actor; });
    if (it != jobs_.end()) {
      it->mesh = std::move(mesh);  // keeps its place in the queue
      it->epoch = epoch;
      ++dropped_;
      replaced = true;
    } else {
      jobs_.push_back({actor, epoch, std::move(mesh)});
    }
  }
  wake_.notify_one();
  return replaced;
}

void FitWorker::remove(const std::string& actor) {
  std::lock_guard lock(mutex_);
  ++epochs_[actor];  // a fit running now for it is discarded when it lands
  std::erase_if(jobs_, [&](const Job& j) { return j.actor == actor; });
  std::erase_if(results_, [&](const FitResult& r) { return r.actor == actor; });
}

std::vector<FitResult> FitWorker::take() {
  std::vector<FitResult> out;
  std::lock_guard lock(mutex_);
  out.swap(results_);
  return out;
}

void FitWorker::drain() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return (jobs_.empty() && !busy_) || stop_; });
}

std::string FitWorker::priority_note() const {
  std::lock_guard lock(mutex_);
  return priority_note_;
}

std::uint64_t FitWorker::fitted() const {
  std::lock_guard lock(mutex_);
  return fitted_;
}

std::uint64_t FitWorker::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

void FitWorker::run() {
  std::string note;
  if (options_.nice_increment > 0) {
    // Failing to lower our own priority changes only the share, not the results. A real-time
    // caller (the projector's masks' path): time-sharing by default — beside a real-time render
    // thread that drew the whole scene (session 17) the fit starved this way; with the scene on
    // its own time-sharing thread (session 18) it shares the rest with it — or (`realtime`) the
    // lowest real-time priority, below the render thread, above every time-sharing thread.
    note = lower_this_thread(options_.nice_increment, options_.realtime);
    if (!note.empty())
      note = "motion fit thread: its priority was not lowered (" + note +
             "): it shares the CPU with the render thread as an equal";
  }
  std::unique_lock lock(mutex_);
  priority_note_ = note;
  started_ = true;
  idle_.notify_all();
  while (true) {
    wake_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
    if (stop_) break;
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    busy_ = true;
    // Trackers of actors removed since (their epoch moved on) go; a new one starts below.
    std::erase_if(trackers_, [this](const auto& t) { return epochs_[t.first] != t.second.first; });
    lock.unlock();
    auto it = trackers_.find(job.actor);
    if (it == trackers_.end())
      it = trackers_.emplace(job.actor, std::pair(job.epoch, MotionTracker(options_.motion))).first;
    FitResult r =
        fit_motion(it->second.second, job.actor, job.mesh, options_.motion.region_size_m);
    lock.lock();
    busy_ = false;
    ++fitted_;
    if (epochs_[job.actor] == job.epoch) results_.push_back(std::move(r));
    if (jobs_.empty()) idle_.notify_all();
  }
  busy_ = false;
  idle_.notify_all();
}

}  // namespace studio::projector
