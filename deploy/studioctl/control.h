#pragma once
// studioctl capture start|stop and camera get|set: commands to the capture services
// (studio/capture/command, studio/camera/control), confirmed from their read-back
// (studio/camera/state).

#include <string>
#include <vector>

namespace studio::ctl {

int capture_command(const std::vector<std::string>& argv);
int camera_command(const std::vector<std::string>& argv);
extern const char kCaptureHelp[];
extern const char kCameraHelp[];

}  // namespace studio::ctl
