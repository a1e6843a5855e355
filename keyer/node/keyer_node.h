#pragma once
// The standalone keyer service (issue 4 item 3, `studio-keyer --config keyer.yaml`), for setups
// where keying runs on another machine than capture: subscribes studio/camera/image, keys every
// raw RGB8 CameraImage of the configured cameras (or of every camera seen) with the keyer library
// and publishes studio/camera/mask (AlphaMask, mask codec bytes) with the image's camera_id,
// frame and capture_ns. The capture node then runs with `masks: false` and
// `image: {rate: 1000, raw: true}` (every frame, raw).
//
// Runs on runtime::ServiceLoop (runtime/service_loop.h). Bounded work: the loop thread copies each accepted image into its camera's single "newest
// frame" slot; keying threads take whichever camera has a frame waiting. A frame replaced in its
// slot before a keying thread got to it is counted as dropped, so a node that falls behind
// drops frames (and says so) instead of queueing them.
//
// Rejections are counted, never fatal (counters in studio/service/status):
//   images_rejected        total of the reasons below (rejected_<reason>)
//   rejected_malformed     samples the wire validator refused (sizes inconsistent, bad id, ...)
//   rejected_format        MONO8 and JPEG images (the chroma and difference keys need colour
//                          pixels; the capture node sends raw RGB8 with `image.raw: true`)
//   rejected_keyer         the keyer refused the frame (difference key: size differs from the
//                          camera's clean plate)
//   rejected_cameras       camera ids beyond max_cameras (when keying every camera seen)
// Other counters: images_in, masks_published, frames_dropped, frames_unkeyed (difference key
// before a clean plate exists), plates_captured, controls_rejected, frames_missed (frame numbers
// skipped between a camera's images: lost in transport before the node saw them, or never sent
// when the capture node's image.rate is below the frame rate; at most 1000 per gap).
//
// Difference key: one clean plate per camera, loaded from a file given in the config
// (`plates: {cam0: plate0.png}`), or captured on command: CameraControl on studio/camera/control
// with feature "KeyerPlate" and value N >= 1 averages the camera's next N frames into a new plate
// (those frames are not keyed); value 0 clears the plate.
//
// Config keys (the common service keys are read by runtime::service_main):
//   keyer: {...} | FILE        keyer options, the schema of keyer/keyer.example.yaml: either the
//                              `keyer:` section of this file or the path of a keyer.yaml
//   cameras: [cam0, cam1]      camera ids to key (default: every camera seen)
//   max_cameras: 16            limit of cameras keyed when `cameras` is not given (1..64)
//   threads: 1                 keying threads (1..16); one camera is keyed by one thread at a time
//   plates: {cam0: FILE}       clean plates (PNG/JPEG, the camera's frame size), relative to this
//                              file (only with `key: difference`)
//   plate_dir: DIR             keep plates captured on command as DIR/<camera>.png and load them
//                              at start (a restarted node keys at once: with the actor on set a
//                              clean plate cannot be shot again); `plates:` entries come first;
//                              KeyerPlate 0 removes the file. Created if missing. Failed saves
//                              are counted (plate_saves_failed) and logged.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "keyer/keyer_options.h"
#include "runtime/service.h"

namespace studio::keyer {

struct KeyerNodeOptions {
  KeyerOptions keyer;
  std::vector<std::string> cameras;         // empty: every camera seen (up to max_cameras)
  int max_cameras = 16;
  int threads = 1;
  std::map<std::string, std::string> plates;  // clean plate files by camera id (resolved paths)
  std::string plate_dir;                      // empty: plates on command are not kept

  Expected<void> validate() const;
};

runtime::ServiceDefinition keyer_service_definition();

// Reads the node's keys of the service config (the common keys are service_main's).
Expected<KeyerNodeOptions> read_keyer_node_options(yaml::MapReader& config);

// Builds the node (reads the plate files) — exposed for tests that host the node in-process.
Expected<std::unique_ptr<runtime::Node>> make_keyer_node(KeyerNodeOptions options,
                                                         runtime::NodeContext& context);

}  // namespace studio::keyer
