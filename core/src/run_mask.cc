#include "core/run_mask.h"

#include <cassert>

namespace studio {

RunMask RunMask::from_mask(MaskView mask) {
  RunMask out(mask.width(), mask.height());
  for (int y = 0; y < mask.height(); ++y) {
    const uint8_t* row = mask.row(y);
    int x = 0;
    const int w = mask.width();
    while (x < w) {
      while (x < w && row[x] == 0) ++x;
      if (x == w) break;
      const int begin = x;
      while (x < w && row[x] != 0) ++x;
      out.push_run(y, begin, x);
    }
  }
  out.finish();
  return out;
}

Mask RunMask::to_mask() const {
  Mask mask(width_, height_, 0);
  for (int y = 0; y < height_; ++y)
    for (const Run& r : row(y))
      for (int x = r.begin; x < r.end; ++x) mask(x, y) = 255;
  return mask;
}

uint64_t RunMask::area() const {
  uint64_t a = 0;
  for (const Run& r : runs_) a += uint64_t(r.end - r.begin);
  return a;
}

bool RunMask::valid() const {
  if (width_ < 0 || height_ < 0) return false;
  if (row_start_.size() != std::size_t(height_) + 1) return false;
  if (row_start_.front() != 0 || row_start_.back() != runs_.size()) return false;
  for (int y = 0; y < height_; ++y) {
    if (row_start_[y] > row_start_[y + 1]) return false;
    int32_t prev_end = -1;
    for (const Run& r : row(y)) {
      if (r.begin < 0 || r.begin >= r.end || r.end > width_ || r.begin <= prev_end) return false;
      prev_end = r.end;
    }
  }
  return true;
}

bool RunMask::contains(int x, int y) const {
  if (y < 0 || y >= height_) return false;
  for (const Run& r : row(y))
    if (x >= r.begin && x < r.end) return true;
  return false;
}

void RunMask::clear() {
  runs_.clear();
  row_start_.assign(std::size_t(height_) + 1, 0);
  building_row_ = 0;
}

void RunMask::push_run(int y, int32_t begin, int32_t end) {
  assert(y >= building_row_ && y < height_);
  while (building_row_ < y) row_start_[++building_row_] = uint32_t(runs_.size());
  runs_.push_back({begin, end});
  row_start_[y + 1] = uint32_t(runs_.size());
}

void RunMask::finish() {
  while (building_row_ < height_) row_start_[++building_row_] = uint32_t(runs_.size());
}

}  // namespace studio
