#include "balance_worker.h"

#include <sys/resource.h>
#include <unistd.h>

#include "core/log.h"

namespace studio::preview {

BalanceWorker::BalanceWorker(int nice)
    : snapshot_(balance_.snapshot()), thread_([this, nice] {
        // Linux: the nice value of a thread (its tid as the process id).
        if (nice != 0 && setpriority(PRIO_PROCESS, gettid(), nice) != 0)
          STUDIO_LOG(warn, "preview") << "colour balance worker: cannot set nice " << nice;
        run();
      }) {}

BalanceWorker::~BalanceWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool BalanceWorker::submit(Job&& job) {
  {
    std::lock_guard lock(mutex_);
    if (busy_ || job_) return false;
    job_ = std::move(job);
  }
  wake_.notify_one();
  return true;
}

BalanceSnapshot BalanceWorker::snapshot() const {
  std::lock_guard lock(mutex_);
  return snapshot_;
}

void BalanceWorker::wait_idle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return !busy_ && !job_; });
}

void BalanceWorker::restart() {
  std::lock_guard lock(mutex_);
  restart_ = true;
  job_.reset();
  snapshot_ = RigBalance().snapshot();
}

uint64_t BalanceWorker::pooled() const {
  std::lock_guard lock(mutex_);
  return pooled_;
}

void BalanceWorker::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || job_; });
      if (!job_) return;  // stopping with nothing in hand
      job = std::move(*job_);
      job_.reset();
      busy_ = true;
      if (restart_) {
        balance_ = RigBalance();
        restart_ = false;
      }
    }
    std::vector<BalanceView> views;
    for (std::size_t i = 0; i < job.cameras.size(); ++i)
      views.push_back(
          {job.cameras[i],
           ImageView<const Rgb8>(reinterpret_cast<const Rgb8*>(job.images[i].rgb.data()),
                                 job.images[i].width, job.images[i].height),
           &job.masks[i]});
    const auto ok = balance_.add(job.rig, job.mesh, views);
    if (!ok) STUDIO_LOG(warn, "preview") << ok.error().message;
    {
      std::lock_guard lock(mutex_);
      if (ok && !restart_) {  // a restart while pooling: this job was of the old colours
        snapshot_ = balance_.snapshot();
        ++pooled_;
      }
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace studio::preview
