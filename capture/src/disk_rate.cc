#include "capture/disk_rate.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <vector>

#include "capture/take.h"

namespace studio::capture {

Expected<double> measure_write_rate(const std::string& dir, std::size_t bytes) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string path = dir + "/.disk_rate_probe";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail("disk rate: cannot create " + path + ": " + std::strerror(errno));
  std::vector<char> chunk(4u << 20);
  for (std::size_t i = 0; i < chunk.size(); ++i) chunk[i] = char(i * 131 + 7);  // not all zero
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t done = 0;
  int err = 0;
  while (done < bytes && !err) {
    const ssize_t w = ::write(fd, chunk.data(), std::min(chunk.size(), bytes - done));
    if (w <= 0)
      err = w < 0 ? errno : ENOSPC;
    else
      done += std::size_t(w);
  }
  if (!err && ::fdatasync(fd) != 0) err = errno;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ::close(fd);
  ::unlink(path.c_str());
  if (err) return fail("disk rate: writing " + path + ": " + std::strerror(err));
  return double(done) / 1e6 / std::max(s, 1e-6);
}

double take_bytes_per_second(int width, int height, double fps) {
  return (double(kFrameHeaderSize) + 3.0 * width * height) * fps;
}

}  // namespace studio::capture
