#pragma once
// Free-D over UDP and the decorator that gives frames of any FrameSource their per-frame
// calibration from it.
//
// FreeDListener: one UDP socket (default port 40000) and one thread. Every datagram is decoded
// with decode_freed(); rejected datagrams are counted by reason (wrong length, unknown type, bad
// checksum) and otherwise ignored; accepted packets are stamped with their arrival time
// (CLOCK_REALTIME ns) and kept per Free-D camera id: the newest, plus a short history for
// matching video frames by time. Destruction stops the thread promptly (self-pipe).
//
// TrackedSource: wraps a FrameSource; for each frame it looks up the packet of its Free-D camera
// whose arrival time is nearest to capture_ns + latency_ns (within max_skew_ns) and attaches
// freed_to_camera() of it as Frame::calibration. Frames without a match pass through without a
// calibration and are counted (untracked()).

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "capture/frame_source.h"
#include "capture/freed.h"
#include "core/error.h"

namespace studio::capture {

struct FreeDListenerOptions {
  std::string bind_address = "0.0.0.0";  // IPv4 address to bind; "127.0.0.1" in tests
  uint16_t port = kFreeDDefaultPort;     // 0 = any free port (see FreeDListener::port())
  std::size_t history = 64;              // packets kept per camera id for matching by time

  Expected<void> validate() const;
};

struct FreeDSample {
  FreeDPacket packet;
  int64_t arrival_ns = 0;  // CLOCK_REALTIME when the datagram was read
};

struct FreeDListenerStats {
  uint64_t datagrams = 0;  // every datagram read
  uint64_t accepted = 0;
  std::array<uint64_t, kFreeDRejectCount> rejected{};  // indexed by FreeDReject
  uint64_t rejected_total() const { return rejected[0] + rejected[1] + rejected[2]; }
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
  std::optional<FreeDSample> latest(uint8_t freed_id) const;
  // The kept packet of `freed_id` whose arrival is nearest to time_ns, if within max_skew_ns.
  std::optional<FreeDSample> nearest(uint8_t freed_id, int64_t time_ns, int64_t max_skew_ns) const;
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
  // The tracker's pose for a frame exposed at t arrives at t + latency_ns (tracker processing
  // and network delay; may be negative when video is the slower path).
  int64_t latency_ns = 0;
  int64_t max_skew_ns = 20'000'000;  // half a 25 fps period

  Expected<void> validate() const;
};

class TrackedSource : public FrameSource {
 public:
  // `inner` and `listener` must be non-null; options must have passed validate().
  TrackedSource(std::unique_ptr<FrameSource> inner, std::shared_ptr<const FreeDListener> listener,
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

  uint64_t untracked() const { return untracked_; }

 private:
  std::unique_ptr<FrameSource> inner_;
  std::shared_ptr<const FreeDListener> listener_;
  TrackedSourceOptions options_;
  uint64_t untracked_ = 0;
};

}  // namespace studio::capture
