#include "capture/recorder.h"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>

#include "capture/take_calibration.h"

namespace studio::capture {
namespace {

std::string errno_text(const std::string& what, int err) {
  return what + ": " + std::strerror(err);
}

}  // namespace

Expected<void> RecorderOptions::validate() const {
  if (dir.empty()) return fail("recorder: dir is empty");
  if (queue_frames < 1 || queue_frames > 10000)
    return fail("recorder: queue_frames must be in 1..10000, got " + std::to_string(queue_frames));
  if (sync_interval_ms < 1 || sync_interval_ms > 60000)
    return fail("recorder: sync_interval_ms must be in 1..60000, got " +
                std::to_string(sync_interval_ms));
  return {};
}

Expected<std::unique_ptr<Recorder>> Recorder::start(const RecorderOptions& options, TakeInfo info) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  if (info.width == 0 || info.height == 0) return fail("recorder: take has no frame size");
  std::error_code ec;
  std::filesystem::create_directories(options.dir, ec);
  if (ec) return fail("recorder: cannot create " + options.dir + ": " + ec.message());
  const std::string frames_path = options.dir + "/" + kFramesFile;
  const int frames_fd =
      ::open(frames_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_APPEND | O_CLOEXEC, 0644);
  if (frames_fd < 0) return fail(errno_text("recorder: cannot create " + frames_path, errno));
  const std::string index_path = options.dir + "/" + kIndexFile;
  // Index header first (entries are appended as frames land; rewritten at the end), then
  // take.yaml with status recording.
  info.status = "recording";
  info.frames = 0;
  info.drops = 0;
  info.first_frame.reset();
  info.last_frame.reset();
  Expected<void> written = write_index(options.dir, {});
  if (written) written = write_take_yaml(options.dir, info);
  if (!written) {
    ::close(frames_fd);
    return fail("recorder: " + written.error().message);
  }
  const int index_fd = ::open(index_path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (index_fd < 0) {
    const int err = errno;
    ::close(frames_fd);
    return fail(errno_text("recorder: cannot open " + index_path, err));
  }
  // The new files' names are durable before the first frame is.
  if (auto synced = sync_directory(options.dir); !synced) {
    ::close(frames_fd);
    ::close(index_fd);
    return fail("recorder: " + synced.error().message);
  }
  auto r = std::unique_ptr<Recorder>(new Recorder(options, std::move(info), frames_fd, index_fd));
  r->last_sync_ = std::chrono::steady_clock::now();
  r->writer_ = std::thread([p = r.get()] { p->writer_loop(); });
  return r;
}

Recorder::Recorder(RecorderOptions options, TakeInfo info, int frames_fd, int index_fd)
    : options_(std::move(options)),
      info_(std::move(info)),
      frames_fd_(frames_fd),
      index_fd_(index_fd) {}

Recorder::~Recorder() {
  stop();
  (void)wait();
}

bool Recorder::push(uint64_t frame, int64_t capture_ns, ImageView<const Rgb8> image,
                    const std::optional<Camera>& calibration) {
  if (image.width() != int(info_.width) || image.height() != int(info_.height)) return false;
  const std::size_t row_bytes = std::size_t(image.width()) * sizeof(Rgb8);
  std::vector<uint8_t> buffer;
  {
    std::lock_guard lock(mutex_);
    if (state_ != RecorderState::kRecording) return false;
    if (queue_.size() >= options_.queue_frames) {
      ++stats_.queue_drops;
      return false;
    }
    if (!free_buffers_.empty()) {
      buffer = std::move(free_buffers_.back());
      free_buffers_.pop_back();
    }
  }
  // Copy outside the lock (the writer keeps writing meanwhile).
  buffer.resize(row_bytes * std::size_t(image.height()));
  for (int y = 0; y < image.height(); ++y)
    std::memcpy(buffer.data() + row_bytes * std::size_t(y), image.row(y), row_bytes);
  {
    std::lock_guard lock(mutex_);
    if (state_ != RecorderState::kRecording) return false;
    queue_.push_back(Slot{frame, capture_ns, std::move(buffer), calibration});
    stats_.max_queue_depth = std::max(stats_.max_queue_depth, queue_.size());
  }
  wake_.notify_one();
  return true;
}

void Recorder::add_drops(uint64_t n) {
  std::lock_guard lock(mutex_);
  stats_.other_drops += n;
}

void Recorder::stop(std::optional<uint64_t> stop_frame) {
  {
    std::lock_guard lock(mutex_);
    if (state_ == RecorderState::kRecording) {
      state_ = RecorderState::kStopping;
      stop_frame_ = stop_frame;
    }
  }
  wake_.notify_one();
}

Expected<TakeInfo> Recorder::wait() {
  if (writer_.joinable()) writer_.join();
  std::lock_guard lock(mutex_);
  if (result_) return *result_;
  return fail("recorder: take " + info_.take + " is still recording");
}

RecorderState Recorder::state() const {
  std::lock_guard lock(mutex_);
  return state_;
}

std::string Recorder::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

RecorderStats Recorder::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void Recorder::writer_loop() {
  bool failed = false;
  for (;;) {
    Slot slot;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return !queue_.empty() || state_ != RecorderState::kRecording; });
      if (queue_.empty()) break;  // stopping and drained
      slot = std::move(queue_.front());
      queue_.pop_front();
    }
    const auto t0 = std::chrono::steady_clock::now();
    bool ok = write_frame(slot.pixels, slot.frame, slot.capture_ns);
    if (ok && slot.calibration) ok = write_calibration(slot.frame, *slot.calibration);
    if (ok && std::chrono::steady_clock::now() - last_sync_ >=
                  std::chrono::milliseconds(options_.sync_interval_ms))
      ok = sync_files();
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::lock_guard lock(mutex_);
    stats_.write_ms_total += ms;
    free_buffers_.push_back(std::move(slot.pixels));
    if (!ok) {
      failed = true;
      // Frames still queued are not recorded; they count as drops of the failed take.
      stats_.other_drops += queue_.size();
      for (auto& s : queue_) free_buffers_.push_back(std::move(s.pixels));
      queue_.clear();
      break;
    }
  }
  finalise(failed);
}

bool Recorder::write_frame(const std::vector<uint8_t>& pixels, uint64_t frame, int64_t capture_ns) {
  FrameHeader h;
  h.frame = frame;
  h.capture_ns = capture_ns;
  h.width = info_.width;
  h.height = info_.height;
  h.format = info_.format;
  h.payload_size = pixels.size();
  uint8_t header[kFrameHeaderSize];
  encode_frame_header(h, pixels, header);

  const std::size_t total = kFrameHeaderSize + pixels.size();
  std::size_t done = 0;
  int err = 0;
  while (done < total) {
    iovec iov[2];
    int n = 0;
    if (done < kFrameHeaderSize) {
      iov[n++] = {header + done, kFrameHeaderSize - done};
      iov[n++] = {const_cast<uint8_t*>(pixels.data()), pixels.size()};
    } else {
      const std::size_t p = done - kFrameHeaderSize;
      iov[n++] = {const_cast<uint8_t*>(pixels.data()) + p, pixels.size() - p};
    }
    const ssize_t w = ::writev(frames_fd_, iov, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      err = errno;
      break;
    }
    if (w == 0) {
      err = EIO;
      break;
    }
    done += std::size_t(w);
  }
  if (err == 0) {
    uint8_t entry[16];
    const uint64_t offset = good_bytes_;
    std::memcpy(entry, &frame, 8);
    std::memcpy(entry + 8, &offset, 8);
    // A failed index append is an error too (the disk is full); the index is rebuilt at the end.
    const ssize_t w = ::write(index_fd_, entry, sizeof entry);
    const int index_err = w == ssize_t(sizeof entry) ? 0 : w < 0 ? errno : ENOSPC;
    // The frame itself is complete: keep it, even when its index entry failed.
    good_bytes_ += total;
    index_.push_back({frame, offset});
    if (!first_frame_) first_frame_ = frame;
    last_frame_ = frame;
    std::lock_guard lock(mutex_);
    ++stats_.frames_written;
    stats_.bytes_written += total;
    if (index_err == 0) return true;
    error_ = errno_text("recorder: cannot append to " + options_.dir + "/index", index_err);
    return false;
  }
  // Remove the torn frame so the file ends with a complete one.
  if (::ftruncate(frames_fd_, off_t(good_bytes_)) != 0) {
    // Leave it: scan_frames() stops at the torn frame and verify-take reports it.
  }
  std::lock_guard lock(mutex_);
  error_ = errno_text("recorder: cannot write frame " + std::to_string(frame) + " to " +
                          options_.dir + "/" + kFramesFile,
                      err);
  return false;
}

bool Recorder::write_calibration(uint64_t frame, const Camera& camera) {
  if (calibration_fd_ < 0) {
    const std::string path = options_.dir + "/" + kCalibrationFile;
    calibration_fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (calibration_fd_ < 0 || !sync_directory(options_.dir)) {
      std::lock_guard lock(mutex_);
      error_ = errno_text("recorder: cannot create " + path, errno);
      return false;
    }
  }
  const std::string line = format_calibration_line(frame, camera);
  const ssize_t w = ::write(calibration_fd_, line.data(), line.size());
  if (w == ssize_t(line.size())) return true;
  std::lock_guard lock(mutex_);
  error_ = errno_text("recorder: cannot append to " + options_.dir + "/" + kCalibrationFile,
                      w < 0 ? errno : ENOSPC);
  return false;
}

bool Recorder::sync_files() {
  last_sync_ = std::chrono::steady_clock::now();
  for (int fd : {frames_fd_, index_fd_, calibration_fd_}) {
    if (fd >= 0 && ::fdatasync(fd) != 0) {
      std::lock_guard lock(mutex_);
      error_ = errno_text("recorder: fdatasync " + options_.dir, errno);
      return false;
    }
  }
  std::lock_guard lock(mutex_);
  ++stats_.syncs;
  return true;
}

void Recorder::finalise(bool failed) {
  std::string sync_error;
  for (int fd : {frames_fd_, calibration_fd_})
    if (fd >= 0 && ::fdatasync(fd) != 0 && sync_error.empty())
      sync_error = errno_text("recorder: fdatasync", errno);
  ::close(frames_fd_);
  ::close(index_fd_);
  if (calibration_fd_ >= 0) ::close(calibration_fd_);
  frames_fd_ = index_fd_ = calibration_fd_ = -1;

  TakeInfo final_info = info_;
  RecorderStats stats;
  {
    std::lock_guard lock(mutex_);
    stats = stats_;
    final_info.stop_frame = stop_frame_ ? stop_frame_ : info_.stop_frame;
    if (!failed && !sync_error.empty()) {
      failed = true;
      error_ = sync_error;
    }
    final_info.error = failed ? error_ : "";
  }
  final_info.first_frame = first_frame_;
  final_info.last_frame = last_frame_;
  final_info.frames = stats.frames_written;
  final_info.drops = stats.queue_drops + stats.other_drops;
  final_info.status = failed ? "error" : "complete";
  auto index_written = write_index(options_.dir, index_);
  auto yaml_written = write_take_yaml(options_.dir, final_info);

  std::lock_guard lock(mutex_);
  if (failed) {
    state_ = RecorderState::kError;
    result_ = fail(error_);
  } else if (!index_written || !yaml_written) {
    state_ = RecorderState::kError;
    error_ = "recorder: " + (!index_written ? index_written.error() : yaml_written.error()).message;
    result_ = fail(error_);
  } else {
    state_ = RecorderState::kFinished;
    result_ = final_info;
  }
}

}  // namespace studio::capture
