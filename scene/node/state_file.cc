#include "state_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "scene/serialize.h"

namespace studio::scene::node {
namespace {

constexpr char kMagic[8] = {'S', 'T', 'S', 'R', 'V', 'S', 'T', '1'};

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

std::vector<std::uint8_t> encode_state(const Scene& scene, const std::set<NodeId>& published) {
  std::vector<std::uint8_t> out(std::begin(kMagic), std::end(kMagic));
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
  if (bytes.size() < sizeof kMagic + 4 + 8 + 8 ||
      std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    return fail("not a scene server state file (bad magic or too short)");
  std::uint64_t sum = 0;
  for (int i = 0; i < 8; ++i) sum |= std::uint64_t(bytes[bytes.size() - 8 + i]) << (8 * i);
  if (sum != fnv1a64(bytes.data(), bytes.size() - 8)) return fail("checksum mismatch");
  const std::vector<std::uint8_t> body(bytes.begin(), bytes.end() - 8);
  Cursor c{body, sizeof kMagic};
  std::uint32_t count = 0;
  if (!c.u32(count) || count > c.left() / 4) return fail("bad published id count");
  PersistedState state;
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

Expected<void> write_state(const std::string& dir, const Scene& scene,
                           const std::set<NodeId>& published) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail("state_dir " + dir + ": " + ec.message());
  const std::string path = state_path(dir), tmp = path + ".tmp";
  const std::vector<std::uint8_t> bytes = encode_state(scene, published);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(tmp + ": " + errno_text());
  const bool ok = write_all(fd, bytes.data(), bytes.size()) && ::fsync(fd) == 0;
  const std::string why = ok ? "" : errno_text();
  ::close(fd);
  if (!ok) return fail(tmp + ": " + why);
  if (::rename(tmp.c_str(), path.c_str()) != 0) return fail(path + ": rename: " + errno_text());
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return fail(dir + ": " + errno_text());
  const bool synced = ::fsync(dfd) == 0;
  const std::string dwhy = synced ? "" : errno_text();
  ::close(dfd);
  if (!synced) return fail(dir + ": fsync: " + dwhy);
  return {};
}

Expected<std::optional<PersistedState>> read_state(const std::string& dir) {
  const std::string path = state_path(dir);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::optional<PersistedState>{};
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path + ": cannot open");
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
  auto state = decode_state(bytes);
  if (!state) return fail(path + ": corrupt state file: " + state.error().message);
  return std::optional<PersistedState>(std::move(*state));
}

}  // namespace studio::scene::node
