#pragma once
// Free-D over UDP and the decorator that gives frames of any FrameSource their per-frame
// calibration from it.
//
// FreeDListener: one UDP socket (default port 40000) and one thread. Every datagram is decoded
// with decode_freed() and stamped with its arrival time (CLOCK_REALTIME ns). Matching is by TIME,
// not by arrival order: a packet arriving during studio frame a (clock.frame_at(arrival)) holds
// the pose of frame a - delay_frames of its camera id (trackers are genlocked and send one D1
// per video frame; delay_frames is the tracker's lag). Rejected datagrams are counted by reason:
// malformed (wrong length, unknown type, bad checksum), an id no camera here tracks
// (unknown_id; with a shared port every process sees every tracker and keeps its own ids), a
// packet for a frame already delivered (too_late), a second packet for one frame (duplicate: the
// first one counts). Destruction stops the thread promptly (self-pipe).
//
// Port sharing: with `shared: true` (or a multicast `group`) the socket sets SO_REUSEADDR, so
// several capture processes on one host bind the same port; Linux gives every such socket a
// copy of each BROADCAST or MULTICAST datagram (a unicast datagram goes to one socket only, so
// a unicast tracker needs one port per process). Without `shared` a second bind fails.
//
// TrackedSource: wraps a FrameSource; frame f gets freed_to_camera() of its tracker's packet for
// frame f as Frame::calibration, waiting for it until the end of the frame window in which it
// may still arrive (clock.time_of(f + delay_frames + 1) + grace). Frames without one pass
// through without a calibration and are counted (untracked()). A source that synthesises its
// pictures (the simulated camera, FrameSource::follow_pose) renders frame f from that same pose,
// so images, masks and calibration agree.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "capture/frame_clock.h"
#include "capture/frame_source.h"
#include "capture/freed.h"
#include "core/error.h"

namespace studio::capture {

struct FreeDListenerOptions {
  std::string bind_address = "0.0.0.0";  // IPv4 address to bind; "127.0.0.1" in tests
  uint16_t port = kFreeDDefaultPort;     // 0 = any free port (see FreeDListener::port())
  std::size_t history = 64;              // packets kept per camera id for matching by time
  bool shared = false;                   // SO_REUSEADDR: share the port (broadcast/multicast)
  std::string group;                     // IPv4 multicast group to join ("" = none; implies shared)
  FrameClock clock;                      // studio clock: arrival time -> frame

  Expected<void> validate() const;
};

struct FreeDSample {
  FreeDPacket packet;
  int64_t arrival_ns = 0;  // CLOCK_REALTIME when the datagram was read
  uint64_t frame = 0;      // the video frame it belongs to: frame_at(arrival) - delay_frames
};

struct FreeDListenerStats {
  uint64_t datagrams = 0;  // every datagram read
  uint64_t accepted = 0;
  std::array<uint64_t, kFreeDRejectCount> rejected{};  // indexed by FreeDReject
  uint64_t rejected_total() const {
    uint64_t n = 0;
    for (uint64_t r : rejected) n += r;
    return n;
  }
};

class FreeDListener {
 public:
  // Binds the socket and starts the receive thread; fails with one line (bad address, port in
  // use, ...).
  static Expected<std::unique_ptr<FreeDListener>> create(const FreeDListenerOptions& options);
  ~FreeDListener();
  FreeDListener(const FreeDListener&) = delete;
  FreeDListener& operator=(const FreeDListener&) = delete;

  uint16_t port() const;  // the bound port
  const FreeDListenerOptions& options() const;
  // Takes the packets of `freed_id` (tracker lag `delay_frames` >= 0). Once any id is tracked,
  // packets of the others are rejected as unknown_id; before, every id is kept (tests, tools).
  void track(uint8_t freed_id, int delay_frames);
  bool tracks(uint8_t freed_id) const;
  std::optional<FreeDSample> latest(uint8_t freed_id) const;
  // The packet of `freed_id` for video frame `frame`; waits for it until CLOCK_REALTIME reaches
  // until_ns (nullopt then).
  std::optional<FreeDSample> wait_frame(uint8_t freed_id, uint64_t frame, int64_t until_ns) const;
  // Frame `frame` of `freed_id` was delivered: later packets for it or earlier ones are too_late.
  void delivered(uint8_t freed_id, uint64_t frame);
  FreeDListenerStats stats() const;
  // Blocks until `accepted + rejected_total()` reaches `count` or the timeout expires; returns
  // whether it did (for tests and start-up checks).
  bool wait_for_datagrams(uint64_t count, std::chrono::milliseconds timeout) const;

  // The per-datagram path of the receive thread (public so that it can be exercised without a
  // socket): decode, count, keep.
  void handle_datagram(std::span<const uint8_t> bytes, int64_t arrival_ns);

 private:
  struct State;
  explicit FreeDListener(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

struct TrackedSourceOptions {
  FreeDCameraOptions camera;
  FrameClock clock;
  int delay_frames = 0;      // the tracker's data for frame f arrives during frame f + delay
  int64_t grace_ns = -1;     // waited past that frame's end for a late packet; -1 = period / 4
  int64_t silent_ns = 500'000'000;  // no packet for this long: the tracker is silent

  Expected<void> validate() const;
};

struct TrackingStatus {
  bool silent = true;         // no packet of this camera's id for silent_ns (or never)
  double since_s = -1;        // seconds since the last packet (-1: never)
  uint64_t untracked = 0;     // frames delivered without a calibration
};

class TrackedSource : public FrameSource {
 public:
  // `inner` and `listener` must be non-null; options must have passed validate().
  TrackedSource(std::unique_ptr<FrameSource> inner, std::shared_ptr<FreeDListener> listener,
                TrackedSourceOptions options);

  const std::string& id() const override { return inner_->id(); }
  Expected<void> start() override { return inner_->start(); }
  void stop() override { inner_->stop(); }
  // A frame whose size differs from the lens table's (options.camera.width/height) is an error:
  // the calibration would not describe it.
  Expected<std::optional<Frame>> next(std::chrono::milliseconds timeout) override;
  std::vector<Feature> features() const override { return inner_->features(); }
  Expected<double> set_feature(std::string_view name, double value) override {
    return inner_->set_feature(name, value);
  }
  SourceStats stats() const override { return inner_->stats(); }
  TimeSource time_source() const override { return inner_->time_source(); }

  uint64_t untracked() const { return untracked_; }
  // Thread-safe: for the camera's state.
  TrackingStatus status(int64_t now_ns) const;
  const TrackedSourceOptions& options() const { return options_; }
  const FreeDListener& listener() const { return *listener_; }
  std::shared_ptr<FreeDListener> shared_listener() const { return listener_; }

 private:
  // The calibration of frame f (waits for its packet; marks it delivered).
  std::optional<Camera> resolve(uint64_t frame);

  std::unique_ptr<FrameSource> inner_;
  std::shared_ptr<FreeDListener> listener_;
  TrackedSourceOptions options_;
  bool following_ = false;  // the inner source renders from resolve()'s poses
  std::optional<std::pair<uint64_t, std::optional<Camera>>> resolved_;
  std::atomic<uint64_t> untracked_{0};
};

}  // namespace studio::capture
