#include "take.h"

#include <chrono>
#include <map>
#include <set>
#include <thread>

#include "core/clock.h"
#include "json_writer.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"
#include "wire/sample.h"

namespace studio::demo {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

struct CamState {
  bool recording = false;
  std::string take;
};

}  // namespace

Expected<std::string> run_take(const TakeOptions& o) {
  if (o.name.empty() || o.name.size() > 63) return fail("take: name must be 1..63 characters");
  if (o.frames < 1) return fail("take: --frames must be >= 1");
  const int ncams = int(o.studio.camera_ids.size());
  auto participant = wire::Participant::create();
  if (!participant) return std::unexpected(participant.error());
  auto commands = wire::Publication<studio_CaptureCommand>::create(*participant);
  if (!commands) return std::unexpected(commands.error());
  auto states = wire::Subscription<studio_CameraState>::create(*participant, {}, 16);
  if (!states) return std::unexpected(states.error());
  const auto deadline = Clock::now() + std::chrono::milliseconds(int64_t(o.timeout_s * 1000));

  // Each capture process has one command reader; one process may serve several cameras, so
  // count servers through their camera states instead of matched readers.
  std::map<std::string, CamState> cams;
  auto poll = [&] {
    (*states)->visit([&](const studio_CameraState& s, const wire::SampleMeta& meta) {
      if (!meta.valid_data) return;
      cams[s.camera_id] = CamState{bool(s.recording), std::string(s.take)};
    });
  };
  auto all_cams = [&](auto pred) {
    for (const auto& id : o.studio.camera_ids) {
      auto it = cams.find(id);
      if (it == cams.end() || !pred(it->second)) return false;
    }
    return true;
  };
  while (Clock::now() < deadline && !all_cams([](const CamState&) { return true; })) {
    poll();
    std::this_thread::sleep_for(50ms);
  }
  if (!all_cams([](const CamState&) { return true; }))
    return fail("take: not every camera's state arrived (are the capture servers running?)");
  if (!(*commands)->wait_for_readers(
          1, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now())))
    return fail("take: no capture server reads studio/capture/command");
  std::this_thread::sleep_for(200ms);  // let every server's command reader match

  const auto& clock = o.studio.clock;
  const uint64_t start =
      clock.frame_at(realtime_ns()) + uint64_t(o.lead_s * 1e9 / double(clock.period_ns)) + 1;
  const uint64_t stop = start + uint64_t(o.frames);
  auto send = [&](studio_CaptureAction action, uint64_t at) -> Expected<void> {
    wire::Owned<studio_CaptureCommand> c;
    wire::set(c->take, o.name);
    c->action = action;
    c->at_frame = at;
    c->frame = clock.frame_at(realtime_ns());
    c->capture_ns = realtime_ns();
    return (*commands)->write(*c);
  };
  if (auto r = send(studio_CAPTURE_START, start); !r) return std::unexpected(r.error());

  std::set<std::string> confirmed_start, confirmed_stop;
  while (Clock::now() < deadline && int(confirmed_start.size()) < ncams) {
    poll();
    for (const auto& id : o.studio.camera_ids)
      if (cams[id].take == o.name) confirmed_start.insert(id);
    std::this_thread::sleep_for(20ms);
  }
  if (auto r = send(studio_CAPTURE_STOP, stop); !r) return std::unexpected(r.error());
  // Done when the stop frame has passed and no camera records any more.
  const int64_t stop_ns = clock.time_of(stop) + clock.period_ns;
  while (Clock::now() < deadline) {
    poll();
    for (const auto& id : o.studio.camera_ids)
      if (!cams[id].recording && realtime_ns() > stop_ns) confirmed_stop.insert(id);
    if (int(confirmed_stop.size()) == ncams) break;
    std::this_thread::sleep_for(50ms);
  }
  JsonWriter j;
  j.begin_object();
  j.field("take", o.name).field("start_frame", start).field("stop_frame", stop);
  j.field("frames", uint64_t(o.frames));
  j.key("confirmed_start").begin_array();
  for (const auto& id : confirmed_start) j.value(id);
  j.end_array();
  j.key("confirmed_stop").begin_array();
  for (const auto& id : confirmed_stop) j.value(id);
  j.end_array();
  j.field("complete", int(confirmed_start.size()) == ncams && int(confirmed_stop.size()) == ncams);
  j.end_object();
  return j.str();
}

}  // namespace studio::demo
