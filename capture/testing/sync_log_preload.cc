// A write layer for power-loss tests (LD_PRELOAD): every successful fdatasync()/fsync() of a
// regular file appends "<size> <path>\n" to $STUDIO_SYNC_LOG. After kill -9, a test cuts every
// file back to the size it last had durably (append-only files: what a power cut would leave,
// since unsynced page-cache data is what the cut loses); files never synced are cut to 0.
#include <dlfcn.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

namespace {

void log_sync(int fd) {
  const char* log = getenv("STUDIO_SYNC_LOG");
  if (!log) return;
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return;
  char link[64], path[PATH_MAX];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 0) return;
  path[n] = 0;
  char line[PATH_MAX + 32];
  const int len = snprintf(line, sizeof line, "%lld %s\n", (long long)st.st_size, path);
  const int out = open(log, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (out < 0) return;
  (void)!write(out, line, size_t(len));  // one write: lines from threads do not interleave
  close(out);
}

template <class F>
F real(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
}

}  // namespace

extern "C" int fdatasync(int fd) {
  static auto f = real<int (*)(int)>("fdatasync");
  const int r = f(fd);
  if (r == 0) log_sync(fd);
  return r;
}

extern "C" int fsync(int fd) {
  static auto f = real<int (*)(int)>("fsync");
  const int r = f(fd);
  if (r == 0) log_sync(fd);
  return r;
}
