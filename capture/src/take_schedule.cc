#include "capture/take_schedule.h"

namespace studio::capture {

Expected<void> TakeSchedule::start(const std::string& take, uint64_t at_frame) {
  if (recording_) return fail("take " + take + ": take " + recording_->name + " is recording");
  if (pending_ && pending_->name != take)
    return fail("take " + take + ": take " + pending_->name + " is already scheduled");
  if (last_ && at_frame <= *last_)
    return fail("take " + take + ": start frame " + std::to_string(at_frame) +
                " has already passed (frame " + std::to_string(*last_) + " handled)");
  if (pending_ && pending_->stop_frame && *pending_->stop_frame <= at_frame)
    return fail("take " + take + ": stop frame " + std::to_string(*pending_->stop_frame) +
                " is not after the start frame " + std::to_string(at_frame));
  if (pending_)
    pending_->start_frame = at_frame;
  else
    pending_ = Take{take, at_frame, std::nullopt};
  return {};
}

Expected<uint64_t> TakeSchedule::stop(const std::string& take, uint64_t at_frame) {
  Take* t = recording_ && recording_->name == take ? &*recording_
            : pending_ && pending_->name == take   ? &*pending_
                                                   : nullptr;
  if (!t) return fail("take " + take + ": not scheduled or recording");
  uint64_t effective = at_frame;
  if (last_ && effective <= *last_) effective = *last_ + 1;
  if (effective <= t->start_frame && t == &*pending_) {
    // Stopping a take before it began: it never records.
    pending_.reset();
    return effective;
  }
  t->stop_frame = effective;
  return effective;
}

TakeSchedule::Decision TakeSchedule::on_frame(uint64_t frame) {
  Decision d;
  if (last_ && frame <= *last_) return d;  // out of order or repeated: ignore
  last_ = frame;
  if (recording_ && recording_->stop_frame && frame >= *recording_->stop_frame) {
    d.ended = std::move(recording_);
    recording_.reset();
  }
  if (!recording_ && pending_ && frame >= pending_->start_frame) {
    if (pending_->stop_frame && frame >= *pending_->stop_frame) {
      // The source delivered nothing inside [start, stop): the take is empty.
      pending_.reset();
      return d;
    }
    d.begin = true;
    d.missed = frame - pending_->start_frame;
    recording_ = std::move(pending_);
    pending_.reset();
  }
  if (recording_) {
    d.record = true;
    d.take = *recording_;
  }
  return d;
}

}  // namespace studio::capture
