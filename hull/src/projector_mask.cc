// The projector's actor mask by the viewpoint cut (hull/projector_mask.h).
#include "hull/projector_mask.h"

#include <algorithm>
#include <string>
#include <vector>

#include "hull/viewpoint_cut.h"

namespace studio::hull {

Expected<void> ProjectorMaskOptions::validate() const {
  if (step < 1 || step > 64)
    return fail("projector mask step " + std::to_string(step) + " outside 1..64");
  return cut.validate();
}

RunMask expand_samples(const RunMask& samples, int step, int width, int height) {
  RunMask out(width, height);
  const int half = step / 2;
  std::vector<Run> row;
  for (int y = 0; y < height; ++y) {
    // The sample row nearest to pixel row y: sy = (y + half) / step.
    const int sy = (y + half) / step;
    if (sy >= samples.height()) continue;
    row.clear();
    for (const Run& r : samples.row(sy)) {
      const int begin = std::max(0, r.begin * step - half);
      const int end = std::min(width, r.end * step - half);
      if (begin >= end) continue;
      if (!row.empty() && begin <= row.back().end) {
        row.back().end = std::max(row.back().end, end);
      } else {
        row.push_back({begin, end});
      }
    }
    for (const Run& r : row) out.push_run(y, r.begin, r.end);
  }
  out.finish();
  return out;
}

Expected<RunMask> projector_mask(const Camera& projector, const Eigen::AlignedBox3d& box,
                                 std::span<const View> views, const ProjectorMaskOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  if (projector.width < 1 || projector.height < 1)
    return fail("projector '" + projector.id + "': size " + std::to_string(projector.width) + "x" +
                std::to_string(projector.height));
  ViewpointOptions vo;
  vo.step = options.step;
  vo.cut = options.cut;
  auto cut = viewpoint_cut(projector, box, views, vo);
  if (!cut) return std::unexpected(cut.error());
  if (options.step == 1) return std::move(cut->coverage);
  return expand_samples(cut->coverage, options.step, projector.width, projector.height);
}

}  // namespace studio::hull
