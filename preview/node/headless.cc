#include "headless.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "camera_matching.h"
#include "preview_node.h"
#include "runtime/metrics.h"
#include "runtime/signals.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "status_ticker.h"
#include "view_pipeline.h"
#include "wire/entity.h"

namespace studio::preview {
namespace {

using Clock = std::chrono::steady_clock;

bool write_png(const std::string& path, const std::vector<uint8_t>& rgba, int w, int h) {
  cv::Mat image(h, w, CV_8UC4, const_cast<uint8_t*>(rgba.data())), bgr;
  cv::cvtColor(image, bgr, cv::COLOR_RGBA2BGR);
  try {
    return cv::imwrite(path, bgr);
  } catch (const cv::Exception&) {
    return false;
  }
}

// The picture written beside `path` and renamed over it, so a reader never sees half a PNG.
bool replace_png(const std::string& path, const std::vector<uint8_t>& rgba, int w, int h) {
  const std::string tmp = path + ".part.png";
  if (!write_png(tmp, rgba, w, h)) return false;
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}

// [r, g, b] with 4 decimals.
std::string gains_json(const Eigen::Vector3f& g) {
  char b[64];
  std::snprintf(b, sizeof b, "[%.4f,%.4f,%.4f]", g.x(), g.y(), g.z());
  return b;
}

// {"on", "applied", "frames", "busy", "rig_frames", "rig_dropped", "pairs", "residual",
// "gains": {camera id: [r, g, b]}, "estimated": {...}}: the pipeline's colour balance at the end
// of the run (preview/rig_balance.h; frames pooled, busy: meshes due while the worker was still
// pooling; rig_frames: rig samples (every camera, their own estimate), rig_dropped: given up;
// gains are the estimate when applied, else 1).
std::string balance_json(const ViewPipeline& pipeline) {
  const BalanceSnapshot rb = pipeline.colour_balance();
  const offline::ColourBalance& b = rb.balance;
  char head[256];
  std::snprintf(head, sizeof head,
                "{\"on\":%s,\"applied\":%s,\"frames\":%d,\"busy\":%llu,\"rig_frames\":%llu,"
                "\"rig_dropped\":%llu,\"pairs\":%d,\"residual\":%.5f,\"gains\":{",
                pipeline.colour_balance_on() ? "true" : "false", b.applied ? "true" : "false",
                b.frames, (unsigned long long)pipeline.counts().balance_busy,
                (unsigned long long)pipeline.counts().balance_rig_frames,
                (unsigned long long)pipeline.counts().balance_rig_dropped, b.pairs, b.residual);
  std::string out = head;
  for (std::size_t i = 0; i < rb.cameras.size() && i < b.gains.size(); ++i)
    out += (i ? "," : "") + json_text(rb.cameras[i]) + ":" + gains_json(b.gains[i]);
  out += "},\"estimated\":{";
  for (std::size_t i = 0; i < rb.cameras.size() && i < b.estimated.size(); ++i)
    out += (i ? "," : "") + json_text(rb.cameras[i]) + ":" + gains_json(b.estimated[i]);
  return out + "}}";
}

int error(const std::string& message, int status) {
  std::fprintf(stderr, "studio-preview: %s\n", message.c_str());
  return status;
}

}  // namespace

int run_headless(const PreviewConfig& config, const HeadlessOptions& options) {
  // Before any thread (EGL's, DDS's) exists: they inherit the blocked signals.
  runtime::SignalWatcher signals({SIGINT, SIGTERM});
  if (!options.record.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.record, ec);
    if (ec) return error("--record: cannot create '" + options.record + "'", 2);
  }
  auto context = scene_render::HeadlessContext::create();
  if (!context) return error(context.error().message, 1);
  auto participant = wire::Participant::create(
      config.domain >= 0 ? dds_domainid_t(config.domain) : wire::default_domain(),
      config.dds_config);
  if (!participant) return error(participant.error().message, 1);
  runtime::Metrics metrics;
  runtime::NodeContext node_context{*participant, metrics, config.instance};
  const std::string requester = config.instance + "-" + std::to_string(::getpid());
  PreviewNode node(node_context, requester);
  if (auto ok = node.start(); !ok) return error(ok.error().message, 1);
  auto status = StatusTicker::create(node_context, node);
  if (!status) return error(status.error().message, 1);
  PipelineOptions po;
  po.blend = config.blend;
  po.blend_options.cameras = config.blend_cameras;
  po.wait = std::chrono::milliseconds(config.wait_ms);
  po.asset_root = config.asset_root;
  po.overlays = config.overlays;
  po.prefetch = options.every_s <= 0;  // low-rate pictures ask only for the meshes they draw
  po.carve_all_masks = config.carve_masks;
  po.colour_balance = config.colour_balance;
  po.balance_every = config.colour_balance_every;
  // Low-rate pictures sample no rig either: the capture servers answer for drawn meshes only.
  po.balance_rig_every =
      options.every_s > 0
          ? std::chrono::milliseconds(0)
          : std::chrono::milliseconds(std::lround(1000 * config.colour_balance_rig_s));
  auto pipeline = ViewPipeline::create(node, po);
  if (!pipeline) return error(pipeline.error().message, 1);
  status->before_publish([&] { (*pipeline)->report(metrics); });
  auto target = scene_render::RenderTarget::create(config.width, config.height);
  if (!target) return error(target.error().message, 1);

  std::ofstream log;
  if (!options.record.empty()) log.open(options.record + "/frames.jsonl");
  std::vector<uint8_t> rgba;
  const auto start = Clock::now();
  const bool every = options.every_s > 0;
  const double limit_s = options.duration_s > 0 ? options.duration_s
                         : every                ? 1e9  // until a signal
                                                : options.timeout_s;
  const auto deadline = start + std::chrono::duration<double>(limit_s);
  const auto interval = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(std::max(options.every_s, 0.0)));
  auto last_drawn = start - interval;
  int drawn = 0;
  std::string match_json;  // --match-cameras: each round's changes sent, or why not
  int match_rounds = 0;    // kMatchRounds at most; set to it to stop trying
  while (Clock::now() < deadline) {
    if (signals.wait(std::chrono::milliseconds(0))) break;
    status->tick();
    if (every && Clock::now() - last_drawn < interval) {  // not yet: no render, no requests
      std::this_thread::sleep_for(std::min<Clock::duration>(interval - (Clock::now() - last_drawn),
                                                            std::chrono::milliseconds(20)));
      continue;
    }
    if (options.frames > 0 && !(*pipeline)->has_work()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(3));
      continue;
    }
    target->bind();
    const FrameReport r = (*pipeline)->render(config.viewpoint, config.width, config.height, true);
    if (options.frames == 0) {
      if (Clock::now() - start >= std::chrono::duration<double>(options.settle_s)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    if (!r.new_mesh) continue;
    ++drawn;
    if (options.match_cameras && match_rounds < kMatchRounds) {
      // Again whenever the balance, pooled afresh after the last round, still applies: the
      // cameras it had not linked yet, and what the last round's estimate got wrong.
      const BalanceSnapshot b = (*pipeline)->colour_balance();
      if (b.balance.applied && b.balance.frames >= kMatchAutoFrames &&
          (!(*pipeline)->rig_sampling() ||
           (*pipeline)->rig_colour_balance().balance.frames >= kMatchRigFrames) &&
          largest_gain_offset(b.balance.estimated) > kMatchAutoOffset) {
        auto m = match_cameras(node, **pipeline);
        match_json += match_json.empty() ? "" : ",";
        if (m) {
          match_json += camera_match_json(*m);
          std::fprintf(stderr, "studio-preview: match cameras: %s\n",
                       camera_match_text(*m).c_str());
          // Nothing sent (every change within min_change, or clamped): the balance goes on.
          match_rounds = m->plan.changes.empty() ? kMatchRounds : match_rounds + 1;
        } else {
          match_json += "{\"error\":" + json_text(m.error().message) + "}";
          std::fprintf(stderr, "studio-preview: %s\n", m.error().message.c_str());
          match_rounds = kMatchRounds;
        }
      }
    }
    if (every) {
      last_drawn = Clock::now();
      target->read_rgba(rgba);
      if (!replace_png(options.screenshot, rgba, config.width, config.height))
        return error("cannot write '" + options.screenshot + "'", 1);
    }
    if (!options.record.empty()) {
      target->read_rgba(rgba);
      const std::string name = std::to_string(drawn) + ".png";
      if (!write_png(options.record + "/" + name, rgba, config.width, config.height))
        return error("--record: cannot write " + name, 1);
      log << "{\"image\":\"" << name << "\",\"source_frame\":" << r.source_frame
          << ",\"textured\":" << (r.textured ? "true" : "false") << ",\"cameras\":[";
      for (std::size_t i = 0; i < r.cameras.size(); ++i)
        log << (i ? "," : "") << "\"" << r.cameras[i] << "\"";
      log << "],\"carving_masks\":" << r.carving_masks << ",\"gains\":[";
      for (std::size_t i = 0; i < r.gains.size(); ++i)
        log << (i ? "," : "") << gains_json(r.gains[i]);
      log << "],\"estimated\":[";
      for (std::size_t i = 0; i < r.estimated.size(); ++i)
        log << (i ? "," : "") << gains_json(r.estimated[i]);
      log << "],\"balance_pooled\":" << (r.balance_pooled ? "true" : "false") << "}\n";
      log.flush();
    }
    if (!every && options.duration_s <= 0 && drawn >= options.frames) break;
  }
  target->bind();
  target->read_rgba(rgba);
  const bool written = replace_png(options.screenshot, rgba, config.width, config.height);
  (*pipeline)->finish_colour_balance();  // the summary includes the mesh the worker holds
  const PipelineCounts& c = (*pipeline)->counts();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const OverlayCounts o = node.overlays().counts();
  if (options.json)
    std::printf(
        "{\"screenshot\":\"%s\",\"width\":%d,\"height\":%d,\"meshes\":%llu,"
        "\"textured\":%llu,\"untextured\":%llu,\"late\":%llu,\"refused\":%llu,"
        "\"skipped\":%llu,\"seconds\":%.3f,\"renderer\":\"%s\",\"overlays\":{\"heads\":%zu,"
        "\"cameras\":%zu,\"projectors\":%zu,\"thumbnails\":%zu},\"colour_balance\":%s,"
        "\"camera_match\":%s}\n",
        options.screenshot.c_str(), config.width, config.height, (unsigned long long)c.meshes,
        (unsigned long long)c.textured, (unsigned long long)c.untextured,
        (unsigned long long)c.late, (unsigned long long)c.refused, (unsigned long long)c.skipped,
        seconds, context->renderer().c_str(), o.heads, node.cameras().size(), o.projectors,
        o.thumbnails, balance_json(**pipeline).c_str(),
        match_json.empty() && !options.match_cameras ? "null" : ("[" + match_json + "]").c_str());
  else
    std::printf(
        "%s: %dx%d, %d meshes drawn (%llu textured, %llu untextured: %llu late, %llu refused; "
        "%llu skipped) in %.1f s, %s\n",
        options.screenshot.c_str(), config.width, config.height, drawn,
        (unsigned long long)c.textured, (unsigned long long)c.untextured,
        (unsigned long long)c.late, (unsigned long long)c.refused, (unsigned long long)c.skipped,
        seconds, context->renderer().c_str());
  for (const auto& p : (*pipeline)->asset_problems())
    std::fprintf(stderr, "asset: %s\n", p.c_str());
  status->stopping();
  node.stop();
  if (!written) return error("cannot write '" + options.screenshot + "'", 1);
  if (every && drawn == 0) return error("no mesh drawn", 1);
  if (!every && options.duration_s <= 0 && drawn < options.frames)
    return error("only " + std::to_string(drawn) + " of " + std::to_string(options.frames) +
                     " meshes within " + std::to_string(int(options.timeout_s)) + " s",
                 1);
  return 0;
}

}  // namespace studio::preview
