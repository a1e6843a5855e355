#pragma once
// studio-preview --headless: renders through EGL (no display) for tests, the demo report and
// render farms. Options from the command line (main.cc).
#include <string>

#include "preview_config.h"

namespace studio::preview {

struct HeadlessOptions {
  std::string screenshot;  // PNG of the last frame
  int frames = 1;          // meshes to draw (each a new mesh); 0 = the scene only
  double timeout_s = 30;   // give up waiting for meshes after this long
  double duration_s = 0;   // > 0: draw every mesh for this long (frames ignored), then stop
  double settle_s = 1.0;   // --frames 0: wait this long for the scene before the screenshot
  // > 0: low-rate pictures (the demo's): at most one new mesh drawn every this many seconds,
  // the screenshot rewritten (atomically) with each; only drawn meshes' images are requested.
  // Runs for duration_s, or until SIGINT/SIGTERM when that is 0.
  double every_s = 0;
  std::string record;  // folder: every drawn mesh's frame as <n>.png + frames.jsonl
  bool json = false;   // summary as one JSON line
  // Whenever the colour balance is applied with some camera beyond kMatchAutoOffset
  // (kMatchAutoFrames pooled since the last match), send it to the cameras' controls, up to
  // kMatchRounds times (node/camera_matching.h).
  bool match_cameras = false;
};

// SIGINT/SIGTERM end the run as its deadline does (the screenshot is written).
// Exit status: 0 done; 1 runtime failure (no EGL, DDS, fewer meshes than asked in time, or
// with every_s no mesh drawn; the screenshot is still written); 2 bad input.
int run_headless(const PreviewConfig& config, const HeadlessOptions& options);

}  // namespace studio::preview
