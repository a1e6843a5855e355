#pragma once
// A real GenICam camera (GigE Vision / USB3 Vision) through Aravis 0.8, behind FrameSource.
//
// open() finds the device by its Aravis id (e.g. "Basler-21234567", an IP address, or the fake
// cameras "Fake_1" / "Aravis-Fake-GV01"), configures pixel format, size, frame rate and trigger,
// reads the configuration back (a value the camera does not accept is an error, never silently
// changed), and allocates a pool of `buffers` stream buffers of one payload each.
//
// Streaming: next() pops completed buffers, converts them to RGB8 (Mono8 → grey, RGB8 → copy,
// Bayer RG/GR/GB/BG 8 → RGB by OpenCV's bilinear demosaic) and returns them to the pool.
// Camera time: capture_ns is the camera's own timestamp of the frame mapped to the host clock
// (CLOCK_REALTIME) by a CameraTimeLatch (capture/camera_time.h): seeded by a GenICam latch
// (TimestampLatch + TimestampLatchValue, or GevTimestampControlLatch + GevTimestampValue, with
// GevTimestampTickFrequency) when the camera has one, refined by every frame's arrival. A camera
// that stamps nothing (timestamp 0), or `camera_time: false`, falls back to the host arrival
// time (Aravis' system timestamp); time_source() says which (TimeSource::camera or
// host_arrival). frame = clock.frame_at(capture_ns) (DESIGN §5).
//
// Software trigger: with TriggerMode::software and `clock_trigger` (the default) a trigger
// thread fires TriggerSoftware at every studio frame, half a period after the frame's start
// (clock.time_of(f) + period/2, CLOCK_REALTIME, absolute sleeps), so the camera delivers exactly
// one frame per studio frame, in step with the studio clock, like a genlocked camera.
// clock_trigger false leaves the triggering to software_trigger() calls.
// Drops = stream underruns (a frame arrived while no buffer was free: consumer too slow or pool
// too small) + buffers completed with an error status (missing packets, timeout, size mismatch)
// + frames that could not be converted.
//
// Disappearance: the device is declared lost when Aravis reports "control-lost" (GigE
// heartbeat) or when, after `lost_after` without any buffer, a register read fails. Then
// stats().connected becomes false (and on_state is called), next() returns nullopt while it
// re-opens the device by id with exponential back-off (retry_initial doubling up to retry_max),
// and on success re-applies the configuration, restarts acquisition, counts a reconnect and
// resumes.
//
// Threading: start()/next() from one thread; stop(), stats(), features() and set_feature() may
// be called from others. No GLib main loop is needed.

#include <chrono>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "capture/frame_clock.h"
#include "capture/frame_source.h"
#include "core/error.h"
#include "core/image.h"

namespace studio::capture {

enum class CameraPixelFormat { keep, mono8, rgb8, bayer_rg8, bayer_gr8, bayer_gb8, bayer_bg8 };
// GenICam CameraPixelFormat names: "Mono8", "RGB8", "BayerRG8", "BayerGR8", "BayerGB8", "BayerBG8";
// "" or "keep" = leave the camera's current format.
Expected<CameraPixelFormat> parse_pixel_format(std::string_view name);
const char* genicam_name(CameraPixelFormat format);

// Converts one tightly packed image in a GenICam layout to RGB8. Bayer names give the colours of
// the first two pixels of the first row (BayerRG8: R G / G B). Fails with one line when the data
// is shorter than the format needs or the format is `keep`.
Expected<Image<Rgb8>> convert_to_rgb(CameraPixelFormat format, std::span<const uint8_t> data,
                                     int width, int height);

enum class TriggerMode { free_run, software, line };

struct AravisOptions {
  std::string device_id;  // Aravis device id; empty = the first device found
  std::string camera_id;  // studio camera id; empty = the device id
  CameraPixelFormat pixel_format = CameraPixelFormat::keep;
  int width = 0, height = 0;  // 0 keeps the camera's current size (region at offset 0, 0)
  double frame_rate = 0;      // frames per second in free run; 0 keeps the camera's
  TriggerMode trigger = TriggerMode::free_run;
  std::string trigger_line = "Line0";  // TriggerSource for TriggerMode::line
  bool clock_trigger = true;           // software trigger fired at the studio clock (above)
  bool camera_time = true;             // the camera's timestamps when it has them (above)
  int buffers = 16;                    // stream buffer pool, 2..256 (a 600 ms stall at 25 fps)
  FrameClock clock;
  std::chrono::milliseconds retry_initial{250};
  std::chrono::milliseconds retry_max{4000};
  std::chrono::milliseconds lost_after{2000};  // silence before probing the device
  // Aravis interfaces to use ("Fake", "GigEVision", "USB3Vision"); empty = Aravis' defaults.
  // A process-wide setting of Aravis, applied by open(); tests use {"Fake"} so that no
  // discovery packet is sent on any network.
  std::vector<std::string> interfaces;
  // Called from next()'s thread whenever `connected` changes.
  std::function<void(const SourceStats&)> on_state;

  Expected<void> validate() const;
};

// Ids of the devices Aravis finds on the given interfaces (empty = defaults).
std::vector<std::string> list_aravis_devices(const std::vector<std::string>& interfaces = {});

class AravisSource : public FrameSource {
 public:
  // Opens and configures the device; fails with one line when it is absent or refuses a setting.
  static Expected<std::unique_ptr<AravisSource>> open(const AravisOptions& options);
  ~AravisSource() override;
  AravisSource(const AravisSource&) = delete;
  AravisSource& operator=(const AravisSource&) = delete;

  const std::string& id() const override;
  Expected<void> start() override;
  void stop() override;
  Expected<std::optional<Frame>> next(std::chrono::milliseconds timeout) override;
  // Gain, ExposureTime (µs), AcquisitionFrameRate, and any of BlackLevel, Gamma, Focus, Zoom,
  // Iris the camera implements; BalanceRatioRed / BalanceRatioBlue where it has SFNC's
  // BalanceRatioSelector + BalanceRatio (Aravis's fake camera has not; capture_gv_test extends
  // its description with them). Empty while disconnected.
  std::vector<Feature> features() const override;
  Expected<double> set_feature(std::string_view name, double value) override;
  SourceStats stats() const override;
  TimeSource time_source() const override;

  // Software triggers fired by the clock trigger thread (and by software_trigger()).
  uint64_t triggers() const;
  // TriggerMode::software: one frame per call.
  Expected<void> software_trigger();

  // The configuration read back from the device at the last (re)connection.
  struct Config {
    std::string pixel_format;
    int width = 0, height = 0;
    double frame_rate = 0;
    std::string vendor, model, serial;
    unsigned payload_bytes = 0;
  };
  Config config() const;

 private:
  struct Impl;
  explicit AravisSource(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::capture
