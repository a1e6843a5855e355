#pragma once
// The control panel's windows (TCSVT 2004 §II), drawn with Dear ImGui over the 3D view:
//   Cameras    per camera the allow-listed features (Gain, ExposureTime, Focus, Zoom, Iris,
//              BalanceRatioRed, BalanceRatioBlue) as
//              sliders over their published ranges; a released slider sends CameraControl; the
//              read-back value (studio/camera/state) beside it.
//   Capture    take name, start / stop at a frame (CaptureCommand), per camera recording, take,
//              fps and drops.
//   Animation  play, pause, seek, speed (SceneCommand), move a node.
//   Services   every service seen on studio/service/status: state, rates, latency; one that
//              stopped reporting (lease expired or silent for 3 s) or failed is drawn in red.
//   View       texturing (blend / nearest), the colour balance (estimate per camera; "Match
//              cameras" sends it to the cameras' Gain and white balance), counts of textured and
//              untextured meshes, the overlays' switches (head marker, camera frusta, projector
//              frusta, projector screens), bookmarks, a keyframed camera move.
//   Projectors every projector seen on studio/projector/calibration or /frame: its latest
//              thumbnail (what it shows), render frame, mesh frame, latency and margin.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "preview/viewpoint.h"
#include "preview_node.h"
#include "view_pipeline.h"

namespace studio::preview {

struct ItemRect {
  float x = 0, y = 0, w = 0, h = 0;
  double value = 0;
};

struct PanelState {
  bool cameras = false, capture = false, animation = false, services = false, view = true,
       projectors = false;
  std::map<std::string, double> edits;     // "cam/feature" → the slider's value
  std::map<std::string, double> scripted;  // "cam/feature" → value to apply next frame
  char take[64] = "take";
  long long at_frame = 0;
  double seek_s = 0, speed = 1;
  char node[64] = "";
  float move[3] = {0, 0, 0};
  char bookmark[64] = "a";
  Bookmarks bookmarks;
  std::vector<MoveKey> keys;
  std::optional<CameraMove> move_playing;
  double move_start_s = 0;
  std::string last_error;
  std::string match_result;  // View: the last "Match cameras" (what was sent, or why not)
  std::string match_source;  // View: what the button sends now (the whole rig's or the view's)
  bool press_match = false;  // the test hook's press of "Match cameras"
  // Filled while drawing, for the test hook's layout file.
  std::map<std::string, ItemRect> windows, items;
};

// Draws the open panels; may change `view` (bookmarks, camera moves). now_s: seconds since start.
void draw_panels(PanelState& state, PreviewNode& node, ViewPipeline& pipeline, Viewpoint& view,
                 double now_s);

}  // namespace studio::preview
