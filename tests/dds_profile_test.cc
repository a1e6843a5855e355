// The DDS profiles of deploy/dds: the production profile parses and carries masks through its
// own multicast group (network partition) between two processes, and every bulk topic's reader
// announces its own group; both profiles are exercised on
// the loopback interface only (the production interface line is swapped for lo).

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <thread>

#include "harness/fixture.h"
#include "harness/wire_samples.h"
#include "wire/endpoint.h"

namespace studio::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void replace(std::string& s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << "profile no longer contains: " << from;
  s.replace(at, from.size(), to);
}

class DdsProfileTest : public ProcessTest {};

TEST_F(DdsProfileTest, StudioProfileRoutesMasksThroughTheirPartitionBetweenProcesses) {
  // studio.xml, moved onto lo and isolated by this test's discovery tag; the trace shows the
  // configuration Cyclone actually applied.
  std::string xml = slurp(std::filesystem::path(STUDIO_SOURCE_DIR) / "deploy/dds/studio.xml");
  replace(xml, R"(<NetworkInterface autodetermine="true" multicast="default"/>)",
          R"(<NetworkInterface name="lo" multicast="true"/>)");
  replace(xml, "<Discovery>", "<Discovery><Tag>" + dds_.tag + "</Tag>");
  replace(xml, "</Domain>",
          "<Tracing><Verbosity>finest</Verbosity><OutputFile>${STUDIO_TRACE}</OutputFile></"
          "Tracing></Domain>");
  const auto profile = dir_ / "studio-on-lo.xml";
  std::ofstream(profile) << xml;
  const auto trace = dir_ / "peer.trace";

  Process peer = Process::start({.name = "peer",
                                 .binary = built_binary("tests/wire_peer"),
                                 .args = {"echo"},
                                 .env = {{"CYCLONEDDS_URI", "file://" + profile.string()},
                                         {"STUDIO_DDS_DOMAIN", std::to_string(dds_.domain_id)},
                                         {"STUDIO_TRACE", trace.string()}},
                                 .dir = dir_})
                     .value();
  ASSERT_TRUE(peer.wait_ready(15s)) << peer.log();
  setenv("STUDIO_TRACE", (dir_ / "test.trace").c_str(), 1);
  auto p = wire::Participant::create(dds_.domain_id, "file://" + profile.string()).value();
  auto out_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto in_topic = wire::Topic<studio_AlphaMask>::create(p, "studio/camera/mask/echo").value();
  auto writer = wire::Writer<studio_AlphaMask>::create(p, out_topic).value();
  auto reader = wire::Reader<studio_AlphaMask>::create(p, in_topic).value();
  ASSERT_TRUE(writer.wait_for_readers(1, 10s));
  auto mask = make<studio_AlphaMask>(2);
  bool echoed = false;
  const auto deadline = Clock::now() + 10s;
  while (!echoed && Clock::now() < deadline) {
    ASSERT_TRUE(writer.write(*mask).has_value());
    std::this_thread::sleep_for(20ms);
    for (auto& r : reader.take()) echoed |= r.meta.valid_data && same(*r.data, *mask);
  }
  EXPECT_TRUE(echoed);
  EXPECT_EQ(peer.stop(), 0);
  // The peer's mask reader advertised the partition's group as its multicast locator (so our
  // writer sent masks there), while its reader of the echo topic stayed on the default group.
  const std::string applied = slurp(trace);
  auto subscription_of = [&](const std::string& topic) {
    const auto at =
        applied.find("DCPSSubscription/SubscriptionBuiltinTopicData:{topic_name=\"" + topic + "\"");
    if (at == std::string::npos) return std::string();
    return applied.substr(at, applied.find('\n', at) - at);
  };
  const std::string masks = subscription_of("studio/camera/mask");
  ASSERT_FALSE(masks.empty()) << "no mask reader in the peer's trace";
  EXPECT_NE(masks.find("multicast_locator={udp/239.255.42.1:"), std::string::npos) << masks;
  // Every bulk topic's reader announces its partition's group (a host joins it only for its
  // readers); the small topics stay on the default group.
  const std::pair<const char*, const char*> bulk[] = {
      {"studio/actor/mesh", "239.255.42.2"},        {"studio/actor/segments", "239.255.42.3"},
      {"studio/camera/image", "239.255.42.4"},      {"studio/camera/image_reply", "239.255.42.4"},
      {"studio/projector/frame", "239.255.42.5"},   {"studio/projector/mask", "239.255.42.5"}};
  for (const auto& [topic, group] : bulk) {
    const std::string sub = subscription_of(topic);
    ASSERT_FALSE(sub.empty()) << "no " << topic << " reader in the peer's trace";
    EXPECT_NE(sub.find(std::string("multicast_locator={udp/") + group + ":"), std::string::npos)
        << topic << ": " << sub;
  }
  for (const char* topic : {"studio/camera/calibration", "studio/actor/head", "studio/scene/node",
                            "studio/service/status"}) {
    const std::string sub = subscription_of(topic);
    ASSERT_FALSE(sub.empty()) << "no " << topic << " reader in the peer's trace";
    EXPECT_EQ(sub.find("239.255.42."), std::string::npos) << topic << ": " << sub;
  }
}

// The loopback profile (tests, the single-machine demo) sends data to the matched readers only:
// a peer with a mask reader announces (SPDP) its unicast data locator and no default multicast
// one, so a writer on this host never multicasts masks (or meshes) to every process of the
// studio; discovery still multicasts (the peer and this process find each other without a peer
// list). Negative control: the same profile with multicast data allowed (as before session 10)
// announces the default group 239.255.0.1, which every writer would then send to.
TEST_F(DdsProfileTest, LoopbackProfileSendsDataOnlyToItsReaders) {
  const std::string loopback =
      slurp(std::filesystem::path(STUDIO_SOURCE_DIR) / "deploy/dds/loopback.xml");
  // The peer's trace after a writer here matched its mask reader.
  const auto peer_trace = [&](const std::string& xml, const std::string& name) {
    std::string x = xml;
    replace(x, "</Domain>",
            "<Tracing><Verbosity>finest</Verbosity><OutputFile>${STUDIO_TRACE}</OutputFile></"
            "Tracing></Domain>");
    const auto profile = dir_ / (name + ".xml");
    std::ofstream(profile) << x;
    const auto trace = dir_ / (name + ".trace");
    Env env = dds_.env();
    env[0].second = "file://" + profile.string();
    env.push_back({"STUDIO_TRACE", trace.string()});
    Process peer = Process::start({.name = "peer-" + name,
                                   .binary = built_binary("tests/wire_peer"),
                                   .args = {"echo"},
                                   .env = env,
                                   .dir = dir_})
                       .value();
    EXPECT_TRUE(peer.wait_ready(15s)) << peer.log();
    auto p = wire::Participant::create(dds_.domain_id, dds_.config_uri).value();
    auto topic = wire::Topic<studio_AlphaMask>::create(p).value();
    auto writer = wire::Writer<studio_AlphaMask>::create(p, topic).value();
    EXPECT_TRUE(writer.wait_for_readers(1, 10s)) << name;
    EXPECT_EQ(peer.stop(), 0);
    return slurp(trace);
  };
  ASSERT_NE(dds_.config_uri.find("deploy/dds/loopback.xml"), std::string::npos);
  const std::string unicast = peer_trace(loopback, "loopback");
  ASSERT_NE(unicast.find("DCPSSubscription/SubscriptionBuiltinTopicData:{topic_name=\"studio/"
                         "camera/mask\""),
            std::string::npos)
      << "no mask reader in the peer's trace";
  EXPECT_NE(unicast.find("default_unicast_locator={udp/127.0.0.1:"), std::string::npos);
  EXPECT_EQ(unicast.find("default_multicast_locator="), std::string::npos);
  std::string multicast_data = loopback;
  replace(multicast_data, "<AllowMulticast>spdp</AllowMulticast>",
          "<AllowMulticast>true</AllowMulticast>");
  const std::string control = peer_trace(multicast_data, "multicast-data");
  EXPECT_NE(control.find("default_multicast_locator={udp/239.255.0.1:"), std::string::npos);
}

TEST_F(DdsProfileTest, LoopbackProfileSelectsOnlyLoWithMulticast) {
  const auto trace = dir_ / "peer.trace";
  Env env = dds_.env();
  env[0].second += ",<Tracing><Verbosity>config</Verbosity><OutputFile>" + trace.string() +
                   "</OutputFile></Tracing>";
  Process peer = Process::start({.name = "peer",
                                 .binary = built_binary("tests/wire_peer"),
                                 .args = {"bench-echo"},
                                 .env = env,
                                 .dir = dir_})
                     .value();
  ASSERT_TRUE(peer.wait_ready(15s)) << peer.log();
  const std::string applied = slurp(trace);
  EXPECT_NE(applied.find("selected interfaces: lo "), std::string::npos) << applied.substr(0, 2000);
  EXPECT_EQ(applied.find("eth0 (index"), std::string::npos);
  EXPECT_NE(applied.find("Tag/#text: " + dds_.tag), std::string::npos);
  EXPECT_NE(applied.find("NetworkInterface[@multicast]: true"), std::string::npos);
  EXPECT_EQ(peer.stop(), 0);
}

}  // namespace
}  // namespace studio::testing
