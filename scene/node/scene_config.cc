#include "scene_config.h"

#include <cmath>
#include <filesystem>

namespace studio::scene::node {
namespace {

#define TRY(expr)                                                     \
  do {                                                                \
    if (auto ok_ = (expr); !ok_) return std::unexpected(ok_.error()); \
  } while (0)

// Reads config[key] as a number in [lo, hi] into out (absent: out unchanged).
template <class T>
Expected<void> number(yaml::MapReader& m, const char* key, T& out, double lo, double hi,
                      const char* what) {
  auto n = m.optional(key);
  if (!n) return {};
  if constexpr (std::is_integral_v<T>) {
    auto v = n->as_int();
    if (!v) return std::unexpected(v.error());
    if (!(double(*v) >= lo && double(*v) <= hi)) return n->fail(std::string("expected ") + what);
    out = T(*v);
  } else {
    auto v = n->as_double();
    if (!v) return std::unexpected(v.error());
    if (!(*v >= lo && *v <= hi)) return n->fail(std::string("expected ") + what);
    out = T(*v);
  }
  return {};
}

}  // namespace

const char* const kConfigHelp =
    "  clock:                 the studio clock (DESIGN 5): frame = floor((now - epoch_ns) / "
    "period)\n"
    "    fps: F               frames per second, 0.1..1000 (default 25); or\n"
    "    period_ns: N         frame period in ns, 1e6..1e10 (not both)\n"
    "    epoch_ns: N          CLOCK_REALTIME ns of frame 0 (default 0)\n"
    "    source: studio|commands\n"
    "                         studio (default): the server ticks itself every studio frame,\n"
    "                         evaluating animations and publishing the nodes they move;\n"
    "                         commands: only SCENE_TICK commands evaluate (replays, tests,\n"
    "                         a director stepping frames)\n"
    "  scene: FILE            the scene at first start, when state_dir holds no state: a scene\n"
    "                         file (.yaml: set, nodes, animations, play; see studio-scene render\n"
    "                         --help) or a set (.glb/.gltf/.obj); its fps must be the clock's.\n"
    "                         Default: start empty. SCENE_LOAD_SET replaces the scene the same\n"
    "                         way (relative paths from this file's folder).\n"
    "  state_dir: DIR         where the scene and its animation clocks are persisted: a "
    "write-ahead\n"
    "                         copy before every batch of accepted commands is published\n"
    "                         (scene.wal.0/1, in the kernel: survives kill -9), and a durable\n"
    "                         copy (scene.state: write, fsync, rename, fsync the directory)\n"
    "                         every persist_interval. Loaded on start (the newest valid copy), so\n"
    "                         a restart after kill -9 resumes where it was; no valid copy stops\n"
    "                         the start with one line (move the files away to start empty).\n"
    "                         Absent: nothing is persisted (default).\n"
    "  persist_interval: S    seconds a change made by the clock alone (animation ticks) may stay\n"
    "                         unpersisted, and the longest the durable copy (fsync'd) lags the\n"
    "                         write-ahead one, 0.05..3600 (default 1)\n"
    "  command_queue: N       SceneCommand samples kept while the server is busy, 32..1000000\n"
    "                         (default 16384); older ones are lost (counter commands_lost)\n"
    "Topics: studio/scene/command in; studio/scene/node (one keyed instance per node, disposed\n"
    "when removed) and studio/scene/state (hash, counts, last error) out.\n";

std::string resolve_path(const std::string& base_dir, const std::string& path) {
  std::filesystem::path p(path);
  if (p.is_relative() && !base_dir.empty()) p = std::filesystem::path(base_dir) / p;
  return p.lexically_normal().string();
}

int64_t NodeOptions::frame_at(int64_t now_ns) const {
  const int64_t d = now_ns - epoch_ns;
  return d >= 0 ? d / period_ns : -((-d + period_ns - 1) / period_ns);
}

Expected<void> NodeOptions::validate() const {
  if (!(period_ns >= 1'000'000 && period_ns <= 10'000'000'000))
    return fail("clock.period_ns: expected 1e6..1e10");
  if (epoch_ns < 0) return fail("clock.epoch_ns: expected >= 0");
  if (!(persist_interval >= 0.05 && persist_interval <= 3600))
    return fail("persist_interval: expected 0.05..3600 s");
  if (command_queue < 32 || command_queue > 1'000'000)
    return fail("command_queue: expected 32..1000000");
  return {};
}

Expected<NodeOptions> read_node_options(yaml::MapReader& config) {
  NodeOptions o;
  if (auto n = config.optional("clock")) {
    auto c = yaml::MapReader::from(*n);
    if (!c) return std::unexpected(c.error());
    if (c->has("fps") && c->has("period_ns")) return n->fail("give fps or period_ns, not both");
    double fps = 25;
    TRY(number(*c, "fps", fps, 0.1, 1000, "fps in 0.1..1000"));
    o.period_ns = int64_t(std::llround(1e9 / fps));
    TRY(number(*c, "period_ns", o.period_ns, 1e6, 1e10, "ns in 1e6..1e10"));
    TRY(number(*c, "epoch_ns", o.epoch_ns, 0, 9.2e18, "ns >= 0"));
    if (auto s = c->optional("source")) {
      auto v = s->as_string();
      if (!v) return std::unexpected(v.error());
      if (*v == "studio")
        o.clock_source = ClockSource::studio;
      else if (*v == "commands")
        o.clock_source = ClockSource::commands;
      else
        return s->fail("expected studio or commands");
    }
    TRY(c->finish());
  }
  // Paths relative to the config file's folder, as every path in a studio config.
  o.base_dir = std::filesystem::path(config.node().file()).parent_path().string();
  auto path_key = [&](const char* key, std::string& out) -> Expected<void> {
    auto n = config.optional(key);
    if (!n) return {};
    auto v = n->as_string();
    if (!v) return std::unexpected(v.error());
    if (v->empty()) return n->fail("expected a path");
    out = resolve_path(o.base_dir, *v);
    return {};
  };
  TRY(path_key("scene", o.scene_file));
  TRY(path_key("state_dir", o.state_dir));
  TRY(number(config, "persist_interval", o.persist_interval, 0.05, 3600, "0.05..3600 s"));
  TRY(number(config, "command_queue", o.command_queue, 32, 1'000'000, "32..1000000"));
  TRY(o.validate());
  return o;
}

}  // namespace studio::scene::node
