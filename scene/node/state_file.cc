#include "state_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <utility>

#include "scene/serialize.h"

namespace studio::scene::node {
namespace {

constexpr char kMagic[8] = {'S', 'T', 'S', 'R', 'V', 'S', 'T', '2'};

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
}
void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
}

struct Cursor {
  const std::vector<std::uint8_t>& bytes;
  std::size_t at = 0;
  std::size_t left() const { return bytes.size() - at; }
  bool u32(std::uint32_t& v) {
    if (left() < 4) return false;
    v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t(bytes[at + i]) << (8 * i);
    at += 4;
    return true;
  }
  bool u64(std::uint64_t& v) {
    if (left() < 8) return false;
    v = 0;
    for (int i = 0; i < 8; ++i) v |= std::uint64_t(bytes[at + i]) << (8 * i);
    at += 8;
    return true;
  }
};

std::string errno_text() { return std::strerror(errno); }

// write(2) all of it, retrying short writes and EINTR.
bool write_all(int fd, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= std::size_t(n);
  }
  return true;
}

}  // namespace

std::vector<std::uint8_t> encode_state(const Scene& scene, const std::set<NodeId>& published,
                                       std::uint64_t sequence) {
  std::vector<std::uint8_t> out(std::begin(kMagic), std::end(kMagic));
  put_u64(out, sequence);
  put_u32(out, std::uint32_t(published.size()));
  for (const NodeId& id : published) {
    put_u32(out, std::uint32_t(id.size()));
    out.insert(out.end(), id.begin(), id.end());
  }
  const std::vector<std::uint8_t> s = serialize(scene);
  put_u64(out, s.size());
  out.insert(out.end(), s.begin(), s.end());
  put_u64(out, fnv1a64(out.data(), out.size()));
  return out;
}

Expected<PersistedState> decode_state(const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < sizeof kMagic + 8 + 4 + 8 + 8 ||
      std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    return fail("not a scene server state file (bad magic or too short)");
  std::uint64_t sum = 0;
  for (int i = 0; i < 8; ++i) sum |= std::uint64_t(bytes[bytes.size() - 8 + i]) << (8 * i);
  if (sum != fnv1a64(bytes.data(), bytes.size() - 8)) return fail("checksum mismatch");
  const std::vector<std::uint8_t> body(bytes.begin(), bytes.end() - 8);
  Cursor c{body, sizeof kMagic};
  PersistedState state;
  if (!c.u64(state.sequence)) return fail("truncated");
  std::uint32_t count = 0;
  if (!c.u32(count) || count > c.left() / 4) return fail("bad published id count");
  for (std::uint32_t i = 0; i < count; ++i) {
    std::uint32_t n = 0;
    if (!c.u32(n) || n > c.left()) return fail("published id " + std::to_string(i) + " truncated");
    state.published.emplace(reinterpret_cast<const char*>(body.data() + c.at), n);
    c.at += n;
  }
  std::uint64_t n = 0;
  if (!c.u64(n) || n != c.left()) return fail("scene bytes truncated");
  auto scene =
      deserialize(std::vector<std::uint8_t>(body.begin() + std::ptrdiff_t(c.at), body.end()));
  if (!scene) return fail("scene: " + scene.error().message);
  state.scene = std::move(*scene);
  return state;
}

std::string state_path(const std::string& dir) {
  return (std::filesystem::path(dir) / "scene.state").string();
}
std::string wal_path(const std::string& dir, int slot) {
  return (std::filesystem::path(dir) / ("scene.wal." + std::to_string(slot))).string();
}

namespace {

// Writes bytes to path + ".tmp" (fsync'd when `durable`) and renames it over path; with
// `durable` the directory is fsync'd after the rename.
Expected<void> replace_file(const std::string& dir, const std::string& path,
                            const std::vector<std::uint8_t>& bytes, bool durable) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail("state_dir " + dir + ": " + ec.message());
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(tmp + ": " + errno_text());
  const bool ok = write_all(fd, bytes.data(), bytes.size()) && (!durable || ::fsync(fd) == 0);
  const std::string why = ok ? "" : errno_text();
  ::close(fd);
  if (!ok) return fail(tmp + ": " + why);
  if (::rename(tmp.c_str(), path.c_str()) != 0) return fail(path + ": rename: " + errno_text());
  if (!durable) return {};
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return fail(dir + ": " + errno_text());
  const bool synced = ::fsync(dfd) == 0;
  const std::string dwhy = synced ? "" : errno_text();
  ::close(dfd);
  if (!synced) return fail(dir + ": fsync: " + dwhy);
  return {};
}

// nullopt: no such file (or an empty slot); else the decoded state or why it is not one. A
// write-ahead slot holds a u64 length, then the record (and maybe older bytes after it).
std::optional<Expected<PersistedState>> read_one(const std::string& path, bool slot) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return Expected<PersistedState>(fail(path + ": cannot open"));
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
  if (slot) {
    if (bytes.empty()) return std::nullopt;
    std::uint64_t n = 0;
    Cursor c{bytes};
    if (!c.u64(n) || n > c.left())
      return Expected<PersistedState>(fail(path + ": corrupt state file: bad record length"));
    bytes = std::vector<std::uint8_t>(bytes.begin() + 8, bytes.begin() + 8 + std::ptrdiff_t(n));
  }
  auto state = decode_state(bytes);
  if (!state)
    return Expected<PersistedState>(fail(path + ": corrupt state file: " + state.error().message));
  return Expected<PersistedState>(std::move(*state));
}

}  // namespace

Expected<WriteAheadLog> WriteAheadLog::open(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail("state_dir " + dir + ": " + ec.message());
  WriteAheadLog log;
  log.dir_ = dir;
  for (int slot = 0; slot < 2; ++slot) {
    const std::string path = wal_path(dir, slot);
    log.fd_[slot] = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (log.fd_[slot] < 0) return fail(path + ": " + errno_text());
  }
  return log;
}

WriteAheadLog::WriteAheadLog(WriteAheadLog&& o) noexcept : dir_(std::move(o.dir_)) {
  for (int i = 0; i < 2; ++i) fd_[i] = std::exchange(o.fd_[i], -1);
}
WriteAheadLog& WriteAheadLog::operator=(WriteAheadLog&& o) noexcept {
  if (this != &o) {
    for (int i = 0; i < 2; ++i) {
      if (fd_[i] >= 0) ::close(fd_[i]);
      fd_[i] = std::exchange(o.fd_[i], -1);
    }
    dir_ = std::move(o.dir_);
  }
  return *this;
}
WriteAheadLog::~WriteAheadLog() {
  for (int fd : fd_)
    if (fd >= 0) ::close(fd);
}

Expected<void> WriteAheadLog::write(const std::vector<std::uint8_t>& bytes,
                                    std::uint64_t sequence) {
  const int slot = int(sequence % 2);
  std::vector<std::uint8_t> record;
  record.reserve(bytes.size() + 8);
  put_u64(record, bytes.size());
  record.insert(record.end(), bytes.begin(), bytes.end());
  const std::uint8_t* p = record.data();
  std::size_t left = record.size();
  off_t at = 0;
  while (left > 0) {
    const ssize_t n = ::pwrite(fd_[slot], p, left, at);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(wal_path(dir_, slot) + ": " + errno_text());
    }
    p += n;
    left -= std::size_t(n);
    at += n;
  }
  return {};
}

Expected<void> write_durable(const std::string& dir, const std::vector<std::uint8_t>& bytes) {
  return replace_file(dir, state_path(dir), bytes, true);
}

Expected<void> write_state(const std::string& dir, const Scene& scene,
                           const std::set<NodeId>& published, std::uint64_t sequence) {
  return write_durable(dir, encode_state(scene, published, sequence));
}

Expected<std::optional<LoadedState>> read_state(const std::string& dir) {
  struct Copy {
    std::string path;
    std::optional<Expected<PersistedState>> read;
  };
  std::vector<Copy> copies;
  copies.push_back({state_path(dir), read_one(state_path(dir), false)});
  for (int slot = 0; slot < 2; ++slot)
    copies.push_back({wal_path(dir, slot), read_one(wal_path(dir, slot), true)});
  Copy* best = nullptr;
  std::string errors;
  bool any = false;
  for (Copy& c : copies) {
    if (!c.read) continue;
    any = true;
    if (!c.read->has_value()) {
      errors += (errors.empty() ? "" : "; ") + c.read->error().message;
      continue;
    }
    if (!best || (*c.read)->sequence > (*best->read)->sequence) best = &c;
  }
  if (!any) return std::optional<LoadedState>{};
  if (!best) return fail(errors);
  LoadedState out;
  out.path = best->path;
  out.state = std::move(**best->read);
  const auto& durable = copies[0].read;
  if (durable && !durable->has_value())
    out.warning = durable->error().message + " (a write-ahead copy is used)";
  return std::optional<LoadedState>(std::move(out));
}

}  // namespace studio::scene::node
