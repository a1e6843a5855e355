// The demo report's projector figures (projector_report.h) at the window's edges: a mesh captured
// in the window counts once for the rate and its motion to photon even when its first frame comes
// after the window (the probe listens 0.5 s beyond it); a frame rendered after the window is not
// a frame of the window (not rendered, scored or lit); a mesh captured before the window does not
// count for the rate.
#include "projector_report.h"

#include <gtest/gtest.h>

namespace studio::demo {
namespace {

constexpr int64_t kMs = 1'000'000;

ProjectorSample frame(uint64_t mesh, int64_t capture_ns, int64_t render_done_ns, bool after) {
  ProjectorSample p;
  p.projector_id = "proj1";
  p.render_frame = mesh;
  p.mesh_frame = mesh;
  p.capture_ns = capture_ns;
  p.render_done_ns = render_done_ns;
  p.latency_ms = double(render_done_ns - capture_ns) * 1e-6;
  p.margin_m = 0.05;
  p.scored = !after;
  p.after_window = after;
  return p;
}

TEST(ProjectorFigures, MeshesOfTheWindowCountOnceWhateverTheEdge) {
  // A 1 s window at 25 meshes/s, every mesh's frame 25 ms after its capture; captures at 20 ms
  // past each 40 ms period, from one period before the window to one after it.
  Collected c;
  c.window_start_ns = 1000 * kMs;
  c.window_end_ns = 2000 * kMs;
  for (int k = -1; k <= 25; ++k) {
    const int64_t capture = c.window_start_ns + 20 * kMs + k * 40 * kMs;
    const int64_t done = capture + 25 * kMs;
    if (done < c.window_start_ns) continue;  // the probe drops frames before the window
    const bool after = done >= c.window_end_ns;
    if (after && capture >= c.window_end_ns) continue;  // nor a later mesh's
    c.projector.push_back(frame(uint64_t(100 + k), capture, done, after));
  }
  const ProjectorFigures f = projector_figures(c, 1.0);
  // Meshes captured in the window: k = 0..24, the last (k = 24, captured at 1.98 s) rendered
  // after it.
  EXPECT_DOUBLE_EQ(f.mesh_fps, 25.0);
  ASSERT_EQ(f.motion_to_photon_ms.size(), 25u);
  EXPECT_NEAR(f.motion_to_photon_ms.front(), 25.0, 1e-9);
  EXPECT_NEAR(f.motion_to_photon_ms.back(), 25.0, 1e-9);
  // Frames rendered in the window: k = -1 (rendered at 1.005 s) .. 23; scored, none after it.
  EXPECT_EQ(f.rendered, 25u);
  EXPECT_EQ(f.scored, 25u);
  EXPECT_EQ(f.unscored, 0u);
  EXPECT_DOUBLE_EQ(f.rendered_fps, 25.0);
  EXPECT_DOUBLE_EQ(f.margin_mean_m, 0.05);

  // Without the late frame (a projector that stopped at the window's end) the mesh is missing.
  c.projector.pop_back();
  EXPECT_DOUBLE_EQ(projector_figures(c, 1.0).mesh_fps, 24.0);
}

}  // namespace
}  // namespace studio::demo
