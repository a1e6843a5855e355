#pragma once
// A simulated camera behind the FrameSource interface (libcamera's fake camera): one camera of the
// simulated studio (sim/studio.h), paced by the studio clock (capture/frame_clock.h) in
// real time like a genlocked camera, with simulated GenICam features.
//
// Timing (paced): frame f is exposed at the genlock instant clock.time_of(f) + period/2 and
// becomes available then; capture_ns is that instant, so every SimFrameSource in every process
// gives the same instant the same frame number. next() delivers the frame after the previous one,
// immediately if it is already due: like a streaming camera with `buffer_frames` buffers, a
// consumer that fell behind by up to buffer_frames frames gets every frame, in order. Beyond that
// the oldest frames are overwritten: they are skipped and counted as drops. The first frame after
// start() is the next one to become available. Unpaced: consecutive frames from the
// current one, as fast as next() is called (tests, offline).
// The picture of frame f is SimulatedStudio::render(camera, f): frame numbers are the studio's, so
// all cameras (and processes) show the actor in the same pose at the same frame.
//
// Features (GenICam names; set_feature clamps to the range and returns the read-back value):
//   Gain          dB, 0..24            image *= 10^(Gain/20)
//   ExposureTime  µs, 20..period       image *= ExposureTime / nominal_exposure_us
//   Focus         0..1                 box blur of radius round(|Focus - in_focus| * max_blur_px)
//   BalanceRatioRed, BalanceRatioBlue  0.25..4   red / blue *= the ratio (white balance against
//                                      green; SFNC's BalanceRatio under BalanceRatioSelector)
//   Gamma         read-only, when options.gamma > 0: the camera's transfer curve (delivered =
//                 sensor^Gamma). Its Gain, ExposureTime and white balance then act before it, on
//                 the sensor's linear signal, as a real camera's do: a control's factor f scales
//                 the delivered values by f^Gamma. Without it (0) they scale the delivered values.
// Tracked (follow_pose): before rendering frame f the source asks for its camera; a changed
// camera rebuilds the simulated camera's cached rays and background (SimulatedStudio::set_camera).
// Imperfections on request: `offset_ns` moves the exposure instant (capture_ns) within the
// frame, `jitter_ns` delays each delivery by a pseudo-random amount (seeded by the camera id),
// `drop_every` loses frames like a camera dropping packets (they count in stats().drops), and
// `stamp` writes the frame number into the corner (sim/frame_stamp.h) after the features.
// Brightness is applied through a 256-entry table (saturating), blur as two separable box passes.
// Paced and untracked, the picture of the next frame is rendered in the half period before it is
// due (capture_ns + readout_ns, the read-out capped at half a period; it depends on the frame
// number alone) and delivered then: the image is ready when due, not one render (2-5 ms of CPU at
// 704x576) after it, and the render competes neither with the previous frame's keying nor with
// the hull's work on it. Never delivered early.
// `readout_ns` models what a real camera adds between the exposure instant and the frame reaching
// the host (the rest of the exposure, sensor read-out, link transfer): the frame is delivered no
// earlier than capture_ns + readout_ns. 0 (the library default) is an ideal camera; the capture
// service's config default is a GigE camera's (capture_config: readout_us: auto).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>

#include "capture/frame_clock.h"
#include "capture/frame_source.h"
#include "sim/studio.h"

namespace studio::capture {

struct SimSourceOptions {
  Camera camera;              // id, size, intrinsics and pose of the simulated camera
  sim::StudioOptions studio;  // the scene (actor motion, realism knobs); threads forced to 1
  FrameClock clock;
  bool paced = true;
  // 1 .. 64. 16, as an Aravis stream's default pool (aravis_source.h `buffers`): a consumer held
  // up for up to 15 frame periods (600 ms at 25 fps: a host stall) catches up with every frame.
  // 8 lost 31 masks of a 0.5 s stall of the six capture servers in the demo (BENCHMARKS.md,
  // demo, session 19); a take recorded through such a stall keeps every frame.
  int buffer_frames = 16;
  double gain_db = 0;
  double exposure_us = 10000;
  double nominal_exposure_us = 10000;  // exposure at which the image has its natural brightness
  double focus = 0.5;
  double in_focus = 0.5;  // the Focus value that gives a sharp image
  double gamma = 0;       // > 0 (0.1..4): the GenICam Gamma published (read-only), above
  int max_blur_px = 8;
  // Test knobs of a real camera's imperfections (issue 17 item 6):
  bool stamp = false;         // the frame number as a corner code in the pixels (sim/frame_stamp.h)
  int64_t offset_ns = 0;      // genlock offset of this camera's exposure, |offset| < period/2
  int64_t jitter_ns = 0;      // delivery delayed by a uniform 0..jitter (driver/transport)
  int64_t readout_ns = 0;     // delivered no earlier than capture_ns + readout_ns (0..1 period)
  uint64_t drop_every = 0;    // frames f with f % drop_every == drop_every-1 are lost (counted)
  Expected<void> validate() const;
};

class SimFrameSource : public FrameSource {
 public:
  static Expected<std::unique_ptr<SimFrameSource>> create(const SimSourceOptions& options);

  const std::string& id() const override { return options_.camera.id; }
  Expected<void> start() override;
  void stop() override;
  Expected<std::optional<Frame>> next(std::chrono::milliseconds timeout) override;
  std::vector<Feature> features() const override;
  Expected<double> set_feature(std::string_view name, double value) override;
  SourceStats stats() const override;
  TimeSource time_source() const override { return TimeSource::studio_clock; }
  // A tracked simulated camera: frame f is rendered from pose(f) (its intrinsics and pose; the
  // id and size stay), so its image and true mask agree with the tracker's calibration.
  bool follow_pose(PoseOfFrame pose) override;

  const sim::SimulatedStudio& studio() const { return studio_; }

 private:
  SimFrameSource(SimSourceOptions options, sim::SimulatedStudio studio);
  bool wait_until(int64_t due_ns, std::chrono::steady_clock::time_point deadline);
  void apply_features(Image<Rgb8>& image);

  SimSourceOptions options_;
  sim::SimulatedStudio studio_;
  PoseOfFrame pose_;
  std::optional<uint64_t> last_frame_;
  bool started_ = false;

  mutable std::mutex mutex_;  // features, stats, stopping_
  std::condition_variable wake_;
  bool stopping_ = false;
  double gain_db_, exposure_us_, focus_;
  double ratio_red_ = 1, ratio_blue_ = 1;  // BalanceRatioRed, BalanceRatioBlue
  SourceStats stats_;
  std::vector<uint16_t> blur_row_;
  struct Ahead {
    uint64_t frame = 0;
    Image<Rgb8> image;
  };
  std::optional<Ahead> ahead_;  // paced, untracked: the next frame, rendered before its instant
  uint64_t jitter_state_ = 0;
};

}  // namespace studio::capture
