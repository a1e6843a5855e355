#pragma once
// A small live studio for the fault tests, started as systemd starts it: each service from its
// unit's ExecStart= and Environment= (deploy/systemd/*.service.in, @STUDIO_BINDIR@ = this build
// tree, @STUDIO_CONFDIR@ = the test's etc/, %i = the instance), with configs written into etc/:
// four simulated cameras (176x144, 25 fps, keyed in the capture servers) on the example studio's
// ring, the hull (rig.yaml of exactly those cameras), the tracker and the scene server (the demo
// museum, persisted). A Monitor participant in the test process counts what the pipeline
// delivers and what each service reports on studio/service/status.

#include <chrono>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "harness/fixture.h"
#include "wire/endpoint.h"

namespace studio::faults {

// The command line and environment of a unit's ExecStart, for this build tree.
struct UnitCommand {
  std::string binary;  // relative to the build tree (hull/studio-hull)
  std::vector<std::string> args;
  testing::Env env;
};
UnitCommand unit_command(const std::string& unit, const std::string& instance,
                         const std::filesystem::path& confdir);

// What the pipeline delivers, as seen by one participant (polled; no background thread).
class Monitor {
 public:
  Monitor();
  // Takes everything that arrived.
  void poll();
  // Polls for `d`; returns the distinct frames of studio/actor/segments per second in that time.
  double segments_hz(std::chrono::milliseconds d);
  // Polls until pred() or the timeout.
  template <class Pred>
  bool until(Pred pred, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    do {
      poll();
      if (pred()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    } while (std::chrono::steady_clock::now() < end);
    return false;
  }

  struct Status {
    int pid = 0;
    studio_ServiceState state = studio_SERVICE_STARTING;
    double input_hz = 0;
    std::map<std::string, uint64_t> counters;
    std::chrono::steady_clock::time_point at;
    std::size_t samples = 0;
  };
  // Newest status per "service:instance"; first arrival of each pid.
  std::map<std::string, Status> status;
  std::map<int, std::chrono::steady_clock::time_point> first_status_of_pid;
  std::set<std::string> degraded_seen;  // "service:instance" that reported DEGRADED
  // Newest mask frame per camera and the time it arrived; segment frames and head updates.
  std::map<std::string, uint64_t> mask_frame;
  uint64_t segment_frames = 0, head_updates = 0;
  uint64_t last_segment_frame = 0;
  std::chrono::steady_clock::time_point last_segment_at, last_head_at;

 private:
  wire::Participant participant_;
  wire::Topic<studio_AlphaMask> mask_topic_;
  wire::Reader<studio_AlphaMask> masks_;
  wire::Topic<studio_SegmentSet> seg_topic_;
  wire::Reader<studio_SegmentSet> segments_;
  wire::Topic<studio_HeadPose> head_topic_;
  wire::Reader<studio_HeadPose> heads_;
  wire::Topic<studio_ServiceStatus> status_topic_;
  wire::Reader<studio_ServiceStatus> statuses_;
};

class StudioTest : public testing::ProcessTest {
 protected:
  static constexpr int kCameras = 4;
  void SetUp() override;
  // Starts the unit (`studio-hull.service`, `studio-capture@.service` with instance cam0) as
  // systemd would; `extra_env` added (WATCHDOG_USEC, ...); in network namespace `netns`
  // (`ip netns exec`) when not empty.
  testing::Process& start_unit(const std::string& name, const std::string& unit,
                               const std::string& instance = "", const testing::Env& extra_env = {},
                               const std::string& netns = "");
  // Every camera, hull, tracker (and scene) started and READY; segments flowing.
  void start_studio(bool scene);
  testing::Process* find(const std::string& name);

  std::filesystem::path etc_;
};

}  // namespace studio::faults
