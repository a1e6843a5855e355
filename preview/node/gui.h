#pragma once
// studio-preview's window (GLFW + Dear ImGui, OpenGL 3.3 core): the 3D view over the whole
// window, orbit with the left mouse button, pan with the right, zoom with the wheel, fly with
// W/A/S/D/Q/E; the panels of panels.h over it.
//
// Test hook (--test-script FILE): one action per line, run in order between frames, so a test
// drives the real window and its panels exactly as a user's edit would:
//   wait_meshes N            until N meshes were drawn (30 s at most)
//   wait SECONDS
//   open PANEL               cameras | capture | animation | services | view | projectors
//   set CAMERA FEATURE VALUE the camera panel's slider of FEATURE takes VALUE as if dragged
//                            there: the panel sends CameraControl
//   press match_cameras      the View panel's "Match cameras" button (the panel must be open)
//   viewpoint V              eye=X,Y,Z,at=X,Y,Z[,fov=DEG]
//   screenshot PNG           the window as drawn, plus PNG.json: {"windows": {title: [x, y, w,
//                            h]}, "items": {"CAMERA/FEATURE": [x, y, w, h, value],
//                            "projector/ID": [x, y, w, h, render frame], "View/Match
//                            cameras": [x, y, w, h, 0]}, "view": {"meshes": N, "textured": N,
//                            "match": the button's last result}} (top-left origin, pixels)
//   quit
#include <string>

#include "preview_config.h"

namespace studio::preview {

int run_gui(const PreviewConfig& config, const std::string& script_path);

}  // namespace studio::preview
