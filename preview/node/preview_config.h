#pragma once
// preview.yaml (studio-preview --config): the keys, their defaults and the reader.
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "preview/overlays.h"
#include "preview/viewpoint.h"

namespace studio::preview {

struct PreviewConfig {
  // Common keys (as every service reads them, runtime/service.h).
  std::string instance = "preview";
  int64_t domain = -1;  // -1: $STUDIO_DDS_DOMAIN, else Cyclone's default
  std::string dds_config;
  std::string log;
  // The preview's own.
  Viewpoint viewpoint;             // start view
  int width = 1280, height = 720;  // window / screenshot size
  bool blend = true;               // texturing: blend (true) or nearest
  int blend_cameras = 3;           // 1..3
  int wait_ms = 200;               // wait for a new mesh's images, then draw it untextured
  std::string asset_root;          // relative asset paths of scene nodes resolve here
  std::string take = "take";       // the capture panel's default take name
  OverlayOptions overlays;         // head marker, frusta, projector screens in the 3D view
  bool carve_masks = true;         // blend: carve against every camera's mask of the frame
  bool colour_balance = true;      // the cameras' colour balance (preview/rig_balance.h)
  int colour_balance_every = 4;    // pool one textured mesh in this many into it
  double colour_balance_rig_s = 0.5;  // pool every camera's images of one mesh this often (0: off)
  Expected<void> validate() const;
};

inline constexpr const char* kConfigHelp =
    "preview.yaml keys (all optional):\n"
    "  instance: director            name of this preview (image requests carry it)\n"
    "  domain: 0                     DDS domain (default $STUDIO_DDS_DOMAIN)\n"
    "  dds_config: FILE              Cyclone XML profile (default $CYCLONEDDS_URI)\n"
    "  log: info                     log levels, e.g. info,preview=debug\n"
    "  viewpoint: \"eye=0,1.6,5,at=0,1,0,fov=50\"   start view (studio frame, metres)\n"
    "  size: [1280, 720]             window / screenshot size in pixels\n"
    "  texturing: blend              blend (up to 3 cameras, visibility) or nearest (the paper's)\n"
    "  blend_cameras: 3              cameras the blend uses, 1..3\n"
    "  wait_ms: 200                  wait this long for a new mesh's frame-exact images, then\n"
    "                                draw it untextured (counted)\n"
    "  asset_root: DIR               relative asset paths of scene nodes resolve here\n"
    "  take: take                    the capture panel's default take name\n"
    "  carve_masks: true             blend: carve the hull per pixel against every camera's\n"
    "                                actor mask of the mesh's frame (studio/camera/mask), not\n"
    "                                only the three texturing cameras' keys\n"
    "  colour_balance: true          draw each camera's image with its colour gains, estimated\n"
    "                                from the surface points two texturing cameras both see\n"
    "                                (a real rig's cameras differ by a few percent per channel:\n"
    "                                seams in the blend); gains stay 1 while every camera is\n"
    "                                within 5 % of the rig\n"
    "  colour_balance_every: 4       pool one textured mesh in this many into the estimate\n"
    "                                (4-10 ms of CPU each, on a thread of its own)\n"
    "  colour_balance_rig_s: 0.5     this often, pool the images of one mesh from every\n"
    "                                camera, so that the estimate (and Match cameras) covers\n"
    "                                the whole rig, not only the cameras near this view\n"
    "                                (0: off)\n"
    "  head_marker: true             the tracked head (studio/actor/head): a yellow sphere,\n"
    "                                its velocity (orange) and sight lines to each screen\n"
    "  camera_frusta: true           each studio camera's frustum (cyan, from\n"
    "                                studio/camera/calibration)\n"
    "  camera_frustum_m: 0.5         depth at which camera frusta are cut (metres)\n"
    "  projector_frusta: true        each projector's frustum to its screen (magenta, from\n"
    "                                studio/projector/calibration)\n"
    "  projector_screens: true       each screen textured with what its projector shows (the\n"
    "                                latest thumbnail on studio/projector/frame, projected\n"
    "                                through the projector's K [R | t])\n";

// Defaults when path is empty. Errors: "file:line: field: problem".
Expected<PreviewConfig> read_preview_config(const std::string& path);

}  // namespace studio::preview
