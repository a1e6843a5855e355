#include "calibrate/observations.h"

#include "calibrate/text.h"
#include <set>

namespace studio::calibrate {

const char* to_string(Placement placement) {
  switch (placement) {
    case Placement::origin: return "origin";
    case Placement::floor: return "floor";
    case Placement::free: return "free";
  }
  return "free";
}

Expected<Placement> parse_placement(const std::string& text) {
  if (text == "origin") return Placement::origin;
  if (text == "floor") return Placement::floor;
  if (text == "free") return Placement::free;
  return fail("placement '" + text + "' is not one of origin, floor, free");
}

int Observations::camera_index(const std::string& id) const {
  for (size_t i = 0; i < cameras.size(); ++i)
    if (cameras[i].id == id) return static_cast<int>(i);
  return -1;
}

size_t Observations::observation_count() const {
  size_t n = 0;
  for (const auto& f : frames)
    for (const auto& v : f.views) n += v.points.size();
  return n;
}

Expected<void> Observations::validate(int point_count) const {
  if (cameras.empty()) return fail("observations: no cameras");
  if (frames.empty()) return fail("observations: no frames");
  std::set<std::string> ids;
  for (const auto& c : cameras) {
    if (c.id.empty()) return fail("observations: a camera has an empty id");
    if (!ids.insert(c.id).second) return fail("observations: camera " + c.id + " appears twice");
    if (c.width < 0 || c.height < 0 || c.width > 100000 || c.height > 100000)
      return fail("observations: camera " + c.id + " has an impossible image size");
  }
  std::set<std::string> frame_ids;
  int origins = 0;
  for (const auto& f : frames) {
    if (!frame_ids.insert(f.id).second) return fail("observations: frame " + f.id + " appears twice");
    if (f.placement == Placement::origin) {
      ++origins;
      if (f.holdout) return fail("observations: frame " + f.id + ": the origin frame cannot be held out");
    }
    std::set<std::string> seen;
    for (const auto& v : f.views) {
      if (camera_index(v.camera_id) < 0)
        return fail("observations: frame " + f.id + " names unknown camera " + v.camera_id);
      if (!seen.insert(v.camera_id).second)
        return fail("observations: frame " + f.id + " has two views of camera " + v.camera_id);
      std::set<int> points;
      for (const auto& p : v.points) {
        if (p.id < 0 || p.id >= point_count)
          return fail(format("observations: frame {} camera {}: point id {} is not in 0..{}",
                                  f.id, v.camera_id, p.id, point_count - 1));
        if (!points.insert(p.id).second)
          return fail(format("observations: frame {} camera {}: point id {} appears twice",
                                  f.id, v.camera_id, p.id));
        if (!p.pixel.allFinite())
          return fail(format("observations: frame {} camera {}: point {} is not finite",
                                  f.id, v.camera_id, p.id));
      }
    }
  }
  if (origins > 1) return fail("observations: more than one origin frame");
  return {};
}

}  // namespace studio::calibrate
