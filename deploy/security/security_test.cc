// DDS Security against real processes (issue 19 item 3). Every refusal sits beside a positive
// control doing the same thing with the right credentials, so no case passes because nothing
// works:
//   - no identity: discovers nothing, writes arrive nowhere        (control: an identity does both)
//   - an identity from another CA: refused                         (control: this CA's identity)
//   - an expired certificate: refused                              (control: a valid one, same
//   role)
//   - the projector may read the scene, not command it            (control: the preview commands
//   it)
//   - capture cannot be told to record without the permission     (control: the operator records)
//   - tshark on lo in a private network namespace: no plaintext payload in a secure run
//                                                                  (control: the plain run shows
//                                                                  it)
//   - studioctl doctor: a missing file and an expired certificate  (control: a clean identity)
// The PKI is made by deploy/security/make-pki for each test; the services are studio-scene
// --config and studio-capture --config (simulated camera); the participants under test are
// studioctl and studio-security-probe (testing/security_probe.cc).

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "harness/process.h"
#include "studioctl/testing/json.h"
#include "wire/types.h"

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using studio::ctl::testing::Json;
using JsonReader = studio::ctl::testing::JsonReader;
using studio::testing::Env;
using studio::testing::Process;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Outcome {
  int code = -1;
  std::string out, err;
  // The last line of stdout that parses as JSON (the probe prints one).
  Json json() const {
    std::istringstream s(out);
    Json last;
    for (std::string line; std::getline(s, line);)
      if (auto j = JsonReader::parse(line)) last = *j;
    return last;
  }
  std::string field(const char* key) const {
    const Json j = json();
    const Json* v = j.find(key);
    if (!v) return "<absent>";
    if (v->kind == Json::Kind::string) return v->string;
    if (v->kind == Json::Kind::number) return std::to_string(int64_t(v->number));
    if (v->kind == Json::Kind::boolean) return v->boolean ? "true" : "false";
    return "<other>";
  }
};

class SecurityTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = studio::testing::make_test_dir(std::string("security.") + info->name());
    dds_ = studio::testing::DdsDomain::unique();
    dds_.apply_to_this_process();
  }
  void TearDown() override {
    for (auto& p : processes_) p.stop();
    if (HasFailure()) {
      std::fprintf(stderr, "test dir: %s (DDS domain %d)\n", dir_.c_str(), dds_.domain_id);
      for (auto& p : processes_)
        std::fprintf(stderr, "---- %s log ----\n%s\n", p.name().c_str(), p.log().c_str());
    } else {
      std::error_code ec;
      fs::remove_all(dir_, ec);
    }
  }

  static fs::path source(const std::string& rel) { return fs::path(STUDIO_SOURCE_DIR) / rel; }

  // make-pki into dir_/name; returns its exit status (output in the failure message).
  void make_pki(const std::string& name, const std::string& args) {
    const std::string cmd = source("deploy/security/make-pki").string() + " --out '" +
                            (dir_ / name).string() + "' --domains 0-230 " + args + " 2>&1";
    const Outcome r = shell(cmd);
    ASSERT_EQ(r.code, 0) << cmd << "\n" << r.out;
  }
  // The standard PKI of these tests plus an expired identity and a second, foreign CA.
  void make_all_pkis() {
    make_pki("pki",
             "--identity scene --identity capture-cam0 --identity projector-proj0 "
             "--identity preview --identity operator --identity monitor");
    make_pki("pki", "--identity expired=preview --not-before 2020-01-01 --not-after 2021-01-01");
    make_pki("other", "--identity preview --identity monitor");
  }

  // Environment of a secured process: the loopback profile + the secure profile, an identity.
  Env secure_env(const std::string& identity, const std::string& pki = "pki") const {
    Env env = dds_.env();
    for (auto& [k, v] : env)
      if (k == "CYCLONEDDS_URI") v += ",file://" + (std::filesystem::path(STUDIO_BINARY_DIR) / "deploy/dds/secure.xml").string();
    env.emplace_back("STUDIO_SECURITY_DIR", (dir_ / pki).string());
    env.emplace_back("STUDIO_IDENTITY", identity);
    return env;
  }
  Env plain_env() const { return dds_.env(); }

  static std::string env_prefix(const Env& env) {
    std::string s = "env";
    for (const auto& [k, v] : env) s += " " + k + "='" + v + "'";
    return s;
  }

  Outcome shell(const std::string& cmd) {
    const fs::path err = dir_ / ("run." + std::to_string(runs_++) + ".err");
    Outcome r;
    FILE* f = ::popen((cmd + " 2>'" + err.string() + "'").c_str(), "r");
    if (!f) return r;
    char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) r.out.append(buf, n);
    const int status = ::pclose(f);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = slurp(err);
    return r;
  }
  Outcome run(const Env& env, const std::string& binary, const std::vector<std::string>& args) {
    std::string cmd = env_prefix(env) + " " + studio::testing::built_binary(binary).string();
    for (const auto& a : args) cmd += " '" + a + "'";
    return shell(cmd);
  }
  Outcome probe(const Env& env, const std::vector<std::string>& args) {
    return run(env, "deploy/security/studio-security-probe", args);
  }

  Process& spawn(const std::string& name, const std::string& binary, std::vector<std::string> args,
                 const Env& env) {
    auto p = Process::start({.name = name,
                             .binary = studio::testing::built_binary(binary),
                             .args = std::move(args),
                             .env = env,
                             .dir = dir_});
    if (!p) throw std::runtime_error(p.error().message);
    processes_.push_back(std::move(*p));
    return processes_.back();
  }
  std::string write_file(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  // The scene server (studio-scene --config) with the scene identity (or plain).
  Process& start_scene(const Env& env) {
    const std::string config =
        write_file("scene.yaml", "instance: scene0\nstatus_period: 0.5\nclock: {fps: 25}\n");
    auto& p = spawn("scene", "scene/studio-scene", {"--config", config}, env);
    EXPECT_TRUE(p.wait_ready(60s)) << p.log();
    return p;
  }
  // The scene as the read-only monitor sees it: node ids and the server's state.
  Outcome read_scene(double seconds = 3) {
    return probe(secure_env("monitor"), {"scene-read", "--seconds", std::to_string(seconds)});
  }
  static bool has_node(const Outcome& r, const std::string& id) {
    const Json j = r.json();
    if (const Json* nodes = j.find("nodes"))
      for (const auto& n : nodes->array)
        if (n.string == id) return true;
    return false;
  }

  studio::testing::Watchdog watchdog_{std::chrono::seconds(220)};
  fs::path dir_;
  studio::testing::DdsDomain dds_;
  std::deque<Process> processes_;
  int runs_ = 0;
};

// A participant without an identity (the plain loopback profile, same domain) discovers neither
// participants nor topics of the secured studio and its scene command reaches no reader; an
// identity of the studio's CA discovers the scene server and its command changes the scene.
TEST_F(SecurityTest, NoIdentityDiscoversNothingAndItsWritesArriveNowhere) {
  make_all_pkis();
  start_scene(secure_env("scene"));

  const Outcome seen = probe(secure_env("monitor"), {"discover", "--seconds", "4"});
  ASSERT_EQ(seen.code, 0) << seen.out << seen.err;
  EXPECT_GE(std::stoi(seen.field("participants")), 1) << seen.out;
  EXPECT_GE(std::stoi(seen.field("publications")), 2) << seen.out;  // scene node, state, status

  // SPDP announcements are plaintext by the DDS Security design (they carry the identity token
  // the handshake starts from), so the blind participant may list the server's
  // participant; it learns no topic, no writer and no reader (SEDP is encrypted).
  const Outcome blind = probe(plain_env(), {"discover", "--seconds", "4"});
  ASSERT_EQ(blind.code, 0) << blind.out << blind.err;
  EXPECT_EQ(blind.field("publications"), "0") << blind.out;
  EXPECT_EQ(blind.field("subscriptions"), "0") << blind.out;

  const Outcome intruder = probe(plain_env(), {"scene-add", "intruder", "--seconds", "4"});
  EXPECT_EQ(intruder.code, 4) << intruder.out << intruder.err;  // nothing matched
  EXPECT_EQ(intruder.field("writer"), "ok") << intruder.out;    // it could write, to nobody
  EXPECT_EQ(intruder.field("matched_readers"), "0") << intruder.out;

  const Outcome visitor =
      probe(secure_env("operator"), {"scene-add", "visitor", "--seconds", "10"});
  EXPECT_EQ(visitor.code, 0) << visitor.out << visitor.err;
  EXPECT_EQ(visitor.field("acknowledged"), "true") << visitor.out;

  const Outcome scene = read_scene();
  ASSERT_EQ(scene.code, 0) << scene.out << scene.err;
  EXPECT_TRUE(has_node(scene, "visitor")) << scene.out;
  EXPECT_FALSE(has_node(scene, "intruder")) << scene.out;
  const Json state = *scene.json().find("state");
  ASSERT_EQ(state.kind, Json::Kind::object) << scene.out;
  EXPECT_EQ(state.find("accepted")->number, 1) << scene.out;  // the visitor's command only
  EXPECT_EQ(state.find("rejected")->number, 0) << scene.out;
}

// An identity (with governance and permissions) signed by another CA fails the handshake: it
// discovers nothing and its command is lost; the same role from the studio's CA succeeds.
TEST_F(SecurityTest, IdentityFromAnotherCaIsRefused) {
  make_all_pkis();
  start_scene(secure_env("scene"));

  const Outcome foreign = probe(secure_env("preview", "other"), {"discover", "--seconds", "4"});
  ASSERT_EQ(foreign.code, 0) << foreign.out << foreign.err;       // it runs, alone
  EXPECT_EQ(foreign.field("publications"), "0") << foreign.out;   // the handshake failed:
  EXPECT_EQ(foreign.field("subscriptions"), "0") << foreign.out;  // no encrypted discovery
  const Outcome foreign_add =
      probe(secure_env("preview", "other"), {"scene-add", "foreign", "--seconds", "4"});
  EXPECT_EQ(foreign_add.code, 4) << foreign_add.out << foreign_add.err;

  const Outcome native = probe(secure_env("preview"), {"discover", "--seconds", "4"});
  ASSERT_EQ(native.code, 0) << native.out << native.err;
  EXPECT_GE(std::stoi(native.field("publications")), 2) << native.out;
  const Outcome native_add =
      probe(secure_env("preview"), {"scene-add", "native", "--seconds", "10"});
  EXPECT_EQ(native_add.code, 0) << native_add.out << native_add.err;

  const Outcome scene = read_scene();
  EXPECT_TRUE(has_node(scene, "native")) << scene.out;
  EXPECT_FALSE(has_node(scene, "foreign")) << scene.out;
}

// An identity whose certificate expired (issued by the studio's CA, role preview) cannot even
// create its participant; the valid preview identity can, and discovers the scene server.
TEST_F(SecurityTest, ExpiredCertificateIsRefused) {
  make_all_pkis();
  start_scene(secure_env("scene"));

  const Outcome expired = probe(secure_env("expired"), {"discover", "--seconds", "2"});
  EXPECT_EQ(expired.code, 1) << expired.out << expired.err;
  EXPECT_NE(expired.out.find("participant"), std::string::npos) << expired.out;
  EXPECT_NE(expired.err.find("xpired"), std::string::npos) << expired.err;  // Cyclone's reason

  const Outcome valid = probe(secure_env("preview"), {"discover", "--seconds", "4"});
  ASSERT_EQ(valid.code, 0) << valid.out << valid.err;
  EXPECT_GE(std::stoi(valid.field("participants")), 1) << valid.out;
}

// The projector's permissions let it read studio/scene/node, not write studio/scene/command: it
// reads the scene (a node the preview added), its command writer is refused and the scene does not
// change; the preview's identical command does change it.
TEST_F(SecurityTest, ReadOnlyServiceCannotChangeTheScene) {
  make_all_pkis();
  start_scene(secure_env("scene"));
  const Outcome first = probe(secure_env("preview"), {"scene-add", "set", "--seconds", "10"});
  ASSERT_EQ(first.code, 0) << first.out << first.err;

  const Outcome reads = probe(secure_env("projector-proj0"), {"scene-read", "--seconds", "3"});
  EXPECT_EQ(reads.code, 0) << reads.out << reads.err;
  EXPECT_TRUE(has_node(reads, "set")) << reads.out;

  const Outcome writes = probe(secure_env("projector-proj0"), {"scene-add", "projector-edit"});
  EXPECT_EQ(writes.code, 3) << writes.out << writes.err;
  EXPECT_NE(writes.field("writer").find("Not Allowed By Security"), std::string::npos)
      << writes.out;

  const Outcome control =
      probe(secure_env("preview"), {"scene-add", "preview-edit", "--seconds", "10"});
  EXPECT_EQ(control.code, 0) << control.out << control.err;

  const Outcome scene = read_scene();
  EXPECT_TRUE(has_node(scene, "preview-edit")) << scene.out;
  EXPECT_FALSE(has_node(scene, "projector-edit")) << scene.out;
  const Json* state = scene.json().find("state");
  ASSERT_TRUE(state && state->kind == Json::Kind::object) << scene.out;
  EXPECT_EQ(state->find("accepted")->number, 2) << scene.out;  // set + preview-edit
}

// studioctl capture start with the monitor identity (may read the camera state, may not publish
// studio/capture/command) is refused and nothing is recorded, also when the monitor's own
// participant does not enforce its permissions (the capture service does); with the operator
// identity the same command records a take.
TEST_F(SecurityTest, CaptureCannotBeToldToRecordWithoutPermission) {
  make_all_pkis();
  const std::string config =
      write_file("capture.yaml",
                 "instance: cam0\nclock: {fps: 25}\ntakes_dir: takes\nstate_period: 0.2\n"
                 "status_period: 0.5\nmasks: false\ncameras:\n  - id: cam0\n    source: {type: "
                 "sim, ring: 6, index: 0, width: 176, height: 144}\n");
  auto& capture =
      spawn("capture", "capture/studio-capture", {"--config", config}, secure_env("capture-cam0"));
  ASSERT_TRUE(capture.wait_ready(60s)) << capture.log();
  const fs::path takes = dir_ / "takes";

  const Outcome refused = run(secure_env("monitor"), "deploy/studioctl/studioctl",
                              {"capture", "start", "--take", "sneaky", "--wait", "15"});
  EXPECT_NE(refused.code, 0) << refused.out << refused.err;
  EXPECT_NE(refused.err.find("Not Allowed By Security"), std::string::npos) << refused.err;

  // The same identity with its own check switched off (a governance without write access control
  // on studio/capture/command, signed with the studio CA's key as an insider could): its writer
  // is created, and the capture service refuses to match it (Cyclone: "security_attributes
  // mismatch": the studio governance requires write access control on the topic, the writer does
  // not claim it; claiming it would make its own participant check the permissions).
  {
    std::string lax = slurp(dir_ / "pki/governance.xml");
    const auto rule = lax.find("<topic_expression>studio/capture/command</topic_expression>");
    ASSERT_NE(rule, std::string::npos);
    const auto flag = lax.find("<enable_write_access_control>true", rule);
    ASSERT_NE(flag, std::string::npos);
    lax.replace(flag, 33, "<enable_write_access_control>false");
    fs::create_directories(dir_ / "rogue");
    write_file("rogue/governance.xml", lax);
    fs::create_directory_symlink(dir_ / "pki/ca", dir_ / "rogue/ca");
    fs::create_directory_symlink(dir_ / "pki/identities", dir_ / "rogue/identities");
    const Outcome signed_lax = shell(
        "openssl smime -sign -text -in '" + (dir_ / "rogue/governance.xml").string() + "' -out '" +
        (dir_ / "rogue/governance.p7s").string() + "' -signer '" +
        (dir_ / "pki/ca/ca.pem").string() + "' -inkey '" + (dir_ / "pki/ca/ca.key").string() + "'");
    ASSERT_EQ(signed_lax.code, 0) << signed_lax.err;
  }
  const Outcome bypass = run(secure_env("monitor", "rogue"), "deploy/studioctl/studioctl",
                             {"capture", "start", "--take", "bypass", "--wait", "10"});
  EXPECT_NE(bypass.code, 0) << bypass.out << bypass.err;
  // It authenticated and read the cameras' state (studioctl needs that first), its writer exists
  // (no local refusal), and no capture service accepted it as a publisher.
  EXPECT_NE(bypass.err.find("no capture service is listening on studio/capture/command"),
            std::string::npos)
      << bypass.err;

  const Outcome started = run(secure_env("operator"), "deploy/studioctl/studioctl",
                              {"capture", "start", "--take", "granted", "--wait", "20"});
  ASSERT_EQ(started.code, 0) << started.out << started.err;
  bool recorded = false;
  for (int i = 0; i < 100 && !recorded; ++i) {
    std::error_code ec;
    recorded = fs::exists(takes / "granted/cam0/frames.raw", ec) &&
               fs::file_size(takes / "granted/cam0/frames.raw", ec) > 0;
    if (!recorded) std::this_thread::sleep_for(100ms);
  }
  EXPECT_TRUE(recorded) << "no frames in " << (takes / "granted/cam0");
  const Outcome stopped = run(secure_env("operator"), "deploy/studioctl/studioctl",
                              {"capture", "stop", "--take", "granted", "--wait", "20"});
  EXPECT_EQ(stopped.code, 0) << stopped.out << stopped.err;
  EXPECT_FALSE(fs::exists(takes / "sneaky")) << "the refused take was recorded";
  EXPECT_FALSE(fs::exists(takes / "bypass")) << "the remotely refused take was recorded";
}

// In a private network namespace (root), tshark on lo records a plain run and a secure run of
// the same exchange (the operator adds a node whose id is a marker; the server publishes it back
// on studio/scene/node). Both runs deliver (the monitor reads the node back); the plain capture
// holds the marker, the secure one does not, and holds encrypted RTPS submessages (SEC_BODY).
TEST_F(SecurityTest, PacketCaptureOfASecureRunShowsNoPlaintext) {
  ASSERT_EQ(::geteuid(), 0u) << "needs root (a private network namespace for tshark on lo)";
  ASSERT_EQ(::unshare(CLONE_NEWNET), 0) << "unshare(CLONE_NEWNET): " << std::strerror(errno);
  ASSERT_EQ(shell("ip link set lo up").code, 0);
  make_all_pkis();

  struct Capture {
    std::string bytes;
    int sec_body = 0, rtps = 0;
    bool delivered = false;
  };
  auto capture_run = [&](const std::string& mode, const std::string& marker) {
    Capture c;
    const bool secure = mode == "secure";
    const fs::path pcap = dir_ / (mode + ".pcapng");
    auto& tshark =
        spawn("tshark-" + mode, "/usr/bin/tshark", {"-i", "lo", "-n", "-w", pcap.string()}, {});
    // tshark says "Capturing on 'Loopback: lo'" once it captures.
    for (int i = 0; i < 200 && tshark.log().find("Capturing on") == std::string::npos; ++i)
      std::this_thread::sleep_for(50ms);
    EXPECT_NE(tshark.log().find("Capturing on"), std::string::npos) << tshark.log();
    auto& scene = start_scene(secure ? secure_env("scene") : plain_env());
    const Outcome add = probe(secure ? secure_env("operator") : plain_env(),
                              {"scene-add", marker, "--seconds", "10"});
    EXPECT_EQ(add.code, 0) << mode << ": " << add.out << add.err;
    const Outcome back =
        probe(secure ? secure_env("monitor") : plain_env(), {"scene-read", "--seconds", "3"});
    c.delivered = has_node(back, marker);
    scene.stop();
    std::this_thread::sleep_for(500ms);
    tshark.stop();
    c.bytes = slurp(pcap);
    const Outcome count =
        shell("tshark -n -r '" + pcap.string() + "' -Y rtps -T fields -e rtps.sm.id");
    std::istringstream s(count.out);
    for (std::string line; std::getline(s, line);) {
      ++c.rtps;
      if (line.find("0x30") != std::string::npos) ++c.sec_body;  // SEC_BODY submessage
    }
    return c;
  };
  const Capture plain = capture_run("plain", "PLAINMARKER-b7e1c2");
  const Capture secure = capture_run("secure", "SECRETMARKER-4f9a0d");

  EXPECT_TRUE(plain.delivered);
  EXPECT_TRUE(secure.delivered);
  EXPECT_NE(plain.bytes.find("PLAINMARKER-b7e1c2"), std::string::npos)
      << "control: the plain run's payload is visible on the wire";
  EXPECT_EQ(secure.bytes.find("SECRETMARKER-4f9a0d"), std::string::npos)
      << "the secure run's payload is visible on the wire";
  EXPECT_GT(secure.rtps, 20) << "the secure run was captured";
  EXPECT_GT(secure.sec_body, 0) << "no encrypted submessages in the secure run";
  EXPECT_EQ(plain.sec_body, 0);
  // Discovery is encrypted too: in the secure run a topic name appears only inside the signed
  // permissions documents the handshake exchanges (plaintext by the DDS Security design: each
  // side verifies the other's grants), never in discovery.
  auto count = [](const std::string& hay, const std::string& needle) {
    int n = 0;
    for (auto at = hay.find(needle); at != std::string::npos; at = hay.find(needle, at + 1)) ++n;
    return n;
  };
  const std::string name = "studio/scene/command", granted = "<topic>studio/scene/command</topic>";
  EXPECT_GT(count(plain.bytes, name), 0);
  EXPECT_EQ(count(plain.bytes, granted), 0);
  EXPECT_GT(count(secure.bytes, granted), 0);
  EXPECT_EQ(count(secure.bytes, name), count(secure.bytes, granted));
}

// studioctl doctor reads the security files the profile names: all ok for a clean identity
// (control); a deleted permissions file fails security_files, an expired certificate fails
// security_certificates, an unset STUDIO_IDENTITY is named, each with the fix and exit status 1.
TEST_F(SecurityTest, DoctorChecksTheSecurityFiles) {
  make_all_pkis();
  auto checks = [&](const Env& env) {
    const Outcome r = run(env, "deploy/studioctl/studioctl", {"doctor", "--json", "--wait", "0.5"});
    std::map<std::string, Json> out;
    std::istringstream s(r.out);
    for (std::string line; std::getline(s, line);)
      if (auto j = JsonReader::parse(line)) out[j->find("check")->string] = *j;
    return std::pair{r, out};
  };
  auto status = [](std::map<std::string, Json>& c, const char* name) {
    return c.count(name) ? c[name].find("status")->string : std::string("<absent>");
  };
  auto text = [](std::map<std::string, Json>& c, const char* name, const char* key) {
    return c.count(name) ? c[name].find(key)->string : std::string();
  };

  auto [ok_run, ok] = checks(secure_env("monitor"));
  EXPECT_EQ(ok_run.code, 0) << ok_run.out << ok_run.err;
  for (const char* name :
       {"security_files", "security_certificates", "security_documents", "participant"})
    EXPECT_EQ(status(ok, name), "ok") << name << ": " << ok_run.out;

  auto [plain_run, plain] = checks(plain_env());
  EXPECT_EQ(status(plain, "security"), "warn") << plain_run.out;

  fs::remove(dir_ / "pki/identities/monitor/permissions.p7s");
  auto [missing_run, missing] = checks(secure_env("monitor"));
  EXPECT_EQ(missing_run.code, 1) << missing_run.out;
  EXPECT_EQ(status(missing, "security_files"), "fail") << missing_run.out;
  EXPECT_NE(
      text(missing, "security_files", "message").find("monitor/permissions.p7s: No such file"),
      std::string::npos)
      << missing_run.out;
  EXPECT_NE(text(missing, "security_files", "fix").find("make-pki"), std::string::npos);

  auto [expired_run, expired] = checks(secure_env("expired"));
  EXPECT_EQ(expired_run.code, 1) << expired_run.out;
  EXPECT_EQ(status(expired, "security_files"), "ok") << expired_run.out;
  EXPECT_EQ(status(expired, "security_certificates"), "fail") << expired_run.out;
  EXPECT_NE(
      text(expired, "security_certificates", "message").find("expired on Jan  1 00:00:00 2021"),
      std::string::npos)
      << expired_run.out;
  EXPECT_NE(text(expired, "security_certificates", "fix").find("--force"), std::string::npos);
  EXPECT_EQ(status(expired, "security_documents"), "fail") << expired_run.out;  // grant expired

  auto [unset_run, unset] = checks(secure_env(""));
  EXPECT_EQ(status(unset, "security_files"), "fail") << unset_run.out;
  EXPECT_NE(text(unset, "security_files", "fix").find("set STUDIO_IDENTITY"), std::string::npos)
      << unset_run.out;

  // The control once more, for the CA's other identities (the deletion above touched only one).
  auto [again_run, again] = checks(secure_env("preview"));
  EXPECT_EQ(status(again, "security_certificates"), "ok") << again_run.out;
}

// make-pki's artefacts verify with openssl itself (certificate chain, S/MIME signatures), a
// key is private to its owner, a role's permissions hold exactly its topics, and bad input is
// refused with one line (exit 2) and changes nothing.
TEST_F(SecurityTest, MakePkiWritesVerifiableDocumentsAndRefusesBadInput) {
  make_pki("pki", "--identity hull --identity studio-pc3=tracker+monitor --days 30");
  const std::string pki = (dir_ / "pki").string();
  auto ok = [&](const std::string& cmd) {
    const Outcome r = shell(cmd + " >/dev/null");
    EXPECT_EQ(r.code, 0) << cmd << "\n" << r.err;
  };
  ok("openssl verify -CAfile " + pki + "/ca/ca.pem " + pki + "/identities/hull/cert.pem");
  ok("openssl smime -verify -in " + pki + "/governance.p7s -CAfile " + pki + "/ca/ca.pem");
  ok("openssl smime -verify -in " + pki + "/identities/hull/permissions.p7s -CAfile " + pki +
     "/ca/ca.pem");
  EXPECT_EQ(fs::status(dir_ / "pki/identities/hull/key.pem").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  const std::string hull = slurp(dir_ / "pki/identities/hull/permissions.xml");
  for (const char* t : {"studio/actor/segments", "studio/actor/mesh", "studio/service/status",
                        "studio/camera/calibration", "studio/camera/mask"})
    EXPECT_NE(hull.find(std::string("<topic>") + t + "</topic>"), std::string::npos) << t;
  EXPECT_EQ(hull.find("studio/scene/"), std::string::npos) << hull;
  EXPECT_NE(hull.find("<subject_name>CN=hull,O=Studio</subject_name>"), std::string::npos);
  EXPECT_NE(hull.find("<default>DENY</default>"), std::string::npos);
  const std::string pc3 = slurp(dir_ / "pki/identities/studio-pc3/permissions.xml");
  EXPECT_NE(pc3.find("<topic>studio/actor/head</topic>"), std::string::npos) << pc3;
  EXPECT_NE(pc3.find("<topic>studio/*</topic>"), std::string::npos) << pc3;
  const std::string gov = slurp(dir_ / "pki/governance.xml");
  // Every topic of the one wire table (idl/src/types.cc): a topic added there without a rule
  // in make-pki fails here.
  for (const studio::wire::TopicRow& row : studio::wire::topic_table())
    EXPECT_NE(gov.find(std::string("<topic_expression>") + row.name + "</topic_expression>"),
              std::string::npos)
        << row.name;
  // 30 days of validity (2 592 000 s): valid in 2 500 000 s, expired in 2 600 000 s.
  const Outcome end =
      shell("openssl x509 -noout -checkend 2600000 -in " + pki + "/identities/hull/cert.pem");
  EXPECT_NE(end.code, 0) << "valid beyond 30 days";
  ok("openssl x509 -noout -checkend 2500000 -in " + pki + "/identities/hull/cert.pem");

  const std::string make = source("deploy/security/make-pki").string() + " --out '" + pki + "' ";
  for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
           {"--identity hull", "identity 'hull' exists"},
           {"--identity x=director", "unknown role 'director'"},
           {"--identity y --domains 7-300", "ids must be 0..232"},
           {"--identity z --not-before 2030-01-01 --not-after 2029-01-01", "ends before it starts"},
           {"--bogus", "unknown argument '--bogus'"}}) {
    const Outcome r = shell(make + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "pki/identities/x"));
  EXPECT_FALSE(fs::exists(dir_ / "pki/identities/y"));
  const Outcome help = shell(source("deploy/security/make-pki").string() + " --help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("--identity NAME[=ROLE"), std::string::npos);
}

}  // namespace
