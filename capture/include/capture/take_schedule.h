#pragma once
// Frame-accurate capture control (issue 3 item 6, DESIGN §5): a capture command names a future
// studio frame number; every capture server starts recording exactly at that frame and stops
// exactly at the stop frame, without talking to the others (genlocked cameras give every server
// the same frame numbers).
//
// TakeSchedule is the pure decision part, fed from two sides:
//   - commands: start(take, at_frame) / stop(take, at_frame), from the command reader;
//   - frames: on_frame(f), from the capture loop, for every frame the source delivered, in order.
// A take records the frames f with start_frame <= f < stop_frame. "Future" is judged against the
// frames already handled: a start naming a frame <= the last frame handled is refused (it can no
// longer be honoured exactly); a stop naming such a frame ends the take at the next frame and says
// so. If the source drops frame start_frame itself, the take begins at the next delivered frame
// and reports the missed frames (Decision::missed) so the recorder counts them as drops.
// One take at a time per camera. Not thread-safe: the node serialises calls.

#include <cstdint>
#include <optional>
#include <string>

#include "core/error.h"

namespace studio::capture {

class TakeSchedule {
 public:
  struct Take {
    std::string name;
    uint64_t start_frame = 0;
    std::optional<uint64_t> stop_frame;  // exclusive
  };

  // Errors: a take already pending or recording; start frame not in the future; stop <= start.
  Expected<void> start(const std::string& take, uint64_t at_frame);
  // Sets the stop frame of the pending or recording take `take`. Returns the effective stop frame
  // (at_frame, or the next frame when at_frame has already passed). Error: no such take.
  Expected<uint64_t> stop(const std::string& take, uint64_t at_frame);

  struct Decision {
    std::optional<Take> ended;  // end this take before this frame (the frame is not part of it)
    bool begin = false;         // begin `take` with this frame
    bool record = false;        // record this frame into `take`
    uint64_t missed = 0;        // with begin: frames start_frame..f-1 the source never delivered
    Take take;                  // the recording take (with begin / record)
  };
  Decision on_frame(uint64_t frame);
  // Forgets the pending and the recording take (the recorder failed: the take ended in error).
  void cancel() {
    pending_.reset();
    recording_.reset();
  }

  const std::optional<Take>& pending() const { return pending_; }
  const std::optional<Take>& recording() const { return recording_; }
  std::optional<uint64_t> last_frame() const { return last_; }

 private:
  std::optional<Take> pending_;
  std::optional<Take> recording_;
  std::optional<uint64_t> last_;
};

}  // namespace studio::capture
