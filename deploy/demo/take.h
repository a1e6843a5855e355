#pragma once
// `studio-demo-probe take`: records a take of a given length on every capture server, frame
// accurate (DESIGN §5), by publishing CaptureCommand on studio/capture/command:
//   1. waits until every capture server's command reader matched;
//   2. START at_frame = the frame `lead_s` from now (a future frame, so every server starts
//      with the same frame);
//   3. waits for every camera's CameraState to name the take (scheduled or recording);
//   4. STOP at_frame = start + frames, sent once the take is recording (a take's instance keeps
//      only its latest command, so START must have been seen first);
//   5. waits until every camera's CameraState shows it no longer recording.
// The result (JSON) names the take, its frames [start, stop) and which cameras confirmed.
// studioctl (`studioctl capture start|stop --at-frame N`) does the same for an operator; the demo
// uses it when it is built.

#include <string>

#include "core/error.h"
#include "studio_config.h"

namespace studio::demo {

struct TakeOptions {
  StudioConfig studio;
  std::string name = "demo";
  double lead_s = 1.0;
  int frames = 50;  // 2 s at 25 fps
  double timeout_s = 30;
};

// JSON object {take, start_frame, stop_frame, confirmed_start: [...], confirmed_stop: [...],
// complete}. Fails (one line) when no capture server is there to receive the command.
Expected<std::string> run_take(const TakeOptions& options);

}  // namespace studio::demo
