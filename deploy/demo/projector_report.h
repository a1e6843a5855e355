#pragma once
// The projector's figures from the studio/projector/frame samples the probe scored (collected.h):
//   motion to photon   per mesh frame (captured in the window) and projector: its capture_ns →
//                      the first projector frame rendered with that mesh (render_done_ns)
//   mask age           per rendered frame: the latency_ms the projector published (the age of the
//                      newest mesh in its mask when the frame was rendered)
//   mesh → projector   the probe's receipt of the frame's mesh → that first projector frame
//   lit_actor_px       per scored frame: projector pixels on the TRUE actor at display time
//                      (render_done + display lag) that the blackout mask leaves lit
// and OUT/projector.png: the frame with the most lit actor pixels (else one with the actor in
// view), its published thumbnail scaled to the projector's size, the blackout black, the true
// actor's lit pixels red and its blacked-out pixels dark blue.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "collected.h"
#include "json_writer.h"

namespace studio::demo {

struct ProjectorFigures {
  bool ran = false;  // projector frames rendered in the window reached the probe
  std::vector<double> motion_to_photon_ms, mask_age_ms, mesh_to_projector_ms;  // sorted
  std::vector<double> eye_error_m;  // scored frames' eye against the true head at display, sorted
  double mesh_fps = 0;      // the slowest projector's distinct meshes per second
  double rendered_fps = 0;  // the slowest projector's rendered frames per second
  std::map<std::string, std::pair<double, double>> per_projector;  // id -> (rendered, mesh) fps
  uint64_t rendered = 0, scored = 0, unscored = 0, frames_with_lit = 0;
  uint64_t lit_sum = 0, lit_max = 0;
  std::string lit_max_at;  // "proj1 render frame N"
  double actor_px_mean = 0, wasted_px_mean = 0, blackout_px_mean = 0;
  double margin_min_m = 0, margin_mean_m = 0, margin_max_m = 0;
  uint64_t predicted_frames = 0;
};

ProjectorFigures projector_figures(const Collected& c, double window_s);
// The "lit_actor_px" value and "lit_actor_detail" / "projector" objects of the report.
void write_projector(JsonWriter& j, const ProjectorFigures& f, const Collected& c);
// OUT/projector.png (nothing written when no frame was scored); false if writing failed.
bool draw_projector_png(const Collected& c, const std::string& path);

}  // namespace studio::demo
