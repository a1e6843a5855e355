// studio-preview against the running simulated studio (processes on loopback, issue 16):
//  - frame-exact texturing: the actor wears its frame number (sim/frame_code.h); read from the
//    preview's *rendered pixels* at the bands' projected centres, it equals the drawn mesh's
//    source frame every time, over a run of >= 1000 studio frames; >= 95 % of drawn meshes are
//    textured; the scene (the museum, from studio/scene/node) is drawn around the actor;
//  - quality against truth: a held-out camera that feeds nothing; the preview from its pose vs
//    the simulator's image of that camera over the union of the true and rendered silhouettes,
//    PSNR of nearest-camera texturing and of the blend: the blend beats nearest (the issue's
//    28 dB is not reached with the visual hull: see the test and preview_quality_test.cc).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <set>
#include <thread>

#include "preview/viewpoint.h"
#include "scene/view.h"
#include "sim/frame_code.h"
#include "sim/studio.h"
#include "testing/studio_fixture.h"
#include "wire/endpoint.h"
#include "wire/sample.h"

namespace studio::preview::testing {
namespace {

struct Record {
  std::string image;
  uint64_t source_frame = 0;
  bool textured = false;
};

std::vector<Record> read_records(const std::filesystem::path& file) {
  std::vector<Record> out;
  std::ifstream in(file);
  const std::regex re(R"re("image":"([^"]+)","source_frame":(\d+),"textured":(true|false))re");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, re)) out.push_back({m[1], std::stoull(m[2]), m[3] == "true"});
  }
  return out;
}

Eigen::Matrix4d clip_from_world(const Viewpoint& v, int w, int h) {
  return scene::perspective(v.fov_deg * std::numbers::pi / 180, double(w) / h, 0.05, 200.0) *
         scene::look_at(v.eye, v.at);
}

// The frame code read from a rendered preview image (BGR), or nullopt when a band is hidden from
// the viewpoint (by the true body at that frame) or does not read as one digit. Robust to the
// blend mixing neighbouring bands where cameras disagree on where a band is (red and green mix
// to yellow at a band's edge): each band is read at three heights (a quarter, half and three
// quarters of it) over 3x3 pixels each, every pixel classified on its own; the band's digit is
// the majority of the 27 when it has more than half of them and at least three times the votes
// of any other digit, else the band (and the frame) is unread: counted, never a mismatch.
std::optional<int> decode_preview(const cv::Mat& bgr, const Viewpoint& view,
                                  const sim::ActorBody& body) {
  const Eigen::Matrix4d clip = clip_from_world(view, bgr.cols, bgr.rows);
  std::vector<int> digits;
  for (int b = 0; b < sim::frame_code::kBands; ++b) {
    int votes[3] = {0, 0, 0};
    for (const double along : {0.25, 0.5, 0.75}) {
      const Eigen::Vector3d x = sim::frame_code::band_point(body, b, view.eye, along);
      const auto hit = body.ray_hit(view.eye, (x - view.eye).normalized());
      if (!hit || hit->part != int(sim::PartId::torso) || (hit->point - x).norm() > 0.01)
        return std::nullopt;
      bool ok = false;
      const Eigen::Vector2d p = scene::project_to_pixel(clip, x, bgr.cols, bgr.rows, &ok);
      const int u = int(p.x()), v = int(p.y());
      if (!ok || u < 2 || v < 2 || u >= bgr.cols - 2 || v >= bgr.rows - 2) return std::nullopt;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const cv::Vec3b px = bgr.at<cv::Vec3b>(v + dy, u + dx);
          const int d = sim::frame_code::classify(px[2], px[1], px[0]);  // BGR → RGB
          if (d >= 0) ++votes[d];
        }
    }
    const int best = int(std::max_element(votes, votes + 3) - votes);
    int runner_up = 0;
    for (int d = 0; d < 3; ++d)
      if (d != best) runner_up = std::max(runner_up, votes[d]);
    if (2 * votes[best] <= 27 || votes[best] < 3 * runner_up) return std::nullopt;
    digits.push_back(best);
  }
  return sim::frame_code::decode(digits);
}

TEST_F(PreviewStudioTest, BadInputIsOneLineAndExitTwo) {
  std::ofstream(dir_ / "bad.yaml") << "instance: x\ntexturing: sharpest\n";
  std::ofstream(dir_ / "unknown.yaml") << "instance: x\nzoom: 3\n";
  std::ofstream(dir_ / "every.yaml") << "instance: x\ncolour_balance_every: 0\n";
  const std::vector<std::vector<std::string>> cases{
      {"--config", (dir_ / "bad.yaml").string(), "--headless", "--screenshot", "a.png"},
      {"--config", (dir_ / "unknown.yaml").string(), "--headless", "--screenshot", "a.png"},
      {"--config", (dir_ / "missing.yaml").string()},
      {"--viewpoint", "eye=1,2,at=0,0,0", "--headless", "--screenshot", "a.png"},
      {"--headless"},
      {"--frames", "-3", "--headless", "--screenshot", "a.png"},
      {"--every", "0.01", "--headless", "--screenshot", "a.png"},
      {"--colour-balance", "maybe", "--headless", "--screenshot", "a.png"},
      {"--config", (dir_ / "every.yaml").string(), "--headless", "--screenshot", "a.png"},
      {"--every", "2", "--frames", "0", "--headless", "--screenshot", "a.png"},
      {"--screenshot", "a.png"},
      {"--match-cameras"},
      {"--bogus"}};
  for (const auto& args : cases) {
    Process& p = spawn("bad", "preview/studio-preview", args);
    const auto code = p.wait_exit(std::chrono::seconds(20));
    ASSERT_TRUE(code.has_value());
    EXPECT_EQ(*code, 2) << args[0] << " " << p.log();
    const std::string log = p.log();
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
    EXPECT_EQ(log.rfind("studio-preview: ", 0), 0u) << log;
  }
  // Positive control: a good config and --help succeed.
  Process& help = spawn("help", "preview/studio-preview", {"--help"});
  EXPECT_EQ(help.wait_exit(std::chrono::seconds(20)), 0);
  EXPECT_NE(help.log().find("--headless"), std::string::npos);
  EXPECT_NE(help.log().find("--match-cameras"), std::string::npos);
}

// Like every service, the preview publishes studio/service/status: service "preview", its
// instance, RUNNING with its counters while it runs, STOPPING at the end (so the other
// previews' and studioctl's services panels list it).
TEST_F(PreviewStudioTest, PublishesItsServiceStatus) {
  auto participant = wire::Participant::create().value();
  auto topic = wire::Topic<studio_ServiceStatus>::create(participant).value();
  auto reader = wire::Reader<studio_ServiceStatus>::create(participant, topic).value();
  Process& p = spawn("preview", "preview/studio-preview",
                     {"--headless", "--config", preview_config("operator"), "--size", "64x48",
                      "--duration", "4", "--screenshot", (dir_ / "s.png").string()});
  bool running = false, stopping = false, counters = false;
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < deadline && !stopping) {
    for (auto& s : reader.take()) {
      if (!s.meta.valid_data) continue;
      EXPECT_STREQ(s.data->service, "preview");
      EXPECT_STREQ(s.data->instance, "operator");
      EXPECT_EQ(s.data->pid, p.pid());
      running |= s.data->state == studio_SERVICE_RUNNING;
      stopping |= s.data->state == studio_SERVICE_STOPPING;
      for (const auto& c : wire::view(s.data->counters))
        counters |= std::string(c.name) == "meshes_in";
    }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(running);
  EXPECT_TRUE(stopping);
  EXPECT_TRUE(counters) << "the node's counters are in the status";
  EXPECT_EQ(p.wait_exit(30s), 0) << p.log();
}

TEST_F(PreviewStudioTest, TexturesEveryMeshWithTheImagesOfItsOwnFrame) {
  start_studio(true);
  const Viewpoint view{{0.6, 1.9, 3.7}, {0, 1.1, 0}, 54.4};
  const auto rec = dir_ / "rec";
  // A run of ~45 s: >= 1000 studio frames (25 fps) pass while meshes are drawn.
  Process& p = spawn("preview", "preview/studio-preview",
                     {"--headless", "--config", preview_config("director"), "--viewpoint",
                      to_string(view), "--size", "704x576", "--duration", "45", "--record",
                      rec.string(), "--screenshot", (dir_ / "shot.png").string(), "--json"});
  const auto code = p.wait_exit(std::chrono::seconds(120));
  ASSERT_TRUE(code.has_value()) << "preview did not finish";
  ASSERT_EQ(*code, 0) << p.log();
  const auto records = read_records(rec / "frames.jsonl");
  ASSERT_GE(records.size(), 10u) << p.log();
  auto studio = sim::SimulatedStudio::create(cameras(),
                                             [] {
                                               sim::StudioOptions o;
                                               o.frame_code = true;
                                               return o;
                                             }())
                    .value();
  int textured = 0, decoded = 0, mismatched = 0;
  for (const Record& r : records) {
    if (!r.textured) continue;
    ++textured;
    const cv::Mat img = cv::imread((rec / r.image).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(img.empty()) << r.image;
    const auto v = decode_preview(img, view, studio.truth(int64_t(r.source_frame)).body);
    if (!v) continue;
    ++decoded;
    if (*v != int(r.source_frame % sim::frame_code::kModulus)) {
      ++mismatched;
      ADD_FAILURE() << r.image << ": decoded " << *v << ", mesh frame " << r.source_frame
                    << " (mod 81 = " << r.source_frame % 81 << ")";
    }
  }
  const uint64_t span = records.back().source_frame - records.front().source_frame;
  std::printf(
      "frame-exact: %zu meshes drawn over %llu studio frames, %d textured, %d decoded "
      "from the rendered pixels, %d mismatched\n%s\n",
      records.size(), (unsigned long long)span, textured, decoded, mismatched, p.log().c_str());
  EXPECT_EQ(mismatched, 0);
  EXPECT_GE(span, 1000u) << "the run must cover >= 1000 studio frames";
  EXPECT_GE(textured, int(std::ceil(0.95 * double(records.size()))));
  EXPECT_GE(decoded, textured / 2) << "the code must be readable in most textured frames";
  // The scene around the actor: most of the screenshot is not the clear colour.
  const cv::Mat shot = cv::imread((dir_ / "shot.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(shot.empty());
  int background = 0;
  for (int y = 0; y < shot.rows; ++y)
    for (int x = 0; x < shot.cols; ++x) {
      const cv::Vec3b c = shot.at<cv::Vec3b>(y, x);
      background +=
          std::abs(c[0] - 18) <= 2 && std::abs(c[1] - 13) <= 2 && std::abs(c[2] - 13) <= 2;
    }
  EXPECT_LT(background, shot.rows * shot.cols / 2) << "the museum is not drawn";
}

// PSNR over the union of the true silhouette (the simulator's mask of the held-out camera) and
// the rendered one (pixels that are not the renderer's clear colour), pooled over the frames.
struct Score {
  double squared = 0;
  uint64_t samples = 0;
  int frames = 0;
  // Pixels by where they fall: both silhouettes, only the rendered, only the true.
  uint64_t both = 0, rendered_only = 0, true_only = 0;
  double squared_both = 0, squared_rendered_only = 0, squared_true_only = 0;
  double psnr() const { return 10 * std::log10(255.0 * 255.0 / (squared / double(samples))); }
  double psnr_both() const {
    return 10 * std::log10(255.0 * 255 / (squared_both / (3.0 * double(both))));
  }
};

Score score(const std::vector<Record>& records, const std::filesystem::path& dir,
            const sim::SimulatedStudio& truth_studio) {
  Score s;
  Image<Rgb8> truth;
  Mask mask;
  for (const Record& r : records) {
    if (!r.textured) continue;
    const cv::Mat img = cv::imread((dir / r.image).string(), cv::IMREAD_COLOR);
    if (img.empty()) continue;
    truth_studio.render(0, int64_t(r.source_frame), &truth, &mask);
    if (img.cols != truth.width() || img.rows != truth.height()) continue;
    if (s.frames == 0) {  // the first pair, for a person looking at a failure
      cv::Mat t(truth.height(), truth.width(), CV_8UC3, truth.data()), bgr;
      cv::cvtColor(t, bgr, cv::COLOR_RGB2BGR);
      cv::imwrite((dir / ("truth-" + r.image)).string(), bgr);
    }
    ++s.frames;
    for (int y = 0; y < img.rows; ++y)
      for (int x = 0; x < img.cols; ++x) {
        const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
        const bool rendered =
            !(std::abs(c[0] - 18) <= 2 && std::abs(c[1] - 13) <= 2 && std::abs(c[2] - 13) <= 2);
        if (!rendered && !mask(x, y)) continue;
        const Rgb8 t = truth(x, y);
        const double d[3] = {double(c[2]) - t.r, double(c[1]) - t.g, double(c[0]) - t.b};
        const double e = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        s.squared += e;
        s.samples += 3;
        if (rendered && mask(x, y)) {
          ++s.both;
          s.squared_both += e;
        } else {
          ++(rendered ? s.rendered_only : s.true_only);
          (rendered ? s.squared_rendered_only : s.squared_true_only) += e;
        }
      }
  }
  return s;
}

// The records of two previews' recordings (--record dirs) that both drew the same mesh (source
// frame) textured, in matching order.
std::pair<std::vector<Record>, std::vector<Record>> same_meshes(const std::filesystem::path& a,
                                                                const std::filesystem::path& b) {
  std::pair<std::vector<Record>, std::vector<Record>> out;
  for (const Record& r : read_records(a / "frames.jsonl"))
    for (const Record& q : read_records(b / "frames.jsonl"))
      if (r.source_frame == q.source_frame && r.textured && q.textured) {
        out.first.push_back(r);
        out.second.push_back(q);
      }
  return out;
}

// The held-out camera: between cam0 (azimuth 0) and cam1 (45), lower than the ring; it feeds
// nothing. Its calibration and the preview's viewpoint from its pose.
// kW x kH: the studio's image size (PreviewStudioTest::kWidth, kHeight).
std::pair<Camera, Viewpoint> held_out(int kW, int kH) {
  const double az = 20 * std::numbers::pi / 180;
  const Eigen::Vector3d centre(3.6 * std::sin(az), 1.8, 3.6 * std::cos(az)), target(0, 1.1, 0);
  const double focal = 560.0 * kW / 704.0;
  const Camera held =
      support::look_at_camera("held", centre, target, Eigen::Vector3d::UnitY(), kW, kH, focal);
  return {held, {centre, target, 2 * std::atan(0.5 * kH / focal) * 180 / std::numbers::pi}};
}

// The headless preview's --json summary: "colour_balance" {"applied", "frames", ...,
// "estimated": {camera id: [r, g, b]}}.
struct BalanceSummary {
  bool found = false, applied = false;
  int frames = 0, rig_frames = 0, pairs = 0;
  std::map<std::string, Eigen::Vector3d> estimated;
};
BalanceSummary balance_summary(const std::string& log) {
  BalanceSummary b;
  std::smatch m;
  if (!std::regex_search(
          log, m,
          std::regex(
              R"re("colour_balance":\{"on":\w+,"applied":(\w+),"frames":(\d+),"busy":\d+,"rig_frames":(\d+),"rig_dropped":\d+,"pairs":(\d+))re")))
    return b;
  b.found = true;
  b.applied = m[1] == "true";
  b.frames = std::stoi(m[2]);
  b.rig_frames = std::stoi(m[3]);
  b.pairs = std::stoi(m[4]);
  const std::size_t at = log.find("\"estimated\":{", std::size_t(m.position(0)));
  if (at == std::string::npos) return b;
  const std::string rest = log.substr(at, log.find('}', at) - at);
  const std::regex gain(R"re("([^"]+)":\[([0-9.]+),([0-9.]+),([0-9.]+)\])re");
  for (auto it = std::sregex_iterator(rest.begin(), rest.end(), gain); it != std::sregex_iterator();
       ++it)
    b.estimated[(*it)[1]] = {std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4])};
  return b;
}

TEST_F(PreviewStudioTest, BlendBeatsNearestAgainstAHeldOutCamera) {
  // No scene: the preview's background is the clear colour. The plain actor (no frame code: its
  // sharp bands are a test artefact, not studio content).
  // Eight ring cameras + overhead: the hull of four at 90 degrees is a poor solid between them.
  start_studio(false, false, 9);
  const auto [held, view] = held_out(kWidth, kHeight);
  // nearest; blend (carving against every camera's mask of the frame, the default); keys: blend
  // carving against its three cameras' keys only (carve_masks: false).
  std::map<std::string, Process*> previews;
  for (const std::string name : {"nearest", "blend", "keys"}) {
    const std::string mode = name == "nearest" ? "nearest" : "blend";
    previews[name] = &recorded_preview(name, view, name == "keys" ? "carve_masks: false\n" : "",
                                       {"--texturing", mode});
  }
  for (auto& [mode, p] : previews) {
    const auto code = p->wait_exit(std::chrono::seconds(150));
    ASSERT_TRUE(code.has_value()) << mode;
    ASSERT_EQ(*code, 0) << p->log();
  }
  sim::StudioOptions o;
  o.threads = 1;
  auto truth = sim::SimulatedStudio::create({held}, o).value();
  const Score nearest =
      score(read_records(dir_ / "nearest" / "frames.jsonl"), dir_ / "nearest", truth);
  const Score blend = score(read_records(dir_ / "blend" / "frames.jsonl"), dir_ / "blend", truth);
  const Score keys = score(read_records(dir_ / "keys" / "frames.jsonl"), dir_ / "keys", truth);
  std::printf(
      "held-out camera, union of silhouettes: nearest %.2f dB (%d frames), blend %.2f dB "
      "(%d frames), blend carving with its cameras' keys only %.2f dB (%d frames)\n",
      nearest.psnr(), nearest.frames, blend.psnr(), blend.frames, keys.psnr(), keys.frames);
  // The masks that carved each drawn mesh (frames.jsonl "carving_masks"): every camera's mask of
  // the mesh's frame reaches the blend (best-effort: one may be lost), none the others.
  auto carving = [&](const std::string& name) {
    std::vector<int> out;
    std::ifstream in(dir_ / name / "frames.jsonl");
    const std::regex re(R"re("carving_masks":(\d+))re");
    for (std::string line; std::getline(in, line);) {
      std::smatch m;
      if (std::regex_search(line, m, re)) out.push_back(std::stoi(m[1]));
    }
    return out;
  };
  // Paired: the meshes both blends drew (same source frame).
  const auto [both_b, both_k] = same_meshes(dir_ / "blend", dir_ / "keys");
  const Score paired_blend = score(both_b, dir_ / "blend", truth),
              paired_keys = score(both_k, dir_ / "keys", truth);
  std::printf(
      "the same %d meshes: carving against every mask %.2f dB (only rendered %llu px, only true "
      "%llu), against the keys only %.2f dB (%llu, %llu)\n",
      paired_blend.frames, paired_blend.psnr(), (unsigned long long)paired_blend.rendered_only,
      (unsigned long long)paired_blend.true_only, paired_keys.psnr(),
      (unsigned long long)paired_keys.rendered_only, (unsigned long long)paired_keys.true_only);
  // Measured (3 runs, 2026-11-26): +0.37 / +0.55 / +0.67 dB, 25 % less drawn outside the true
  // silhouette (preview_quality_test: +0.33 dB in process, deterministic).
  if (paired_blend.frames >= 3)
    EXPECT_LT(paired_blend.rendered_only, paired_keys.rendered_only);
  else
    std::printf("fewer than 3 meshes drawn by both blends: not compared\n");
  const auto blend_masks = carving("blend"), keys_masks = carving("keys");
  ASSERT_FALSE(blend_masks.empty());
  // Measured: 9 of 9 in every record of 10 runs; best-effort under load may lose one.
  EXPECT_GE(std::count_if(blend_masks.begin(), blend_masks.end(), [](int n) { return n >= 8; }),
            std::ptrdiff_t(0.8 * double(blend_masks.size())));
  EXPECT_EQ(std::count(keys_masks.begin(), keys_masks.end(), 0), std::ptrdiff_t(keys_masks.size()));
  // Where the error is: the share of the summed squared error in each part of the union.
  for (const Score* sc : {&nearest, &blend, &keys})
    std::printf(
        "  pixels in both silhouettes %llu (%.2f dB there, %.0f %% of the error), only rendered "
        "%llu (%.0f %%), only true %llu (%.0f %%)\n",
        (unsigned long long)sc->both,
        10 * std::log10(255.0 * 255 / (sc->squared_both / (3.0 * sc->both))),
        100 * sc->squared_both / sc->squared, (unsigned long long)sc->rendered_only,
        100 * sc->squared_rendered_only / sc->squared, (unsigned long long)sc->true_only,
        100 * sc->squared_true_only / sc->squared);
  // The rig's cameras agree: the colour balance (on by default) estimates gains within its 5 %
  // tolerance and applies none (measured: within 0.5 % in process, preview_quality_test).
  const BalanceSummary same = balance_summary(previews["blend"]->log());
  ASSERT_TRUE(same.found) << previews["blend"]->log();
  double stray = 0;
  for (const auto& [id, g] : same.estimated)
    stray = std::max(stray, (g.array() - 1).abs().maxCoeff());
  std::printf(
      "identical cameras: colour balance over %d frames, %d pairs, largest estimate %.2f %% "
      "off 1, applied: %s\n",
      same.frames, same.pairs, 100 * stray, same.applied ? "yes" : "no");
  EXPECT_GE(same.frames, 3);
  EXPECT_FALSE(same.applied);
  ASSERT_GE(nearest.frames, 10);
  ASSERT_GE(blend.frames, 10);
  EXPECT_GT(blend.psnr(), nearest.psnr());
  // Only the actor is drawn (--overlays none): the camera frusta, on by default since the
  // overlays came, counted as rendered and put 39 % of the pixels outside the true silhouette
  // (blend 11.8-12.2 dB); the actor's own excess is 7-13 % of the pixels in both.
  EXPECT_LT(double(blend.rendered_only), 0.25 * double(blend.both));
  // Issue 16 asks >= 28 dB; measured 19.5-24.7 dB here (9 runs, 2026-11-26; run to run the
  // poses differ). Not reached:
  // 50-80 % of the error is in pixels of one silhouette only, the visual hull's geometry (the
  // hull of ring cameras 45 degrees apart exceeds a round body between cameras; its facets cut
  // inside it elsewhere), the rest in the interior, which the hull's depth misregisters.
  // preview_quality_test separates geometry from texturing: with the actor's true surface the
  // same blend reaches 28.2 dB; preview_error_sources_test measures what limits the hull.
  // Printed above and reported, not asserted.
}

// A rig whose cameras differ as a real rig's do (exposure +-10 %, white balance +-5 %: the
// capture config's sim `response`, drawn by sim::random_camera_response, seed 3), previewed from
// the held-out camera's pose (whose response is 1, 1, 1) with the colour balance (the default)
// and without it. The gains the preview estimated live match the simulated cameras' relative
// responses and are what the balanced preview draws with; the other draws with none.
// BlendBeatsNearestAgainstAHeldOutCamera is the control: there the cameras agree and the default
// balance leaves them alone.
TEST_F(PreviewStudioTest, TheColourBalanceEqualisesCamerasThatDiffer) {
  auto response = sim::random_camera_response(9, 3, 0.1, 0.05);
  for (double& g : response[1]) g *= 1.25;  // cam1's exposure a third of a stop up
  start_studio(false, false, 9, response);
  const auto [held, view] = held_out(kWidth, kHeight);
  // The previews' status (studioctl's view): the balance's gauges.
  auto participant = wire::Participant::create().value();
  auto status_topic = wire::Topic<studio_ServiceStatus>::create(participant).value();
  auto status = wire::Reader<studio_ServiceStatus>::create(participant, status_topic).value();
  std::map<std::string, double> applied_on_status;  // instance -> largest colour_balance_applied
  std::map<std::string, double> rig_linked_on_status;  // ... colour_balance_rig_linked
  auto read_status = [&] {
    for (auto& st : status.take())
      if (st.meta.valid_data && std::string(st.data->service) == "preview")
        for (const auto& c : wire::view(st.data->counters))
          if (std::string(c.name) == "colour_balance_applied") {
            double& a = applied_on_status[st.data->instance];
            a = std::max(a, c.value);
          } else if (std::string(c.name) == "colour_balance_rig_linked") {
            double& l = rig_linked_on_status[st.data->instance];
            l = std::max(l, c.value);
          }
  };
  std::map<std::string, Process*> previews;
  for (const std::string name : {"balanced", "unbalanced"})
    previews[name] = &recorded_preview(name, view, "colour_balance_every: 1\n",
                                       {"--colour-balance", name == "balanced" ? "on" : "off"});
  for (auto& [name, p] : previews) {
    while (p->running()) {
      read_status();
      std::this_thread::sleep_for(50ms);
    }
    const auto code = p->wait_exit(std::chrono::seconds(150));
    ASSERT_TRUE(code.has_value()) << name;
    ASSERT_EQ(*code, 0) << p->log();
  }
  read_status();
  EXPECT_EQ(applied_on_status["balanced"], 1.0);
  EXPECT_EQ(applied_on_status.count("unbalanced") ? applied_on_status["unbalanced"] : -1, 0.0);
  // The rig samples (every camera's images of a mesh, one per 0.5 s) link the whole rig, beyond
  // the view's three texturing cameras; none without the balance.
  std::printf("the whole rig's estimate on the status: %.0f cameras linked\n",
              rig_linked_on_status["balanced"]);
  EXPECT_EQ(rig_linked_on_status["balanced"], 9.0);
  EXPECT_EQ(rig_linked_on_status["unbalanced"], 0.0);
  // The estimate: every pair of cameras it linked, their gain ratio against the truth's.
  const BalanceSummary b = balance_summary(previews["balanced"]->log());
  const BalanceSummary off = balance_summary(previews["unbalanced"]->log());
  ASSERT_TRUE(b.found) << previews["balanced"]->log();
  ASSERT_TRUE(off.found) << previews["unbalanced"]->log();
  EXPECT_TRUE(b.applied);
  EXPECT_GE(b.frames, 20);  // every textured mesh of 30 (colour_balance_every: 1)
  EXPECT_FALSE(off.applied);
  EXPECT_EQ(off.frames, 0);
  const auto truth = sim::balancing_gains(response);
  std::vector<std::pair<int, Eigen::Vector3d>> linked;  // camera index, estimate
  for (const auto& [id, g] : b.estimated)
    if (g != Eigen::Vector3d::Ones()) linked.emplace_back(std::stoi(id.substr(3)), g);
  ASSERT_GE(linked.size(), 2u);
  double worst = 0, worst_without = 0;
  for (std::size_t p = 0; p < linked.size(); ++p)
    for (std::size_t q = p + 1; q < linked.size(); ++q)
      for (int k = 0; k < 3; ++k) {
        const auto& [i, gi] = linked[p];
        const auto& [j, gj] = linked[q];
        const double want =
            truth[std::size_t(i)][std::size_t(k)] / truth[std::size_t(j)][std::size_t(k)];
        worst = std::max(worst, std::abs(gi[k] / gj[k] / want - 1));
        worst_without = std::max(worst_without, std::abs(1 / want - 1));
      }
  std::printf(
      "colour balance: %d frames pooled, %d camera pairs, %zu cameras linked; worst pair "
      "ratio error %.2f %% (%.2f %% between the cameras without it)\n",
      b.frames, b.pairs, linked.size(), 100 * worst, 100 * worst_without);
  // Measured 0.3-5.1 % over 38 runs (pooling one mesh in 2: 0.9-3.4 % in 10): the poses of a
  // run decide which cameras texture and how the view-dependent light (the backing's blue spill
  // above all) biases the medians. preview_quality_test holds the estimate to 1 % on fixed poses
  // (measured 0.44 %); here, against the running studio, it takes out at least half of the
  // cameras' differences.
  EXPECT_LT(worst, 0.5 * worst_without);
  // The gains reached the drawing: each drawn mesh's texturing cameras' gains (frames.jsonl):
  // some differ from 1 in the balanced preview once the estimate is applied, none in the other.
  auto drawn_gains = [&](const std::string& name) {
    std::vector<double> out;
    std::ifstream in(dir_ / name / "frames.jsonl");
    const std::regex list(R"re("gains":\[([^"]*)\],"estimated")re"), number(R"re([0-9.]+)re");
    for (std::string line; std::getline(in, line);) {
      std::smatch m;
      if (!std::regex_search(line, m, list)) continue;
      const std::string l = m[1];
      for (auto it = std::sregex_iterator(l.begin(), l.end(), number); it != std::sregex_iterator();
           ++it)
        out.push_back(std::stod(it->str()));
    }
    return out;
  };
  const auto on = drawn_gains("balanced"), plain = drawn_gains("unbalanced");
  ASSERT_FALSE(on.empty());
  ASSERT_FALSE(plain.empty());
  EXPECT_TRUE(std::any_of(on.begin(), on.end(), [](double g) { return std::abs(g - 1) > 0.005; }));
  EXPECT_TRUE(std::all_of(plain.begin(), plain.end(), [](double g) { return g == 1; }));
  // Against the held-out camera (printed, not asserted): the cameras' few percent are small
  // beside the visual hull's misregistration here, and which cameras texture the view changes
  // with the poses of the run (measured in 5 runs: where both silhouettes agree -0.13, +0.38,
  // +0.04, +0.09, +0.06 dB). preview_quality_test measures the balance's effect
  // deterministically, in process.
  sim::StudioOptions o;
  o.threads = 1;
  auto truth_studio = sim::SimulatedStudio::create({held}, o).value();
  const auto [both_b, both_u] = same_meshes(dir_ / "balanced", dir_ / "unbalanced");
  const Score balanced = score(both_b, dir_ / "balanced", truth_studio),
              unbalanced = score(both_u, dir_ / "unbalanced", truth_studio);
  std::printf(
      "the same %d meshes, held-out camera: where both silhouettes agree %.2f dB balanced, "
      "%.2f dB not; the union %.2f / %.2f dB\n",
      balanced.frames, balanced.psnr_both(), unbalanced.psnr_both(), balanced.psnr(),
      unbalanced.psnr());
}

// The director raises one camera's Gain from the Cameras panel (CameraControl; the simulated
// camera scales its 8-bit values by 10^(dB/20)) while the preview runs: on a rig whose cameras
// agreed, the balance (newest samples per pair) follows, and the gain it settles on for that
// camera against its neighbours undoes the change. frames.jsonl's per-mesh gains show when.
TEST_F(PreviewStudioTest, TheColourBalanceFollowsACameraWhoseGainIsChanged) {
  start_studio(false, false, 9);
  const auto [held, view] = held_out(kWidth, kHeight);
  Process& p = balancing_preview(view, 16);
  auto participant = wire::Participant::create().value();
  auto topic = wire::Topic<studio_CameraControl>::create(participant).value();
  auto control = wire::Writer<studio_CameraControl>::create(participant, topic).value();
  ASSERT_TRUE(control.wait_for_readers(1, 30s));
  std::this_thread::sleep_for(5s);  // the balance has pooled the agreeing rig
  constexpr double kGainDb = 1.5;   // cam0's values x 1.189
  wire::Owned<studio_CameraControl> c;
  wire::set(c->camera_id, "cam0");
  wire::set(c->feature, "Gain");
  c->value = kGainDb;
  ASSERT_TRUE(control.write(*c));
  const auto changed = std::chrono::steady_clock::now();
  const auto code = p.wait_exit(60s);
  ASSERT_TRUE(code.has_value());
  ASSERT_EQ(*code, 0) << p.log();
  const double seconds_after =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - changed).count();
  const BalanceSummary b = balance_summary(p.log());
  ASSERT_TRUE(b.found) << p.log();
  EXPECT_TRUE(b.applied);
  ASSERT_TRUE(b.estimated.count("cam0"));
  // cam0 against each neighbour the estimate linked it with: the inverse of the gain change.
  const double k = std::pow(10.0, kGainDb / 20);
  double worst = 0;
  int neighbours = 0;
  for (const auto& [id, g] : b.estimated) {
    if (id == "cam0" || g == Eigen::Vector3d::Ones()) continue;
    ++neighbours;
    for (int ch = 0; ch < 3; ++ch)
      worst = std::max(worst, std::abs(b.estimated.at("cam0")[ch] / g[ch] * k - 1));
  }
  // Per drawn mesh with cam0 among its texturing cameras: the estimate's cam0 against the
  // other texturing cameras (green; frames.jsonl "estimated"), before the change (meshes 60-109:
  // ~2.5-4.5 s into the run, the change at ~5 s) and over the last 60 meshes. The estimate's own
  // bias between these cameras (the view-dependent light, a few percent) is in both and cancels.
  std::vector<double> ratio;  // per record, NaN where cam0 did not texture
  {
    std::ifstream in(dir_ / "rec" / "frames.jsonl");
    const std::regex cams(R"re("cameras":\[([^\]]*)\])re"),
        est(R"re("estimated":\[(.*)\],"balance_pooled")re"), number(R"re([0-9.]+)re"),
        id(R"re("([^"]+)")re");
    for (std::string line; std::getline(in, line);) {
      ratio.push_back(std::nan(""));
      std::smatch cm, em;
      if (!std::regex_search(line, cm, cams) || !std::regex_search(line, em, est)) continue;
      const std::string ids = cm[1], list = em[1];
      std::vector<std::string> names;
      for (auto it = std::sregex_iterator(ids.begin(), ids.end(), id); it != std::sregex_iterator();
           ++it)
        names.push_back((*it)[1]);
      std::vector<double> v;
      for (auto it = std::sregex_iterator(list.begin(), list.end(), number);
           it != std::sregex_iterator(); ++it)
        v.push_back(std::stod(it->str()));
      if (v.size() != 3 * names.size() || names.size() < 2) continue;
      double own = 0, others = 0;
      int n = 0;
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == "cam0")
          own = v[3 * i + 1];
        else {
          others += std::log(v[3 * i + 1]);
          ++n;
        }
      if (own > 0 && n > 0) ratio.back() = own / std::exp(others / n);
    }
  }
  auto median_of = [&](std::size_t from, std::size_t to) {
    std::vector<double> m;
    for (std::size_t i = from; i < to && i < ratio.size(); ++i)
      if (!std::isnan(ratio[i])) m.push_back(ratio[i]);
    if (m.empty()) return std::nan("");
    std::nth_element(m.begin(), m.begin() + std::ptrdiff_t(m.size() / 2), m.end());
    return m[m.size() / 2];
  };
  ASSERT_GE(ratio.size(), 200u);
  const double before = median_of(60, 110), after = median_of(ratio.size() - 60, ratio.size());
  const double change = after / before;
  std::size_t half = 0;  // the first mesh after the change with half of it (in log) taken up
  for (std::size_t i = 110; i < ratio.size() && !half; ++i)
    if (ratio[i] < before / std::sqrt(k)) half = i;
  std::printf(
      "gain +%.1f dB on cam0 (x%.3f), %zu meshes drawn: the estimate's cam0 against its "
      "fellow texturing cameras %.4f before, %.4f over the last 60 meshes (%.1f s after "
      "the change): x%.4f (want x%.4f); at the end against %d linked cameras within "
      "%.2f %% of 1 / %.3f; half of it taken up at mesh %zu\n",
      kGainDb, k, ratio.size(), before, after, seconds_after, change, 1 / k, neighbours,
      100 * worst, k, half);
  EXPECT_GE(neighbours, 1);
  // Measured within 0.3-3.4 % of the change (13 runs; mostly a little past it): the live
  // estimate's pose-dependent error (TheColourBalanceEqualisesCamerasThatDiffer: up to 5.1 %).
  EXPECT_NEAR(change * k, 1.0, 0.06);
  EXPECT_GT(half, 110u);
}

// "Match cameras" (node/camera_matching.h): on a rig whose cameras differ (cam1 two thirds of a
// stop up), the headless preview sends its estimate to the capture service once it applies; the
// simulated cameras' Gain and white balance (BalanceRatioRed / Blue) read back the values sent,
// the cameras then differ far less against the simulator's truth, and the balance starts afresh
// on the matched images.
class PreviewMatchTest : public PreviewStudioTest {
 protected:
  // `gamma` > 0: every simulated camera publishes GenICam Gamma and its controls act before it
  // (capture/sim_source.h): a control's factor f scales what the camera delivers by f^gamma.
  void run_match(double gamma) {
    auto response = sim::random_camera_response(9, 3, 0.1, 0.05);
    for (double& g : response[1]) g *= 1.6;
    start_studio(false, false, 9, response,
                 gamma > 0 ? ", gamma: " + std::to_string(gamma) : std::string());
    const auto [held, view] = held_out(kWidth, kHeight);
    auto participant = wire::Participant::create().value();
    auto state_topic = wire::Topic<studio_CameraState>::create(participant).value();
    auto states = wire::Reader<studio_CameraState>::create(participant, state_topic).value();
    Process& p = balancing_preview(view, 14, {"--match-cameras"});
    const auto code = p.wait_exit(60s);
    ASSERT_TRUE(code.has_value());
    ASSERT_EQ(*code, 0) << p.log();
    // The rounds as sent ("camera_match" of the summary: one object per round, in order).
    const std::string log = p.log();
    const auto at = log.find("\"camera_match\":[{\"level_db\"");
    ASSERT_NE(at, std::string::npos) << log;
    const std::string match = log.substr(at, log.find('\n', at) - at);
    int rounds = 0;
    for (std::size_t i = match.find("\"level_db\""); i != std::string::npos;
         i = match.find("\"level_db\"", i + 1))
      ++rounds;
    std::map<std::string, Eigen::Vector3d> applied;  // per camera: the factor of every round
    std::map<std::pair<std::string, std::string>, double> sent;
    {
      const std::regex change(
          R"re(\{"camera":"([^"]+)","feature":"([^"]+)","from":([-0-9.]+),"to":([-0-9.]+)\})re");
      for (auto it = std::sregex_iterator(match.begin(), match.end(), change);
           it != std::sregex_iterator(); ++it) {
        const std::string cam = (*it)[1], feature = (*it)[2];
        const double from = std::stod((*it)[3]), to = std::stod((*it)[4]);
        sent[{cam, feature}] = to;
        Eigen::Vector3d& f = applied.try_emplace(cam, Eigen::Vector3d::Ones()).first->second;
        // What the change does to the delivered values: its factor, through the camera's Gamma.
        const double curve = gamma > 0 ? gamma : 1.0;
        if (feature == "Gain") f *= std::pow(10.0, curve * (to - from) / 20);
        if (feature == "BalanceRatioRed") f.x() *= std::pow(to / from, curve);
        if (feature == "BalanceRatioBlue") f.z() *= std::pow(to / from, curve);
      }
    }
    std::vector<std::string> matched;  // the balance's linked sets (the others: the level only)
    for (std::size_t i = match.find("\"matched\":["); i != std::string::npos;
         i = match.find("\"matched\":[", i + 1)) {
      const std::string list = match.substr(i, match.find(']', i) - i);
      const std::regex id(R"re("(cam[0-9]+)")re");
      for (auto it = std::sregex_iterator(list.begin(), list.end(), id);
           it != std::sregex_iterator(); ++it)
        if (std::find(matched.begin(), matched.end(), (*it)[1]) == matched.end())
          matched.push_back((*it)[1]);
    }
    ASSERT_FALSE(sent.empty()) << match;
    // The rig samples' estimate (16 samples of every camera) links the whole rig, not only the
    // cameras near the view (3-4 of them without it).
    EXPECT_EQ(matched.size(), 9u) << match;
    // The capture service read the values back (studio/camera/state, transient-local: the latest).
    std::map<std::string, std::map<std::string, double>> read_back;
    for (auto& st : states.take())
      if (st.meta.valid_data)
        for (const auto& f : wire::view(st.data->features))
          read_back[std::string(st.data->camera_id)][std::string(f.name)] = f.value;
    for (const auto& [key, to] : sent)
      EXPECT_NEAR(read_back[key.first][key.second], to, 1e-4 * std::max(1.0, std::abs(to)))
          << key.first << " " << key.second;
    // Against the truth: the matched cameras' pair ratios, before and after the match.
    const auto truth = sim::balancing_gains(response);
    double before = 0, after = 0;
    for (const std::string& a : matched)
      for (const std::string& b : matched)
        for (int k = 0; a < b && k < 3; ++k) {
          const Eigen::Vector3d fa = applied.count(a) ? applied.at(a) : Eigen::Vector3d::Ones(),
                                fb = applied.count(b) ? applied.at(b) : Eigen::Vector3d::Ones();
          const double ta = truth[std::size_t(std::stoi(a.substr(3)))][std::size_t(k)],
                       tb = truth[std::size_t(std::stoi(b.substr(3)))][std::size_t(k)];
          before = std::max(before, std::abs(ta / tb - 1));
          after = std::max(after, std::abs((ta / fa[k]) / (tb / fb[k]) - 1));
        }
    // Every camera of the rig, matched or not (the others took the level only, which no ratio
    // sees).
    double rig_before = 0, rig_after = 0;
    for (std::size_t a = 0; a < truth.size(); ++a)
      for (std::size_t c = a + 1; c < truth.size(); ++c)
        for (int k = 0; k < 3; ++k) {
          const std::string ia = "cam" + std::to_string(a), ic = "cam" + std::to_string(c);
          const Eigen::Vector3d fa = applied.count(ia) ? applied.at(ia) : Eigen::Vector3d::Ones(),
                                fc = applied.count(ic) ? applied.at(ic) : Eigen::Vector3d::Ones();
          const double ta = truth[a][std::size_t(k)], tc = truth[c][std::size_t(k)];
          rig_before = std::max(rig_before, std::abs(ta / tc - 1));
          rig_after = std::max(rig_after, std::abs((ta / fa[k]) / (tc / fc[k]) - 1));
        }
    // The balance after the match: pooled afresh (fewer frames than meshes drawn) on the matched
    // images; its estimate between the matched cameras.
    const BalanceSummary b = balance_summary(log);
    ASSERT_TRUE(b.found) << log;
    double estimate_left = 0;
    for (const auto& [x, gx] : b.estimated)
      for (const auto& [y, gy] : b.estimated)
        for (int k = 0; x < y && k < 3 && std::count(matched.begin(), matched.end(), x) &&
                        std::count(matched.begin(), matched.end(), y);
             ++k)
          if (gx != Eigen::Vector3d::Ones() && gy != Eigen::Vector3d::Ones())
            estimate_left = std::max(estimate_left, std::abs(gx[k] / gy[k] - 1));
    int drawn = 0;
    {
      std::ifstream in(dir_ / "rec" / "frames.jsonl");
      for (std::string line; std::getline(in, line);) ++drawn;
    }
    std::printf(
        "match cameras: %d rounds, %zu controls, %zu cameras matched (%s); their worst pair ratio "
        "against the truth %.2f %% before, %.2f %% after; the balance afterwards: %d frames "
        "pooled of %d meshes drawn, applied %d, its worst pair ratio %.2f %%; the whole rig's "
        "worst "
        "pair ratio %.2f %% before, %.2f %% after\n",
        rounds, sent.size(), matched.size(), match.substr(0, match.find(",\"changes\"")).c_str(),
        100 * before, 100 * after, b.frames, drawn, int(b.applied), 100 * estimate_left,
        100 * rig_before, 100 * rig_after);
    EXPECT_GE(rounds, 1);
    EXPECT_LE(rounds, 3);
    EXPECT_GT(before, 0.2);           // cam1's two thirds of a stop among them
    EXPECT_LT(after, 0.35 * before);  // the estimate's error is what remains (up to ~6 %)
    // Measured 2.5-6.3 % over the whole rig (the overhead camera's view-dependent bias the most);
    // matching the view's set alone left it at 8.3-10.3 % (the cameras it did not link).
    EXPECT_LT(rig_after, 0.3 * rig_before);
    EXPECT_GE(b.frames, 8);
    EXPECT_LT(b.frames, drawn - 8);  // started afresh after the match
  }
};

TEST_F(PreviewMatchTest, MovesTheBalanceIntoTheCameras) { run_match(0); }

// The same rig of cameras that publish Gamma 0.45 and apply Gain and white balance before it (a
// real camera's order): the plan sends each factor to the power 1 / Gamma
// (preview/camera_match.h CameraControls::exponent), so that what the cameras deliver moves by
// the estimate. Sent as the factor itself, the cameras would take only its 0.45th power (cam1's
// 1.6 would be left at 1.6^0.55, 29 % off).
TEST_F(PreviewMatchTest, ThroughTheCamerasGamma) { run_match(0.45); }

// The control: on a rig whose cameras agree the balance never applies, so --match-cameras sends
// nothing and the cameras keep their controls.
TEST_F(PreviewStudioTest, MatchCamerasLeavesAgreeingCamerasAlone) {
  start_studio(false, false, 9);
  const auto [held, view] = held_out(kWidth, kHeight);
  Process& p = balancing_preview(view, 8, {"--match-cameras"});
  const auto code = p.wait_exit(60s);
  ASSERT_TRUE(code.has_value());
  ASSERT_EQ(*code, 0) << p.log();
  const BalanceSummary b = balance_summary(p.log());
  ASSERT_TRUE(b.found) << p.log();
  EXPECT_GE(b.frames, 24) << "pooled enough to have matched";
  EXPECT_FALSE(b.applied);
  EXPECT_NE(p.log().find("\"camera_match\":[]"), std::string::npos) << p.log();
  auto participant = wire::Participant::create().value();
  auto topic = wire::Topic<studio_CameraState>::create(participant).value();
  auto states = wire::Reader<studio_CameraState>::create(participant, topic).value();
  std::set<std::string> cameras;  // read back
  for (auto deadline = std::chrono::steady_clock::now() + 10s;
       cameras.size() < 9 && std::chrono::steady_clock::now() < deadline;) {
    for (auto& st : states.take())
      if (st.meta.valid_data) {
        cameras.insert(std::string(wire::str(st.data->camera_id)));
        for (const auto& f : wire::view(st.data->features)) {
          const std::string name(wire::str(f.name));
          if (name == "Gain") {
            EXPECT_EQ(f.value, 0) << wire::str(st.data->camera_id);
          } else if (name == "BalanceRatioRed" || name == "BalanceRatioBlue") {
            EXPECT_EQ(f.value, 1) << wire::str(st.data->camera_id) << " " << name;
          }
        }
      }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(cameras.size(), 9u);
}

}  // namespace
}  // namespace studio::preview::testing
