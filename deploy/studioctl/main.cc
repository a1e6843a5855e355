// studioctl: the studio operator's tool (DESIGN §6). One binary, verbs in the habits of
// `ros2 topic` and `systemctl`; --json everywhere, --help everywhere; the DDS domain and profile
// chosen as the services choose them.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "studioctl/cli.h"
#include "studioctl/control.h"
#include "studioctl/doctor.h"
#include "studioctl/scene.h"
#include "studioctl/status.h"
#include "studioctl/topics.h"

namespace {

const char kHelp[] =
    "usage: studioctl COMMAND [options]\n"
    "\n"
    "  status [--require LIST] [--wait S]           live services (studio/service/status)\n"
    "  status --watch S                             one line per service up / restarted / gone\n"
    "  topic list|info|hz|echo [TOPIC]              topics of the domain; samples with IDL names\n"
    "  capture start|stop [--take NAME] [--at-frame N]   frame-accurate recording on every camera\n"
    "  camera get|set CAM [FEATURE [VALUE]]        camera features, with the camera's read-back\n"
    "  scene load|play|pause|seek|speed|hash        the scene server: commands with its verdict, "
    "state hash\n"
    "  doctor                                       checks this host against the DDS profile, says "
    "what to fix\n"
    "\n"
    "Every command takes:\n"
    "  --domain N         DDS domain id (default: $STUDIO_DDS_DOMAIN, else Cyclone's default)\n"
    "  --dds-config FILE  Cyclone DDS XML profile (default: $CYCLONEDDS_URI)\n"
    "  --json             machine output: one JSON object per line\n"
    "  --help             the command's own help (e.g. studioctl topic --help)\n"
    "\n"
    "Exit status: 0 success, 1 failure (one line on stderr), 2 bad usage.\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace studio::ctl;
  std::vector<std::string> args(argv + 1, argv + argc);
  // Common flags may come before the command: move them after it.
  std::vector<std::string> leading;
  while (!args.empty() && args[0].starts_with("--") && args[0] != "--help") {
    const bool valued = (args[0] == "--domain" || args[0] == "--dds-config");
    leading.push_back(args[0]);
    args.erase(args.begin());
    if (valued && !args.empty()) {
      leading.push_back(args[0]);
      args.erase(args.begin());
    }
  }
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::fputs(kHelp, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  std::vector<std::string> rest(args.begin() + 1, args.end());
  // Leading common flags go after the verb (topic list --json), where every parser accepts them.
  const std::size_t at = (command == "status" || command == "doctor" || rest.empty()) ? 0 : 1;
  rest.insert(rest.begin() + std::ptrdiff_t(std::min(at, rest.size())), leading.begin(),
              leading.end());
  try {
    if (command == "status") return status_command(rest);
    if (command == "topic") return topic_command(rest);
    if (command == "capture") return capture_command(rest);
    if (command == "camera") return camera_command(rest);
    if (command == "scene") return scene_command(rest);
    if (command == "doctor") return doctor_command(rest);
  } catch (const std::exception& e) {
    return complain(command, std::string("internal error: ") + e.what());
  }
  return complain(command,
                  "unknown command (status, topic, capture, camera, scene, doctor; see --help)", 2);
}
