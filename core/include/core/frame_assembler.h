#pragma once
// Assembles one studio frame from items that N sources send independently (the hull waits for
// the masks of all cameras of one frame — DESIGN §5 — "bounded by a deadline, then uses what it
// has and counts the misses").
//
// Contract
// - add(source, frame, capture_ns, item, now): stores the item; a second item for the same
//   source and frame replaces the first. Items for a frame already emitted or dropped are late
//   (counted, discarded); an unknown source is counted and discarded.
// - pop(now) returns at most one frame, the decision being:
//     1. the NEWEST frame that is complete (every source present); every older pending frame is
//        discarded (counted as dropped: real time prefers fresh complete data);
//     2. else the OLDEST pending frame whose deadline (first item's arrival + deadline) has
//        passed: emitted with what it has if it holds >= min_sources items (the missing sources
//        are counted per source), otherwise dropped;
//     3. else nothing.
// - At most max_pending frames are held; adding a newer frame beyond that drops the oldest.
// - next_deadline() tells a waiting loop how long it may sleep.
// Pure and single-threaded (the node calls it from its one loop thread).

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace studio {

struct FrameAssemblerCounts {
  uint64_t complete = 0;       // frames emitted with every source
  uint64_t partial = 0;        // frames emitted at the deadline with some sources missing
  uint64_t dropped = 0;        // frames discarded (superseded, too few sources, overflow)
  uint64_t late = 0;           // items that arrived after their frame was emitted or dropped
  uint64_t unknown_source = 0;
  std::vector<uint64_t> missing_by_source;  // per source: frames emitted without it
};

template <class T>
class FrameAssembler {
 public:
  using Clock = std::chrono::steady_clock;

  struct Options {
    std::vector<std::string> sources;
    std::chrono::nanoseconds deadline = std::chrono::milliseconds(40);
    std::size_t min_sources = 1;
    std::size_t max_pending = 8;
  };

  struct Frame {
    uint64_t frame = 0;
    int64_t capture_ns = 0;              // the earliest capture time among the items
    std::vector<std::optional<T>> items;  // indexed like Options::sources
    std::size_t present() const {
      std::size_t n = 0;
      for (const auto& i : items) n += i.has_value();
      return n;
    }
  };

  explicit FrameAssembler(Options options) : options_(std::move(options)) {
    counts_.missing_by_source.assign(options_.sources.size(), 0);
  }

  const Options& options() const { return options_; }
  const FrameAssemblerCounts& counts() const { return counts_; }

  // Index of a source, or -1.
  int source_index(std::string_view source) const {
    for (std::size_t i = 0; i < options_.sources.size(); ++i)
      if (options_.sources[i] == source) return int(i);
    return -1;
  }

  void add(std::string_view source, uint64_t frame, int64_t capture_ns, T item, Clock::time_point now) {
    const int s = source_index(source);
    if (s < 0) {
      ++counts_.unknown_source;
      return;
    }
    if (emitted_any_ && frame <= last_done_) {
      ++counts_.late;
      return;
    }
    auto it = pending_.find(frame);
    if (it == pending_.end()) {
      Pending p;
      p.first_arrival = now;
      p.frame.frame = frame;
      p.frame.capture_ns = capture_ns;
      p.frame.items.resize(options_.sources.size());
      it = pending_.emplace(frame, std::move(p)).first;
      while (pending_.size() > options_.max_pending) drop(pending_.begin());
      it = pending_.find(frame);
      if (it == pending_.end()) return;  // the new frame itself was the oldest: dropped
    }
    Frame& f = it->second.frame;
    f.capture_ns = std::min(f.capture_ns, capture_ns);
    f.items[std::size_t(s)] = std::move(item);
  }

  std::optional<Frame> pop(Clock::time_point now) {
    // 1. newest complete frame
    for (auto it = pending_.rbegin(); it != pending_.rend(); ++it) {
      if (it->second.frame.present() == options_.sources.size()) {
        const uint64_t frame = it->first;
        Frame out = std::move(it->second.frame);
        while (!pending_.empty() && pending_.begin()->first < frame) drop(pending_.begin());
        pending_.erase(frame);
        finish(frame);
        ++counts_.complete;
        return out;
      }
    }
    // 2. oldest frame past its deadline
    while (!pending_.empty()) {
      auto it = pending_.begin();
      if (now < it->second.first_arrival + options_.deadline) break;
      if (it->second.frame.present() < options_.min_sources) {
        drop(it);
        continue;
      }
      Frame out = std::move(it->second.frame);
      const uint64_t frame = it->first;
      pending_.erase(it);
      finish(frame);
      ++counts_.partial;
      for (std::size_t i = 0; i < out.items.size(); ++i)
        if (!out.items[i]) ++counts_.missing_by_source[i];
      return out;
    }
    return std::nullopt;
  }

  // When the oldest pending frame reaches its deadline; nullopt when nothing is pending.
  std::optional<Clock::time_point> next_deadline() const {
    if (pending_.empty()) return std::nullopt;
    return pending_.begin()->second.first_arrival + options_.deadline;
  }

  std::size_t pending() const { return pending_.size(); }

 private:
  struct Pending {
    Clock::time_point first_arrival;
    Frame frame;
  };

  void drop(typename std::map<uint64_t, Pending>::iterator it) {
    const uint64_t frame = it->first;
    pending_.erase(it);
    finish(frame);
    ++counts_.dropped;
  }
  void finish(uint64_t frame) {
    if (!emitted_any_ || frame > last_done_) last_done_ = frame;
    emitted_any_ = true;
  }

  Options options_;
  std::map<uint64_t, Pending> pending_;
  FrameAssemblerCounts counts_;
  bool emitted_any_ = false;
  uint64_t last_done_ = 0;
};

}  // namespace studio
