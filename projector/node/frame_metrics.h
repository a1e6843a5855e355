#pragma once
// The projector node's counters and gauges (studio/service/status; the list is in
// projector_config.cc's --help), and what one rendered frame sets in them.

#include "runtime/service_loop.h"

namespace studio::projector {

struct FrameMetrics {
  explicit FrameMetrics(runtime::ServiceLoop& loop)
      : rendered(loop.counter("frames_rendered")),
        eye_rejected(loop.counter("eye_rejected")),
        head_stale(loop.counter("head_stale")),
        scene_left_out(loop.counter("scene_nodes_left_out")),
        assets_failed(loop.counter("assets_failed")),
        superseded(loop.counter("meshes_superseded")),
        mesh_errors(loop.counter("mesh_motion_errors")),
        from_cache(loop.counter("frames_from_cache")),
        rerendered(loop.counter("scene_rerendered")),
        held(loop.counter("frames_held")),
        fits_deferred(loop.counter("motion_fits_deferred")),
        fits_relatched(loop.counter("motion_fits_relatched")),
        images_drawn(loop.counter("scene_images_drawn")),
        images_unshown(loop.counter("scene_images_unshown")),
        moving_nodes(loop.metrics().gauge("scene_moving_nodes")),
        cache_move_mm(loop.metrics().gauge("scene_cache_move_mm")),
        held_shift_px(loop.metrics().gauge("scene_held_shift_px")),
        cpu_per_frame_ms(loop.metrics().gauge("cpu_per_frame_ms")),
        margin_mm(loop.metrics().gauge("margin_mm")),
        latency_p_ms(loop.metrics().gauge("latency_p_ms")),
        render_ms(loop.metrics().gauge("render_ms")),
        overrun_p_ms(loop.metrics().gauge("overrun_p_ms")),
        mesh_triangles(loop.metrics().gauge("mesh_triangles")) {
    loop.count_as_output(rendered);
  }
  runtime::Counter &rendered, &eye_rejected, &head_stale, &scene_left_out, &assets_failed,
      &superseded, &mesh_errors, &from_cache, &rerendered, &held, &fits_deferred, &fits_relatched,
      &images_drawn, &images_unshown;
  runtime::Gauge &moving_nodes, &cache_move_mm, &held_shift_px, &cpu_per_frame_ms, &margin_mm, &latency_p_ms,
      &render_ms, &overrun_p_ms, &mesh_triangles;
};

}  // namespace studio::projector
