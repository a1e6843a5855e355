#include "capture/pacing.h"
#include "capture/file_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/take.h"

namespace studio::capture {
namespace {

namespace fs = std::filesystem;

bool has_image_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const char* known : {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm"}) {
    if (ext == known) return true;
  }
  return false;
}

// Reads any 8-bit image file as RGB8; an empty image when OpenCV cannot decode it.
Image<Rgb8> read_rgb(const std::string& path) {
  cv::Mat bgr;
  try {
    bgr = cv::imread(path, cv::IMREAD_COLOR);  // grey, palette and alpha images become BGR
  } catch (const cv::Exception&) {
    return {};
  }
  if (bgr.empty() || bgr.type() != CV_8UC3) return {};
  Image<Rgb8> image(bgr.cols, bgr.rows);
  cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, image.data());
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return image;
}

}  // namespace

Expected<void> FileSourceOptions::validate() const {
  if (path.empty()) return fail("file source: path is empty");
  if (!(fps > 0 && fps <= 1000)) {
    return fail("file source " + path + ": fps must be in (0, 1000], got " + std::to_string(fps));
  }
  if (!clock.valid()) return fail("file source " + path + ": clock period must be positive");
  if (start_ns < 0) return fail("file source " + path + ": start_ns must not be negative");
  return {};
}

Expected<std::vector<std::string>> list_image_files(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return fail("image folder " + folder + ": not a directory");
  std::vector<std::string> files;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_regular_file(type_ec) && has_image_extension(it->path())) {
      files.push_back(it->path().string());
    }
  }
  if (ec) return fail("image folder " + folder + ": " + ec.message());
  if (files.empty()) return fail("image folder " + folder + ": no PNG/JPEG/BMP/TIFF images");
  std::sort(files.begin(), files.end());
  return files;
}

Expected<std::unique_ptr<FileSource>> FileSource::create(const FileSourceOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  std::string id = options.id;
  if (id.empty()) {
    fs::path p(options.path);
    id = (p.has_filename() ? p.filename() : p.parent_path().filename()).string();
  }
  std::error_code ec;
  if (fs::is_regular_file(fs::path(options.path) / kFramesFile, ec)) {
    // A take: the index when it is intact, else a scan of frames.raw (after a crash).
    std::vector<IndexEntry> entries;
    if (auto index = read_index(options.path); index && !index->empty()) {
      entries = std::move(*index);
    } else {
      auto scan = scan_frames(options.path);
      if (!scan) return fail("take " + options.path + ": " + scan.error().message);
      entries = std::move(scan->intact);
    }
    if (entries.empty()) return fail("take " + options.path + ": no intact frames in frames.raw");
    std::vector<std::string> labels;
    std::vector<std::pair<uint64_t, uint64_t>> take_entries;
    for (const IndexEntry& e : entries) {
      labels.push_back(options.path + "#" + std::to_string(e.frame));
      take_entries.emplace_back(e.frame, e.offset);
    }
    return std::unique_ptr<FileSource>(
        new FileSource(options, std::move(id), std::move(labels), std::move(take_entries)));
  }
  auto files = list_image_files(options.path);
  if (!files) return std::unexpected(files.error());
  return std::unique_ptr<FileSource>(new FileSource(options, std::move(id), std::move(*files), {}));
}

FileSource::FileSource(FileSourceOptions options, std::string id, std::vector<std::string> files,
                       std::vector<std::pair<uint64_t, uint64_t>> take_entries)
    : options_(std::move(options)),
      id_(std::move(id)),
      files_(std::move(files)),
      take_(!take_entries.empty()),
      take_entries_(std::move(take_entries)) {
  period_ns_ = std::max<int64_t>(1, int64_t(std::llround(1e9 / options_.fps)));
}

Image<Rgb8> FileSource::load(std::size_t item) {
  if (!take_) return read_rgb(files_[item]);
  const IndexEntry entry{take_entries_[item].first, take_entries_[item].second};
  auto header = read_frame(options_.path, entry, take_pixels_);
  if (!header) return {};
  const int w = int(header->width), h = int(header->height);
  if (w <= 0 || h <= 0) return {};
  const std::size_t n = std::size_t(w) * std::size_t(h);
  Image<Rgb8> image(w, h);
  if (header->format == PixelFormat::kRgb8 && take_pixels_.size() >= 3 * n) {
    std::memcpy(image.data(), take_pixels_.data(), 3 * n);
  } else if (header->format == PixelFormat::kMono8 && take_pixels_.size() >= n) {
    for (std::size_t i = 0; i < n; ++i) {
      const uint8_t v = take_pixels_[i];
      image.data()[i] = Rgb8{v, v, v};
    }
  } else {
    return {};
  }
  return image;
}

Expected<void> FileSource::start() {
  std::lock_guard lock(mutex_);
  const int64_t now = realtime_ns();
  if (options_.start_ns == 0) {
    const FrameClock& c = options_.clock;
    first_capture_ns_ = c.time_of(c.frame_at(now) + 1) + c.period_ns / 2;
    first_due_ns_ = first_capture_ns_;
  } else {
    first_capture_ns_ = options_.start_ns;
    first_due_ns_ = now;
  }
  index_ = 0;
  failures_in_pass_ = 0;
  first_width_ = first_height_ = 0;
  started_ = true;
  finished_ = false;
  stopping_ = false;
  stats_ = SourceStats{};
  return {};
}

void FileSource::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
}

bool FileSource::wait_until(int64_t due_ns, std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  return wait_until_realtime(lock, wake_, stopping_, due_ns, deadline);
}

Expected<std::optional<Frame>> FileSource::next(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  if (!started_) return fail("file source " + id_ + ": next() before start()");
  for (;;) {
    if (finished_) {
      wait_until(INT64_MAX, deadline);
      return std::optional<Frame>();
    }
    const int64_t offset = int64_t(index_) * period_ns_;
    if (options_.paced && !wait_until(first_due_ns_ + offset, deadline)) {
      return std::optional<Frame>();
    }
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return std::optional<Frame>();
    }
    const std::size_t file = std::size_t(index_ % files_.size());
    Frame frame;
    frame.capture_ns = first_capture_ns_ + offset;
    frame.frame = options_.clock.frame_at(frame.capture_ns);
    frame.image = load(file);
    ++index_;
    const bool end_of_pass = file + 1 == files_.size();
    bool ok = !frame.image.pixels().empty();
    if (ok && first_width_ == 0) {
      first_width_ = frame.image.width();
      first_height_ = frame.image.height();
    }
    ok = ok && frame.image.width() == first_width_ && frame.image.height() == first_height_;
    {
      std::lock_guard lock(mutex_);
      if (ok) {
        ++stats_.frames;
      } else {
        ++stats_.drops;
      }
    }
    failures_in_pass_ += ok ? 0 : 1;
    if (end_of_pass) {
      const bool all_failed = failures_in_pass_ == files_.size();
      failures_in_pass_ = 0;
      if (all_failed) {
        finished_ = true;
        return fail("file source " + id_ + ": none of the " + std::to_string(files_.size()) +
                    (take_ ? " take frames" : " images") + " in " + options_.path +
                    " could be decoded");
      }
      if (!options_.loop) finished_ = true;
    }
    if (ok) return std::optional<Frame>(std::move(frame));
    if (std::chrono::steady_clock::now() >= deadline) return std::optional<Frame>();
  }
}

SourceStats FileSource::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace studio::capture
