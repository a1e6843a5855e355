#include "studioctl/discovery.h"

#include <cstring>
#include <map>
#include <thread>

namespace studio::ctl {
namespace {

struct Peer {
  std::string host, process;
  int pid = 0;
};

std::string guid_key(const dds_guid_t& g) {
  return std::string(reinterpret_cast<const char*>(g.v), 16);
}

std::string prop(const dds_qos_t* qos, const char* name) {
  char* value = nullptr;
  if (qos == nullptr || !dds_qget_prop(qos, name, &value) || value == nullptr) return {};
  std::string s = value;
  dds_free(value);
  return s;
}

// Reads every alive sample of a built-in topic reader (loaned) and hands it to f.
template <class T, class F>
dds_return_t read_all(dds_entity_t reader, F&& f) {
  constexpr int kBatch = 64;
  void* samples[kBatch] = {};
  dds_sample_info_t infos[kBatch];
  // read (not take) with the not-read mask walks the cache once, batch by batch.
  while (true) {
    samples[0] = nullptr;
    const dds_return_t n =
        dds_read_mask(reader, samples, infos, kBatch, kBatch,
                      DDS_NOT_READ_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ALIVE_INSTANCE_STATE);
    if (n < 0) return n;
    for (int i = 0; i < n; ++i)
      if (infos[i].valid_data) f(*static_cast<const T*>(samples[i]));
    if (n > 0) dds_return_loan(reader, samples, n);
    if (n < kBatch) return 0;
  }
}

}  // namespace

Expected<std::vector<Endpoint>> discover(const wire::Participant& self,
                                         std::chrono::nanoseconds wait) {
  dds_guid_t own{};
  if (auto rc = dds_get_guid(self.handle(), &own); rc < 0)
    return fail(wire::dds_error("dds_get_guid", rc));
  wire::Entity participants(
      dds_create_reader(self.handle(), DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr));
  wire::Entity publications(
      dds_create_reader(self.handle(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr));
  wire::Entity subscriptions(
      dds_create_reader(self.handle(), DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr));
  for (const auto* e : {&participants, &publications, &subscriptions})
    if (e->handle() < 0) return fail(wire::dds_error("built-in topic reader", e->handle()));
  std::this_thread::sleep_for(wait);

  std::map<std::string, Peer> peers;
  read_all<dds_builtintopic_participant_t>(participants.handle(), [&](const auto& p) {
    Peer peer{prop(p.qos, "__Hostname"), prop(p.qos, "__ProcessName"), 0};
    peer.pid = std::atoi(prop(p.qos, "__Pid").c_str());
    peers[guid_key(p.key)] = std::move(peer);
  });

  std::vector<Endpoint> out;
  auto add = [&](const dds_builtintopic_endpoint_t& e, bool writer) {
    if (std::memcmp(e.participant_key.v, own.v, 16) == 0) return;
    Endpoint ep;
    ep.writer = writer;
    ep.topic = e.topic_name ? e.topic_name : "";
    ep.type = e.type_name ? e.type_name : "";
    if (auto it = peers.find(guid_key(e.participant_key)); it != peers.end()) {
      ep.host = it->second.host;
      ep.pid = it->second.pid;
      ep.process = it->second.process;
    }
    dds_reliability_kind_t rel{};
    dds_duration_t block = 0;
    ep.reliability = "best-effort";
    if (dds_qget_reliability(e.qos, &rel, &block) && rel == DDS_RELIABILITY_RELIABLE)
      ep.reliability = "reliable";
    dds_durability_kind_t dur{};
    ep.durability = "volatile";
    if (dds_qget_durability(e.qos, &dur)) {
      switch (dur) {
        case DDS_DURABILITY_VOLATILE:
          ep.durability = "volatile";
          break;
        case DDS_DURABILITY_TRANSIENT_LOCAL:
          ep.durability = "transient-local";
          break;
        case DDS_DURABILITY_TRANSIENT:
          ep.durability = "transient";
          break;
        case DDS_DURABILITY_PERSISTENT:
          ep.durability = "persistent";
          break;
      }
    }
    out.push_back(std::move(ep));
  };
  if (auto rc = read_all<dds_builtintopic_endpoint_t>(publications.handle(),
                                                      [&](const auto& e) { add(e, true); });
      rc < 0)
    return fail(wire::dds_error("DCPSPublication", rc));
  if (auto rc = read_all<dds_builtintopic_endpoint_t>(subscriptions.handle(),
                                                      [&](const auto& e) { add(e, false); });
      rc < 0)
    return fail(wire::dds_error("DCPSSubscription", rc));
  return out;
}

}  // namespace studio::ctl
