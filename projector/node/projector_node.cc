#include "projector_node.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <optional>
#include <pthread.h>
#include <sched.h>
#include <set>
#include <thread>

#include "core/clock.h"
#include "core/log.h"
#include "frame_metrics.h"
#include "frame_output.h"
#include "frame_stages.h"
#include "projector/eye_source.h"
#include "projector/fit_worker.h"
#include "projector/mesh_inbox.h"
#include "projector/scene_handoff.h"
#include "projector/thread_priority.h"
#include "projector_wire.h"
#include "runtime/service_loop.h"
#include "scene_mirror.h"
#include "wire/convert.h"
#include "wire/sample.h"
#include "wire/scene_convert.h"

namespace studio::projector {
namespace {

constexpr const char* kLog = "projector";
using SteadyClock = std::chrono::steady_clock;

class ProjectorNode : public runtime::Node {
 public:
  ProjectorNode(ProjectorNodeOptions options, ProjectorView view, const Projector& projector,
                runtime::NodeContext& ctx)
      : options_(std::move(options)),
        view_(std::move(view)),
        projector_(projector),
        mirror_(options_.scene_cache.settle_s),
        eye_(Eigen::Vector3d(options_.default_eye[0], options_.default_eye[1],
                             options_.default_eye[2]),
             options_.head_timeout_s),
        planner_([&] {
          MaskPlannerOptions m = options_.mask_options();
          if (options_.mask_outline) m.grow.projector = projector.camera;
          return m;
        }()),
        loop_(ctx, kLog),
        stages_(loop_.metrics()),
        m_(loop_) {
    calibration_ =
        &loop_.output<studio_ProjectorCalibration>({.counter = "calibrations_out", .rate = false});
    frames_ = &loop_.output<studio_ProjectorFrame>({.counter = "frames_published", .rate = false});
    loop_.input<studio_SceneNode>({.received = "scene_nodes_in",
                                   .rejected = "scene_nodes_rejected",
                                   .reason_prefix = "scene_nodes_rejected_",
                                   .rate = false,
                                   .instance_changes = true,
                                   .batch = 1024},
                                  [this](const studio_SceneNode& s, const wire::SampleMeta& meta) {
                                    return on_node(s, meta);
                                  });
    loop_.input<studio_ActorMesh>({.received = "meshes_in",
                                   .rejected = "meshes_rejected",
                                   .reason_prefix = "meshes_rejected_",
                                   .instance_changes = true},
                                  [this](const studio_ActorMesh& s, const wire::SampleMeta& meta) {
                                    return on_mesh(s, meta);
                                  });
    loop_.input<studio_HeadPose>(
        {.received = "heads_in",
         .rejected = "heads_rejected",
         .reason_prefix = "heads_rejected_",
         .rate = false},
        [this](const studio_HeadPose& s, const wire::SampleMeta&) { return on_head(s); });
    loop_.thread(
        "render", [this] { render_loop(); },
        [this] {
          std::lock_guard lock(mutex_);
          stop_ = true;
          wake_.notify_all();
        });
  }
  ~ProjectorNode() override { stop(); }

  Expected<void> start() override {
    {
      std::lock_guard lock(mutex_);
      stop_ = false;
      init_ = std::promise<Expected<void>>();
    }
    if (options_.late_latch && options_.fit_thread && !fits_) {
      auto w = FitWorker::create(
          {options_.mask_options().motion, options_.fit_nice, options_.fit_realtime});
      if (!w) return std::unexpected(w.error());
      fits_ = std::move(*w);
      if (const std::string note = fits_->priority_note(); !note.empty())
        STUDIO_LOG(warn, kLog) << note;
    }
    if (const int policy = ::sched_getscheduler(0);
        !options_.scene_thread && (policy == SCHED_FIFO || policy == SCHED_RR))
      STUDIO_LOG(warn, kLog) << "scene_thread: false in a real-time process: the scene is "
                                "rasterised at real-time priority beside the pipeline";
    auto init = init_.get_future();
    if (auto ok = loop_.start(); !ok) return ok;
    if (auto ok = init.get(); !ok) {  // GL context or renderer failed
      loop_.stop();
      return ok;
    }
    wire::Owned<studio_ProjectorCalibration> c;
    if (auto ok = wire::from_core(projector_, view_.pixel_from_screen(), *c); ok)
      (void)calibration_->write(*c);
    else
      STUDIO_LOG(warn, kLog) << ok.error().message << " (not published)";
    return {};
  }
  void stop() override { loop_.stop(); }
  runtime::NodeHealth health() override {
    runtime::NodeHealth h = loop_.health();
    h.degraded = degraded_.load();
    return h;
  }

 private:
  runtime::Outcome on_node(const studio_SceneNode& s, const wire::SampleMeta& meta) {
    std::lock_guard lock(mutex_);
    if (meta.disposed || !meta.valid_data) {  // a disposed instance, with or without data
      mirror_.remove(std::string(s.node_id));
      return {};
    }
    auto node = wire::to_core(s);
    if (!node) return runtime::reject("to_core", node.error().message);
    mirror_.update(std::move(*node), seconds(SteadyClock::now().time_since_epoch()));
    return {};
  }

  // A mesh is decoded and checked here and handed to the render thread (MeshInbox), which is
  // woken at once and estimates its motion once, in the next frame.
  runtime::Outcome on_mesh(const studio_ActorMesh& s, const wire::SampleMeta& meta) {
    const std::string id(s.actor_id);
    if (meta.disposed || !meta.valid_data) {
      std::lock_guard lock(mutex_);
      inbox_.dispose(id);
      return {};
    }
    if (s.vertices._length == 0 || s.triangles._length == 0)
      return runtime::reject("empty", "actor " + id + ": empty mesh (previous mask kept)");
    ActorMesh mesh = mesh_of(s);
    m_.mesh_triangles.set(double(s.triangles._length / 3));  // what the per-mesh work scales with
    std::lock_guard lock(mutex_);
    auto replaced = inbox_.offer(id, s.frame, std::move(mesh));
    if (!replaced) return runtime::reject("mesh", replaced.error().message);
    mesh_arrived_ = SteadyClock::now();
    if (*replaced) m_.superseded.add();
    wake_.notify_all();
    return {};
  }

  runtime::Outcome on_head(const studio_HeadPose& s) {
    const Eigen::Vector3d p(s.position[0], s.position[1], s.position[2]);
    const Eigen::Vector3d v(s.velocity[0], s.velocity[1], s.velocity[2]);
    std::lock_guard lock(mutex_);
    if (options_.actor != s.actor_id) return {};  // another actor's head
    head_speed_ = v.norm();
    const double now = seconds(SteadyClock::now().time_since_epoch());
    eye_.head(p, now);
    if (v.allFinite()) head_velocity_ = v;
    head_at_ = now;
    return {};
  }

  // The render thread's planner takes what the handlers left: removals, new meshes (their
  // motion estimated and mask mesh simplified here, outside the lock), the followed head's
  // speed. Returns when the newest mesh taken arrived (nullopt: no mesh).
  std::optional<SteadyClock::time_point> take_inputs() {
    MeshInbox::Taken taken;
    std::optional<double> head_speed;
    std::optional<SteadyClock::time_point> arrived;
    {
      std::lock_guard lock(mutex_);
      taken = inbox_.take();
      head_speed = head_speed_;
      if (!taken.meshes.empty()) arrived = mesh_arrived_;
    }
    if (fits_) install_fits();  // before the latches: a new mesh gets the newest field
    if (arrived && options_.late_latch) {
      stages_.add(FrameStages::wait, seconds(SteadyClock::now() - *arrived));
      // Removals, then each new mesh latched: simplified and given the previous fit's
      // velocities; its own fit follows, on the fit thread or after the frame.
      for (const std::string& id : taken.removed) {
        planner_.remove(id);
        if (fits_) fits_->remove(id);
      }
      int refused = 0;
      for (auto& [id, p] : taken.meshes) {
        std::optional<ActorMesh> copy;  // the fit thread's (the planner keeps its own)
        if (fits_) copy = p.mesh;
        if (auto ok = planner_.latch_mesh(id, p.frame, std::move(p.mesh)); !ok) {
          if (refused++ == 0) STUDIO_LOG(debug, kLog) << ok.error().message;
        } else {
          stages_.add(FrameStages::simplify, planner_.last_mesh_cost().simplify_s);
          stages_.add(FrameStages::latch, planner_.last_mesh_cost().latch_s);
          if (copy && fits_->submit(id, std::move(*copy))) m_.fits_deferred.add();
        }
      }
      if (refused > 0) m_.mesh_errors.add(refused);
    } else if (arrived) {
      stages_.add(FrameStages::wait, seconds(SteadyClock::now() - *arrived));
      std::string error;
      if (const int refused = apply(std::move(taken), planner_, &error); refused > 0) {
        m_.mesh_errors.add(refused);
        STUDIO_LOG(debug, kLog) << error;
      }
      stages_.add(FrameStages::motion, planner_.last_mesh_cost().motion_s);
      stages_.add(FrameStages::simplify, planner_.last_mesh_cost().simplify_s);
    } else {
      apply(std::move(taken), planner_);
    }
    if (head_speed) planner_.set_head_speed(options_.mesh_actor, *head_speed);
    return arrived;
  }
  // The fits the fit thread finished since the last frame, installed in the planner (in order).
  void install_fits() {
    for (FitResult& r : fits_->take()) {
      if (!r.error.empty()) {
        m_.mesh_errors.add();
        STUDIO_LOG(debug, kLog) << "actor " << r.actor << ": " << r.error;
      }
      stages_.add(FrameStages::motion, r.motion_s + r.field_s);
      if (planner_.apply_fit(std::move(r)) == MaskPlanner::Applied::field) m_.fits_relatched.add();
    }
  }
  static double seconds(SteadyClock::duration d) {
    return std::chrono::duration<double>(d).count();
  }

  // The eye for this frame: the followed head when fresh, else the last good eye.
  Eigen::Vector3d eye_now(bool last_good = false) {
    std::lock_guard lock(mutex_);
    if (last_good) return eye_.last_good();
    bool stale = false;
    const Eigen::Vector3d eye = eye_.eye(seconds(SteadyClock::now().time_since_epoch()), &stale);
    if (stale) m_.head_stale.add();
    return eye;
  }

  // What the render thread keeps from frame to frame.
  struct Frame {
    RenderScene scene;
    projector_render::Readback readback;
    CpuPerFrame cpu;
    double render_s = 0;  // smoothed render time: a frame is shown about this much later
    uint64_t count = 0;
    // Late latching: the scene of the next frame is drawn (prepared), from `eye`, with `drawn`.
    bool prepared = false;
    Eigen::Vector3d eye = Eigen::Vector3d::Zero();
    Expected<projector_render::FrameInfo> drawn = projector_render::FrameInfo{};
  };
  // Late latching: the eye for a frame drawn ahead, shown about ahead_s from now: the followed
  // head moved on by its velocity (at most 0.1 s of it) while its pose is fresh, else eye_now().
  Eigen::Vector3d eye_ahead(double ahead_s) {
    std::lock_guard lock(mutex_);
    const double now = seconds(SteadyClock::now().time_since_epoch());
    bool stale = false;
    const Eigen::Vector3d eye = eye_.eye(now, &stale);
    if (stale) m_.head_stale.add();
    if (!head_at_ || now - *head_at_ >= options_.head_timeout_s) return eye;
    return eye + head_velocity_ * std::clamp(now + ahead_s - *head_at_, 0.0, 0.1);
  }

  // The render thread: its own GL context (EGL surfaceless, or the full-screen window's), one
  // frame per period.
  void render_loop() {
    FrameOutput out;  // outlives the renderer, this thread
    auto fr = open_frame_output(options_, view_, projector_.camera.id, out);
    init_.set_value(fr ? Expected<void>{} : std::unexpected(fr.error()));
    if (!fr) return;
    std::thread scene;
    if (options_.scene_thread) scene = start_scene_thread();
    struct Join {  // the scene thread stops with this one (before the handoff's images go)
      ProjectorNode& node;
      std::thread& t;
      ~Join() {
        {
          std::lock_guard lock(node.scene_mutex_);
          node.scene_stop_ = true;
        }
        node.scene_wake_.notify_all();
        if (node.handoff_) node.handoff_->stop();
        if (t.joinable()) t.join();
        node.scene_on_ = false;
      }
    } join{*this, scene};
    Frame state;
    const auto period = std::chrono::duration_cast<SteadyClock::duration>(
        std::chrono::duration<double>(1.0 / options_.rate));
    auto next = SteadyClock::now();
    bool fit_deferred = false;  // the last frame's meshes were not fitted (late latching)
    // A frame when a new mesh arrives (at once: the mesh's motion-to-photon latency is its
    // transport + motion estimate + one render), else one period after the last frame (the
    // scene and the eye move without meshes too).
    // Late latching (the default): after each frame the next frame's scene is drawn ahead
    // (flushed: llvmpipe rasterises it on its threads) and the frame's meshes' motion fitted,
    // so a new mesh waits only for its mask and the finish.
    while (loop_.running()) {
      {
        std::unique_lock lock(mutex_);
        if (wake_.wait_until(lock, next, [this] { return stop_ || inbox_.has_meshes(); }) && stop_)
          return;
      }
      // After a mesh's frame the next frame without a mesh waits two periods: meshes come at
      // about the rate, and a frame begun just before the next mesh arrives would make it wait.
      const bool mesh = render_one(*fr, state, out.window ? &*out.window : nullptr);
      next = SteadyClock::now() + (mesh ? 2 * period : period);
      if (options_.late_latch) {
        if (!scene_on_) prepare_ahead(*fr, state, seconds(next - SteadyClock::now()));
        if (fits_) continue;  // the fit thread fits the frame's meshes
        // A newer mesh already waiting (the thread is behind): its frame goes first and this
        // mesh's fit is dropped; the next fit is against the last mesh fitted, over two mesh
        // intervals (MaskPlanner::latch_mesh), and the margin counts the velocities' age. Never
        // two in a row, so the velocities are at most one interval older than otherwise.
        bool waiting = false;
        {
          std::lock_guard lock(mutex_);
          waiting = inbox_.has_meshes();
        }
        if (waiting && !fit_deferred) {
          fit_deferred = true;
          m_.fits_deferred.add();
        } else {
          fit_deferred = false;
          const auto t = SteadyClock::now();
          if (planner_.fit_pending() > 0)
            stages_.add(FrameStages::motion, seconds(SteadyClock::now() - t));
        }
      }
    }
  }

  // Late latching: the next frame's scene (rebuilt first when the mirror changed) drawn from the
  // eye expected when it is shown (eye_ahead), masks left for the frame.
  void prepare_ahead(projector_render::FrameRenderer& fr, Frame& st, double until_next_s) {
    const auto t = SteadyClock::now();
    st.eye = eye_ahead(std::max(until_next_s, 0.0) + st.render_s + options_.display_lag_s);
    st.drawn = draw_scene(fr, st.scene, st.eye, {}, true);
    st.prepared = true;
    stages_.add(FrameStages::ahead, seconds(SteadyClock::now() - t));
  }

  // The scene from `eye` (the last good eye when the projection refuses it: `eye` is replaced),
  // the masks over it (ahead: none, the scene only, FrameRenderer::prepare). The scene is rebuilt
  // first when the mirror changed.
  Expected<projector_render::FrameInfo> draw_scene(projector_render::FrameRenderer& fr,
                                                   RenderScene& scene, Eigen::Vector3d& eye,
                                                   std::span<const ActorMesh> masks, bool ahead) {
    std::optional<std::map<scene::NodeId, scene::Node>> nodes;
    std::set<scene::NodeId> moving;
    {
      std::lock_guard lock(mutex_);
      const double now = seconds(SteadyClock::now().time_since_epoch());
      if (mirror_.dirty(now)) {
        nodes = mirror_.nodes();
        moving = mirror_.moving(now);
        mirror_.clean();
      }
    }
    if (nodes) {
      auto r = scene.rebuild(*nodes, moving, fr.renderer());
      m_.scene_left_out.add(r.left_out);
      m_.assets_failed.add(r.assets_failed);
      m_.moving_nodes.set(double(scene.layers.moving_nodes));
    }
    const bool cache = options_.scene_cache.enabled;
    auto draw = [&](const Eigen::Vector3d& e) {
      return ahead ? scene.prepare(fr, e, cache) : scene.draw(fr, e, masks, cache);
    };
    auto drawn = draw(eye);
    if (!drawn) {  // an eye the projection refuses: the last good eye (checked at start)
      m_.eye_rejected.add();
      STUDIO_LOG(debug, kLog) << drawn.error().message;
      eye = eye_now(true);
      drawn = draw(eye);
    }
    if (drawn) (drawn->from_cache ? m_.from_cache : m_.rerendered).add();
    if (drawn && drawn->held) {
      m_.held.add();
      m_.held_shift_px.set(drawn->shift_px);
    }
    if (drawn && cache) m_.cache_move_mm.set(fr.cache_allowed_move_m(eye) * 1e3);
    return drawn;
  }

  // scene_thread: starts the scene thread and waits for its renderer and first image. On a
  // failure (no second display, no renderer) the scene stays on the render thread (logged).
  std::thread start_scene_thread() {
    scene_ready_ = std::promise<Expected<void>>();
    auto ready = scene_ready_.get_future();
    handoff_ = std::make_unique<SceneHandoff>();
    images_skipped_ = 0;
    image_age_s_ = 0;
    {
      std::lock_guard lock(scene_mutex_);
      scene_stop_ = false;
    }
    std::thread t([this] { scene_loop(); });
    if (auto ok = ready.get(); !ok) {
      STUDIO_LOG(warn, kLog) << "scene thread: " << ok.error().message
                             << "; the scene is drawn on the render thread";
      t.join();
      return {};
    }
    scene_on_ = true;
    if (!handoff_->wait_first(std::chrono::seconds(10)))
      STUDIO_LOG(warn, kLog) << "scene thread: no scene image after 10 s";
    return t;
  }

  // The scene thread: a renderer on a display of its own (its own llvmpipe rasteriser threads,
  // created here below the process's priority), one scene image per period, drawn from the eye
  // expected when the image is shown: its own draw and read-back, then the measured age of the
  // images frames use (read-back -> frame done: the wait for a frame to take it, that frame),
  // then the display lag.
  void scene_loop() {
    pthread_setname_np(pthread_self(), "scene");
    // Time-sharing even in a real-time process: the scene's rasteriser threads (created below,
    // with this thread's priority) would otherwise add whole cores of real-time load beside the
    // real-time pipeline and run it into the kernel's real-time throttling.
    const std::string note = lower_this_thread(options_.scene_nice);
    auto context = scene_render::HeadlessContext::create(scene_render::EglScreen::own);
    if (!context) {
      scene_ready_.set_value(std::unexpected(context.error()));
      return;
    }
    auto fr = projector_render::FrameRenderer::create(view_, frame_renderer_options(options_));
    if (!fr) {
      scene_ready_.set_value(std::unexpected(fr.error()));
      return;
    }
    if (!note.empty())
      STUDIO_LOG(warn, kLog) << "scene thread: its priority was not lowered (" << note
                             << "): it shares the CPU with the masks' frames as an equal";
    scene_ready_.set_value({});
    RenderScene scene;
    const double period_s = 1.0 / options_.rate;
    const auto period = std::chrono::duration_cast<SteadyClock::duration>(
        std::chrono::duration<double>(period_s));
    double image_s = 0;  // smoothed: an image's draw and read-back
    for (uint64_t n = 0;; ++n) {
      {
        std::lock_guard lock(scene_mutex_);
        if (scene_stop_) return;
      }
      const auto t0 = SteadyClock::now();
      const double age_s = image_age_s_.load();
      Eigen::Vector3d eye = eye_ahead(image_s + (age_s > 0 ? age_s : 0.5 * period_s) +
                                      options_.display_lag_s);
      auto drawn = draw_scene(*fr, scene, eye, {}, true);
      if (drawn) {
        SceneImage& img = handoff_->back();
        fr->read_image(img.rgba);
        img.eye = eye;
        img.from_cache = drawn->from_cache;
        img.held = drawn->held;
        img.shift_px = drawn->shift_px;
        img.done = SteadyClock::now();
        handoff_->publish();
        m_.images_drawn.add();
        const double took = seconds(img.done - t0);
        image_s = n == 0 ? took : 0.9 * image_s + 0.1 * took;
        stages_.add(FrameStages::scene_image, took);
      }
      std::unique_lock lock(scene_mutex_);
      scene_wake_.wait_until(lock, t0 + period, [this] { return scene_stop_; });
    }
  }

  // scene_thread: the newest scene image as the frame's scene (its eye into `eye`); before the
  // first image, black (the masks are drawn over it all the same).
  Expected<projector_render::FrameInfo> load_scene_image(
      projector_render::FrameRenderer& fr, Eigen::Vector3d& eye,
      std::optional<SteadyClock::time_point>& image_done) {
    const auto t = SteadyClock::now();
    const SceneImage* img = handoff_->take();
    if (const uint64_t skipped = handoff_->skipped(); skipped > images_skipped_) {
      m_.images_unshown.add(skipped - images_skipped_);
      images_skipped_ = skipped;
    }
    projector_render::FrameInfo info;
    if (img) {
      fr.load_image(img->rgba);
      eye = img->eye;
      image_done = img->done;
      info.from_cache = img->from_cache;
      info.held = img->held;
      info.shift_px = img->shift_px;
    } else {
      black_.assign(std::size_t(fr.width()) * fr.height() * 4, 0);
      for (std::size_t i = 3; i < black_.size(); i += 4) black_[i] = 255;
      fr.load_image(black_);
    }
    stages_.add(FrameStages::load, seconds(SteadyClock::now() - t));
    return info;
  }

  // One frame; true when it drew a new mesh.
  bool render_one(projector_render::FrameRenderer& fr, Frame& st, WindowOutput* window) {
    const bool late = options_.late_latch;
    if (late && !scene_on_ && !st.prepared) prepare_ahead(fr, st, 0);  // the first frame
    const auto arrived = take_inputs();
    Eigen::Vector3d eye = late ? st.eye : eye_now();
    std::optional<SteadyClock::time_point> image_done;  // scene_thread: the image's read-back
    const int64_t start_ns = realtime_ns();
    auto t = SteadyClock::now();
    auto stage = [&](FrameStages::Stage s) {
      const auto now = SteadyClock::now();
      stages_.add(s, seconds(now - t));
      t = now;
    };
    std::optional<MaskPlan> plan;
    const int64_t lag_ns = int64_t(options_.display_lag_s * 1e9);
    if (auto p = planner_.plan(start_ns + int64_t(st.render_s * 1e9) + lag_ns))
      plan = std::move(*p);
    stage(FrameStages::mask);
    const std::span<const ActorMesh> masks =
        plan ? std::span<const ActorMesh>(plan->masks) : std::span<const ActorMesh>();
    Expected<projector_render::FrameInfo> drawn = projector_render::FrameInfo{};
    if (scene_on_) {  // the masks over the scene thread's newest image
      drawn = load_scene_image(fr, eye, image_done);
      t = SteadyClock::now();
      if (drawn) drawn->masks = fr.draw_masks(masks);
    } else if (late) {  // the masks over the scene drawn ahead
      drawn = std::move(st.drawn);
      st.prepared = false;
      if (drawn) drawn->masks = fr.draw_masks(masks);
    } else {
      drawn = draw_scene(fr, st.scene, eye, masks, false);
    }
    stage(FrameStages::draw);
    fr.finish();
    stage(FrameStages::finish);
    if (arrived) stages_.add(FrameStages::mesh_to_frame, seconds(t - *arrived));
    if (window) {  // on the projector: after the frame counts as rendered, like a display's lag
      window->show(fr.framebuffer(), fr.width(), fr.height());
      stage(FrameStages::present);
    }
    const int64_t done_ns = realtime_ns();
    if (image_done) {
      const double age = seconds(SteadyClock::now() - *image_done);
      stages_.add(FrameStages::scene_age, age);
      const double mean = image_age_s_.load();
      image_age_s_ = mean > 0 ? 0.95 * mean + 0.05 * age : age;
    }
    const double took = (done_ns - start_ns) * 1e-9;
    st.render_s = st.count++ == 0 ? took : 0.9 * st.render_s + 0.1 * took;
    m_.rendered.add();
    if (auto cpu = st.cpu.frame_done()) m_.cpu_per_frame_ms.set(*cpu * 1e3);
    if (drawn) {
      std::lock_guard lock(mutex_);
      eye_.good(eye);
    }
    if (plan) planner_.shown(*plan, done_ns + lag_ns);  // on the cloth
    m_.latency_p_ms.set(planner_.latency_s() * 1e3);
    m_.overrun_p_ms.set(planner_.overrun_s() * 1e3);
    m_.render_ms.set(st.render_s * 1e3);
    if (plan) m_.margin_mm.set(plan->margin.margin_m * 1e3);
    if (plan && plan->newest_capture_ns > 0)
      loop_.completed(plan->newest_frame, plan->newest_capture_ns);
    degraded_ = !drawn;
    if (options_.frame_every > 0 && st.count % uint64_t(options_.frame_every) == 0)
      publish_frame(fr, st.readback,
                    {projector_.camera.id, plan ? &*plan : nullptr, eye,
                     options_.form == projector_render::Form::two_pass, st.count, done_ns},
                    *frames_, stages_);
    return arrived.has_value();
  }

  ProjectorNodeOptions options_;
  ProjectorView view_;
  Projector projector_;
  std::mutex mutex_;  // guards what follows up to the loop (handlers vs the render thread)
  std::condition_variable wake_;
  bool stop_ = false;
  SceneMirror mirror_;
  MeshInbox inbox_;  // meshes for the render thread
  std::optional<double> head_speed_;
  Eigen::Vector3d head_velocity_ = Eigen::Vector3d::Zero();  // of the followed head
  std::optional<double> head_at_;  // when its last pose arrived (steady clock, seconds)
  EyeSource eye_;
  SteadyClock::time_point mesh_arrived_;  // of the newest mesh offered
  std::promise<Expected<void>> init_;
  std::atomic<bool> degraded_{false};
  runtime::Output<studio_ProjectorCalibration>* calibration_ = nullptr;
  runtime::Output<studio_ProjectorFrame>* frames_ = nullptr;
  MaskPlanner planner_;        // the render thread's alone
  std::unique_ptr<FitWorker> fits_;  // late_latch + fit_thread: the motion fits' thread
  // scene_thread: the scene thread's images, its stop flag and wake-up, its start's result.
  std::unique_ptr<SceneHandoff> handoff_;
  std::mutex scene_mutex_;
  std::condition_variable scene_wake_;
  bool scene_stop_ = false;  // guarded by scene_mutex_
  std::promise<Expected<void>> scene_ready_;
  bool scene_on_ = false;                 // the render thread's: images come from the thread
  uint64_t images_skipped_ = 0;           // the render thread's: handoff_.skipped() counted
  std::vector<std::uint8_t> black_;       // the render thread's: before the first image
  std::atomic<double> image_age_s_{0};    // the render thread's: images' mean age at use
  runtime::ServiceLoop loop_;  // stopped before the state above goes
  FrameStages stages_;         // the render thread's (gauges of loop_'s metrics)
  FrameMetrics m_;
};

}  // namespace

Expected<std::unique_ptr<runtime::Node>> make_projector_node(const ProjectorNodeOptions& options,
                                                             const Projector& projector,
                                                             runtime::NodeContext& context) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  auto view = ProjectorView::create(projector);
  if (!view) return fail("projector " + projector.camera.id + ": " + view.error().message);
  const Eigen::Vector3d eye(options.default_eye[0], options.default_eye[1], options.default_eye[2]);
  // The default eye must give a picture: it is what the projector shows without a head.
  if (auto ok = view->single_pass(eye); !ok && options.form == projector_render::Form::single_pass)
    return fail("default_eye: " + ok.error().message);
  if (auto ok = view->two_pass(eye); !ok) return fail("default_eye: " + ok.error().message);
  return std::unique_ptr<runtime::Node>(
      std::make_unique<ProjectorNode>(options, std::move(*view), projector, context));
}

}  // namespace studio::projector
