#pragma once
// A binary mask as per-row runs of foreground pixels: the form masks travel in (after the RLE
// codec, core/mask_codec.h) and the form the visual hull cuts with, without ever expanding the
// mask to a full image.
//
// Invariants (valid()): runs of row y are runs[row_start[y] .. row_start[y+1]); within a row
// they are sorted, non-empty, disjoint and not touching (begin < end < next.begin), and inside
// [0, width). row_start has height+1 entries, starts at 0 and ends at runs.size().

#include <cstdint>
#include <span>
#include <vector>

#include "core/image.h"

namespace studio {

struct Run {
  int32_t begin;  // first foreground pixel
  int32_t end;    // one past the last
  friend bool operator==(const Run&, const Run&) = default;
};

class RunMask {
 public:
  RunMask() = default;
  RunMask(int width, int height) : width_(width), height_(height), row_start_(std::size_t(height) + 1, 0) {}

  // Foreground = pixels != 0.
  static RunMask from_mask(MaskView mask);
  // 255 for foreground, 0 for background.
  Mask to_mask() const;

  int width() const { return width_; }
  int height() const { return height_; }
  std::span<const Run> row(int y) const {
    return {runs_.data() + row_start_[y], runs_.data() + row_start_[y + 1]};
  }
  const std::vector<Run>& runs() const { return runs_; }
  const std::vector<uint32_t>& row_start() const { return row_start_; }
  uint64_t area() const;
  bool valid() const;
  bool contains(int x, int y) const;

  // Building: push_run() with non-decreasing y and, within a row, increasing runs; rows
  // skipped are empty. finish() closes the remaining rows; clear() empties the mask (keeping its
  // size) for reuse without reallocation.
  void clear();
  void push_run(int y, int32_t begin, int32_t end);
  void finish();

  friend bool operator==(const RunMask&, const RunMask&) = default;

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<uint32_t> row_start_;
  std::vector<Run> runs_;
  int building_row_ = 0;
};

}  // namespace studio
