#pragma once
// The preview's DDS side (issue 16), a runtime::Node on runtime::ServiceLoop: it mirrors what
// the preview draws and shows, and sends what its panels command.
//
//   in:  studio/scene/node (keyed, transient-local; disposals remove) → a scene::Scene mirror
//        studio/actor/mesh → the newest mesh per actor with its source frame
//        studio/camera/calibration → cameras;  studio/camera/state → the camera panel
//        studio/camera/image_reply → frame-exact camera images (only replies to this requester)
//        studio/camera/mask → every camera's actor mask of the last kKeptMaskFrames frames
//        (the blend carves the hull against all of them, frame-exactly)
//        studio/service/status → the services panel
//        studio/actor/head, studio/projector/calibration, studio/projector/frame → the overlays
//        (overlay_inputs.h)
//   out: studio/camera/image_request, studio/camera/control, studio/capture/command,
//        studio/scene/command
//
// Frame-exact texturing (the paper's way): for a mesh built from the masks of frame F the
// preview requests the images of (camera, F) of the cameras it will texture from; the capture
// servers answer from their rings (capture/node/image_ring.h). images() returns them only when
// every one of exactly frame F has arrived (preview/frame_images.h keeps the books); the caller
// waits briefly or draws untextured.
//
// Threads: the handlers run on the loop thread; every public method is thread-safe (one mutex).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <expected>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/run_mask.h"
#include "overlay_inputs.h"
#include "preview/frame_images.h"
#include "runtime/service_loop.h"
#include "scene/actor_mesh.h"
#include "scene/scene.h"

namespace studio::preview {

struct LiveMesh {
  scene::ActorMesh mesh;
  uint64_t source_frame = 0;
  int64_t capture_ns = 0;
  uint64_t sequence = 0;  // increases with every mesh received
};

struct CameraFeatureView {
  std::string name;
  double value = 0, min = 0, max = 0;
};
struct CameraStateView {
  std::string camera_id;
  uint64_t frame = 0;
  double fps = 0;
  uint64_t drops = 0;
  bool recording = false;
  std::string take, error;
  int state = 0;  // studio_CameraRunState
  std::vector<CameraFeatureView> features;
};
struct ServiceView {
  std::string service, instance;
  int state = 0;  // studio_ServiceState
  double input_hz = 0, output_hz = 0, latency_ms = 0;
  std::chrono::steady_clock::time_point seen;
  bool alive = true;  // false once its liveliness lease expired (disposed / no writers)
};

class PreviewNode : public runtime::Node {
 public:
  PreviewNode(runtime::NodeContext& context, std::string requester);
  ~PreviewNode() override;
  Expected<void> start() override;
  void stop() override;
  runtime::NodeHealth health() override;

  // Snapshots (copies) for the render and GUI thread.
  std::map<std::string, Camera> cameras() const;
  const OverlayInputs& overlays() const;  // heads, projectors and their thumbnails
  std::optional<LiveMesh> mesh_after(uint64_t sequence) const;  // newest, if newer than sequence
  uint64_t mesh_sequence() const;                               // of the newest mesh (0: none yet)
  // The scene mirror, rebuilt when it changed since `version` (nullopt: unchanged).
  std::optional<scene::Scene> scene_after(uint64_t& version) const;
  std::vector<CameraStateView> camera_states() const;
  std::vector<ServiceView> services() const;

  // Requests the images of `frame` from the named cameras (those not already here).
  void request_images(uint64_t frame, const std::vector<std::string>& cameras);
  // Called on the loop thread for every new mesh (its source frame and the centre of its
  // bounds), outside the node's lock: the cameras whose images to request at once (the
  // renderer's choice for its current viewpoint), so the request does not wait for the next
  // drawn frame (the capture rings keep one second). Empty function: none.
  using Prefetch =
      std::function<std::vector<std::string>(uint64_t frame, const Eigen::Vector3d& centre)>;
  void set_prefetch(Prefetch prefetch);
  // The images of exactly `frame` of every named camera, once all have arrived; waits up to
  // `wait`. Missing: `refused` (a capture server answered EVICTED or NOT_YET) or late (no reply
  // yet).
  // The actor masks of exactly `frame` that arrived (camera id → mask; cameras whose mask of
  // that frame was lost or is older than the kept frames are absent).
  std::map<std::string, RunMask> masks(uint64_t frame) const;
  using Missing = FrameImageStore::Missing;
  std::expected<std::vector<FrameImage>, Missing> images(uint64_t frame,
                                                         const std::vector<std::string>& cameras,
                                                         std::chrono::milliseconds wait);

  // Without waiting: every named camera answered `frame` (image here or refused), and the
  // images of it that are here (a rig-wide request pools whichever came).
  bool images_answered(uint64_t frame, const std::vector<std::string>& cameras) const;
  std::vector<std::pair<std::string, FrameImage>> images_here(
      uint64_t frame, const std::vector<std::string>& cameras) const;

  Expected<void> send_control(const std::string& camera, const std::string& feature, double value);
  Expected<void> send_capture(const std::string& take, bool start, uint64_t at_frame);
  // SceneCommand verbs PLAY, PAUSE, SEEK (value seconds), SPEED (value factor), MOVE_NODE
  // (target, translation).
  Expected<void> send_scene(int verb, const std::string& target, double value,
                            const Eigen::Vector3d& translation = Eigen::Vector3d::Zero());

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::preview
