// libFuzzer target for the observations.yaml reader (calibrate/cli/observations_yaml.cc; the file
// comes from outside: other detectors, hand edits). Any input either fails with ONE line naming
// the file, or yields observations that satisfy the reader's contract: every frame has an id,
// point ids are non-negative, every view's camera is listed, camera sizes are positive, and
// writing them out and reading them back gives the same observations. yaml-cpp exceptions must
// not escape. Built only by the fuzz preset:
//   cmake --build build/fuzz --target observations_yaml_fuzz
//   build/fuzz/calibrate/cli/observations_yaml_fuzz -max_total_time=600 -max_len=4096
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "observations_yaml.h"

using namespace studio::calibrate;

namespace {

bool same(const Observations& a, const Observations& b) {
  if (a.frames.size() != b.frames.size()) return false;
  for (size_t f = 0; f < a.frames.size(); ++f) {
    const FrameObservations &x = a.frames[f], &y = b.frames[f];
    if (x.id != y.id || x.placement != y.placement || x.holdout != y.holdout ||
        x.views.size() != y.views.size())
      return false;
    for (size_t v = 0; v < x.views.size(); ++v) {
      if (x.views[v].camera_id != y.views[v].camera_id ||
          x.views[v].points.size() != y.views[v].points.size())
        return false;
      for (size_t p = 0; p < x.views[v].points.size(); ++p) {
        const PointObservation &q = x.views[v].points[p], &r = y.views[v].points[p];
        // format_double writes the shortest round-tripping text; NaN never compares equal.
        if (q.id != r.id || !(q.pixel == r.pixel)) return false;
      }
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto file = parse_observations_yaml(text, "fuzz.yaml");
  if (!file) {
    const std::string& m = file.error().message;
    if (m.empty() || m.find('\n') != std::string::npos || m.rfind("fuzz.yaml", 0) != 0)
      std::abort();
    return 0;
  }
  const Observations& obs = file->observations;
  if (obs.frames.empty()) std::abort();
  for (const CameraInfo& c : obs.cameras)
    if (c.width < 0 || c.height < 0) std::abort();
  for (const FrameObservations& f : obs.frames)
    for (const View& v : f.views) {
      if (obs.camera_index(v.camera_id) < 0) std::abort();
      for (const PointObservation& p : v.points)
        if (p.id < 0) std::abort();
    }
  // Round trip (the target is needed to write; a grid stands in when the file has none).
  const TargetSpec target = file->target ? *file->target : *parse_target_spec("grid:10x10:0.1");
  auto again = parse_observations_yaml(format_observations_yaml(obs, target), "again.yaml");
  if (!again) std::abort();
  if (!same(obs, again->observations)) std::abort();
  return 0;
}
