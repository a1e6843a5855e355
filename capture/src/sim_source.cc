#include "capture/pacing.h"
#include "capture/sim_source.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <thread>

#include "sim/frame_stamp.h"

namespace studio::capture {
namespace {

constexpr double kGainMax = 24.0;
constexpr double kExposureMin = 20.0;
constexpr double kRatioMin = 0.25, kRatioMax = 4.0;  // BalanceRatioRed, BalanceRatioBlue

double exposure_max(const FrameClock& clock) { return double(clock.period_ns) / 1000.0; }

// One box-blur pass of radius r along rows (horizontal) of an RGB image, in place.
void box_rows(Image<Rgb8>& img, int r, std::vector<uint16_t>& tmp) {
  const int w = img.width();
  tmp.resize(std::size_t(w) * 3);
  for (int y = 0; y < img.height(); ++y) {
    Rgb8* row = &img(0, y);
    for (int x = 0; x < w; ++x) {
      tmp[3 * x] = row[x].r;
      tmp[3 * x + 1] = row[x].g;
      tmp[3 * x + 2] = row[x].b;
    }
    for (int c = 0; c < 3; ++c) {
      int sum = 0;
      for (int k = -r; k <= r; ++k) sum += tmp[3 * std::clamp(k, 0, w - 1) + c];
      const int n = 2 * r + 1;
      for (int x = 0; x < w; ++x) {
        reinterpret_cast<uint8_t*>(&row[x])[c] = uint8_t((sum + n / 2) / n);
        sum += tmp[3 * std::min(x + r + 1, w - 1) + c] - tmp[3 * std::max(x - r, 0) + c];
      }
    }
  }
}

// Vertical pass via a transposed walk over columns (kept simple: column buffer).
void box_cols(Image<Rgb8>& img, int r, std::vector<uint16_t>& tmp) {
  const int h = img.height();
  tmp.resize(std::size_t(h) * 3);
  for (int x = 0; x < img.width(); ++x) {
    for (int y = 0; y < h; ++y) {
      tmp[3 * y] = img(x, y).r;
      tmp[3 * y + 1] = img(x, y).g;
      tmp[3 * y + 2] = img(x, y).b;
    }
    for (int c = 0; c < 3; ++c) {
      int sum = 0;
      for (int k = -r; k <= r; ++k) sum += tmp[3 * std::clamp(k, 0, h - 1) + c];
      const int n = 2 * r + 1;
      for (int y = 0; y < h; ++y) {
        reinterpret_cast<uint8_t*>(&img(x, y))[c] = uint8_t((sum + n / 2) / n);
        sum += tmp[3 * std::min(y + r + 1, h - 1) + c] - tmp[3 * std::max(y - r, 0) + c];
      }
    }
  }
}

bool same_camera(const Camera& a, const Camera& b) {
  const auto &ia = a.intrinsics, &ib = b.intrinsics;
  return ia.fx == ib.fx && ia.fy == ib.fy && ia.cx == ib.cx && ia.cy == ib.cy &&
         ia.skew == ib.skew && a.distortion.model == b.distortion.model &&
         a.distortion.rd3 == b.distortion.rd3 && a.distortion.rd5 == b.distortion.rd5 &&
         a.cam_from_world.R() == b.cam_from_world.R() &&
         a.cam_from_world.translation == b.cam_from_world.translation;
}

}  // namespace

Expected<void> SimSourceOptions::validate() const {
  if (camera.id.empty()) return fail("sim source: camera id is empty");
  if (camera.width <= 0 || camera.height <= 0)
    return fail("sim source " + camera.id + ": bad size");
  if (!clock.valid()) return fail("sim source " + camera.id + ": clock period must be > 0");
  if (!(gain_db >= 0 && gain_db <= kGainMax))
    return fail("sim source " + camera.id + ": Gain must be in 0..24 dB");
  if (!(exposure_us >= kExposureMin && exposure_us <= exposure_max(clock)))
    return fail("sim source " + camera.id + ": ExposureTime must be in 20..frame period us");
  if (!(nominal_exposure_us > 0)) return fail("sim source " + camera.id + ": bad nominal exposure");
  if (!(focus >= 0 && focus <= 1) || !(in_focus >= 0 && in_focus <= 1))
    return fail("sim source " + camera.id + ": Focus must be in 0..1");
  if (buffer_frames < 1 || buffer_frames > 64)
    return fail("sim source " + camera.id + ": buffer_frames must be in 1..64");
  if (2 * (offset_ns < 0 ? -offset_ns : offset_ns) >= clock.period_ns)
    return fail("sim source " + camera.id + ": offset must be within half a frame period (" + std::to_string(offset_ns) + " ns, period " + std::to_string(clock.period_ns) + " ns)");
  if (jitter_ns < 0 || jitter_ns > 10 * clock.period_ns)
    return fail("sim source " + camera.id + ": jitter must be in 0..10 frame periods");
  if (readout_ns < 0 || readout_ns > clock.period_ns)
    return fail("sim source " + camera.id + ": readout must be in 0..1 frame period");
  if (gamma != 0 && !(gamma >= 0.1 && gamma <= 4))
    return fail("sim source " + camera.id + ": gamma must be 0 (none) or in 0.1..4");
  if (max_blur_px < 0 || max_blur_px > 64)
    return fail("sim source " + camera.id + ": max_blur_px must be in 0..64");
  return {};
}

Expected<std::unique_ptr<SimFrameSource>> SimFrameSource::create(const SimSourceOptions& options) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  sim::StudioOptions so = options.studio;
  so.threads = 1;
  auto studio = sim::SimulatedStudio::create({options.camera}, so);
  if (!studio) return fail("sim source " + options.camera.id + ": " + studio.error().message);
  return std::unique_ptr<SimFrameSource>(new SimFrameSource(options, std::move(*studio)));
}

SimFrameSource::SimFrameSource(SimSourceOptions options, sim::SimulatedStudio studio)
    : options_(std::move(options)),
      studio_(std::move(studio)),
      gain_db_(options_.gain_db),
      exposure_us_(options_.exposure_us),
      focus_(options_.focus),
      jitter_state_(std::hash<std::string>{}(options_.camera.id)) {}

Expected<void> SimFrameSource::start() {
  std::lock_guard lock(mutex_);
  stopping_ = false;
  started_ = true;
  last_frame_.reset();
  ahead_.reset();
  return {};
}

void SimFrameSource::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
}

bool SimFrameSource::wait_until(int64_t due_ns, std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  return wait_until_realtime(lock, wake_, stopping_, due_ns, deadline);
}

Expected<std::optional<Frame>> SimFrameSource::next(std::chrono::milliseconds timeout) {
  if (!started_) return fail("sim source " + id() + ": next() before start()");
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  const FrameClock& clock = options_.clock;
  const int64_t half = clock.period_ns / 2;
  const int64_t now = realtime_ns();
  // Newest frame whose genlock instant has passed.
  const uint64_t newest = clock.frame_at(now - half);
  uint64_t f;
  uint64_t skipped = 0;
  if (!options_.paced) {
    f = last_frame_ ? *last_frame_ + 1 : clock.frame_at(now);
  } else if (!last_frame_) {
    f = newest + 1;  // the next frame to become available
  } else {
    f = *last_frame_ + 1;
    const uint64_t oldest_kept = newest + 1 >= uint64_t(options_.buffer_frames)
                                     ? newest + 1 - uint64_t(options_.buffer_frames)
                                     : 0;
    if (f < oldest_kept) {  // the camera's buffers overflowed: frames before oldest_kept are gone
      skipped = oldest_kept - f;
      f = oldest_kept;
    }
  }
  if (options_.drop_every > 0 && f % options_.drop_every == options_.drop_every - 1) {
    ++skipped;  // the camera lost this frame: the next one is delivered instead
    ++f;
  }
  const int64_t capture_ns = clock.time_of(f) + half + options_.offset_ns;
  auto ran_out = [&] {
    std::lock_guard lock(mutex_);
    stats_.drops += skipped;  // consumed even when the wait ran out
    if (skipped) last_frame_ = f - 1;
    return std::optional<Frame>();
  };
  // An untracked camera's picture depends on f alone: render it while waiting for its instant,
  // so that it is ready when the frame is due instead of one render later (kept if the wait runs
  // out). It starts half a period before the frame is due (capture_ns + the read-out), not at
  // once: after the previous frame's keying in every capture server on the machine (all run at
  // one real-time priority, where a render started early would hold up another server's keying,
  // hence its mask), and after the previous frame's hull, so that the renders of every camera on
  // the machine (a simulation cost: a real camera renders nothing) do not hold up the
  // subscribers of its mesh below the capture servers' priority (issue 20).
  const int64_t render_at = capture_ns - half + std::min(options_.readout_ns, half);
  if (options_.paced && !pose_ && !(ahead_ && ahead_->frame == f)) {
    if (!wait_until(render_at, deadline)) return ran_out();
    ahead_.emplace();
    ahead_->frame = f;
    studio_.render(0, int64_t(f), &ahead_->image, nullptr);
  }
  if (options_.paced && !wait_until(capture_ns, deadline)) return ran_out();
  if (pose_) {
    if (auto camera = pose_(f); camera && !same_camera(*camera, studio_.cameras()[0])) {
      Camera c = *camera;
      c.id = options_.camera.id;
      c.width = options_.camera.width;
      c.height = options_.camera.height;
      if (auto moved = studio_.set_camera(0, c); !moved)
        return fail("sim source " + id() + ": tracked pose: " + moved.error().message);
    }
  }
  Frame frame;
  frame.frame = f;
  frame.capture_ns = capture_ns;
  if (ahead_ && ahead_->frame == f && !pose_) {
    frame.image = std::move(ahead_->image);
  } else {
    studio_.render(0, int64_t(f), &frame.image, nullptr);
  }
  ahead_.reset();
  apply_features(frame.image);
  if (options_.stamp) sim::stamp_frame(frame.image.view(), f);
  // The camera's read-out and transfer: the frame reaches the host no earlier than this.
  if (options_.paced && options_.readout_ns > 0 &&
      !wait_until(capture_ns + options_.readout_ns, deadline + std::chrono::nanoseconds(
                                                                  options_.readout_ns)))
    return ran_out();
  if (options_.jitter_ns > 0) {  // late delivery: a driver/transport delay of its own
    jitter_state_ = jitter_state_ * 6364136223846793005ull + 1442695040888963407ull;
    std::this_thread::sleep_for(
        std::chrono::nanoseconds(int64_t((jitter_state_ >> 11) % uint64_t(options_.jitter_ns))));
  }
  last_frame_ = f;
  std::lock_guard lock(mutex_);
  stats_.frames += 1;
  stats_.drops += skipped;
  return std::optional<Frame>(std::move(frame));
}

void SimFrameSource::apply_features(Image<Rgb8>& image) {
  double gain, exposure, focus, ratio[3] = {1, 1, 1};
  {
    std::lock_guard lock(mutex_);
    gain = gain_db_;
    exposure = exposure_us_;
    focus = focus_;
    ratio[0] = ratio_red_;
    ratio[2] = ratio_blue_;
  }
  const double k = std::pow(10.0, gain / 20.0) * exposure / options_.nominal_exposure_us;
  double factor[3];  // on the delivered values, per channel
  for (int c = 0; c < 3; ++c)
    factor[c] = options_.gamma > 0 ? std::pow(k * ratio[c], options_.gamma) : k * ratio[c];
  if (std::abs(factor[0] - 1.0) > 1e-6 || std::abs(factor[1] - 1.0) > 1e-6 ||
      std::abs(factor[2] - 1.0) > 1e-6) {
    uint8_t lut[3][256];  // per channel: red, green, blue
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 256; ++i)
        lut[c][i] = uint8_t(std::clamp(std::lround(i * factor[c]), 0l, 255l));
    for (Rgb8& p : image.pixels()) {
      p.r = lut[0][p.r];
      p.g = lut[1][p.g];
      p.b = lut[2][p.b];
    }
  }
  const int r = int(std::lround(std::abs(focus - options_.in_focus) * options_.max_blur_px));
  if (r > 0) {
    box_rows(image, r, blur_row_);
    box_cols(image, r, blur_row_);
  }
}

std::vector<Feature> SimFrameSource::features() const {
  std::lock_guard lock(mutex_);
  std::vector<Feature> out{
      {"Gain", gain_db_, 0, kGainMax, true},
      {"ExposureTime", exposure_us_, kExposureMin, exposure_max(options_.clock), true},
      {"Focus", focus_, 0, 1, true},
      {"BalanceRatioRed", ratio_red_, kRatioMin, kRatioMax, true},
      {"BalanceRatioBlue", ratio_blue_, kRatioMin, kRatioMax, true}};
  if (options_.gamma > 0)
    out.push_back({"Gamma", options_.gamma, options_.gamma, options_.gamma, false});
  return out;
}

Expected<double> SimFrameSource::set_feature(std::string_view name, double value) {
  if (!std::isfinite(value))
    return fail("camera " + id() + ": feature '" + std::string(name) + "': value is not finite");
  std::lock_guard lock(mutex_);
  if (name == "Gain") return gain_db_ = std::clamp(value, 0.0, kGainMax);
  if (name == "ExposureTime")
    return exposure_us_ = std::clamp(value, kExposureMin, exposure_max(options_.clock));
  if (name == "Focus") return focus_ = std::clamp(value, 0.0, 1.0);
  if (name == "BalanceRatioRed") return ratio_red_ = std::clamp(value, kRatioMin, kRatioMax);
  if (name == "BalanceRatioBlue") return ratio_blue_ = std::clamp(value, kRatioMin, kRatioMax);
  return fail("camera " + id() + ": feature '" + std::string(name) + "' is not available");
}

bool SimFrameSource::follow_pose(PoseOfFrame pose) {
  pose_ = std::move(pose);
  return true;
}

SourceStats SimFrameSource::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace studio::capture
