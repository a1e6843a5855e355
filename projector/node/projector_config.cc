// The projector service's options and its definition for runtime::service_main
// (projector_node.h).
#include <algorithm>

#include "projector_node.h"
#include "yaml_io/options.h"
#include "yaml_io/rig_yaml.h"

namespace studio::projector {

Expected<void> ProjectorNodeOptions::validate() const {
  if (projector.empty()) return fail("id: the projector's id in the rig is required");
  if (actor.empty() || actor.size() > 63 || mesh_actor.empty() || mesh_actor.size() > 63)
    return fail("actor, mesh_actor: 1..63 characters");
  if (!(rate >= 1 && rate <= 240)) return fail("rate: 1..240 frames per second");
  if (eye_texture.size() != 2 || thumbnail.size() != 2 || default_eye.size() != 3)
    return fail("eye_texture and thumbnail: 2 numbers; default_eye: 3");
  if (output == OutputKind::window && monitor.empty())
    return fail("monitor: a name (or primary) for output: window");
  if (frame_every < 0) return fail("frame_every: >= 0");
  if (!(eye_texture_scale >= 0.1 && eye_texture_scale <= 1))
    return fail("eye_texture_scale: 0.1..1");
  if (!(display_lag_s >= 0 && display_lag_s <= 1)) return fail("display_lag: 0..1 seconds");
  if (!(head_timeout_s > 0)) return fail("head_timeout: > 0 seconds");
  if (fit_nice < 0 || fit_nice > 19) return fail("fit_nice: 0..19");
  if (scene_nice < 0 || scene_nice > 19) return fail("scene_nice: 0..19");
  if (auto ok = scene_cache.validate(); !ok) return ok;
  return mask_options().validate();
}

MaskPlannerOptions ProjectorNodeOptions::mask_options() const {
  MaskPlannerOptions m;
  m.margin = margin;
  m.latency_window = std::size_t(std::max(latency.window, 1));
  m.latency_quantile = latency.quantile;
  m.initial_latency_s = latency.initial;
  m.parallel_mesh_work = parallel_mesh_work;
  m.grow.presimplify = mask_presimplify;
  return m;  // the outline's projector (mask_outline): set by the node, which holds it
}

runtime::ServiceDefinition projector_service_definition() {
  runtime::ServiceDefinition d;
  d.name = "projector";
  d.summary =
      "One data projector: the scene from the actor's eye onto its screen, actors masked black.";
  d.config_help =
      "  projector:                (required section)\n"
      "    rig: FILE               rig.yaml holding the projector (relative to the config file)\n"
      "    id: proj0               the projector's id in the rig (required)\n"
      "    actor: actor            the head (studio/actor/head key; the tracker's actor_id)\n"
      "                            that is the eye\n"
      "    mesh_actor: actor0      that actor's mesh (studio/actor/mesh key; the hull's ids):\n"
      "                            the head's speed joins its margin. Every actor's mesh is\n"
      "                            masked, whichever head is followed\n"
      "    rate: 25                frames per second rendered without meshes (1..240); a new\n"
      "                            actor mesh is drawn at once (its motion estimated once,\n"
      "                            on a fixed vertex budget); a mesh not yet drawn when a\n"
      "                            newer one arrives is dropped (meshes_superseded)\n"
      "    form: single_pass       single_pass (homography folded into the projection, the\n"
      "                            paper's) or two_pass (eye texture + 3x3 warp)\n"
      "    output: headless        headless (EGL surfaceless, no display needed) or window: a\n"
      "                            full-screen GLFW window on `monitor` showing every frame\n"
      "                            (same renderer; the frame is blitted to the window, scaled if\n"
      "                            the monitor's mode is not the projector's size)\n"
      "    monitor: primary        output: window: the monitor's name as GLFW reports it (X11:\n"
      "                            the xrandr output, e.g. HDMI-1) or primary; an unknown name\n"
      "                            fails at start listing the connected monitors\n"
      "    eye_texture: [0, 0]     two_pass eye texture size; 0 0 = one texel per projector pixel\n"
      "                            on the screen, x eye_texture_scale\n"
      "    eye_texture_scale: 1    two_pass, eye_texture 0 0: each side of the suggested size x\n"
      "                            this (0.1..1; 0.5: the scene shaded on a quarter of the\n"
      "                            texels, the warp magnifies 2x)\n"
      "    default_eye: [0, 1.7, 2]  eye (studio frame, m) until the actor's head arrives\n"
      "    display_lag: 0.016      seconds from a rendered frame to its light on the cloth (the\n"
      "                            projector's input lag): masks are predicted to that instant\n"
      "                            and the measured latency the margin covers includes it\n"
      "    head_timeout: 2.0       seconds; an older head pose keeps the last good eye\n"
      "    frame_every: 1          publish studio/projector/frame every N frames (0: never)\n"
      "    thumbnail: [160, 90]    RGB8 thumbnail size in studio/projector/frame ([0, 0]: none)\n"
      "    late_latch: true        take the mesh off the long path: after each frame the next\n"
      "                            frame's scene is drawn ahead (from the head moved on by its\n"
      "                            velocity to that frame's display) and the new meshes' motion\n"
      "                            fitted; a new mesh then only waits for the previous fit's\n"
      "                            velocities looked up per vertex (mask_growth push: and its\n"
      "                            simplification), its mask drawn over the prepared scene,\n"
      "                            finish and read-back (the margin counts the older\n"
      "                            velocity: projector/mask_margin.h);\n"
      "                            false: motion fit, scene and masks after the mesh arrives\n"
      "    fit_thread: true        late_latch: the motion fits run on a thread of their own, so\n"
      "                            a new mesh never waits for the previous mesh's fit; each\n"
      "                            finished fit is installed at the next frame (a fit that lands\n"
      "                            after a newer mesh re-latches it with fresher velocities:\n"
      "                            motion_fits_relatched); a mesh waiting for the thread when a\n"
      "                            newer one comes is not fitted (motion_fits_deferred);\n"
      "                            false: fitted on the render thread after each frame\n"
      "    fit_nice: 3             fit_thread: its nice value above the process's (0..19): the\n"
      "                            render thread and the rasteriser come first and the fit takes\n"
      "                            what they leave; a real-time projector's (its systemd unit)\n"
      "                            runs time-sharing at the process's nice + this, beside the\n"
      "                            scene thread (the same by default); a fit that lands late\n"
      "                            only ages the velocities, which the margin counts\n"
      "    fit_realtime: false     a real-time projector's fit thread at real-time priority 1\n"
      "                            instead: every mesh fitted (a smaller margin) but the scene\n"
      "                            thread gets only what the fits leave (on a shared 2-core PC\n"
      "                            the scene then lags: BENCHMARKS.md, demo, session 18)\n"
      "    scene_thread: true      the scene drawn on a thread of its own, into a renderer on\n"
      "                            a display of its own (its own llvmpipe rasteriser threads),\n"
      "                            from the eye expected when its image is shown; each frame\n"
      "                            puts its masks over the newest image, so a new mesh never\n"
      "                            waits for the scene (replaces late_latch's scene drawn\n"
      "                            ahead; gauges scene_image_ms, scene_image_age_ms; counter\n"
      "                            scene_images_unshown); false: the scene on the render thread\n"
      "    scene_nice: 3           scene_thread: its nice value above the process's (0..19):\n"
      "                            the masks' frames come first (a real-time projector's scene\n"
      "                            thread runs time-sharing at the process's nice + this: its\n"
      "                            rasteriser threads' load stays out of the real-time budget)\n"
      "    parallel_mesh_work: true  late_latch false: a new mesh's mask simplification runs on\n"
      "                            a second thread while its motion is fitted (the mesh waits\n"
      "                            for the longer of the two, not their sum; same result and\n"
      "                            CPU); false: one after the other on the render thread\n"
      "    mask_presimplify: true  mask_growth push: a hull mesh of more than 12000 triangles\n"
      "                            is clustered (meshoptimizer sloppy) to ~12000 before the\n"
      "                            edge collapse to the mask's 3000 (2-4x less CPU for it on\n"
      "                            the demo's hull meshes; both errors x 1.5 added to the\n"
      "                            mask's push, so the mask is ~1 cm fatter); false: the edge\n"
      "                            collapse alone (projector/mask_geometry.h)\n"
      "    mask_growth: outline    how the mask grows by the margin: outline = the whole mesh\n"
      "                            (not simplified up to 100 000 triangles: cheaper, and no\n"
      "                            simplifier error; clustered beyond) plus a\n"
      "                            band of the margin's angular size round its silhouette as\n"
      "                            this projector sees it (the margin ball's projection, no\n"
      "                            more); push = every vertex of the simplified mesh moved out\n"
      "                            along its normal by margin / cosine (up to 3.3 x the margin\n"
      "                            where a hull mesh's normals spread: spikes of wasted black)\n"
      "    margin:                 the mask's security margin (projector/mask_margin.h)\n"
      "      floor: 0.01           metres, what motion does not explain (hull error, ...)\n"
      "      cap: 0.20             metres, largest margin (clamped and flagged above)\n"
      "      prediction: true      move every mesh forward by its predicted motion\n"
      "      velocity_uncertainty: 0.05  m/s, sigma of the velocity estimate\n"
      "      head_disagreement: 0.5      m/s; a head faster than the mesh by more: no prediction\n"
      "      max_acceleration: 15.0      m/s^2, physical bound on the actor's acceleration\n"
      "      acceleration: worst_case    the prediction term's a: worst_case = max_acceleration\n"
      "                                  always (an actor at rest may start moving during the\n"
      "                                  latency; the estimate sees it 2-3 meshes late); estimate\n"
      "                                  = the median of the last 5 meshes' largest region\n"
      "                                  acceleration, bounded by max_acceleration (smaller\n"
      "                                  margins, light on an actor starting from rest: the demo\n"
      "                                  measured 183-2982 px over 60 s); worst_case also adds\n"
      "                                  a L^2 / 2 to the no-prediction term (v L), estimate not\n"
      "    latency:                the margin covers each mesh's age when the frame is shown\n"
      "                            (capture_ns -> render done + display_lag, planned) plus this\n"
      "                            quantile of how much later than planned frames were shown\n"
      "      window: 100           frames measured\n"
      "      quantile: 0.95        of the lateness (and of motion to photon, latency_p_ms)\n"
      "      initial: 0.04         seconds, the latency before the first frame is shown\n"
      "    scene_cache:            render the static scene once, reuse it (colour + depth) while\n"
      "                            it is unchanged and the eye moved so little that no static\n"
      "                            point shifts more than max_error_px (bound from the off-axis\n"
      "                            geometry: projector/static_shift.h); the nodes changed within\n"
      "                            `settle` seconds (animated ones) are drawn every frame\n"
      "      enabled: true         false: every frame draws the whole scene\n"
      "      max_error_px: 0.5     projector pixels (0..10]\n"
      "      settle: 1.0           seconds a changed node stays with the moving nodes\n"
      "      hold_frames: 0        0..25: a layer drawn for a moving eye also serves this many\n"
      "                            following frames however far the eye moved (the static\n"
      "                            scene redrawn at most every hold_frames + 1 frames, lagging\n"
      "                            the eye by up to that many; moving nodes and masks every\n"
      "                            frame): for projector PCs without a GPU; 0 (default):\n"
      "                            the bound alone decides\n"
      "  The frame is read back for studio/projector/frame (blackout mask, thumbnail) in both\n"
      "  outputs; a window needs a display (DISPLAY; under systemd a graphical session).\n"
      "  Topics: studio/scene/node, studio/actor/mesh, studio/actor/head in;\n"
      "  studio/projector/calibration, studio/projector/frame, studio/service/status out\n"
      "  (latency = motion to photon; margin_mm, latency_p_ms, overrun_p_ms (frames shown later\n"
      "  than planned: the margin covers the mesh's age at display + this), render_ms,\n"
      "  eye_rejected, meshes_rejected, meshes_superseded, mesh_motion_errors, mesh_triangles\n"
      "  (of the last mesh received), motion_fits_deferred, motion_fits_relatched; where a mesh's\n"
      "  time goes, ms: stage_wait_ms, stage_motion_ms, stage_simplify_ms, stage_mask_ms,\n"
      "  stage_draw_ms, stage_finish_ms, stage_readback_ms, stage_publish_ms, stage_present_ms,\n"
      "  stage_latch_ms, stage_ahead_ms, stage_load_ms,\n"
      "  mesh_to_frame_ms: see projector/node/frame_stages.h; the scene cache: frames_from_cache,\n"
      "  scene_rerendered (frames that drew the static scene; with scene_thread: the thread's\n"
      "  images), scene_moving_nodes,\n"
      "  scene_cache_move_mm (eye move the cached layer allows), frames_held and\n"
      "  scene_held_shift_px (frames served by hold_frames beyond the bound, and the last such\n"
      "  frame's displacement bound, projector px); cpu_per_frame_ms: the process's\n"
      "  CPU time, every thread (llvmpipe's too), per rendered frame over about a second;\n"
      "  scene_thread: scene_images_drawn, scene_images_unshown (drawn, replaced before a frame\n"
      "  took them), scene_image_ms (an image drawn and read back, wall), scene_image_age_ms\n"
      "  (the image a frame used: read back -> the frame done)).\n";
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& ctx) -> Expected<std::unique_ptr<runtime::Node>> {
    auto section = config.required("projector");
    if (!section) return std::unexpected(section.error());
    static const yaml::Schema<MarginOptions> margin_schema{
        yaml::field("floor", &MarginOptions::floor_m).min(0),
        yaml::field("cap", &MarginOptions::cap_m).min(0),
        yaml::field("prediction", &MarginOptions::prediction),
        yaml::field("velocity_uncertainty", &MarginOptions::velocity_uncertainty_mps).min(0),
        yaml::field("head_disagreement", &MarginOptions::head_disagreement_mps).min(0),
        yaml::field("max_acceleration", &MarginOptions::max_acceleration_mps2).range(0.1, 1000),
        yaml::field("acceleration", &MarginOptions::worst_case_acceleration,
                    [](const yaml::Node& n) -> Expected<bool> {
                      auto s = n.as_string();
                      if (!s) return std::unexpected(s.error());
                      if (*s == "worst_case") return true;
                      if (*s == "estimate") return false;
                      return fail("acceleration: '" + *s + "' (expected worst_case or estimate)");
                    }),
    };
    static const yaml::Schema<LatencyOptions> latency_schema{
        yaml::field("window", &LatencyOptions::window).range(1, 100000),
        yaml::field("quantile", &LatencyOptions::quantile).range(0.01, 1),
        yaml::field("initial", &LatencyOptions::initial).range(0, 10),
    };
    static const yaml::Schema<SceneCacheOptions> cache_schema{
        yaml::field("enabled", &SceneCacheOptions::enabled),
        yaml::field("max_error_px", &SceneCacheOptions::max_error_px).range(1e-3, 10),
        yaml::field("settle", &SceneCacheOptions::settle_s).range(0, 60),
        yaml::field("hold_frames", &SceneCacheOptions::hold_frames).range(0, 25),
    };
    static const yaml::Schema<ProjectorNodeOptions> schema{
        yaml::field("rig", &ProjectorNodeOptions::rig).required().relative_path(),
        yaml::field("id", &ProjectorNodeOptions::projector).required(),
        yaml::field("actor", &ProjectorNodeOptions::actor),
        yaml::field("mesh_actor", &ProjectorNodeOptions::mesh_actor),
        yaml::field("rate", &ProjectorNodeOptions::rate).range(1, 240),
        yaml::enum_field("form", &ProjectorNodeOptions::form,
                         {{"single_pass", projector_render::Form::single_pass},
                          {"two_pass", projector_render::Form::two_pass}}),
        yaml::enum_field("output", &ProjectorNodeOptions::output,
                         {{"headless", OutputKind::headless}, {"window", OutputKind::window}}),
        yaml::field("monitor", &ProjectorNodeOptions::monitor),
        yaml::field("eye_texture", &ProjectorNodeOptions::eye_texture).size(2),
        yaml::field("eye_texture_scale", &ProjectorNodeOptions::eye_texture_scale).range(0.1, 1),
        yaml::field("default_eye", &ProjectorNodeOptions::default_eye).size(3),
        yaml::field("display_lag", &ProjectorNodeOptions::display_lag_s).range(0, 1),
        yaml::field("head_timeout", &ProjectorNodeOptions::head_timeout_s).min(0.01),
        yaml::field("frame_every", &ProjectorNodeOptions::frame_every).range(0, 100000),
        yaml::field("thumbnail", &ProjectorNodeOptions::thumbnail).size(2),
        yaml::field("late_latch", &ProjectorNodeOptions::late_latch),
        yaml::field("fit_thread", &ProjectorNodeOptions::fit_thread),
        yaml::field("fit_nice", &ProjectorNodeOptions::fit_nice).range(0, 19),
        yaml::field("fit_realtime", &ProjectorNodeOptions::fit_realtime),
        yaml::field("scene_thread", &ProjectorNodeOptions::scene_thread),
        yaml::field("scene_nice", &ProjectorNodeOptions::scene_nice).range(0, 19),
        yaml::field("parallel_mesh_work", &ProjectorNodeOptions::parallel_mesh_work),
        yaml::field("mask_presimplify", &ProjectorNodeOptions::mask_presimplify),
        yaml::enum_field("mask_growth", &ProjectorNodeOptions::mask_outline,
                         {{"outline", true}, {"push", false}}),
        yaml::field("margin", &ProjectorNodeOptions::margin, margin_schema),
        yaml::field("latency", &ProjectorNodeOptions::latency, latency_schema),
        yaml::field("scene_cache", &ProjectorNodeOptions::scene_cache, cache_schema),
    };
    auto read = schema.read(*section);
    if (!read) return std::unexpected(read.error());
    const ProjectorNodeOptions& options = *read;
    auto rig = yaml::read_rig(options.rig);
    if (!rig) return std::unexpected(rig.error());
    const Projector* p = rig->find_projector(options.projector);
    if (!p) return fail(options.rig + ": no projector '" + options.projector + "'");
    return make_projector_node(options, *p, ctx);
  };
  return d;
}

}  // namespace studio::projector
