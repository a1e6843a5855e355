// studioctl as a process against real processes over Cyclone DDS (loopback, one domain per test):
//  - every topic of idl/studio.idl (the "// studio/...:" comment above its struct) is in the wire
//    table and `topic echo --json` prints its samples with exactly the IDL's member names, in
//    order, arrays as arrays and enums by name (a new IDL topic nobody taught studioctl fails
//    here); python3's json module agrees that every line is JSON; text mode summarises bulky
//    arrays;
//  - with a real studio-capture (simulated camera): topic list / info show its topics and pid,
//    hz reports the configured 25 Hz, status lists it and --require fails for a missing service
//    (positive control: passes when present), camera set changes a feature and get reads it
//    back, capture start/stop at a frame produces a take that starts at exactly that frame;
//  - --help everywhere, bad usage is one line with exit 2.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "harness/fixture.h"
#include "studioctl/testing/json.h"

namespace studio::ctl {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using testing_json = ctl::testing::JsonReader;
using ctl::testing::Json;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  for (std::string l; std::getline(s, l);)
    if (!l.empty()) out.push_back(l);
  return out;
}

// The topics of idl/studio.idl as the IDL states them: topic name -> struct members (name, kind).
struct IdlMember {
  std::string name;
  bool array = false;  // T name[N] or sequence<...>
  bool enumeration = false;
  bool structure = false;
};
struct IdlTopic {
  std::string topic, type;
  std::vector<IdlMember> members;
};

std::vector<IdlTopic> idl_topics() {
  std::string idl = slurp(fs::path(STUDIO_SOURCE_DIR) / "idl/studio.idl");
  std::set<std::string> enums, structs;
  const std::regex enum_re(R"(enum\s+(\w+))"), struct_re(R"(struct\s+(\w+))");
  for (std::sregex_iterator it(idl.begin(), idl.end(), enum_re), end; it != end; ++it)
    enums.insert((*it)[1]);
  for (std::sregex_iterator it(idl.begin(), idl.end(), struct_re), end; it != end; ++it)
    structs.insert((*it)[1]);
  std::vector<IdlTopic> out;
  const std::regex topic_re(
      R"(//\s*(studio/[A-Za-z0-9_/]+):[^\n]*\n(?:\s*//[^\n]*\n)*\s*(?:@\w+\s+)*struct\s+(\w+)\s*\{([^}]*)\})");
  for (std::sregex_iterator it(idl.begin(), idl.end(), topic_re), end; it != end; ++it) {
    IdlTopic t{(*it)[1], (*it)[2], {}};
    std::string body = std::regex_replace(std::string((*it)[3]), std::regex(R"(//[^\n]*)"), "");
    std::stringstream s(body);
    for (std::string stmt; std::getline(s, stmt, ';');) {
      stmt = std::regex_replace(stmt, std::regex(R"(@\w+)"), "");
      std::smatch m;
      if (!std::regex_search(stmt, m, std::regex(R"((\w+)\s*(\[\s*\d+\s*\])?\s*$)"))) continue;
      IdlMember mem{m[1], m[2].matched || stmt.find("sequence") != std::string::npos};
      std::smatch ty;
      if (std::regex_search(stmt, ty, std::regex(R"(^\s*(\w+))"))) {
        mem.enumeration = enums.contains(ty[1]);
        mem.structure = structs.contains(ty[1]);
      }
      t.members.push_back(mem);
    }
    out.push_back(std::move(t));
  }
  return out;
}

class StudioctlTest : public studio::testing::ProcessTest {
 protected:
  struct Run {
    int code = -1;
    std::string out, err;
  };

  // Runs studioctl in this test's DDS domain (the fixture exported it into this process's
  // environment) and collects stdout and stderr.
  // prefix: prepended to the command line (environment overrides, a wrapper such as unshare).
  Run studioctl(const std::vector<std::string>& args, const std::string& prefix = "") {
    std::string cmd =
        prefix + " " + studio::testing::built_binary("deploy/studioctl/studioctl").string();
    for (const auto& a : args) cmd += " '" + a + "'";
    const fs::path err = dir_ / ("studioctl." + std::to_string(runs_++) + ".err");
    cmd += " 2>'" + err.string() + "'";
    Run r;
    FILE* f = ::popen(cmd.c_str(), "r");
    if (!f) return r;
    char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) r.out.append(buf, n);
    const int status = ::pclose(f);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = slurp(err);
    return r;
  }

  static std::vector<Json> json_lines(const Run& r) {
    std::vector<Json> out;
    for (const auto& l : lines_of(r.out)) {
      auto j = testing_json::parse(l);
      EXPECT_TRUE(j.has_value()) << "not JSON: " << l.substr(0, 300);
      if (j) out.push_back(std::move(*j));
    }
    return out;
  }

  std::string write_file(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }

  studio::testing::Process& start_capture(const std::string& extra = "") {
    const std::string config = write_file("capture.yaml",
                                          "instance: cam0\nclock: {fps: 25}\ntakes_dir: "
                                          "takes\nstate_period: 0.2\nstatus_period: 0.5\n" +
                                              extra +
                                              "cameras:\n  - id: cam0\n    source: {type: sim, "
                                              "ring: 6, index: 0, width: 176, height: 144}\n");
    auto& p = spawn("capture", "capture/studio-capture", {"--config", config});
    EXPECT_TRUE(p.wait_ready(30s)) << p.log();
    return p;
  }

  int runs_ = 0;
};

TEST_F(StudioctlTest, HelpEverywhereAndBadUsageIsOneLine) {
  for (std::vector<std::string> args : {std::vector<std::string>{"--help"},
                                        {"status", "--help"},
                                        {"topic", "--help"},
                                        {"topic", "echo", "--help"},
                                        {"topic", "hz", "--help"},
                                        {"topic", "list", "--help"},
                                        {"topic", "info", "--help"},
                                        {"capture", "--help"},
                                        {"capture", "start", "--help"},
                                        {"camera", "--help"},
                                        {"camera", "set", "--help"},
                                        {"doctor", "--help"}}) {
    auto r = studioctl(args);
    EXPECT_EQ(r.code, 0) << args[0] << r.err;
    EXPECT_NE(r.out.find("usage: studioctl"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--json"), std::string::npos) << r.out;
  }
  struct Bad {
    std::vector<std::string> args;
    std::string expect;
  } bad[] = {
      {{"frobnicate"}, "unknown command"},
      {{"topic", "echo"}, "name one TOPIC"},
      {{"topic", "echo", "studio/no/such"}, "unknown topic 'studio/no/such'"},
      {{"topic", "hz", "studio/actor/head", "--window", "x"}, "--window: expected a number"},
      {{"status", "--require", "hull,,tracker"}, "empty entry"},
      {{"status", "--domain", "999"}, "--domain: expected a DDS domain id"},
      {{"status", "--dds-config", "/nonexistent.xml"}, "cannot read '/nonexistent.xml'"},
      {{"camera", "set", "cam0", "Gain", "loud"}, "VALUE: expected a number"},
      {{"capture", "start", "--take", "bad/name"}, "is not a take name"},
      {{"topic", "list", "--bogus"}, "unknown option '--bogus'"},
  };
  for (const auto& b : bad) {
    auto r = studioctl(b.args);
    EXPECT_NE(r.code, 0) << b.args[0];
    EXPECT_NE(r.err.find(b.expect), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

TEST_F(StudioctlTest, EveryIdlTopicEchoesAsJsonWithTheIdlMemberNames) {
  const auto topics = idl_topics();
  ASSERT_GE(topics.size(), 13u) << "the topic comments of idl/studio.idl were not found";
  auto& pub = spawn("publisher", "deploy/studioctl/studioctl_topic_publisher", {"--rate", "20"});
  ASSERT_TRUE(pub.wait_ready(30s)) << pub.log();

  std::string all_json;
  for (const auto& t : topics) {
    SCOPED_TRACE(t.topic);
    auto r = studioctl({"topic", "echo", t.topic, "--json", "--count", "2", "--timeout", "20"});
    ASSERT_EQ(r.code, 0) << r.err;
    auto samples = json_lines(r);
    ASSERT_EQ(samples.size(), 2u) << r.out.substr(0, 500);
    for (const auto& s : samples) {
      ASSERT_EQ(s.kind, Json::Kind::object);
      std::vector<std::string> want;
      for (const auto& m : t.members) want.push_back(m.name);
      EXPECT_EQ(s.keys(), want) << t.type;
      for (const auto& m : t.members) {
        const Json* v = s.find(m.name);
        ASSERT_NE(v, nullptr);
        if (m.array) {
          EXPECT_EQ(v->kind, Json::Kind::array) << m.name;
        } else if (m.enumeration) {
          EXPECT_EQ(v->kind, Json::Kind::string) << m.name;  // enums by name
        } else if (m.structure) {
          EXPECT_EQ(v->kind, Json::Kind::object) << m.name;
        }
      }
    }
    all_json += r.out;
    // Text mode too (readable, never empty).
    auto text = studioctl({"topic", "echo", t.topic, "--count", "1", "--timeout", "20"});
    ASSERT_EQ(text.code, 0) << text.err;
    EXPECT_NE(text.out.find(t.members.front().name + ":"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("---"), std::string::npos);
  }

  // Bulky arrays: in full with --json (every run of the mask), summarised in text.
  auto mask = studioctl(
      {"topic", "echo", "studio/camera/mask", "--json", "--count", "1", "--timeout", "20"});
  auto m = json_lines(mask);
  ASSERT_EQ(m.size(), 1u);
  const Json* row_start = m[0].find("row_start");
  const Json* height = m[0].find("height");
  ASSERT_TRUE(row_start && height);
  EXPECT_EQ(row_start->array.size(), std::size_t(height->number) + 1);
  EXPECT_EQ(m[0].find("encoding")->string, "MASK_RUNS");
  auto mask_text =
      studioctl({"topic", "echo", "studio/camera/mask", "--count", "1", "--timeout", "20"});
  EXPECT_NE(mask_text.out.find("values)]"), std::string::npos) << mask_text.out;
  EXPECT_NE(mask_text.out.find("encoding: MASK_RUNS"), std::string::npos) << mask_text.out;

  // One instance only: --key (the publisher writes masks of cam0..cam3).
  auto one = studioctl({"topic", "echo", "studio/camera/mask", "--json", "--count", "3", "--key",
                        "cam2", "--timeout", "20"});
  ASSERT_EQ(one.code, 0) << one.err;
  auto cam2 = json_lines(one);
  ASSERT_EQ(cam2.size(), 3u);
  for (const auto& j : cam2) EXPECT_EQ(j.find("camera_id")->string, "cam2");

  // A second parser agrees: python3's json module reads every line.
  const std::string file = write_file("echo.jsonl", all_json);
  const std::string py =
      "python3 -c \"import json,sys; n=sum(1 for l in open(sys.argv[1]) if json.loads(l) is not "
      "None); print(n)\" '" +
      file + "'";
  FILE* f = ::popen(py.c_str(), "r");
  ASSERT_NE(f, nullptr);
  char buf[64] = {};
  std::fgets(buf, sizeof buf, f);
  EXPECT_EQ(::pclose(f), 0);
  EXPECT_EQ(std::atoi(buf), int(2 * topics.size()));

  // Every row of the wire table is a topic of the IDL (and so echoed above).
  auto list = studioctl({"topic", "list", "--all", "--json", "--wait", "0.5"});
  ASSERT_EQ(list.code, 0) << list.err;
  std::set<std::string> idl_names;
  for (const auto& t : topics) idl_names.insert(t.topic);
  for (const auto& row : json_lines(list)) {
    if (row.find("known")->boolean) {
      EXPECT_TRUE(idl_names.contains(row.find("topic")->string)) << row.find("topic")->string;
    }
  }
}

TEST_F(StudioctlTest, TopicListInfoAndHzShowARealCaptureService) {
  auto& capture = start_capture();
  auto list = studioctl({"topic", "list", "--json", "--wait", "4"});
  ASSERT_EQ(list.code, 0) << list.err;
  std::map<std::string, Json> by_topic;
  for (auto& j : json_lines(list)) by_topic[j.find("topic")->string] = j;
  ASSERT_TRUE(by_topic.count("studio/camera/mask")) << list.out;
  EXPECT_GE(by_topic["studio/camera/mask"].find("writers")->number, 1);
  EXPECT_EQ(by_topic["studio/camera/mask"].find("type")->string, "studio::AlphaMask");
  EXPECT_EQ(by_topic["studio/camera/mask"].find("qos")->find("reliability")->string, "best-effort");
  ASSERT_TRUE(by_topic.count("studio/camera/control"));
  EXPECT_GE(by_topic["studio/camera/control"].find("readers")->number, 1);
  ASSERT_TRUE(by_topic.count("studio/capture/command"));
  EXPECT_EQ(by_topic["studio/camera/mask"].find("hosts")->array.size(), 1u);

  auto text = studioctl({"topic", "list"});
  EXPECT_NE(text.out.find("studio/camera/state"), std::string::npos) << text.out;

  auto info = studioctl({"topic", "info", "studio/camera/mask", "--json", "--wait", "4"});
  ASSERT_EQ(info.code, 0) << info.err;
  auto i = json_lines(info);
  ASSERT_EQ(i.size(), 1u);
  const Json* writers = i[0].find("writers");
  ASSERT_TRUE(writers && writers->array.size() == 1) << info.out;
  EXPECT_EQ(int(writers->array[0].find("pid")->number), capture.pid());
  EXPECT_EQ(writers->array[0].find("reliability")->string, "best-effort");

  // The capture clock runs at 25 fps: one mask per frame (a loaded 2-core machine may drop a few
  // frames; the bounds tell 25 Hz from any other plausible rate).
  auto hz =
      studioctl({"topic", "hz", "studio/camera/mask", "--json", "--count", "4", "--window", "3"});
  ASSERT_EQ(hz.code, 0) << hz.err;
  auto reports = json_lines(hz);
  ASSERT_EQ(reports.size(), 4u);
  const Json& last = reports.back();
  EXPECT_NEAR(last.find("rate_hz")->number, 25.0, 8.0) << hz.out;
  EXPECT_GT(last.find("max_s")->number, 0.0);
  EXPECT_LE(last.find("min_s")->number, 0.04 + 1e-9);
  ASSERT_TRUE(last.find("instances")->find("cam0")) << hz.out;
  EXPECT_NEAR(last.find("instances")->find("cam0")->number, 25.0, 8.0);
  auto hz_text = studioctl({"topic", "hz", "studio/camera/mask", "--count", "2"});
  EXPECT_NE(hz_text.out.find("average rate:"), std::string::npos) << hz_text.out;
}

TEST_F(StudioctlTest, StatusListsServicesAndRequireFailsForAMissingOne) {
  auto& capture = start_capture();
  auto& tracker =
      spawn("tracker", "tracker/studio-tracker",
            {"--config", write_file("tracker.yaml", "instance: tracker0\nstatus_period: 0.5\n")});
  ASSERT_TRUE(tracker.wait_ready(30s)) << tracker.log();
  auto status = studioctl({"status", "--json"});
  ASSERT_EQ(status.code, 0) << status.err;
  bool found = false;
  for (const auto& s : json_lines(status)) {
    if (s.find("service")->string != "capture") continue;
    found = true;
    EXPECT_EQ(s.find("instance")->string, "cam0");
    EXPECT_EQ(s.find("state")->string, "SERVICE_RUNNING");
    EXPECT_EQ(int(s.find("pid")->number), capture.pid());
    EXPECT_LT(s.find("last_seen_s")->number, 3.0);
    EXPECT_FALSE(s.find("host")->string.empty());
  }
  EXPECT_TRUE(found) << status.out;
  bool tracker_seen = false;
  for (const auto& s : json_lines(status))
    if (s.find("service")->string == "tracker")
      tracker_seen = s.find("instance")->string == "tracker0";
  EXPECT_TRUE(tracker_seen) << status.out;
  auto text = studioctl({"status"});
  EXPECT_NE(text.out.find("capture"), std::string::npos);
  EXPECT_NE(text.out.find("running"), std::string::npos);

  // Positive control, then refusals.
  EXPECT_EQ(studioctl({"status", "--require", "capture:cam0"}).code, 0);
  EXPECT_EQ(studioctl({"status", "--require", "capture,tracker:tracker0"}).code, 0);
  auto missing = studioctl({"status", "--require", "capture:cam0,hull,tracker,keyer"});
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("required but not running: hull, keyer"), std::string::npos)
      << missing.err;
  auto other = studioctl({"status", "--require", "capture:cam7"});
  EXPECT_EQ(other.code, 1);
  EXPECT_NE(other.err.find("capture:cam7"), std::string::npos);

  // After the service stops, it is missing.
  EXPECT_EQ(capture.stop(), 0);
  std::this_thread::sleep_for(4s);  // the status topic's liveliness lease (3 s)
  EXPECT_EQ(studioctl({"status", "--require", "capture:cam0"}).code, 1);
}

TEST_F(StudioctlTest, CameraSetChangesAFeatureAndGetReadsItBack) {
  start_capture();
  auto before = studioctl({"camera", "get", "cam0", "Gain"});
  ASSERT_EQ(before.code, 0) << before.err;
  EXPECT_EQ(std::stod(before.out), 0.0);

  auto set = studioctl({"camera", "set", "cam0", "Gain", "6", "--json"});
  ASSERT_EQ(set.code, 0) << set.err;
  auto s = json_lines(set);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].find("value")->number, 6.0);
  auto after = studioctl({"camera", "get", "cam0", "Gain"});
  EXPECT_EQ(std::stod(after.out), 6.0) << after.out;

  // The camera clamps: the read-back says what it applied.
  auto clamped = studioctl({"camera", "set", "cam0", "Gain", "100"});
  ASSERT_EQ(clamped.code, 0) << clamped.err;
  EXPECT_NE(clamped.out.find("clamped"), std::string::npos) << clamped.out;
  EXPECT_EQ(std::stod(studioctl({"camera", "get", "cam0", "Gain"}).out), 24.0);

  auto all = studioctl({"camera", "get", "cam0", "--json"});
  std::set<std::string> names;
  for (const auto& f : json_lines(all)) names.insert(f.find("name")->string);
  EXPECT_TRUE(names.contains("ExposureTime")) << all.out;

  // Refusals: a feature the camera refuses, one it does not have, a camera that does not exist.
  auto bogus = studioctl({"camera", "set", "cam0", "Bogus", "1"});
  EXPECT_EQ(bogus.code, 1);
  EXPECT_NE(bogus.err.find("'Bogus' is not allowed"), std::string::npos) << bogus.err;
  auto unknown = studioctl({"camera", "get", "cam0", "Bogus"});
  EXPECT_EQ(unknown.code, 1);
  EXPECT_NE(unknown.err.find("has no feature 'Bogus'"), std::string::npos) << unknown.err;
  auto nocam = studioctl({"camera", "get", "cam9", "--wait", "2"});
  EXPECT_EQ(nocam.code, 1);
  EXPECT_NE(nocam.err.find("'cam9' did not report"), std::string::npos) << nocam.err;
}

TEST_F(StudioctlTest, CaptureStartAtAFrameProducesATakeFromThatFrame) {
  auto& capture = start_capture();
  // The camera's current frame, from its state (the first state may predate the first frame).
  uint64_t now = 0;
  for (int i = 0; i < 20 && now == 0; ++i) {
    auto state = studioctl(
        {"topic", "echo", "studio/camera/state", "--json", "--count", "1", "--timeout", "20"});
    ASSERT_EQ(state.code, 0) << state.err;
    for (const auto& j : json_lines(state)) now = uint64_t(j.find("frame")->number);
  }
  ASSERT_GT(now, 0u);
  const uint64_t start = now + 100;  // 4 s ahead at 25 fps: room for a loaded machine

  auto started = studioctl(
      {"capture", "start", "--take", "ctl_take", "--at-frame", std::to_string(start), "--json"});
  ASSERT_EQ(started.code, 0) << started.err << started.out;
  auto s = json_lines(started);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].find("camera_id")->string, "cam0");
  EXPECT_TRUE(s[0].find("ok")->boolean);
  EXPECT_EQ(uint64_t(s[0].find("at_frame")->number), start);

  // Wait until recording (the state says so), then stop with the defaults (the take the
  // cameras report, 50 frames ahead).
  bool recording = false;
  for (int i = 0; i < 40 && !recording; ++i) {
    auto r = studioctl(
        {"topic", "echo", "studio/camera/state", "--json", "--count", "1", "--timeout", "10"});
    for (const auto& j : json_lines(r)) recording = j.find("recording")->boolean;
    if (!recording) std::this_thread::sleep_for(200ms);
  }
  ASSERT_TRUE(recording);
  auto stopped = studioctl({"capture", "stop"});
  ASSERT_EQ(stopped.code, 0) << stopped.err;
  EXPECT_NE(stopped.out.find("take ctl_take stops at frame"), std::string::npos) << stopped.out;

  const fs::path yaml = dir_ / "takes/ctl_take/cam0/take.yaml";
  std::string text;
  for (int i = 0; i < 100; ++i) {
    text = slurp(yaml);
    if (text.find("status: complete") != std::string::npos) break;
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_NE(text.find("start_frame: " + std::to_string(start) + "\n"), std::string::npos) << text;
  // The take covers [start, stop) exactly: every frame of it is recorded or counted as a drop (a
  // loaded machine may drop the first frames; then first_frame is later by as many drops).
  auto value_of = [&](const std::string& key) -> int64_t {
    const auto at = text.find("\n" + key + ": ");
    return at == std::string::npos ? -1 : std::stoll(text.substr(at + key.size() + 3));
  };
  const int64_t stop = value_of("stop_frame"), first = value_of("first_frame");
  const int64_t frames = value_of("frames"), drops = value_of("drops");
  ASSERT_GT(stop, int64_t(start)) << text;
  EXPECT_EQ(frames + drops, stop - int64_t(start)) << text;
  EXPECT_GE(first, int64_t(start)) << text;
  EXPECT_LE(first - int64_t(start), drops) << text;
  EXPECT_GT(frames, 0) << text;
  EXPECT_NE(text.find("status: complete"), std::string::npos) << text;
  EXPECT_GT(fs::file_size(dir_ / "takes/ctl_take/cam0/frames.raw"), 0u);

  // A start frame in the past is refused by the camera, and studioctl says so.
  auto late = studioctl({"capture", "start", "--take", "late_take", "--at-frame", "1"});
  EXPECT_EQ(late.code, 1) << late.out;
  EXPECT_NE(late.err.find("did not accept"), std::string::npos) << late.err;
  EXPECT_EQ(capture.stop(), 0);
}

TEST_F(StudioctlTest, CommandsWithoutAServiceFailClearly) {
  auto r = studioctl({"camera", "set", "cam0", "Gain", "1", "--wait", "1"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("did not report its state"), std::string::npos) << r.err;
  auto c = studioctl({"capture", "start", "--at-frame", "100", "--wait", "1"});
  EXPECT_EQ(c.code, 1);
  EXPECT_NE(c.err.find("no capture service is listening"), std::string::npos) << c.err;
  auto e = studioctl({"topic", "echo", "studio/actor/head", "--count", "1", "--timeout", "1"});
  EXPECT_EQ(e.code, 1);
  EXPECT_NE(e.err.find("timed out after 0 of 1 samples"), std::string::npos) << e.err;
}

// doctor: every check passes on the test profile (the clock may only warn); each injected fault
// (a profile naming a missing interface, a buffer minimum above net.core.rmem_max, an unreadable
// profile, a host without a multicast route) fails its check with the fix, and exits 1.
TEST_F(StudioctlTest, DoctorPassesOnTheTestProfileAndNamesEachInjectedFault) {
  auto checks_of = [&](const Run& r) {
    std::map<std::string, Json> out;
    for (auto& j : json_lines(r)) out[j.find("check")->string] = j;
    return out;
  };
  auto ok = studioctl({"doctor", "--json"});
  EXPECT_EQ(ok.code, 0) << ok.out << ok.err;
  auto c = checks_of(ok);
  for (const char* name :
       {"profile", "interfaces", "socket_buffers", "multicast_route", "participant"})
    EXPECT_EQ(c[name].find("status")->string, "ok") << name << ": " << ok.out;
  EXPECT_NE(c["clock"].find("status")->string, "fail");
  auto text = studioctl({"doctor"});
  EXPECT_NE(text.out.find("ok   interfaces: interfaces: lo"), std::string::npos) << text.out;

  const std::string loopback = slurp(fs::path(STUDIO_SOURCE_DIR) / "deploy/dds/loopback.xml");
  auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string x = loopback;
    const auto at = x.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) x.replace(at, from.size(), to);
    return write_file(name, x);
  };
  auto no_if = studioctl(
      {"doctor", "--json", "--dds-config", variant("noif.xml", "name=\"lo\"", "name=\"studio9\"")});
  EXPECT_EQ(no_if.code, 1);
  c = checks_of(no_if);
  EXPECT_EQ(c["interfaces"].find("status")->string, "fail");
  EXPECT_NE(c["interfaces"].find("message")->string.find("studio9 does not exist"),
            std::string::npos)
      << no_if.out;
  EXPECT_NE(c["interfaces"].find("fix")->string.find("ip link set"), std::string::npos);

  auto big = studioctl({"doctor", "--json", "--dds-config",
                        variant("big.xml", "SocketReceiveBufferSize min=\"1MB\"",
                                "SocketReceiveBufferSize min=\"1GB\"")});
  EXPECT_EQ(big.code, 1);
  c = checks_of(big);
  EXPECT_EQ(c["socket_buffers"].find("status")->string, "fail") << big.out;
  EXPECT_NE(c["socket_buffers"].find("fix")->string.find("sysctl -w net.core.rmem_max=1000000000"),
            std::string::npos)
      << big.out;

  auto missing =
      studioctl({"doctor", "--json"}, "CYCLONEDDS_URI=file://" + (dir_ / "absent.xml").string());
  EXPECT_EQ(missing.code, 1);
  c = checks_of(missing);
  EXPECT_EQ(c["profile"].find("status")->string, "fail");
  EXPECT_NE(c["profile"].find("message")->string.find("absent.xml cannot be read"),
            std::string::npos)
      << missing.out;

  // A host with only lo (a fresh network namespace) and a profile that auto-detects: no multicast
  // route and no usable interface.
  const std::string autodetect = write_file(
      "auto.xml", "<CycloneDDS xmlns=\"https://cdds.io/config\"><Domain Id=\"any\"/></CycloneDDS>");
  auto isolated = studioctl({"doctor", "--json", "--dds-config", autodetect},
                            "unshare -n sh -c 'ip link set lo up && exec \"$0\" \"$@\"'");
  EXPECT_EQ(isolated.code, 1) << isolated.err;
  c = checks_of(isolated);
  ASSERT_TRUE(c.count("multicast_route")) << isolated.out << isolated.err;
  EXPECT_EQ(c["multicast_route"].find("status")->string, "fail") << isolated.out;
  EXPECT_NE(c["multicast_route"].find("fix")->string.find("ip route add 224.0.0.0/4"),
            std::string::npos);
  EXPECT_EQ(c["interfaces"].find("status")->string, "fail") << isolated.out;
  // Positive control of the same profile on this host (it has a routed, multicast interface).
  auto host = studioctl({"doctor", "--json", "--dds-config", autodetect});
  c = checks_of(host);
  EXPECT_EQ(c["multicast_route"].find("status")->string, "ok") << host.out;
}

}  // namespace
}  // namespace studio::ctl
