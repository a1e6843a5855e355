#pragma once
// Keyframe animation on the scene clock.
//
// A Track drives one path (translation, rotation or scale) of one node through keyframes at
// strictly increasing times (seconds of animation time). Values are stored as 4-vectors:
// translation and scale use xyz (w ignored, 0), rotation is a quaternion (x, y, z, w), unit.
// Sampling at time t: before the first key -> the first value, after the last -> the last value;
// between keys k and k+1 with u = (t - t_k) / (t_k+1 - t_k):
//   step:   value_k
//   linear: lerp(value_k, value_k+1, u) for translation and scale, slerp for rotation (shortest
//           arc)
//
// An Animation is a named set of tracks and a play mode; its duration is its last key time.
// The AnimationClock maps a studio frame to animation time (DESIGN §5: every service names the
// same instant with the same frame number):
//   clock time   c(f) = anchor_time + speed * (f - anchor_frame) * frame_period   (playing)
//                c(f) = anchor_time                                             (paused)
//   animation time from the mode, with d = duration:
//     once:      clamp(c, 0, d)
//     loop:      c mod d (in [0, d))
//     ping_pong: triangle wave: c mod 2d, mirrored in (d, 2d)
// Play / pause / seek / speed re-anchor the clock at the command's frame so the clock time is
// continuous across the change (seek sets it).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/node.h"

namespace studio::scene {

enum class TrackPath : std::uint8_t { translation = 0, rotation = 1, scale = 2 };
enum class Interpolation : std::uint8_t { step = 0, linear = 1 };
enum class PlayMode : std::uint8_t { once = 0, loop = 1, ping_pong = 2 };

struct Track {
  NodeId node;
  TrackPath path = TrackPath::translation;
  Interpolation interpolation = Interpolation::linear;
  std::vector<double> times;
  std::vector<Eigen::Vector4d> values;

  // At least one key, as many values as times, finite strictly increasing times >= 0, finite
  // values, rotations of norm > 1e-9 (stored normalised), scales with |s| >= 1e-9.
  Expected<void> validate() const;
  bool operator==(const Track&) const = default;
};

struct Animation {
  std::string name;
  PlayMode mode = PlayMode::loop;
  std::vector<Track> tracks;

  double duration() const;  // the last key time over all tracks
  // A non-empty name without control characters, at least one track, every track valid.
  Expected<void> validate() const;
  bool operator==(const Animation&) const = default;
};

struct AnimationClock {
  bool playing = false;
  double speed = 1.0;
  std::int64_t anchor_frame = 0;
  double anchor_time = 0.0;

  // Clock time at studio frame f (frame_period in seconds).
  double clock_time(std::int64_t frame, double frame_period) const;
  bool operator==(const AnimationClock&) const = default;
};

// Animation time for a clock time under a mode (see the header comment).
double animation_time(double clock_time, double duration, PlayMode mode);

// Track value at animation time t (binary search over the keys).
Eigen::Vector4d sample(const Track& track, double t);

// Same value, found by a linear scan from the first key: the naive baseline of the benchmark.
Eigen::Vector4d sample_linear_scan(const Track& track, double t);

const char* to_string(TrackPath p);
const char* to_string(Interpolation i);
const char* to_string(PlayMode m);

}  // namespace studio::scene
