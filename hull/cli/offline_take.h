#pragma once
// A recorded take read for the offline refinement (studio-hull offline --refine/--texture): per
// frame, every camera's colour image (RGB8 frames of capture/take.h) and its silhouette, keyed on
// the fly. Frames are matched across cameras by frame number; every camera must hold every frame
// of the selection (one-line errors otherwise, as cli/frame_input.h).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "core/run_mask.h"
#include "keyer/keyer_options.h"

namespace studio::hull::cli {

struct ColourFrame {
  std::vector<Image<Rgb8>> images;  // rig order
  std::vector<RunMask> masks;
};

class ColourTake {
 public:
  // `all_frames`: every frame number recorded by every camera (the whole take, whatever the
  // selection: a shard writes the index only when the whole take is done).
  static Expected<std::unique_ptr<ColourTake>> open(const std::string& dir,
                                                    const std::vector<Camera>& cameras,
                                                    const keyer::KeyerOptions& key, int slots);
  ~ColourTake();
  const std::vector<uint64_t>& all_frames() const;
  // Frame `frame` (a number of all_frames()); calls with different slots may run concurrently.
  // read_ms / key_ms accumulate the time of each stage.
  Expected<void> load(uint64_t frame, int slot, ColourFrame& out, double& read_ms, double& key_ms);

 private:
  struct Impl;
  explicit ColourTake(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::hull::cli
