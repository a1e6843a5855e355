#include "studioctl/scene.h"

#include <unistd.h>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <map>
#include <thread>

#include "scene/serialize.h"
#include "studioctl/cli.h"
#include "studioctl/printer.h"
#include "studioctl/send.h"
#include "wire/endpoint.h"
#include "wire/scene_convert.h"

namespace studio::ctl {

const char kSceneHelp[] =
    "usage: studioctl scene load FILE      [--at-frame N] [--wait S] [--json]\n"
    "       studioctl scene play           [--animation NAME] [--from S] [--mode M] [--at-frame "
    "N]\n"
    "       studioctl scene pause          [--animation NAME] [--at-frame N]\n"
    "       studioctl scene seek SECONDS   [--animation NAME] [--at-frame N]\n"
    "       studioctl scene speed FACTOR   [--animation NAME] [--at-frame N]\n"
    "       studioctl scene hash           [--instance NAME] [--wait S] [--json]\n"
    "\n"
    "Commands to the scene server (studio/scene/command, SceneCommand; studio-scene):\n"
    "  load FILE   replaces the whole scene with a scene file (.yaml) or a set (.glb/.gltf/.obj),\n"
    "              all or nothing; FILE is read by the server, relative to its config's folder\n"
    "  play        plays the animation(s) (--from S: from clock time S seconds; --mode once|loop|\n"
    "              ping-pong: a new play mode, default unchanged)\n"
    "  pause       stops the animation clock(s) where they are\n"
    "  seek S      sets the animation clock(s) to S seconds\n"
    "  speed F     playback speed factor (negative plays backwards)\n"
    "  --animation NAME   one animation (e.g. set/flight); default: every animation\n"
    "  --at-frame N       the studio frame the change takes effect at (default: now)\n"
    "Each command waits for the server's verdict on studio/scene/state (its sender and command\n"
    "id) and prints it: accepted (with the new state hash) or the server's error; exit 1 when it\n"
    "is rejected, no server listens, or no verdict arrives within --wait S (default 10).\n"
    "\n"
    "  hash        the server's state (studio/scene/state): frame, state_hash (nodes, animations\n"
    "              and their clocks), nodes_hash, node and animation counts, commands; and the\n"
    "              same nodes hash computed here from the nodes received on studio/scene/node\n"
    "              (scene::hash_nodes), after listening at least 1 s (discovery of every writer).\n"
    "              Exit 1 when they do not agree within --wait S (default 5):\n"
    "              this host does not hold the scene the server holds.\n"
    "  --instance NAME    the server's instance (default: the first heard)\n"
    "\n"
    "Hashes are printed as 16 hex digits (strings in --json).\n"
    "Common options: --domain N, --dds-config FILE, --json, --help.\n";

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

std::string hex(uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

std::string sender_name() {
  char host[64] = {};
  ::gethostname(host, sizeof host - 1);
  std::string s = "studioctl@" + std::string(host) + ":" + std::to_string(::getpid());
  return s.substr(0, 63);
}

// The newest SceneState per server instance.
class States {
 public:
  static Expected<States> open(const wire::Participant& p) {
    auto t = wire::Topic<studio_SceneState>::create(p);
    if (!t) return std::unexpected(t.error());
    auto r = wire::Reader<studio_SceneState>::create(p, *t);
    if (!r) return std::unexpected(r.error());
    return States(std::move(*t), std::move(*r));
  }
  // Takes what arrived; true when something did.
  bool poll() {
    bool any = false;
    for (auto& s : reader_.take(64)) {
      if (!s.meta.valid_data) continue;
      latest_[std::string(wire::str(s.data->instance))] = std::move(s.data);
      any = true;
    }
    return any;
  }
  // The newest state of a server whose last command handled is `sender`'s `id`, or nullptr.
  const studio_SceneState* find_verdict(const std::string& sender, uint64_t id) const {
    for (const auto& [name, s] : latest_)
      if (wire::str(s->last_sender) == sender && s->last_command_id == id) return s.get();
    return nullptr;
  }
  // The state of `instance` ("" = the first one heard), or nullptr.
  const studio_SceneState* find(const std::string& instance) const {
    if (instance.empty()) return latest_.empty() ? nullptr : latest_.begin()->second.get();
    auto it = latest_.find(instance);
    return it == latest_.end() ? nullptr : it->second.get();
  }

 private:
  States(wire::Topic<studio_SceneState> t, wire::Reader<studio_SceneState> r)
      : topic_(std::move(t)), reader_(std::move(r)) {}
  wire::Topic<studio_SceneState> topic_;
  wire::Reader<studio_SceneState> reader_;
  std::map<std::string, wire::Owned<studio_SceneState>> latest_;
};

void state_json(Printer& pr, const studio_SceneState& s) {
  pr.key("instance");
  pr.string(wire::str(s.instance));
  pr.key("frame");
  pr.number(s.frame);
  pr.key("state_hash");
  pr.string(hex(s.state_hash));
  pr.key("nodes_hash");
  pr.string(hex(s.nodes_hash));
  pr.key("node_count");
  pr.number(uint64_t(s.node_count));
  pr.key("animation_count");
  pr.number(uint64_t(s.animation_count));
  pr.key("commands_accepted");
  pr.number(s.commands_accepted);
  pr.key("commands_rejected");
  pr.number(s.commands_rejected);
  pr.key("commands_lost");
  pr.number(s.commands_lost);
}

std::string state_text(const studio_SceneState& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "scene %s at frame %" PRIu64 ": state %s, nodes %s, %u nodes, %u animations",
                std::string(wire::str(s.instance)).c_str(), s.frame, hex(s.state_hash).c_str(),
                hex(s.nodes_hash).c_str(), s.node_count, s.animation_count);
  return buf;
}

int command(const std::string& verb, const Args& a) {
  const std::string what = "scene " + verb;
  const bool takes_value = verb == "seek" || verb == "speed" || verb == "load";
  if (a.positional.size() != (takes_value ? 1u : 0u))
    return complain(what,
                    takes_value ? "expected one " +
                                      std::string(verb == "load"   ? "FILE"
                                                  : verb == "seek" ? "SECONDS"
                                                                   : "FACTOR") +
                                      " (see --help)"
                                : "unexpected argument '" + a.positional[0] + "'",
                    2);
  auto wait = seconds_flag(a, "--wait", 10, 0.1, 600);
  if (!wait) return complain(what, wait.error().message, 2);

  wire::Owned<studio_SceneCommand> c;
  const std::string sender = sender_name();
  wire::set(c->sender, sender);
  c->command_id = 1;  // the first of this sender (one per studioctl process)
  c->at_frame = studio_SCENE_AT_NOW;
  c->mode = studio_SCENE_MODE_KEEP;
  c->capture_ns = realtime_ns();
  if (const auto* v = a.value("--at-frame")) {
    auto n = parse_count("--at-frame", *v);
    if (!n) return complain(what, n.error().message, 2);
    if (*n > uint64_t(INT64_MAX)) return complain(what, "--at-frame: out of range", 2);
    c->at_frame = int64_t(*n);
  }
  const std::string animation = a.value("--animation") ? *a.value("--animation") : "";
  if (animation.size() > 63) return complain(what, "--animation: at most 63 characters", 2);
  wire::set(c->target, animation);
  if (verb == "load") {
    if (a.positional[0].empty() || a.positional[0].size() > 255)
      return complain(what, "FILE: 1..255 characters", 2);
    wire::set(c->path, a.positional[0]);
    c->verb = studio_SCENE_LOAD_SET;
  } else if (verb == "play") {
    c->verb = studio_SCENE_PLAY;
    if (const auto* f = a.value("--from")) {
      auto v = parse_number("--from", *f);
      if (!v) return complain(what, v.error().message, 2);
      c->has_value = true;
      c->value = *v;
    }
    if (const auto* m = a.value("--mode")) {
      if (*m == "once")
        c->mode = studio_SCENE_MODE_ONCE;
      else if (*m == "loop")
        c->mode = studio_SCENE_MODE_LOOP;
      else if (*m == "ping-pong")
        c->mode = studio_SCENE_MODE_PING_PONG;
      else
        return complain(what, "--mode: expected once, loop or ping-pong, got '" + *m + "'", 2);
    }
  } else if (verb == "pause") {
    c->verb = studio_SCENE_PAUSE;
  } else {
    auto v = parse_number(verb == "seek" ? "SECONDS" : "FACTOR", a.positional[0]);
    if (!v) return complain(what, v.error().message, 2);
    c->verb = verb == "seek" ? studio_SCENE_SEEK : studio_SCENE_SPEED;
    c->has_value = true;
    c->value = *v;
  }

  auto p = open_participant(a.common);
  if (!p) return complain(what, p.error().message);
  auto states = States::open(*p);
  if (!states) return complain(what, states.error().message);
  auto topic = wire::Topic<studio_SceneCommand>::create(*p);
  if (!topic) return complain(what, topic.error().message);
  auto writer = wire::Writer<studio_SceneCommand>::create(*p, *topic);
  if (!writer) return complain(what, writer.error().message);
  const auto deadline = Clock::now() + to_ns(*wait);
  if (auto r = send_acked(*writer, *c, deadline, "scene server"); !r)
    return complain(what, r.error().message);

  // The verdict: the server's state naming this sender and command id.
  const studio_SceneState* verdict = nullptr;
  while (!verdict) {
    states->poll();
    verdict = states->find_verdict(sender, c->command_id);
    if (verdict || Clock::now() >= deadline) break;
    std::this_thread::sleep_for(10ms);
  }
  if (!verdict)
    return complain(what,
                    "the scene server acknowledged the command but reported no verdict "
                    "on studio/scene/state within " +
                        std::to_string(*wait).substr(0, 4) + " s");
  const bool ok = verdict->last_accepted;
  if (a.common.json) {
    Printer pr(Printer::Mode::json);
    pr.begin_object();
    pr.key("command");
    pr.string(verb);
    pr.key("accepted");
    pr.number(ok);
    pr.key("error");
    pr.string(ok ? "" : std::string(wire::str(verdict->last_error)));
    state_json(pr, *verdict);
    pr.end_object();
    emit(pr.take());
  } else if (ok) {
    emit(verb + ": accepted; " + state_text(*verdict));
  }
  if (!ok)
    return complain(what,
                    "rejected by the scene server: " + std::string(wire::str(verdict->last_error)));
  return 0;
}

int hash(const Args& a) {
  const std::string what = "scene hash";
  if (!a.positional.empty())
    return complain(what, "unexpected argument '" + a.positional[0] + "'", 2);
  auto wait = seconds_flag(a, "--wait", 5, 0.1, 600);
  if (!wait) return complain(what, wait.error().message, 2);
  const std::string instance = a.value("--instance") ? *a.value("--instance") : "";

  auto p = open_participant(a.common);
  if (!p) return complain(what, p.error().message);
  auto states = States::open(*p);
  if (!states) return complain(what, states.error().message);
  auto topic = wire::Topic<studio_SceneNode>::create(*p);
  if (!topic) return complain(what, topic.error().message);
  auto nodes = wire::Reader<studio_SceneNode>::create(*p, *topic);
  if (!nodes) return complain(what, nodes.error().message);

  // The scene as this host receives it: keyed instances, a disposed one removed (as every reader
  // of studio/scene/node must read them).
  std::map<scene::NodeId, scene::Node> held;
  uint64_t unconvertible = 0;
  uint64_t local = scene::hash_nodes(held);
  const studio_SceneState* state = nullptr;
  const auto start = Clock::now();
  const auto deadline = start + to_ns(*wait);
  // Listen at least 1 s (or --wait) before judging: every writer of studio/scene/node must be
  // discovered and its transient-local history delivered, not only the server's.
  const auto settle = start + std::min(to_ns(*wait), std::chrono::nanoseconds(1'000'000'000));
  while (true) {
    bool changed = false;
    for (auto got = nodes->take(256); !got.empty(); got = nodes->take(256)) {
      for (auto& r : got) {
        changed = true;
        if (r.meta.disposed) {
          held.erase(std::string(wire::str(r.data->node_id)));
        } else if (r.meta.valid_data) {
          if (auto n = wire::to_core(*r.data))
            held[n->id] = std::move(*n);
          else
            ++unconvertible;
        }
      }
    }
    if (changed) local = scene::hash_nodes(held);
    states->poll();
    state = states->find(instance);
    if (state && state->nodes_hash == local && state->node_count == held.size() &&
        Clock::now() >= settle)
      break;
    if (Clock::now() >= deadline) break;
    std::this_thread::sleep_for(10ms);
  }
  if (!state)
    return complain(what, (instance.empty() ? std::string("no scene server")
                                            : "scene server '" + instance + "'") +
                              " reported its state on studio/scene/state within " +
                              std::to_string(*wait).substr(0, 4) + " s");
  const bool agree = state->nodes_hash == local && state->node_count == held.size();
  if (a.common.json) {
    Printer pr(Printer::Mode::json);
    pr.begin_object();
    state_json(pr, *state);
    pr.key("local_nodes_hash");
    pr.string(hex(local));
    pr.key("local_node_count");
    pr.number(uint64_t(held.size()));
    pr.key("consistent");
    pr.number(agree);
    pr.end_object();
    emit(pr.take());
  } else {
    emit(state_text(*state));
    emit("state_hash " + hex(state->state_hash));
    emit("nodes_hash " + hex(state->nodes_hash) + " (server), " + hex(local) + " (" +
         std::to_string(held.size()) +
         " nodes received here): " + (agree ? "consistent" : "DIFFERENT"));
  }
  if (!agree)
    return complain(
        what, "the nodes received here (" + std::to_string(held.size()) + ", hash " + hex(local) +
                  ") differ from the server's (" + std::to_string(state->node_count) + ", hash " +
                  hex(state->nodes_hash) + ")" +
                  (unconvertible
                       ? "; " + std::to_string(unconvertible) + " sample(s) could not be converted"
                       : ""));
  return 0;
}

}  // namespace

int scene_command(const std::vector<std::string>& argv) {
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h") {
    std::fputs(kSceneHelp, argv.empty() ? stderr : stdout);
    return argv.empty() ? 2 : 0;
  }
  const std::string verb = argv[0];
  const bool known = verb == "load" || verb == "play" || verb == "pause" || verb == "seek" ||
                     verb == "speed" || verb == "hash";
  if (!known)
    return complain("scene", "unknown verb '" + verb + "' (load, play, pause, seek, speed, hash)",
                    2);
  auto a = verb == "hash" ? parse_args({argv.begin() + 1, argv.end()}, {"--wait", "--instance"})
                          : parse_args({argv.begin() + 1, argv.end()},
                                       {"--wait", "--animation", "--at-frame", "--from", "--mode"});
  if (!a) return complain("scene " + verb, a.error().message, 2);
  if (a->help) {
    std::fputs(kSceneHelp, stdout);
    return 0;
  }
  if (verb != "play" && (a->has("--from") || a->has("--mode")))
    return complain("scene " + verb, "--from and --mode are play's options", 2);
  return verb == "hash" ? hash(*a) : command(verb, *a);
}

}  // namespace studio::ctl
