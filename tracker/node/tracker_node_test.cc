// The tracker node as a real process (issue 6 item 3): this test publishes SegmentSets cut from
// the simulated studio's true masks on studio/actor/segments and reads studio/actor/head.
//   - tracked heads match the simulator's true head centre (≤ 3 cm RMS, every frame ≤ 5 cm);
//   - empty hulls: the node keeps publishing, confidence decays to 0, positions stay finite and
//     near the last head;
//   - no input: keep-alive samples at publish_rate, coasting with decaying confidence to 0;
//   - samples the validator rejects are dropped without stopping the node;
//   - bad configuration: one line on stderr, exit 1.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <algorithm>
#include <map>
#include <optional>

#include "core/run_mask.h"
#include "harness/fixture.h"
#include "hull/silhouette_cut.h"
#include "segments_wire.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "wire/endpoint.h"

namespace studio::tracker {
namespace {

using namespace std::chrono_literals;
constexpr int64_t kFramePeriodNs = 40'000'000;  // the simulated studio's 25 fps

int64_t realtime_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Head {
  uint64_t frame;
  int64_t capture_ns;
  Eigen::Vector3d position, velocity;
  double confidence;
};

// Head-sized balls (diameter 0.2 m, the reference head) of occupancy on a 2 cm column grid.
hull::SegmentSet balls(const std::vector<Eigen::Vector3d>& centres) {
  hull::GridSpec g;
  g.box_min = {-1, 0, -1};
  g.box_max = {1, 2, 1};
  g.cells_u = g.cells_v = 100;
  std::vector<std::vector<hull::Interval>> cols(g.columns());
  for (const Eigen::Vector3d& centre : centres)
    for (int j = 0; j < g.cells_v; ++j)
      for (int i = 0; i < g.cells_u; ++i) {
        const Eigen::Vector3d p = g.point(i, j, 0);
        const double dx = p.x() - centre.x(), dz = p.z() - centre.z();
        const double r2 = 0.1 * 0.1 - dx * dx - dz * dz;
        if (r2 > 0)
          cols[std::size_t(i) + std::size_t(j) * 100] = {
              {float(centre.y() - std::sqrt(r2)), float(centre.y() + std::sqrt(r2))}};
      }
  return hull::SegmentSet::from_columns(g, cols);
}

class TrackerNodeTest : public testing::ProcessTest {
 protected:
  void SetUp() override {
    ProcessTest::SetUp();
    participant_.emplace(wire::Participant::create().value());
    seg_topic_.emplace(wire::Topic<studio_SegmentSet>::create(*participant_).value());
    head_topic_.emplace(wire::Topic<studio_HeadPose>::create(*participant_).value());
    writer_.emplace(wire::Writer<studio_SegmentSet>::create(*participant_, *seg_topic_).value());
    reader_.emplace(wire::Reader<studio_HeadPose>::create(*participant_, *head_topic_).value());
    spec_.box_min = {-1.6, 0, -1.6};
    spec_.box_max = {1.6, 2.6, 1.6};
    spec_.axis = hull::Axis::y;
    spec_.cells_u = spec_.cells_v = 128;
  }
  void TearDown() override {
    reader_.reset();
    writer_.reset();
    head_topic_.reset();
    seg_topic_.reset();
    participant_.reset();
    ProcessTest::TearDown();
  }

  std::string write_config(const std::string& text) {
    const auto path = dir_ / "tracker.yaml";
    std::ofstream(path) << text;
    return path.string();
  }

  testing::Process& start_node(const std::string& yaml) {
    auto& p = spawn("tracker", "tracker/studio-tracker", {"--config", write_config(yaml)});
    EXPECT_TRUE(p.wait_ready(20s)) << p.log();
    EXPECT_TRUE(writer_->wait_for_readers(1, 10s));
    // The node's writer matched us once a keep-alive arrives.
    EXPECT_TRUE(next_head(10s).has_value());
    return p;
  }

  void send(const hull::SegmentSet& set, uint64_t frame, int64_t capture_ns,
            const char* actor_id = "hull") {
    wire::Owned<studio_SegmentSet> s;
    wire::set(s->actor_id, actor_id);
    s->frame = frame;
    s->capture_ns = capture_ns;
    wire::from_core(set, *s);
    ASSERT_TRUE(writer_->write(*s).has_value());
  }

  std::optional<Head> next_head(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      for (auto& r : reader_->take(1)) {
        if (!r.meta.valid_data) continue;
        EXPECT_STREQ(r.data->actor_id, "actor");
        auto pose = wire::to_core(*r.data);  // finite, confidence in [0, 1]
        EXPECT_TRUE(pose.has_value());
        if (!pose) continue;
        return Head{r.data->frame, r.data->capture_ns, pose->position, pose->velocity,
                    pose->confidence};
      }
      std::this_thread::sleep_for(2ms);
    }
    return std::nullopt;
  }

  // Sends `set` as `frame` until the node answers for that frame (best-effort: resend on loss).
  std::optional<Head> exchange(const hull::SegmentSet& set, uint64_t frame, int64_t capture_ns) {
    for (int attempt = 0; attempt < 5; ++attempt) {
      send(set, frame, capture_ns);
      const auto deadline = std::chrono::steady_clock::now() + 3s;
      while (std::chrono::steady_clock::now() < deadline)
        if (auto h = next_head(100ms); h && h->frame == frame && h->capture_ns == capture_ns)
          return h;
    }
    return std::nullopt;
  }

  hull::SegmentSet cut(const sim::SimulatedStudio& studio, int frame, Eigen::Vector3d* head) {
    std::vector<Mask> masks;
    const sim::FrameTruth truth = studio.render_all(frame, nullptr, &masks);
    *head = truth.head_centre();
    std::vector<RunMask> runs;
    for (const Mask& m : masks) runs.push_back(RunMask::from_mask(m.view()));
    std::vector<hull::View> views;
    for (int c = 0; c < studio.camera_count(); ++c)
      views.push_back({&studio.cameras()[std::size_t(c)], &runs[std::size_t(c)]});
    return hull::visual_hull(spec_, views).value();
  }

  std::optional<wire::Participant> participant_;
  std::optional<wire::Topic<studio_SegmentSet>> seg_topic_;
  std::optional<wire::Topic<studio_HeadPose>> head_topic_;
  std::optional<wire::Writer<studio_SegmentSet>> writer_;
  std::optional<wire::Reader<studio_HeadPose>> reader_;
  hull::GridSpec spec_;
};

TEST_F(TrackerNodeTest, TracksTheSimulatedHeadThenDegradesGracefully) {
  start_node("instance: t1\npublish_rate: 20\nfilter:\n  max_missed: 5\n  coast_decay: 0.5\n");
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::walk;
  so.actor.seed = 5;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so).value();

  // 1. Tracking: frames 0, 3, ..., 45 of the walk (capture times on the studio clock).
  const int64_t t0 = realtime_ns();
  double sum2 = 0, worst = 0;
  int n = 0;
  Head last{};
  Eigen::Vector3d truth;
  for (int f = 0; f <= 45; f += 3) {
    const hull::SegmentSet set = cut(studio, f, &truth);
    auto h = exchange(set, uint64_t(f), t0 + f * kFramePeriodNs);
    ASSERT_TRUE(h.has_value()) << "no HeadPose for frame " << f;
    EXPECT_GE(h->confidence, 0.3) << f;
    const double e = (h->position - truth).norm();
    sum2 += e * e;
    worst = std::max(worst, e);
    ++n;
    last = *h;
  }
  const double rms = std::sqrt(sum2 / n);
  std::printf("node head error over %d frames: %.1f mm RMS, worst %.1f mm\n", n, rms * 1000,
              worst * 1000);
  EXPECT_LE(rms, 0.03);
  EXPECT_LE(worst, 0.05);

  // 2. Empty hulls (the actor left the volume): still published, confidence halves per frame
  // (coast_decay 0.5) and is 0 once the track is dropped after max_missed = 5 frames.
  const hull::SegmentSet empty = hull::SegmentSet::empty(spec_);
  double previous = last.confidence;
  for (int k = 1; k <= 7; ++k) {
    const uint64_t f = 45 + uint64_t(k) * 3;
    auto h = exchange(empty, f, t0 + int64_t(f) * kFramePeriodNs);
    ASSERT_TRUE(h.has_value()) << "no HeadPose for empty frame " << f;
    EXPECT_TRUE(h->position.allFinite());
    EXPECT_LT((h->position - last.position).norm(), 0.3) << "coasting head flew off, k " << k;
    if (k <= 5) {
      EXPECT_NEAR(h->confidence, previous * 0.5, 1e-9) << k;
    } else {
      EXPECT_EQ(h->confidence, 0.0) << k;
      EXPECT_EQ(h->velocity.norm(), 0.0);
    }
    previous = h->confidence;
  }

  // 3. The actor comes back: tracked again.
  const int back = 69;  // after the last empty frame (66)
  auto h = exchange(cut(studio, back, &truth), back, t0 + back * kFramePeriodNs);
  ASSERT_TRUE(h.has_value());
  EXPECT_GE(h->confidence, 0.3);
  EXPECT_LT((h->position - truth).norm(), 0.05);

  // 4. No input at all: keep-alives at ~20 Hz with the last frame, coasting with confidence
  // decaying by 0.5 per tick, 0 after 5 ticks; capture_ns advances; positions finite.
  std::vector<Head> alive;
  const auto until = std::chrono::steady_clock::now() + 1s;
  while (std::chrono::steady_clock::now() < until)
    if (auto k = next_head(100ms)) alive.push_back(*k);
  ASSERT_GE(alive.size(), 10u) << "keep-alive rate too low";
  EXPECT_LE(alive.size(), 30u) << "keep-alive rate too high";
  double c = h->confidence;
  int64_t t = h->capture_ns;
  for (std::size_t i = 0; i < alive.size(); ++i) {
    EXPECT_EQ(alive[i].frame, uint64_t(back));
    EXPECT_TRUE(alive[i].position.allFinite());
    EXPECT_LT((alive[i].position - h->position).norm(), 0.3);
    EXPECT_GT(alive[i].capture_ns, t);
    t = alive[i].capture_ns;
    if (i < 5)
      EXPECT_NEAR(alive[i].confidence, c * 0.5, 1e-9) << i;
    else
      EXPECT_EQ(alive[i].confidence, 0.0) << i;
    c = alive[i].confidence;
  }
}

TEST_F(TrackerNodeTest, RejectedSamplesAreDroppedAndTheNodeCarriesOn) {
  auto status_topic = wire::Topic<studio_ServiceStatus>::create(*participant_).value();
  auto status = wire::Reader<studio_ServiceStatus>::create(*participant_, status_topic).value();
  start_node("publish_rate: 2\nstatus_period: 0.2\n");
  // Its own key, so the good sample below cannot replace it in the node's keep-last-1 cache
  // before the node takes (and validates) it.
  wire::Owned<studio_SegmentSet> bad;
  wire::set(bad->actor_id, "hull-bad");
  bad->nu = bad->nv = 2;
  for (int k = 0; k < 3; ++k) bad->box_max[k] = 1;
  bad->axis = 1;
  wire::assign(bad->interval_start, std::vector<uint32_t>{0, 1, 1, 1, 7});  // more than sent
  wire::assign(bad->intervals, std::vector<float>{0.5f, 0.25f});

  // Counters from the node's status samples.
  double rejected = 0, sets_in = 0, heads_out = 0;
  auto poll_status = [&] {
    for (auto& r : status.take()) {
      if (!r.meta.valid_data) continue;
      EXPECT_STREQ(r.data->service, "tracker");
      for (const auto& c : wire::view(r.data->counters)) {
        if (std::string(c.name) == "rejected") rejected = c.value;
        if (std::string(c.name) == "segment_sets_in") sets_in = c.value;
        if (std::string(c.name) == "heads_out") heads_out = c.value;
      }
    }
  };
  // Best-effort: resend until the status reports the rejection.
  for (auto deadline = std::chrono::steady_clock::now() + 10s;
       rejected < 1 && std::chrono::steady_clock::now() < deadline;) {
    ASSERT_TRUE(writer_->write(*bad).has_value());
    for (int i = 0; i < 10 && rejected < 1; ++i) {
      std::this_thread::sleep_for(50ms);
      poll_status();
    }
  }
  EXPECT_GE(rejected, 1);
  EXPECT_EQ(sets_in, 0);  // rejected by the reader's validator, never handed to the tracker

  // A head-sized ball: found where it is.
  const Eigen::Vector3d centre(0.3, 1.6, -0.2);
  auto h = exchange(balls({centre}), 7, realtime_ns());
  ASSERT_TRUE(h.has_value());
  EXPECT_GT(h->confidence, 0.5);
  EXPECT_LT((h->position - centre).norm(), 0.02) << h->position.transpose();

  // The status reports the accepted set.
  for (auto deadline = std::chrono::steady_clock::now() + 10s;
       sets_in < 1 && std::chrono::steady_clock::now() < deadline;) {
    std::this_thread::sleep_for(50ms);
    poll_status();
  }
  EXPECT_GE(sets_in, 1);
  EXPECT_GE(heads_out, 1);
}

TEST_F(TrackerNodeTest, PublishTracksAddsOneSamplePerLiveTrack) {
  start_node("publish_rate: 2\npublish_tracks: true\n");
  const Eigen::Vector3d a(-0.5, 1.6, 0.1), b(0.5, 1.5, -0.3);
  const auto set = balls({a, b});
  std::map<std::string, Eigen::Vector3d> seen;
  for (int attempt = 0; attempt < 5 && seen.size() < 3; ++attempt) {
    send(set, 3, realtime_ns());
    const auto deadline = std::chrono::steady_clock::now() + 1s;
    while (std::chrono::steady_clock::now() < deadline && seen.size() < 3) {
      for (auto& r : reader_->take()) {
        if (!r.meta.valid_data || r.data->frame != 3 || r.data->confidence < 0.5) continue;
        seen[r.data->actor_id] = {r.data->position[0], r.data->position[1], r.data->position[2]};
      }
      std::this_thread::sleep_for(5ms);
    }
  }
  ASSERT_EQ(seen.size(), 3u);
  ASSERT_TRUE(seen.count("actor") && seen.count("actor/1") && seen.count("actor/2"));
  // Track ids follow detection order; match them to the balls by position.
  const double d1 = std::min((seen["actor/1"] - a).norm(), (seen["actor/1"] - b).norm());
  const double d2 = std::min((seen["actor/2"] - a).norm(), (seen["actor/2"] - b).norm());
  EXPECT_LT(d1, 0.02);
  EXPECT_LT(d2, 0.02);
  EXPECT_GT((seen["actor/1"] - seen["actor/2"]).norm(), 0.5);
  EXPECT_LT(std::min((seen["actor"] - a).norm(), (seen["actor"] - b).norm()), 0.02);
}

// The hull publishes each actor of a frame as its own SegmentSet: the node gathers them into one
// update, so every head is seen every frame (one update per set would miss the other actor's
// head each time: its confidence would drop by coast_decay, 0.8, on every update).
TEST_F(TrackerNodeTest, ActorsOfOneFrameAreOneUpdate) {
  start_node("publish_rate: 2\npublish_tracks: true\ngather_ms: 30\n");
  const Eigen::Vector3d a(-0.5, 1.6, 0.1), b(0.5, 1.5, -0.3);
  const auto set_a = balls({a}), set_b = balls({b});
  std::map<std::string, std::vector<double>> confidence;  // per track, frames >= 3
  const int64_t t0 = realtime_ns();
  for (uint64_t frame = 1; frame <= 10; ++frame) {
    const int64_t capture_ns = t0 + int64_t(frame) * 40'000'000;
    send(set_a, frame, capture_ns, "actor0");
    send(set_b, frame, capture_ns, "actor1");
    const auto until = std::chrono::steady_clock::now() + 150ms;
    while (std::chrono::steady_clock::now() < until) {
      for (auto& r : reader_->take()) {
        if (!r.meta.valid_data || r.data->frame < 3 || r.data->capture_ns == 0) continue;
        const std::string id = r.data->actor_id;
        if (id != "actor") confidence[id].push_back(r.data->confidence);
      }
      std::this_thread::sleep_for(5ms);
    }
  }
  ASSERT_EQ(confidence.size(), 2u) << "two tracks";
  for (const auto& [id, values] : confidence) {
    ASSERT_GE(values.size(), 4u) << id;
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    EXPECT_GT(*hi, 0.5) << id;
    EXPECT_GE(*lo, 0.95 * *hi) << id << ": a head missed in some update";
  }
}

TEST_F(TrackerNodeTest, BadConfigIsOneLineAndExitOne) {
  struct Case {
    std::string yaml, expect;
  } cases[] = {
      {"bogus: 1\n", "tracker.yaml:1: bogus: unknown key"},
      {"publish_rate: 0\n", "tracker.yaml:1: publish_rate: expected Hz in 0.5..1000"},
      {"gather_ms: 500\n", "tracker.yaml:1: gather_ms: expected 0..100 ms"},
      {"search:\n  max_heads: 0\n", "tracker.yaml:2: search.max_heads"},
      {"search:\n  head_box: [0.2, 0.2]\n", "search.head_box: expected 3 numbers, got 2"},
      {"search:\n  head_box: [0.5, 0.5, 0.5]\n", "outer_box must contain head_box"},
      {"filter:\n  gate: fast\n", "tracker.yaml:2: filter.gate"},
      {"filter:\n  wobble: 1\n", "tracker.yaml:2: filter.wobble: unknown key"},
      {"actor_id: ''\n", "actor_id"},
      {"search: [1, 2\n", "tracker.yaml"},
  };
  for (const auto& c : cases) {
    auto& p = spawn("tracker", "tracker/studio-tracker", {"--config", write_config(c.yaml)});
    const auto rc = p.wait_exit(10s);
    ASSERT_TRUE(rc.has_value()) << c.yaml;
    EXPECT_EQ(*rc, 1) << c.yaml;
    const std::string log = p.log();
    EXPECT_NE(log.find(c.expect), std::string::npos) << c.yaml << " → " << log;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  }
  auto& help = spawn("tracker", "tracker/studio-tracker", {"--help"});
  EXPECT_EQ(help.wait_exit(10s), 0);
  for (const char* key : {"publish_rate", "gather_ms", "actor_id", "head_box", "coast_decay", "locate"})
    EXPECT_NE(help.log().find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace studio::tracker
