// studio-security-probe: a small DDS participant for the DDS Security tests
// (deploy/security/security_test.cc). It joins the domain exactly as a service does
// ($CYCLONEDDS_URI, $STUDIO_DDS_DOMAIN, and with the secure profile $STUDIO_SECURITY_DIR /
// $STUDIO_IDENTITY) and does one thing, printing one JSON line:
//
//   discover [--seconds S]    what this participant discovers: other participants and the
//                             publications / subscriptions of the studio's topics
//   scene-add NODE [--seconds S]
//                             an ADD_NODE of group node NODE on studio/scene/command, written once
//                             a reader matched (or after S seconds without one) and acknowledged
//   scene-read [--seconds S]  the SceneNode ids and the last SceneState it reads within S seconds
//                             (the state only if this identity may read studio/scene/state)
//
// Output keys: "participant" ("ok" or the refusal), "writer"/"reader" ("ok" or the refusal),
// counts and ids. Exit status: 0 done; 1 the participant was refused; 3 the writer or reader was
// refused; 4 nothing matched within S seconds. A refusal is the security plugins' verdict
// (DDS_RETCODE_NOT_ALLOWED_BY_SECURITY or a participant Cyclone would not create).

#include <dds/dds.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include "scene/command.h"
#include "wire/endpoint.h"
#include "wire/scene_convert.h"

namespace {

using namespace studio;
using Clock = std::chrono::steady_clock;

const char kHelp[] =
    "usage: studio-security-probe discover [--seconds S]\n"
    "       studio-security-probe scene-add NODE [--seconds S]\n"
    "       studio-security-probe scene-read [--seconds S]\n"
    "A test participant for the DDS Security tests: joins the domain as a service does\n"
    "($CYCLONEDDS_URI, $STUDIO_DDS_DOMAIN, $STUDIO_SECURITY_DIR, $STUDIO_IDENTITY) and prints one\n"
    "JSON line. Exit 0 done, 1 participant refused, 3 writer/reader refused, 4 nothing matched.\n"
    "Default --seconds: 5.\n";

std::string quoted(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out + "\"";
}

// Participants other than `self` in DCPSParticipant, and the studio endpoints in
// DCPSPublication / DCPSSubscription whose participant is not `self`.
struct Seen {
  std::set<std::string> participants;
  int publications = 0, subscriptions = 0;
};

std::string guid_text(const dds_guid_t& g) {
  char buf[40];
  for (int i = 0; i < 16; ++i) std::snprintf(buf + 2 * i, 3, "%02x", g.v[i]);
  return buf;
}

Seen discover(dds_entity_t participant, std::chrono::milliseconds wait) {
  dds_guid_t self{};
  dds_get_guid(participant, &self);
  const std::string me = guid_text(self);
  const dds_entity_t rp =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr);
  const dds_entity_t rw =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  const dds_entity_t rr =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr);
  std::this_thread::sleep_for(wait);
  Seen seen;
  void* buf[64];
  dds_sample_info_t info[64];
  std::memset(buf, 0, sizeof buf);
  int n = dds_read(rp, buf, info, 64, 64);
  for (int i = 0; i < n; ++i) {
    if (!info[i].valid_data) continue;
    const auto* s = static_cast<const dds_builtintopic_participant_t*>(buf[i]);
    const std::string g = guid_text(s->key);
    if (g != me) seen.participants.insert(g);
  }
  if (n > 0) dds_return_loan(rp, buf, n);
  for (auto [reader, count] :
       {std::pair{rw, &seen.publications}, std::pair{rr, &seen.subscriptions}}) {
    std::memset(buf, 0, sizeof buf);
    n = dds_read(reader, buf, info, 64, 64);
    for (int i = 0; i < n; ++i) {
      if (!info[i].valid_data) continue;
      const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(buf[i]);
      if (guid_text(e->participant_key) != me && std::strncmp(e->topic_name, "studio/", 7) == 0)
        ++*count;
    }
    if (n > 0) dds_return_loan(reader, buf, n);
  }
  return seen;
}

int run_discover(const wire::Participant& p, std::chrono::milliseconds wait) {
  const Seen s = discover(p.handle(), wait);
  std::printf(
      "{\"participant\":\"ok\",\"participants\":%zu,\"publications\":%d,\"subscriptions\":%d}\n",
      s.participants.size(), s.publications, s.subscriptions);
  return 0;
}

int run_scene_add(const wire::Participant& p, const std::string& node,
                  std::chrono::milliseconds wait) {
  auto topic = wire::Topic<studio_SceneCommand>::create(p);
  if (!topic) {
    std::printf("{\"participant\":\"ok\",\"writer\":%s}\n", quoted(topic.error().message).c_str());
    return 3;
  }
  auto writer = wire::Writer<studio_SceneCommand>::create(p, *topic);
  if (!writer) {
    std::printf("{\"participant\":\"ok\",\"writer\":%s}\n", quoted(writer.error().message).c_str());
    return 3;
  }
  const bool matched = writer->wait_for_readers(1, wait);
  scene::Node n;
  n.id = node;
  n.kind = scene::NodeKind::group;
  wire::Owned<studio_SceneCommand> cmd;
  if (auto c = wire::from_core(scene::Command{0, scene::AddNode{n}}, *cmd); !c) {
    std::fprintf(stderr, "studio-security-probe: %s\n", c.error().message.c_str());
    return 2;
  }
  wire::set(cmd->sender, "probe-" + std::to_string(getpid()));
  cmd->command_id = 1;
  cmd->at_frame = studio_SCENE_AT_NOW;  // now, whatever the server's clock says
  const auto w = writer->write(*cmd);
  const dds_return_t acked = dds_wait_for_acks(writer->handle(), DDS_SECS(5));
  std::printf(
      "{\"participant\":\"ok\",\"writer\":\"ok\",\"matched_readers\":%u,\"written\":%s,"
      "\"acknowledged\":%s}\n",
      writer->matched_readers(), w ? "true" : "false",
      matched && acked == DDS_RETCODE_OK ? "true" : "false");
  return matched ? 0 : 4;
}

int run_scene_read(const wire::Participant& p, std::chrono::milliseconds wait) {
  auto nt = wire::Topic<studio_SceneNode>::create(p);
  if (!nt) {
    std::printf("{\"participant\":\"ok\",\"reader\":%s}\n", quoted(nt.error().message).c_str());
    return 3;
  }
  auto nodes = wire::Reader<studio_SceneNode>::create(p, *nt, 1);
  if (!nodes) {
    std::printf("{\"participant\":\"ok\",\"reader\":%s}\n", quoted(nodes.error().message).c_str());
    return 3;
  }
  // The server's state only when this identity may read it (the projector may not).
  auto st = wire::Topic<studio_SceneState>::create(p);
  std::optional<wire::Reader<studio_SceneState>> states;
  if (st)
    if (auto r = wire::Reader<studio_SceneState>::create(p, *st)) states.emplace(std::move(*r));
  std::set<std::string> ids;
  std::string state = "null";
  for (const auto end = Clock::now() + wait; Clock::now() < end;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    nodes->visit([&](const studio_SceneNode& n, const wire::SampleMeta& m) {
      if (m.valid_data && m.alive) ids.insert(std::string(wire::str(n.node_id)));
    });
    if (states)
      states->visit([&](const studio_SceneState& s, const wire::SampleMeta& m) {
        if (!m.valid_data) return;
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "{\"hash\":\"%016llx\",\"nodes\":%u,\"accepted\":%llu,\"rejected\":%llu}",
                      static_cast<unsigned long long>(s.state_hash), s.node_count,
                      static_cast<unsigned long long>(s.commands_accepted),
                      static_cast<unsigned long long>(s.commands_rejected));
        state = buf;
      });
  }
  std::string list;
  for (const auto& id : ids) list += (list.empty() ? "" : ",") + quoted(id);
  std::printf(
      "{\"participant\":\"ok\",\"reader\":\"ok\",\"matched_writers\":%u,\"nodes\":[%s],"
      "\"state\":%s}\n",
      nodes->matched_writers(), list.c_str(), state.c_str());
  return nodes->matched_writers() > 0 ? 0 : 4;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  double seconds = 5;
  std::vector<std::string> pos;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "-h" || args[i] == "--help") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (args[i] == "--seconds" && i + 1 < args.size()) {
      char* end = nullptr;
      seconds = std::strtod(args[++i].c_str(), &end);
      if (*end || !(seconds > 0 && seconds <= 120)) {
        std::fprintf(stderr, "studio-security-probe: --seconds: expected 0 < S <= 120\n");
        return 2;
      }
      continue;
    }
    pos.push_back(args[i]);
  }
  const bool ok_shape = (pos.size() == 1 && (pos[0] == "discover" || pos[0] == "scene-read")) ||
                        (pos.size() == 2 && pos[0] == "scene-add");
  if (!ok_shape) {
    std::fprintf(stderr, "studio-security-probe: bad arguments (see --help)\n");
    return 2;
  }
  auto p = wire::Participant::create();
  if (!p) {
    std::printf("{\"participant\":%s}\n", quoted(p.error().message).c_str());
    return 1;
  }
  const auto wait = std::chrono::milliseconds(int64_t(seconds * 1000));
  if (pos[0] == "discover") return run_discover(*p, wait);
  if (pos[0] == "scene-add") return run_scene_add(*p, pos[1], wait);
  return run_scene_read(*p, wait);
}
