#pragma once
// The recorder (issue 3 item 5): one camera's take written to disk uncompressed at full rate, in
// the format of capture/take.h (frames.raw + index + take.yaml, DESIGN §4).
//
// Threads: push() is called by the capture loop and only copies the frame into a bounded queue
// (buffers are pooled, so a steady take allocates nothing); a dedicated writer thread computes
// each frame's CRC and appends header + payload with one writev() on an O_APPEND descriptor, then
// appends the index entry. If the disk cannot keep up, the queue fills and push() drops the frame
// and counts it (stats().queue_drops): the capture loop never blocks on the disk.
//
// Durability: the writer fdatasync()s frames.raw (and the index and the per-frame calibration
// file) at least every sync_interval_ms while recording, so a power cut loses at most the frames
// of the last interval (plus the queue); `studio-capture verify-take` rebuilds the index from
// what frames.raw kept. take.yaml and the index are replaced by rename, and the folder is
// fsync()ed after each rename and after the files are created.
// Tracked cameras: a frame pushed with a calibration gets a line in the take's `calibration`
// file (capture/take_calibration.h), written after the frame.
//
// End of a take: stop() makes push() refuse further frames; the writer drains the queue,
// fdatasync()s frames.raw, rewrites the index atomically and rewrites take.yaml with
// status complete, first/last frame, count and drops. wait() joins and returns that TakeInfo.
//
// Errors (ENOSPC, EFBIG from a size limit, EIO, ...): the writer truncates frames.raw back to the
// end of the last complete frame (so every earlier frame stays intact and no torn frame
// remains), stops accepting frames, finalises index and take.yaml with status error and the
// message (take.yaml is rewritten in place on a full disk; should even that fail, it keeps
// status recording and `studio-capture verify-take` still recovers every frame), and enters
// state kError; wait() returns the error. Processes that run with a file
// size limit must ignore SIGXFSZ so that the limit shows up as EFBIG here.

#include <condition_variable>
#include <cstdint>
#include <chrono>
#include <deque>
#include <optional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "capture/frame_source.h"
#include "capture/take.h"
#include "core/error.h"
#include "core/image.h"

namespace studio::capture {

struct RecorderOptions {
  std::string dir;                // takes/<take>/<camera_id>; created with its parents; must not
                                  // already hold a frames.raw (a take is never overwritten)
  std::size_t queue_frames = 50;  // 2 s at 25 fps; 1 .. 10000
  int sync_interval_ms = 1000;    // fdatasync at least this often while recording; 1 .. 60000
  Expected<void> validate() const;
};

enum class RecorderState { kRecording, kStopping, kFinished, kError };

struct RecorderStats {
  uint64_t frames_written = 0;
  uint64_t bytes_written = 0;
  uint64_t queue_drops = 0;  // frames refused because the queue was full
  uint64_t other_drops = 0;  // reported by the caller (add_drops)
  std::size_t max_queue_depth = 0;
  double write_ms_total = 0;  // writer thread time in CRC + writev, for the headroom figure
  uint64_t syncs = 0;         // fdatasync rounds while recording
};

class Recorder {
 public:
  // Creates the directory, frames.raw (O_EXCL), the index and take.yaml (status recording) and
  // starts the writer thread. `info` supplies take, camera, size, format, period, start frame
  // and calibration; the frame counters are the recorder's.
  static Expected<std::unique_ptr<Recorder>> start(const RecorderOptions& options, TakeInfo info);
  ~Recorder();  // stop() + wait()
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Queues a copy of the frame. False (and nothing written) when the frame's size differs from
  // the take's, when not recording, or when the queue is full (counted in queue_drops).
  bool push(uint64_t frame, int64_t capture_ns, ImageView<const Rgb8> image,
            const std::optional<Camera>& calibration = std::nullopt);
  bool push(const Frame& frame) {
    return push(frame.frame, frame.capture_ns, frame.image.view(), frame.calibration);
  }
  // Frames the source lost during the take (counted in take.yaml's drops).
  void add_drops(uint64_t n);

  // Ends the take; `stop_frame` (exclusive) goes into take.yaml. Non-blocking; idempotent.
  void stop(std::optional<uint64_t> stop_frame = std::nullopt);
  // Joins the writer (after stop(), or after an error) and returns the final take.yaml contents,
  // or the error that ended the take.
  Expected<TakeInfo> wait();

  RecorderState state() const;
  std::string error() const;  // "" unless kError
  RecorderStats stats() const;
  const std::string& dir() const { return options_.dir; }
  const TakeInfo& info() const { return info_; }  // as given at start (take, camera, size)

 private:
  Recorder(RecorderOptions options, TakeInfo info, int frames_fd, int index_fd);
  void writer_loop();
  // Appends one frame; false with the error set on failure.
  bool write_frame(const std::vector<uint8_t>& pixels, uint64_t frame, int64_t capture_ns);
  bool write_calibration(uint64_t frame, const Camera& camera);
  bool sync_files();
  void finalise(bool failed);

  struct Slot {
    uint64_t frame = 0;
    int64_t capture_ns = 0;
    std::vector<uint8_t> pixels;
    std::optional<Camera> calibration;
  };

  const RecorderOptions options_;
  TakeInfo info_;
  int frames_fd_ = -1;
  int index_fd_ = -1;
  int calibration_fd_ = -1;  // opened with the first calibrated frame
  std::chrono::steady_clock::time_point last_sync_;
  uint64_t good_bytes_ = 0;  // frames.raw length up to the last complete frame
  std::vector<IndexEntry> index_;
  std::optional<uint64_t> first_frame_, last_frame_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Slot> queue_;
  std::vector<std::vector<uint8_t>> free_buffers_;
  std::size_t buffers_allocated_ = 0;
  RecorderState state_ = RecorderState::kRecording;
  std::optional<uint64_t> stop_frame_;
  std::string error_;
  RecorderStats stats_;
  std::optional<Expected<TakeInfo>> result_;
  std::thread writer_;
};

}  // namespace studio::capture
