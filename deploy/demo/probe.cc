#include "probe.h"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <fstream>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "core/clock.h"
#include "report.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"
#include "yaml_io/rig_yaml.h"

namespace studio::demo {

Expected<void> ProbeOptions::validate() const {
  if (studio.camera_ids.empty()) return fail("no cameras (give the capture configs)");
  if (studio.camera_ids.size() > 64) return fail("at most 64 cameras");
  if (!(seconds >= 1 && seconds <= 3600)) return fail("--seconds: expected 1..3600");
  if (!(warmup_s >= 0 && warmup_s <= 600)) return fail("--warmup: expected 0..600");
  if (!(ready_timeout_s >= 1 && ready_timeout_s <= 600)) return fail("--ready-timeout: 1..600");
  if (!(score_rate_hz >= 0 && score_rate_hz <= 100)) return fail("--score-rate: expected 0..100");
  if (!(display_lag_s > 0 && display_lag_s <= 1)) return fail("--display-lag: expected (0, 1] s");
  return {};
}

namespace {

using namespace std::chrono_literals;

// SCHED_FIFO priority of the scoring threads of a real-time probe: below the probe's receive
// path (45) and every pipeline stage (50..58), above every time-sharing process.
constexpr int kScoringPriority = 41;

void read_loadavg(double out[3]) {
  std::ifstream f("/proc/loadavg");
  f >> out[0] >> out[1] >> out[2];
}

std::string state_name(int s) {
  static const char* names[] = {"starting", "running", "degraded", "stopping", "failed"};
  return s >= 0 && s < 5 ? names[s] : "unknown";
}

std::string this_host() {
  char buf[256] = {};
  gethostname(buf, sizeof buf - 1);
  return buf;
}

hull::Mesh mesh_from_wire(const studio_ActorMesh& s) {
  hull::Mesh m;
  const float* v = s.vertices._buffer;
  for (uint32_t i = 0; i + 2 < s.vertices._length; i += 3)
    m.vertices.emplace_back(v[i], v[i + 1], v[i + 2]);
  const uint32_t* t = s.triangles._buffer;
  for (uint32_t i = 0; i + 2 < s.triangles._length; i += 3)
    m.triangles.push_back({t[i], t[i + 1], t[i + 2]});
  return m;
}

// Everything the DDS callbacks (Cyclone's receive threads) write, behind one mutex; the scoring
// thread does the expensive work (truth rendering) outside the callbacks.
class Recorder {
 public:
  explicit Recorder(const ProbeOptions& o) : o_(o), host_(this_host()) {
    for (std::size_t i = 0; i < o.studio.camera_ids.size(); ++i)
      index_[o.studio.camera_ids[i]] = int(i);
  }

  Expected<void> start(const wire::Participant& p) {
    auto io = wire::gather([](auto&&... e) { return Io{std::move(e)...}; },
                           wire::Subscription<studio_CameraCalibration>::create(p),
                           wire::Subscription<studio_AlphaMask>::create(p, {}, 8),
                           wire::Subscription<studio_SegmentSet>::create(p, {}, 8),
                           wire::Subscription<studio_ActorMesh>::create(p, {}, 8),
                           wire::Subscription<studio_HeadPose>::create(p, {}, 8),
                           wire::Subscription<studio_ServiceStatus>::create(p, {}, 8),
                           wire::Subscription<studio_ProjectorCalibration>::create(p),
                           wire::Subscription<studio_ProjectorFrame>::create(p, {}, 8));
    if (!io) return std::unexpected(io.error());
    io_ = std::make_unique<Io>(std::move(*io));
    scorer_thread_ = std::thread([this] { score_loop(); });
    projector_thread_ = std::thread([this] { projector_loop(); });
    auto ok = [](const Expected<void>& r) { return bool(r); };
    if (!ok(io_->cals->on_data_available([this] { on_calibration(); })) ||
        !ok(io_->masks->on_data_available([this] { on_mask(); })) ||
        !ok(io_->segments->on_data_available([this] { on_segments(); })) ||
        !ok(io_->meshes->on_data_available([this] { on_mesh(); })) ||
        !ok(io_->heads->on_data_available([this] { on_head(); })) ||
        !ok(io_->status->on_data_available([this] { on_status(); })) ||
        !ok(io_->proj_cals->on_data_available([this] { on_projector_calibration(); })) ||
        !ok(io_->proj_frames->on_data_available([this] { on_projector_frame(); })))
      return fail("could not install the DDS listeners");
    return {};
  }

  void stop() {
    if (io_) {  // removing a listener waits for a running callback
      for (wire::ReaderBase* r : std::initializer_list<wire::ReaderBase*>{
               &*io_->cals, &*io_->masks, &*io_->segments, &*io_->meshes, &*io_->heads,
               &*io_->status, &*io_->proj_cals, &*io_->proj_frames})
        (void)r->on_data_available({});
    }
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    if (scorer_thread_.joinable()) scorer_thread_.join();
    if (projector_thread_.joinable()) projector_thread_.join();
    if (io_) {
      c_.masks_rejected = io_->masks->rejected().total();
      c_.meshes_rejected = io_->meshes->rejected().total();
      c_.projector_frames_rejected = io_->proj_frames->rejected().total();
    }
  }

  // Ready: every camera's calibration and a first mesh.
  bool ready(std::string* why) {
    std::lock_guard lock(mutex_);
    if (cameras_.size() < o_.studio.camera_ids.size()) {
      *why = "calibrations of " + std::to_string(cameras_.size()) + " of " +
             std::to_string(o_.studio.camera_ids.size()) + " cameras arrived";
      return false;
    }
    if (!first_mesh_) {
      *why = "no actor mesh arrived (is the hull running?)";
      return false;
    }
    return true;
  }

  // Builds the truth from the published calibrations (in config order).
  Expected<void> make_truth() {
    std::vector<Camera> cams;
    {
      std::lock_guard lock(mutex_);
      for (const auto& id : o_.studio.camera_ids) cams.push_back(cameras_.at(id));
    }
    if (!o_.rig.empty()) check_rig(cams);
    auto t = TruthScorer::create(std::move(cams));
    if (!t) return std::unexpected(t.error());
    std::lock_guard lock(mutex_);
    truth_ = std::make_unique<TruthScorer>(std::move(*t));
    return {};
  }

  void open_window(int64_t start_ns, int64_t end_ns) {
    std::lock_guard lock(mutex_);
    c_.window_start_ns = start_ns;
    c_.window_end_ns = end_ns;
    read_loadavg(c_.load_start);
    c_.probe_start = read_proc(getpid());
    for (auto& [key, s] : services_)
      if (s.host == host_) s.proc_start = read_proc(s.pid);
  }

  void close_window() {
    std::lock_guard lock(mutex_);
    read_loadavg(c_.load_end);
    c_.probe_end = read_proc(getpid());
    for (auto& [key, s] : services_)
      if (s.host == host_ && s.proc_start) s.proc_end = read_proc(s.pid);
  }

  // One progress line: the last whole second of capture times (frames at least 0.3 s old).
  std::string progress_line(int64_t now_ns, double t_s, const char* phase) {
    std::lock_guard lock(mutex_);
    const int64_t hi = now_ns - 300'000'000, lo = hi - 1'000'000'000;
    int meshes = 0, heads = 0, masks = 0, frames = 0;
    std::vector<double> lat;
    for (auto it = c_.frames.lower_bound(frame_at(lo)); it != c_.frames.end(); ++it) {
      const FrameTimes& f = it->second;
      if (f.capture_ns >= hi) break;
      if (f.capture_ns < lo) continue;
      ++frames;
      masks += f.masks;
      if (f.mesh_ns) {
        ++meshes;
        lat.push_back(double(std::max(f.mesh_ns, f.head_ns) - f.capture_ns) * 1e-6);
      }
      if (f.head_ns) ++heads;
    }
    const int expected_frames = int(1e9 / double(o_.studio.clock.period_ns) + 0.5);
    const int lost = int(o_.studio.camera_ids.size()) * expected_frames - masks;
    std::sort(lat.begin(), lat.end());
    char buf[320];
    const double p50 = lat.empty() ? 0 : lat[lat.size() / 2];
    const double mx = lat.empty() ? 0 : lat.back();
    const double iou = c_.mesh_scores.empty() ? -1 : c_.mesh_scores.back().mean_iou;
    const double head = c_.heads.empty() ? -1 : c_.heads.back().error_m;
    char iou_s[16] = "n/a", head_s[16] = "n/a";
    if (iou >= 0) std::snprintf(iou_s, sizeof iou_s, "%.3f", iou);
    if (head >= 0) std::snprintf(head_s, sizeof head_s, "%.3f m", head);
    std::snprintf(buf, sizeof buf,
                  "[demo] %-7s %5.1f s  masks/s %5.1f  meshes/s %4.1f  heads/s %4.1f  "
                  "latency p50 %5.1f ms max %5.1f ms  masks lost %d  iou %s  head err %s",
                  phase, t_s, double(masks), double(meshes), double(heads), p50, mx,
                  std::max(0, lost), iou_s, head_s);
    return buf;
  }

  // OUT/actor_view.png: the pictured projector frame (its thumbnail scaled to the projector's
  // size, its full-resolution blackout black) on the cloth from the true eye at display time.
  void write_actor_view(const Collected& c, const std::string& path) const {
    if (!c.projector_picture || !truth_) return;
    const ProjectorPicture& p = *c.projector_picture;
    const auto it = projectors_.find(p.projector_id);
    if (it == projectors_.end() || p.thumb_width <= 0 ||
        p.thumbnail.size() != std::size_t(p.thumb_width) * p.thumb_height * 3)
      return;
    const Camera& cam = it->second.camera;
    cv::Mat thumb(p.thumb_height, p.thumb_width, CV_8UC3, const_cast<uint8_t*>(p.thumbnail.data()));
    cv::Mat full;
    cv::resize(thumb, full, cv::Size(cam.width, cam.height), 0, 0, cv::INTER_LINEAR);
    Image<Rgb8> frame(cam.width, cam.height);
    for (int y = 0; y < cam.height; ++y) {
      const auto* row = full.ptr<cv::Vec3b>(y);
      for (int x = 0; x < cam.width; ++x)
        frame(x, y) =
            p.blackout.contains(x, y) ? Rgb8{0, 0, 0} : Rgb8{row[x][0], row[x][1], row[x][2]};
    }
    auto view = truth_->actor_view(it->second, p.studio_frame, o_.display_lag_s, std::move(frame));
    if (!view) {
      std::fprintf(stderr, "[demo] actor view: %s\n", view.error().message.c_str());
      return;
    }
    cv::Mat rgb(view->height(), view->width(), CV_8UC3, view->data());
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    cv::putText(bgr,
                p.projector_id + " render frame " + std::to_string(p.render_frame) +
                    ": the cloth from the true eye",
                {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1);
    if (!cv::imwrite(path, bgr)) std::fprintf(stderr, "[demo] could not write %s\n", path.c_str());
  }

  Collected finish(bool ready, const std::string& why) {
    std::lock_guard lock(mutex_);
    c_.ready = ready;
    c_.not_ready_reason = why;
    c_.calibrations = int(cameras_.size());
    c_.display_lag_s = o_.display_lag_s;
    for (auto& [key, s] : services_) c_.services.push_back(s);
    return std::move(c_);
  }

 private:
  struct Io {
    wire::Subscription<studio_CameraCalibration> cals;
    wire::Subscription<studio_AlphaMask> masks;
    wire::Subscription<studio_SegmentSet> segments;
    wire::Subscription<studio_ActorMesh> meshes;
    wire::Subscription<studio_HeadPose> heads;
    wire::Subscription<studio_ServiceStatus> status;
    wire::Subscription<studio_ProjectorCalibration> proj_cals;
    wire::Subscription<studio_ProjectorFrame> proj_frames;
  };
  struct ProjectorJob {
    ProjectorSample sample;
    RunMask blackout;
    int thumb_width = 0, thumb_height = 0;
    std::vector<uint8_t> thumbnail;
  };
  struct Job {
    bool is_head = false;
    uint64_t frame = 0;
    std::vector<hull::Mesh> meshes;
    Eigen::Vector3d head = Eigen::Vector3d::Zero();
    double confidence = 0;
  };

  uint64_t frame_at(int64_t ns) const { return o_.studio.clock.frame_at(ns); }
  // The capture instant of frame f as the sim source stamps it (capture/sim_source.h).
  int64_t capture_of(uint64_t f) const {
    return o_.studio.clock.time_of(f) + o_.studio.clock.period_ns / 2;
  }
  bool in_window(int64_t capture_ns) const {
    return c_.window_start_ns && capture_ns >= c_.window_start_ns && capture_ns < c_.window_end_ns;
  }
  FrameTimes& frame(uint64_t f, int64_t capture_ns) {
    FrameTimes& t = c_.frames[f];
    if (!t.capture_ns) t.capture_ns = capture_ns;
    return t;
  }

  void on_calibration() {
    io_->cals->visit([&](const studio_CameraCalibration& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      auto cam = wire::to_core(s);
      if (!cam || !index_.contains(s.camera_id)) return;
      std::lock_guard lock(mutex_);
      cameras_.insert_or_assign(std::string(s.camera_id), *cam);
    });
  }

  void on_mask() {
    const int64_t now = realtime_ns();
    io_->masks->visit([&](const studio_AlphaMask& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      auto it = index_.find(s.camera_id);
      if (it == index_.end()) return;
      std::lock_guard lock(mutex_);
      FrameTimes& t = frame(s.frame, s.capture_ns);
      const uint64_t bit = uint64_t(1) << it->second;
      if (t.mask_bits & bit) return;
      t.mask_bits |= bit;
      ++t.masks;
      t.last_mask_ns = std::max(t.last_mask_ns, now);
    });
  }

  void on_segments() {
    const int64_t now = realtime_ns();
    io_->segments->visit([&](const studio_SegmentSet& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      std::lock_guard lock(mutex_);
      FrameTimes& t = frame(s.frame, s.capture_ns);
      if (!t.segments_ns) t.segments_ns = now;
    });
  }

  void on_mesh() {
    const int64_t now = realtime_ns();
    io_->meshes->visit([&](const studio_ActorMesh& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      std::lock_guard lock(mutex_);
      first_mesh_ = true;
      FrameTimes& t = frame(s.frame, s.capture_ns);
      t.mesh_ns = std::max(t.mesh_ns, now);
      // Scoring: a frame is picked when its first mesh arrives and the scorer is free; its other
      // actors' meshes follow back to back; the next frame's mesh hands the frame to the scorer.
      if (collecting_ && s.frame != collecting_->frame) {
        jobs_.push_back(std::move(*collecting_));
        collecting_.reset();
        wake_.notify_all();
      }
      if (collecting_) {
        collecting_->meshes.push_back(mesh_from_wire(s));
      } else if (truth_ && in_window(s.capture_ns) && jobs_.empty() && !scoring_ &&
                 o_.score_rate_hz > 0 && now - last_pick_ns_ >= int64_t(1e9 / o_.score_rate_hz)) {
        last_pick_ns_ = now;
        collecting_ = Job{false, s.frame, {mesh_from_wire(s)}, Eigen::Vector3d::Zero(), 0};
      }
    });
  }

  void on_head() {
    const int64_t now = realtime_ns();
    io_->heads->visit([&](const studio_HeadPose& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data || o_.head_id != s.actor_id) return;
      // Keep-alive samples coast between frames: their capture_ns is not a frame's instant.
      if (s.capture_ns != capture_of(s.frame)) return;
      std::lock_guard lock(mutex_);
      FrameTimes& t = frame(s.frame, s.capture_ns);
      if (t.head_ns) return;
      t.head_ns = now;
      if (in_window(s.capture_ns)) {
        jobs_.push_back(
            Job{true, s.frame, {}, {s.position[0], s.position[1], s.position[2]}, s.confidence});
        wake_.notify_all();
      }
    });
  }

  void on_status() {
    const int64_t now = realtime_ns();
    io_->status->visit([&](const studio_ServiceStatus& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      std::lock_guard lock(mutex_);
      const std::string key = std::string(s.service) + ":" + s.instance;
      ServiceSeen& seen = services_[key];
      const bool first = seen.service.empty();
      seen.service = s.service;
      seen.instance = s.instance;
      seen.host = s.host;
      seen.pid = s.pid;
      seen.state = state_name(int(s.state));
      seen.input_hz = s.input_hz;
      seen.output_hz = s.output_hz;
      seen.latency_ms = s.latency_ms;
      seen.counters.clear();
      for (uint32_t i = 0; i < s.counters._length; ++i)
        seen.counters[s.counters._buffer[i].name] = s.counters._buffer[i].value;
      if (c_.window_start_ns && now >= c_.window_start_ns && now < c_.window_end_ns) {
        if (!seen.have_start) {
          seen.counters_at_start = seen.counters;
          seen.have_start = true;
        }
        seen.output_hz_sum += s.output_hz;
        seen.input_hz_sum += s.input_hz;
        ++seen.statuses_in_window;
      }
      // A service first seen after the window opened: its CPU is measured from now.
      if (first && c_.window_start_ns && now < c_.window_end_ns && seen.host == host_)
        seen.proc_start = read_proc(seen.pid);
    });
  }

  void on_projector_calibration() {
    io_->proj_cals->visit([&](const studio_ProjectorCalibration& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      auto p = wire::to_core(s);
      if (!p) return;
      std::lock_guard lock(mutex_);
      projectors_.insert_or_assign(std::string(s.projector_id), *p);
      c_.projector_calibrations[s.projector_id] = p->camera.width * p->camera.height;
    });
  }

  // Copies the frame's run table (small) for the projector scorer; the truth is computed there.
  void on_projector_frame() {
    io_->proj_frames->visit([&](const studio_ProjectorFrame& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      std::lock_guard lock(mutex_);
      // Frames rendered in the window, and the late frames of meshes captured in it (the probe
      // listens 0.5 s beyond it), so that a mesh captured at the window's end still counts.
      if (!c_.window_start_ns || s.render_done_ns < c_.window_start_ns) return;
      const bool after = s.render_done_ns >= c_.window_end_ns;
      if (after && !(s.frame && s.capture_ns >= c_.window_start_ns &&
                     s.capture_ns < c_.window_end_ns))
        return;
      ProjectorSample p;
      p.projector_id = s.projector_id;
      p.render_frame = s.render_frame;
      p.mesh_frame = s.frame;
      p.capture_ns = s.capture_ns;
      p.render_done_ns = s.render_done_ns;
      p.latency_ms = s.latency_ms;
      p.margin_m = s.margin_m;
      p.predicted = s.predicted;
      p.eye = Eigen::Vector3d(s.eye[0], s.eye[1], s.eye[2]);
      p.after_window = after;
      if (after) {  // its mesh's figures only
        c_.projector.push_back(std::move(p));
        return;
      }
      auto blackout = wire::to_core(s);
      if (!blackout || !truth_ || projector_jobs_.size() >= o_.projector_queue) {
        if (!blackout) note_projector_error(blackout.error().message);
        c_.projector.push_back(std::move(p));  // unscored
        return;
      }
      ProjectorJob job{
          std::move(p), std::move(*blackout), int(s.thumb_width), int(s.thumb_height), {}};
      job.thumbnail.assign(s.thumbnail._buffer, s.thumbnail._buffer + s.thumbnail._length);
      projector_jobs_.push_back(std::move(job));
      wake_.notify_all();
    });
  }

  void note_projector_error(const std::string& message) {  // with mutex_ held
    if (c_.projector_score_errors++ == 0) c_.projector_score_error = message;
  }

  // Scores every queued projector frame: the true actor at display time against its blackout.
  void projector_loop() {
    const Scheduling own = idle_until_drained();
    bool draining = false;
    while (true) {
      ProjectorJob job;
      const TruthScorer* truth = nullptr;
      std::optional<Projector> projector;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || !projector_jobs_.empty(); });
        if (projector_jobs_.empty()) return;
        if (stopping_ && !draining) {
          draining = true;
          scoring_scheduling(own);
        }
        job = std::move(projector_jobs_.front());
        projector_jobs_.pop_front();
        truth = truth_.get();
        if (auto it = projectors_.find(job.sample.projector_id); it != projectors_.end())
          projector = it->second;
      }
      ProjectorSample& p = job.sample;
      // The simulator's clock: frame f (the actor at f / fps) is stamped capture_of(f).
      const double studio_frame =
          double(p.render_done_ns - capture_of(0)) / double(o_.studio.clock.period_ns);
      Mask actor;
      Expected<TruthScorer::Lit> lit = fail("no calibration of projector " + p.projector_id +
                                            " on studio/projector/calibration");
      if (projector)
        lit = truth->projector_lit(projector->camera, studio_frame, o_.display_lag_s, job.blackout,
                                   &actor);
      std::lock_guard lock(mutex_);
      if (!lit) {
        note_projector_error(lit.error().message);
      } else {
        p.scored = true;
        p.eye_error_m =
            (p.eye - truth->true_head_at(studio_frame + o_.display_lag_s * 1e9 /
                                                            double(o_.studio.clock.period_ns)))
                .norm();
        p.actor_px = lit->actor;
        p.lit_actor_px = lit->lit_actor;
        p.blackout_px = lit->blackout;
        p.wasted_px = lit->wasted;
        // The picture: the frame with the most lit actor pixels, else one with the actor in view.
        auto& pic = c_.projector_picture;
        if (!pic || p.lit_actor_px > pic->lit_actor_px ||
            (p.lit_actor_px == pic->lit_actor_px && pic->actor_px == 0 && p.actor_px > 0)) {
          pic = ProjectorPicture{
              p.projector_id,   p.render_frame,         p.lit_actor_px,   p.actor_px,
              studio_frame,     job.thumb_width,        job.thumb_height, std::move(job.thumbnail),
              std::move(actor), std::move(job.blackout)};
        }
      }
      c_.projector.push_back(std::move(p));
    }
  }

  // Scoring (truth rendering) is the probe's heavy work and not latency-critical, and the probe is
  // the instrument, not the studio: during the window its scoring threads take only CPU that no
  // service wants (SCHED_IDLE), so that the figures are the services', not the services' beside
  // the probe's scoring (at SCHED_FIFO 41 the scorers preempted every time-sharing service, the
  // projector included, ~4 CPU ms per 40 ms frame). What they have not scored by the window's end
  // waits in the queues (projector frames up to projector_queue) and is scored in stop(), the
  // threads back at their scheduling for it (scoring_scheduling): when the probe runs real-time
  // (deploy/demo.sh: SCHED_FIFO 45), kScoringPriority, below every pipeline stage.
  struct Scheduling {
    int policy = SCHED_OTHER;
    sched_param param{};
  };
  static Scheduling idle_until_drained() {
    Scheduling own;
    (void)pthread_getschedparam(pthread_self(), &own.policy, &own.param);
    sched_param idle{};
    (void)pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle);
    return own;
  }
  static void scoring_scheduling(const Scheduling& own) {
    (void)pthread_setschedparam(pthread_self(), own.policy, &own.param);
    lower_to_scoring_priority();
  }
  static void lower_to_scoring_priority() {
    int policy = SCHED_OTHER;
    sched_param param{};
    if (pthread_getschedparam(pthread_self(), &policy, &param) != 0) return;
    if (policy != SCHED_FIFO && policy != SCHED_RR) return;
    param.sched_priority = std::min(param.sched_priority, kScoringPriority);
    pthread_setschedparam(pthread_self(), policy, &param);
  }

  void score_loop() {
    const Scheduling own = idle_until_drained();
    bool draining = false;
    while (true) {
      Job job;
      const TruthScorer* truth = nullptr;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
        if (jobs_.empty()) return;  // stopping, and every queued job scored
        if (stopping_ && !draining) {
          draining = true;
          scoring_scheduling(own);
        }
        job = std::move(jobs_.front());
        jobs_.pop_front();
        truth = truth_.get();
        scoring_ = !job.is_head;
      }
      if (job.is_head) {
        HeadSample h{job.frame, truth->head_error(job.frame, job.head), job.confidence};
        std::lock_guard lock(mutex_);
        c_.heads.push_back(h);
      } else {
        MeshScore m = truth->score_meshes(job.frame, job.meshes);
        std::lock_guard lock(mutex_);
        c_.mesh_scores.push_back(m);
        scoring_ = false;
      }
    }
  }

  void check_rig(const std::vector<Camera>& published) {
    auto rig = yaml::read_rig(o_.rig);
    if (!rig) {
      c_.rig_detail = rig.error().message;
      return;
    }
    double worst = 0;
    std::string detail;
    for (const Camera& p : published) {
      const Camera* r = rig->find_camera(p.id);
      if (!r) {
        detail += p.id + " not in the rig; ";
        worst = std::max(worst, 1e9);
        continue;
      }
      const double d = std::max(
          {(r->cam_from_world.matrix() - p.cam_from_world.matrix()).cwiseAbs().maxCoeff(),
           std::abs(r->intrinsics.fx - p.intrinsics.fx),
           std::abs(r->intrinsics.cx - p.intrinsics.cx), std::abs(double(r->width - p.width))});
      worst = std::max(worst, d);
    }
    c_.rig_max_diff = worst;
    c_.rig_detail = detail.empty() ? "every published camera is in the rig" : detail;
  }

  const ProbeOptions& o_;
  const std::string host_;
  std::map<std::string, int, std::less<>> index_;
  std::unique_ptr<Io> io_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false, scoring_ = false, first_mesh_ = false;
  int64_t last_pick_ns_ = 0;
  std::map<std::string, Camera> cameras_;
  std::map<std::string, Projector> projectors_;  // studio/projector/calibration
  std::deque<ProjectorJob> projector_jobs_;
  std::thread projector_thread_;
  std::map<std::string, ServiceSeen> services_;
  std::unique_ptr<TruthScorer> truth_;
  std::optional<Job> collecting_;
  std::deque<Job> jobs_;
  std::thread scorer_thread_;
  Collected c_;
};

}  // namespace

Expected<std::string> run_probe(const ProbeOptions& o) {
  if (auto v = o.validate(); !v) return std::unexpected(v.error());
  auto participant = wire::Participant::create();
  if (!participant) return std::unexpected(participant.error());
  Recorder rec(o);
  if (auto r = rec.start(*participant); !r) return std::unexpected(r.error());

  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  auto say = [&](const std::string& line) {
    if (o.progress) std::fprintf(stderr, "%s\n", line.c_str());
  };
  std::string why;
  bool ready = false;
  double next_line = 1;
  while (elapsed() < o.ready_timeout_s) {
    if ((ready = rec.ready(&why))) break;
    if (elapsed() >= next_line) {
      say("[demo] waiting " + std::to_string(int(elapsed())) + " s: " + why);
      next_line += 1;
    }
    std::this_thread::sleep_for(100ms);
  }
  if (ready) {
    if (auto t = rec.make_truth(); !t) {
      rec.stop();
      return std::unexpected(t.error());
    }
    const int64_t start = realtime_ns() + int64_t(o.warmup_s * 1e9);
    const int64_t end = start + int64_t(o.seconds * 1e9);
    rec.open_window(start, end);
    const auto w0 = std::chrono::steady_clock::now();
    const double total = o.warmup_s + o.seconds + 0.5;  // + the pipeline's tail for late frames
    for (int s = 1; s <= int(std::ceil(total)); ++s) {
      std::this_thread::sleep_until(
          w0 + std::chrono::milliseconds(int64_t(std::min(double(s), total) * 1000)));
      const double t = std::min(double(s), total);
      say(rec.progress_line(realtime_ns(), t < o.warmup_s ? t : t - o.warmup_s,
                            t < o.warmup_s ? "warmup" : "measure"));
    }
    rec.close_window();
  } else {
    say("[demo] not ready after " + std::to_string(int(o.ready_timeout_s)) + " s: " + why);
  }
  rec.stop();
  Collected c = rec.finish(ready, why);
  if (!o.actor_view_png.empty()) rec.write_actor_view(c, o.actor_view_png);
  return make_report(o, c);
}

}  // namespace studio::demo
