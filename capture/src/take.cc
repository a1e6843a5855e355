#include "capture/take.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "capture/crc32.h"

namespace studio::capture {
namespace {

constexpr uint8_t kMagic[4] = {'S', 'T', 'F', 'R'};
constexpr uint8_t kIndexMagic[4] = {'S', 'T', 'I', 'X'};
constexpr std::size_t kCrcOffset = 40;

template <class T>
void put(uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);  // little-endian hosts (x86-64, aarch64)
}
template <class T>
T get(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::string errno_text(const std::string& what) { return what + ": " + std::strerror(errno); }

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// Reads exactly n bytes at offset (fewer only at end of file); -1 on error.
ssize_t pread_full(int fd, void* buf, std::size_t n, uint64_t offset) {
  std::size_t done = 0;
  while (done < n) {
    const ssize_t r = ::pread(fd, static_cast<char*>(buf) + done, n - done, off_t(offset + done));
    if (r < 0) {
      if (errno == EINTR) continue;
      return -1;
    }
    if (r == 0) break;
    done += std::size_t(r);
  }
  return ssize_t(done);
}

bool write_full(int fd, const void* buf, std::size_t n) {
  std::size_t done = 0;
  while (done < n) {
    const ssize_t r = ::write(fd, static_cast<const char*>(buf) + done, n - done);
    if (r < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    done += std::size_t(r);
  }
  return true;
}

// Writes `bytes` to dir/name via dir/name.tmp, fsync and rename.
Expected<void> write_atomic(const std::string& dir, const std::string& name,
                            std::span<const uint8_t> bytes) {
  const std::string path = dir + "/" + name;
  const std::string tmp = path + ".tmp";
  {
    Fd fd(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
    if (fd.get() < 0) return fail(errno_text("cannot create " + tmp));
    if (!write_full(fd.get(), bytes.data(), bytes.size()) || ::fdatasync(fd.get()) != 0) {
      const auto e = fail(errno_text("cannot write " + tmp));
      ::unlink(tmp.c_str());
      return e;
    }
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) return fail(errno_text("cannot rename " + tmp));
  return sync_directory(dir);  // the rename itself is durable
}

}  // namespace

Expected<void> sync_directory(const std::string& dir) {
  Fd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0 || ::fsync(fd.get()) != 0) return fail(errno_text("cannot sync folder " + dir));
  return {};
}

const char* pixel_format_name(PixelFormat format) {
  switch (format) {
    case PixelFormat::kRgb8:
      return "rgb8";
    case PixelFormat::kMono8:
      return "mono8";
  }
  return "unknown";
}

int bytes_per_pixel(PixelFormat format) { return format == PixelFormat::kMono8 ? 1 : 3; }

uint32_t encode_frame_header(const FrameHeader& h, std::span<const uint8_t> payload,
                             uint8_t (&out)[kFrameHeaderSize]) {
  std::memset(out, 0, sizeof out);
  std::memcpy(out, kMagic, 4);
  put<uint16_t>(out + 4, kTakeVersion);
  put<uint16_t>(out + 6, static_cast<uint16_t>(h.format));
  put<uint64_t>(out + 8, h.frame);
  put<int64_t>(out + 16, h.capture_ns);
  put<uint32_t>(out + 24, h.width);
  put<uint32_t>(out + 28, h.height);
  put<uint64_t>(out + 32, h.payload_size);
  uint32_t crc = crc32_update(0, out, kCrcOffset);
  crc = crc32_update(crc, payload.data(), payload.size());
  put<uint32_t>(out + kCrcOffset, crc);
  return crc;
}

Expected<FrameHeader> decode_frame_header(std::span<const uint8_t> b) {
  if (b.size() < kFrameHeaderSize) return fail("truncated frame header");
  if (std::memcmp(b.data(), kMagic, 4) != 0) return fail("bad frame magic");
  const auto version = get<uint16_t>(b.data() + 4);
  if (version != kTakeVersion) return fail("unsupported frame version " + std::to_string(version));
  FrameHeader h;
  const auto format = get<uint16_t>(b.data() + 6);
  if (format != uint16_t(PixelFormat::kRgb8) && format != uint16_t(PixelFormat::kMono8))
    return fail("unknown pixel format " + std::to_string(format));
  h.format = static_cast<PixelFormat>(format);
  h.frame = get<uint64_t>(b.data() + 8);
  h.capture_ns = get<int64_t>(b.data() + 16);
  h.width = get<uint32_t>(b.data() + 24);
  h.height = get<uint32_t>(b.data() + 28);
  h.payload_size = get<uint64_t>(b.data() + 32);
  h.crc = get<uint32_t>(b.data() + kCrcOffset);
  if (h.width == 0 || h.height == 0 || h.width > 32768 || h.height > 32768)
    return fail("bad frame size " + std::to_string(h.width) + "x" + std::to_string(h.height));
  if (h.payload_size != uint64_t(h.width) * h.height * uint64_t(bytes_per_pixel(h.format)) ||
      h.payload_size > kMaxFramePayload)
    return fail("payload size " + std::to_string(h.payload_size) +
                " does not match the frame size");
  if (get<uint32_t>(b.data() + 44) != 0) return fail("reserved header field is not zero");
  return h;
}

bool frame_crc_matches(std::span<const uint8_t> header_bytes, std::span<const uint8_t> payload) {
  if (header_bytes.size() < kFrameHeaderSize) return false;
  uint32_t crc = crc32_update(0, header_bytes.data(), kCrcOffset);
  crc = crc32_update(crc, payload.data(), payload.size());
  return crc == get<uint32_t>(header_bytes.data() + kCrcOffset);
}

Expected<ScanReport> scan_frames(const std::string& dir) {
  const std::string path = dir + "/" + kFramesFile;
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) return fail(errno_text("cannot open " + path));
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return fail(errno_text("cannot stat " + path));
  ScanReport report;
  report.file_bytes = uint64_t(st.st_size);
  std::vector<uint8_t> payload;
  uint8_t header[kFrameHeaderSize];
  uint64_t offset = 0;
  while (offset < report.file_bytes) {
    const ssize_t n = pread_full(fd.get(), header, sizeof header, offset);
    if (n < 0) return fail(errno_text("cannot read " + path));
    if (std::size_t(n) < sizeof header) {
      report.tail = "partial frame header at byte " + std::to_string(offset);
      break;
    }
    auto h = decode_frame_header(header);
    if (!h) {
      report.tail = h.error().message + " at byte " + std::to_string(offset);
      break;
    }
    const uint64_t end = offset + kFrameHeaderSize + h->payload_size;
    if (end > report.file_bytes) {
      report.tail = "partial frame " + std::to_string(h->frame) + " at byte " +
                    std::to_string(offset) + " (" +
                    std::to_string(report.file_bytes - offset - kFrameHeaderSize) + " of " +
                    std::to_string(h->payload_size) + " payload bytes)";
      break;
    }
    payload.resize(h->payload_size);
    if (pread_full(fd.get(), payload.data(), payload.size(), offset + kFrameHeaderSize) !=
        ssize_t(payload.size()))
      return fail(errno_text("cannot read " + path));
    if (frame_crc_matches(header, payload)) {
      if (report.intact.empty()) {
        report.width = h->width;
        report.height = h->height;
        report.format = h->format;
        report.first_frame = h->frame;
      }
      report.last_frame = h->frame;
      report.intact.push_back({h->frame, offset});
    } else {
      ++report.corrupt;
    }
    offset = end;
    report.valid_bytes = offset;
  }
  return report;
}

Expected<void> write_index(const std::string& dir, std::span<const IndexEntry> entries) {
  std::vector<uint8_t> bytes(8 + entries.size() * 16);
  std::memcpy(bytes.data(), kIndexMagic, 4);
  put<uint32_t>(bytes.data() + 4, kTakeVersion);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    put<uint64_t>(bytes.data() + 8 + 16 * i, entries[i].frame);
    put<uint64_t>(bytes.data() + 16 + 16 * i, entries[i].offset);
  }
  return write_atomic(dir, kIndexFile, bytes);
}

Expected<std::vector<IndexEntry>> read_index(const std::string& dir) {
  const std::string path = dir + "/" + kIndexFile;
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) return fail(errno_text("cannot open " + path));
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return fail(errno_text("cannot stat " + path));
  std::vector<uint8_t> bytes(std::size_t(st.st_size));
  if (pread_full(fd.get(), bytes.data(), bytes.size(), 0) != ssize_t(bytes.size()))
    return fail(errno_text("cannot read " + path));
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kIndexMagic, 4) != 0 ||
      get<uint32_t>(bytes.data() + 4) != kTakeVersion)
    return fail(path + ": not a take index");
  if ((bytes.size() - 8) % 16 != 0) return fail(path + ": partial index entry at the end");
  std::vector<IndexEntry> entries((bytes.size() - 8) / 16);
  for (std::size_t i = 0; i < entries.size(); ++i)
    entries[i] = {get<uint64_t>(bytes.data() + 8 + 16 * i),
                  get<uint64_t>(bytes.data() + 16 + 16 * i)};
  return entries;
}

Expected<FrameHeader> read_frame(const std::string& dir, const IndexEntry& entry,
                                 std::vector<uint8_t>& pixels) {
  const std::string path = dir + "/" + kFramesFile;
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) return fail(errno_text("cannot open " + path));
  uint8_t header[kFrameHeaderSize];
  if (pread_full(fd.get(), header, sizeof header, entry.offset) != ssize_t(sizeof header))
    return fail(path + ": no frame header at byte " + std::to_string(entry.offset));
  auto h = decode_frame_header(header);
  if (!h) return fail(path + ": " + h.error().message + " at byte " + std::to_string(entry.offset));
  if (h->frame != entry.frame)
    return fail(path + ": index names frame " + std::to_string(entry.frame) + ", file holds " +
                std::to_string(h->frame));
  pixels.resize(h->payload_size);
  if (pread_full(fd.get(), pixels.data(), pixels.size(), entry.offset + kFrameHeaderSize) !=
      ssize_t(pixels.size()))
    return fail(path + ": frame " + std::to_string(h->frame) + " is truncated");
  if (!frame_crc_matches(header, pixels))
    return fail(path + ": frame " + std::to_string(h->frame) + " fails its CRC");
  return h;
}

std::string format_take_yaml(const TakeInfo& t) {
  std::string s;
  auto line = [&s](const std::string& key, const std::string& value) {
    s += key + ": " + value + "\n";
  };
  // Ids are validated by the node ([A-Za-z0-9_.-]), so they need no quoting.
  line("take", t.take);
  line("camera", t.camera_id);
  line("format", pixel_format_name(t.format));
  line("width", std::to_string(t.width));
  line("height", std::to_string(t.height));
  line("period_ns", std::to_string(t.period_ns));
  line("start_frame", std::to_string(t.start_frame));
  if (t.stop_frame) line("stop_frame", std::to_string(*t.stop_frame));
  if (t.first_frame) line("first_frame", std::to_string(*t.first_frame));
  if (t.last_frame) line("last_frame", std::to_string(*t.last_frame));
  line("frames", std::to_string(t.frames));
  line("drops", std::to_string(t.drops));
  line("status", t.status);
  if (!t.error.empty()) {
    std::string quoted = "\"";
    for (char c : t.error) {
      if (c == '"' || c == '\\') quoted += '\\';
      quoted += (c == '\n') ? ' ' : c;
    }
    line("error", quoted + "\"");
  }
  if (!t.calibration_yaml.empty()) {
    s += "calibration:\n" + t.calibration_yaml;
    if (!t.calibration_yaml.ends_with('\n')) s += '\n';
  }
  return s;
}

Expected<void> write_take_yaml(const std::string& dir, const TakeInfo& info) {
  std::string text = format_take_yaml(info);
  // Pad to kTakeYamlReserve with a comment, so that the final rewrite fits into the blocks of
  // the first one when the disk is full (see the in-place fallback below).
  if (text.size() + 2 < kTakeYamlReserve) {
    text += "#";
    text.append(kTakeYamlReserve - text.size() - 1, ' ');
    text += "\n";
  }
  auto atomic = write_atomic(dir, kTakeFile,
                             std::span(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
  if (atomic) return atomic;
  // Disk full: overwrite the existing take.yaml in place if the new text fits in its size.
  const std::string path = dir + "/" + kTakeFile;
  Fd fd(::open(path.c_str(), O_WRONLY | O_CLOEXEC));
  struct stat st {};
  if (fd.get() < 0 || ::fstat(fd.get(), &st) != 0 || uint64_t(st.st_size) < text.size())
    return atomic;
  text.resize(std::size_t(st.st_size) - 1, ' ');
  text += "\n";
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t w = ::pwrite(fd.get(), text.data() + done, text.size() - done, off_t(done));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return atomic;
    done += std::size_t(w);
  }
  if (::fdatasync(fd.get()) != 0) return atomic;
  return {};
}

}  // namespace studio::capture
