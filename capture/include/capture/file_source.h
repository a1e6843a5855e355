#pragma once
// File replay behind the FrameSource interface, at a set rate, optionally looping:
// - an image folder (PNG / JPEG / BMP / TIFF, sorted by file name), or
// - one camera's recorded take (DESIGN §4, capture/take.h): a folder holding frames.raw, replayed
//   in index order (the index, or a scan of frames.raw when the index is missing or damaged);
//   RGB8 and MONO8 frames, each checked against its CRC.
//
// Time and frame numbers (DESIGN §5): frame i of the replay gets
//   capture_ns = start_ns + i * (1e9 / fps),   frame = clock.frame_at(capture_ns)
// where i counts every delivered or dropped frame since start(), across loops. With start_ns = 0
// the replay begins at the middle of the studio clock's next frame period (clock.time_of(n) +
// period/2, the genlock instant), so at fps = 1e9 / clock.period_ns the frame numbers are
// consecutive and agree with live cameras.
// Pacing: with `paced` true, next() does not deliver frame i before its due time on
// CLOCK_REALTIME (capture_ns itself when start_ns = 0, else the time of start() plus
// i / fps); a late consumer gets frames immediately, none are skipped. With `paced` false frames
// come as fast as next() is called (offline processing, tests).
// The recorded frame numbers and capture times of a take are not reused: replay is a new
// capture, numbered by the rule above.
// A file or take frame that cannot be decoded (or fails its CRC), or whose size differs from the
// first image's, is skipped and
// counted in stats().drops (its time slot and frame number are consumed, as a camera drop would);
// if every file of a pass fails, next() returns an Error. After the last file without `loop`,
// next() waits out its timeout and returns nullopt; finished() is then true.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "capture/frame_clock.h"
#include "capture/frame_source.h"
#include "core/error.h"

namespace studio::capture {

struct FileSourceOptions {
  std::string id;     // camera id; empty = the folder's name
  std::string path;   // an image folder
  double fps = 25.0;  // replay rate, > 0 and <= 1000
  bool loop = false;
  bool paced = true;
  FrameClock clock;
  int64_t start_ns = 0;  // capture time of the first frame; 0 = from the clock (see above)

  Expected<void> validate() const;
};

// Image files of a folder (regular files with an image extension, case-insensitive), sorted by
// name. Fails with one line if the folder is missing, unreadable or holds no image.
Expected<std::vector<std::string>> list_image_files(const std::string& folder);

class FileSource : public FrameSource {
 public:
  // Lists the folder; fails with one line on bad options or an empty/missing folder.
  static Expected<std::unique_ptr<FileSource>> create(const FileSourceOptions& options);

  const std::string& id() const override { return id_; }
  Expected<void> start() override;
  void stop() override;
  Expected<std::optional<Frame>> next(std::chrono::milliseconds timeout) override;
  SourceStats stats() const override;
  TimeSource time_source() const override { return TimeSource::studio_clock; }

  std::size_t size() const { return files_.size(); }  // images (or take frames) per pass
  bool is_take() const { return take_; }
  bool finished() const { return finished_; }

 private:
  FileSource(FileSourceOptions options, std::string id, std::vector<std::string> files,
             std::vector<std::pair<uint64_t, uint64_t>> take_entries);
  Image<Rgb8> load(std::size_t item);
  // Waits until CLOCK_REALTIME reaches due_ns, stop() or the deadline; true when due.
  bool wait_until(int64_t due_ns, std::chrono::steady_clock::time_point deadline);

  FileSourceOptions options_;
  std::string id_;
  std::vector<std::string> files_;  // image paths, or one label per take frame
  bool take_ = false;
  std::vector<std::pair<uint64_t, uint64_t>> take_entries_;  // (recorded frame, byte offset)
  std::vector<uint8_t> take_pixels_;
  int64_t period_ns_ = 0;
  int64_t first_capture_ns_ = 0;
  int64_t first_due_ns_ = 0;
  uint64_t index_ = 0;  // frames consumed since start()
  uint64_t failures_in_pass_ = 0;
  int first_width_ = 0, first_height_ = 0;
  bool started_ = false;
  bool finished_ = false;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  SourceStats stats_;
};

}  // namespace studio::capture
