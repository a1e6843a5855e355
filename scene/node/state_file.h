#pragma once
// The scene server's persisted state: the whole scene (scene::serialize: nodes, animations and
// their clocks, the frame of the last tick), the ids of the nodes that may be on the wire (written
// as alive SceneNode instances and not yet disposed), and a sequence number that grows with every
// write.
//
// Files in state_dir:
//   scene.wal.0, scene.wal.1  the write-ahead copy, written BEFORE the server publishes a batch of
//                changes: the state of sequence n overwrites slot n % 2 in place (pwrite of a
//                length-prefixed, checksummed record; the files stay open). No fsync and no
//                rename: the bytes are in the kernel, so they survive the server's death
//                (kill -9) — the crash this guards against — at a fraction of a millisecond and
//                without waiting for the file system journal. A write torn by a crash spoils only
//                its own slot; the other slot holds the previous state, which is all that had
//                been published.
//   scene.state  the durable copy, written off the critical path by the server's syncer thread
//                with the full sequence: write scene.state.tmp, fsync, rename, fsync the
//                directory — so after a power loss it is the old or the new state, never a mix.
// read_state() takes the valid copy with the highest sequence. Torn or garbage copies are ignored
// when another is valid (a warning names a bad scene.state); a state_dir whose copies are all
// invalid is an error naming them.
//
// The published ids make a restart clean after kill -9: every node a reader may hold is either in
// the scene or in `published`; on start the server re-publishes the scene and disposes every
// published id the scene no longer has (a removal whose dispose never went out, or a node taken
// out of the state while the server was down).
//
// Encoding: "STSRVST2", u64 sequence, u32 id count, (u32 length, bytes) per id, u64 length +
// scene bytes, u64 FNV-1a of everything before it; little-endian.

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace studio::scene::node {

struct PersistedState {
  Scene scene;
  std::set<NodeId> published;
  std::uint64_t sequence = 0;
};

std::vector<std::uint8_t> encode_state(const Scene& scene, const std::set<NodeId>& published,
                                       std::uint64_t sequence);
Expected<PersistedState> decode_state(const std::vector<std::uint8_t>& bytes);

// Paths of the durable copy and of write-ahead slot `slot` (0 or 1) in `dir`.
std::string state_path(const std::string& dir);
std::string wal_path(const std::string& dir, int slot);

// The write-ahead slots of one state_dir, open for the server's lifetime (see above).
class WriteAheadLog {
 public:
  // Creates `dir` and the two slot files if missing.
  static Expected<WriteAheadLog> open(const std::string& dir);
  WriteAheadLog(WriteAheadLog&& other) noexcept;
  WriteAheadLog& operator=(WriteAheadLog&& other) noexcept;
  ~WriteAheadLog();
  // `bytes` (an encode_state of `sequence`) into slot sequence % 2.
  Expected<void> write(const std::vector<std::uint8_t>& bytes, std::uint64_t sequence);

 private:
  WriteAheadLog() = default;
  std::string dir_;
  int fd_[2] = {-1, -1};
};

// The durable copy: tmp, fsync, rename, fsync the directory. Creates `dir` if missing.
Expected<void> write_durable(const std::string& dir, const std::vector<std::uint8_t>& bytes);
// encode_state + write_durable (tools and tests editing a stopped server's state: give a
// sequence above the one read so it wins over an older scene.wal).
Expected<void> write_state(const std::string& dir, const Scene& scene,
                           const std::set<NodeId>& published, std::uint64_t sequence);

struct LoadedState {
  PersistedState state;
  std::string path;     // the file it came from
  std::string warning;  // "" or why the other file was ignored
};
// nullopt when state_dir holds neither file; an error naming the files when none is valid.
Expected<std::optional<LoadedState>> read_state(const std::string& dir);

}  // namespace studio::scene::node
