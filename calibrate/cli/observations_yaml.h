#pragma once
// observations.yaml (DESIGN §4) and target FILE.yaml for studio-calibrate, read strictly through
// core/yaml (yaml_io/node.h): errors name file, line and field, e.g.
// "obs.yaml:12: frames[3].views.cam0[4]: expected 3 numbers, got 2".
//
//   target: {rows: 10, cols: 10, spacing: 0.1}   # grid; or {type: chessboard|grid|charuco, ...}
//   cameras: {cam0: {width: 704, height: 576}}   # optional: image sizes (else from the extent)
//   frames:
//     - id: 0
//       placement: origin                        # origin | floor | free (default free)
//       holdout: false                           # optional
//       views:
//         cam0: [[point_id, u, v], ...]

#include <optional>
#include <string>
#include <string_view>

#include "calibrate/observations.h"
#include "calibrate/target.h"
#include "core/error.h"

namespace studio::calibrate {

struct ObservationsFile {
  Observations observations;
  std::optional<TargetSpec> target;
};

Expected<ObservationsFile> read_observations_yaml(const std::string& path);
// The same from text already in memory; `name` stands for the file in error messages.
Expected<ObservationsFile> parse_observations_yaml(std::string_view text, const std::string& name);
// A target FILE.yaml: {type: chessboard|grid|charuco, cols, rows, spacing[, marker, dictionary]},
// at the top level or under `target:`.
Expected<TargetSpec> read_target_yaml(const std::string& path);
// The observations as observations.yaml text (the target as a grid/chessboard/charuco map).
std::string format_observations_yaml(const Observations& observations, const TargetSpec& target);

}  // namespace studio::calibrate
