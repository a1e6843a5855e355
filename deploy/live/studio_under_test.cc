#include "studio_under_test.h"

#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "sim/cameras.h"
#include "support/cameras.h"

namespace studio::faults {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string substitute(std::string s, const std::string& instance, const fs::path& confdir) {
  auto replace_all = [&](const std::string& from, const std::string& to) {
    for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
      s.replace(at, from.size(), to);
  };
  replace_all("@STUDIO_CONFDIR@", confdir.string());
  replace_all("%i", instance);
  return s;
}

}  // namespace

UnitCommand unit_command(const std::string& unit, const std::string& instance,
                         const fs::path& confdir) {
  const std::string text = slurp(fs::path(STUDIO_SOURCE_DIR) / "deploy/systemd" / (unit + ".in"));
  UnitCommand c;
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(R"(\nExecStart=@STUDIO_BINDIR@/(\S+)([^\n]*))")))
    throw std::runtime_error(unit + ": no ExecStart=@STUDIO_BINDIR@/... line");
  const std::string binary = m[1];
  const std::map<std::string, std::string> where = {{"studio-capture", "capture/studio-capture"},
                                                    {"studio-keyer", "keyer/studio-keyer"},
                                                    {"studio-hull", "hull/studio-hull"},
                                                    {"studio-tracker", "tracker/studio-tracker"},
                                                    {"studio-scene", "scene/studio-scene"}};
  if (!where.contains(binary)) throw std::runtime_error(unit + ": unknown binary " + binary);
  c.binary = where.at(binary);
  std::stringstream args(substitute(m[2], instance, confdir));
  for (std::string a; args >> a;) c.args.push_back(a);
  const std::regex env_re(R"(\nEnvironment=([A-Z_]+)=([^\n]*))");
  for (std::sregex_iterator it(text.begin(), text.end(), env_re), end; it != end; ++it)
    c.env.emplace_back((*it)[1], substitute((*it)[2], instance, confdir));
  return c;
}

Monitor::Monitor()
    : participant_(wire::Participant::create().value()),
      mask_topic_(wire::Topic<studio_AlphaMask>::create(participant_).value()),
      masks_(wire::Reader<studio_AlphaMask>::create(participant_, mask_topic_).value()),
      seg_topic_(wire::Topic<studio_SegmentSet>::create(participant_).value()),
      segments_(wire::Reader<studio_SegmentSet>::create(participant_, seg_topic_).value()),
      head_topic_(wire::Topic<studio_HeadPose>::create(participant_).value()),
      heads_(wire::Reader<studio_HeadPose>::create(participant_, head_topic_, 16).value()),
      status_topic_(wire::Topic<studio_ServiceStatus>::create(participant_).value()),
      statuses_(
          wire::Reader<studio_ServiceStatus>::create(participant_, status_topic_, 16).value()) {}

void Monitor::poll() {
  const auto now = Clock::now();
  for (auto& s : masks_.take(256))
    if (s.meta.valid_data) mask_frame[std::string(wire::str(s.data->camera_id))] = s.data->frame;
  for (auto& s : segments_.take(256)) {
    if (!s.meta.valid_data || s.data->frame == last_segment_frame) continue;
    last_segment_frame = s.data->frame;
    ++segment_frames;
    last_segment_at = now;
  }
  for (auto& s : heads_.take(256)) {
    // A frame's update carries that frame's capture instant; keep-alives coast in between.
    if (!s.meta.valid_data ||
        s.data->capture_ns != int64_t(s.data->frame) * 40'000'000 + 20'000'000)
      continue;
    ++head_updates;
    last_head_at = now;
  }
  for (auto& s : statuses_.take(256)) {
    if (!s.meta.valid_data) continue;
    const std::string key =
        std::string(wire::str(s.data->service)) + ":" + std::string(wire::str(s.data->instance));
    Status& st = status[key];
    st.pid = s.data->pid;
    st.state = s.data->state;
    st.input_hz = s.data->input_hz;
    st.at = now;
    ++st.samples;
    st.counters.clear();
    for (const auto& c : wire::view(s.data->counters))
      st.counters[std::string(wire::str(c.name))] = uint64_t(c.value);
    first_status_of_pid.try_emplace(s.data->pid, now);
    if (s.data->state == studio_SERVICE_DEGRADED) degraded_seen.insert(key);
  }
}

double Monitor::segments_hz(std::chrono::milliseconds d) {
  poll();
  const uint64_t before = segment_frames;
  const auto t0 = Clock::now();
  while (Clock::now() - t0 < d) {
    poll();
    std::this_thread::sleep_for(5ms);
  }
  return double(segment_frames - before) / std::chrono::duration<double>(Clock::now() - t0).count();
}

void StudioTest::SetUp() {
  ProcessTest::SetUp();
  etc_ = dir_ / "etc";
  fs::create_directories(etc_);
  fs::copy_file(fs::path(STUDIO_SOURCE_DIR) / "deploy/dds/loopback.xml", etc_ / "dds.xml");
  // The cameras: indices 0..3 of the example studio's simulated ring, at 176x144.
  sim::RingOptions ring;
  ring.width = 176;
  ring.height = 144;
  ring.focal_px *= 176.0 / 704.0;  // as the capture server scales it (capture_config.cc)
  auto cameras = sim::ring_cameras(ring);
  cameras.resize(kCameras);
  ASSERT_TRUE(support::write_rig_yaml(cameras, etc_ / "rig.yaml").has_value());
  for (int i = 0; i < kCameras; ++i) {
    const std::string cam = "cam" + std::to_string(i);
    std::ofstream(etc_ / ("capture-" + cam + ".yaml"))
        << "instance: " << cam << "\nstatus_period: 0.2\nclock: {fps: 25, epoch_ns: 0}\n"
        << "takes_dir: " << (dir_ / "takes").string() << "\nstate_period: 1.0\n"
        << "cameras:\n  - id: " << cam << "\n    source: {type: sim, ring: 6, index: " << i
        << ", width: 176, height: 144}\n";
  }
  std::ofstream(etc_ / "hull.yaml")
      << "instance: hull\nstatus_period: 0.2\nhull:\n  rig: rig.yaml\n"
      << "  box: [-1.5, 0.0, -1.5, 1.5, 2.4, 1.5]\n  grid: 64\n  deadline_ms: 40\n"
      << "  min_cameras: 3\n  threads: 1\n  mesh: false\n";
  std::ofstream(etc_ / "tracker.yaml")
      << "instance: tracker\nstatus_period: 0.2\nactor_id: actor\n";
  std::ofstream(etc_ / "scene.yaml")
      << "instance: scene\nstatus_period: 0.2\nclock: {fps: 25, epoch_ns: 0}\nscene: "
      << STUDIO_SCENE_DEFAULT_DIR << "/scene.yaml\nstate_dir: " << (dir_ / "scene-state").string()
      << "\n";
}

testing::Process& StudioTest::start_unit(const std::string& name, const std::string& unit,
                                         const std::string& instance, const testing::Env& extra_env,
                                         const std::string& netns) {
  const UnitCommand c = unit_command(unit, instance, etc_);
  testing::Env env = dds_.env();
  for (const auto& e : c.env) env.push_back(e);  // the unit's Environment= (the profile)
  for (const auto& e : extra_env) env.push_back(e);
  fs::path binary = testing::built_binary(c.binary);
  std::vector<std::string> args = c.args;
  if (!netns.empty()) {
    args.insert(args.begin(), {"netns", "exec", netns, binary.string()});
    binary = "/usr/sbin/ip";  // execs the service: the pid is the service's
  }
  auto p = testing::Process::start(
      {.name = name, .binary = binary, .args = args, .env = env, .dir = dir_});
  if (!p) throw std::runtime_error(p.error().message);
  processes_.push_back(std::move(*p));
  return processes_.back();
}

void StudioTest::start_studio(bool scene) {
  std::vector<testing::Process*> all;
  all.push_back(&start_unit("tracker", "studio-tracker.service"));
  all.push_back(&start_unit("hull", "studio-hull.service"));
  if (scene) all.push_back(&start_unit("scene", "studio-scene.service"));
  for (int i = 0; i < kCameras; ++i) {
    const std::string cam = "cam" + std::to_string(i);
    all.push_back(&start_unit(cam, "studio-capture@.service", cam));
  }
  for (auto* p : all) ASSERT_TRUE(p->wait_ready(30s)) << p->name() << "\n" << p->log();
}

testing::Process* StudioTest::find(const std::string& name) {
  for (auto it = processes_.rbegin(); it != processes_.rend(); ++it)
    if (it->name() == name) return &*it;
  return nullptr;
}

}  // namespace studio::faults
