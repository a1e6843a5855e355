#include "studioctl/control.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <thread>

#include "studioctl/cli.h"
#include "studioctl/printer.h"
#include "studioctl/send.h"
#include "wire/endpoint.h"

namespace studio::ctl {

const char kCaptureHelp[] =
    "usage: studioctl capture start [--take NAME] [--at-frame N] [--lead F] [--wait S] [--json]\n"
    "       studioctl capture stop  [--take NAME] [--at-frame N] [--lead F] [--wait S] [--json]\n"
    "\n"
    "Sends a CaptureCommand (studio/capture/command): every capture service starts (stops)\n"
    "recording take NAME at exactly frame N of the studio clock (DESIGN §5), then waits for each\n"
    "camera's read-back (studio/camera/state) and prints it; exit 1 when a camera reports an "
    "error\n"
    "for the command or no capture service is listening.\n"
    "\n"
    "  --take NAME     letters, digits, _ - . (start: default take-YYYYmmdd-HHMMSS, UTC; stop:\n"
    "                  default the take the cameras report)\n"
    "  --at-frame N    the frame to start/stop at (default: the latest frame the cameras report\n"
    "                  plus --lead, 50 frames)\n"
    "  --wait S        how long to wait for cameras and their read-back (default 10)\n"
    "\n"
    "Common options: --domain N, --dds-config FILE, --json, --help.\n";

const char kCameraHelp[] =
    "usage: studioctl camera get CAM [FEATURE] [--wait S] [--json]\n"
    "       studioctl camera set CAM FEATURE VALUE [--wait S] [--json]\n"
    "\n"
    "  get   the features camera CAM reports in studio/camera/state (GenICam names: ExposureTime,\n"
    "        Gain, ...): value, min, max; with FEATURE only that one (exit 1 if unknown).\n"
    "  set   sends CameraControl (studio/camera/control) and waits for the camera's read-back:\n"
    "        prints the value the camera applied (it may clamp it to its range); exit 1 when the\n"
    "        camera reports an error for FEATURE or no read-back arrives within --wait S\n"
    "        (default 10). Features the camera does not report (commands such as KeyerPlate N)\n"
    "        are confirmed by the absence of an error naming them in the states of the next\n"
    "        second.\n"
    "\n"
    "Common options: --domain N, --dds-config FILE, --json, --help.\n";

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

bool valid_take_name(const std::string& s) {
  if (s.empty() || s.size() > 63 || s == "." || s == "..") return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

std::string default_take_name() {
  const time_t t = time(nullptr);
  tm utc{};
  gmtime_r(&t, &utc);
  char buf[64];
  std::strftime(buf, sizeof buf, "take-%Y%m%d-%H%M%S", &utc);
  return buf;
}

// The latest CameraState per camera, as the capture services publish them.
class States {
 public:
  static Expected<States> open(const wire::Participant& p) {
    auto t = wire::Topic<studio_CameraState>::create(p);
    if (!t) return std::unexpected(t.error());
    auto r = wire::Reader<studio_CameraState>::create(p, *t);
    if (!r) return std::unexpected(r.error());
    return States(std::move(*t), std::move(*r));
  }
  // Polls until pred(latest, fresh) or the deadline; `fresh` holds the cameras whose state
  // arrived in this call. Returns pred's last verdict.
  template <class Pred>
  bool poll_until(Clock::time_point deadline, Pred pred) {
    std::map<std::string, bool> fresh;
    while (true) {
      for (auto& s : reader_.take(64)) {
        if (!s.meta.valid_data) continue;
        const std::string id(wire::str(s.data->camera_id));
        latest_[id] = std::move(s.data);
        fresh[id] = true;
      }
      if (pred(latest_, fresh)) return true;
      if (Clock::now() >= deadline) return false;
      std::this_thread::sleep_for(20ms);
    }
  }
  std::map<std::string, wire::Owned<studio_CameraState>>& latest() { return latest_; }

 private:
  States(wire::Topic<studio_CameraState> t, wire::Reader<studio_CameraState> r)
      : topic_(std::move(t)), reader_(std::move(r)) {}
  wire::Topic<studio_CameraState> topic_;
  wire::Reader<studio_CameraState> reader_;
  std::map<std::string, wire::Owned<studio_CameraState>> latest_;
};

const studio_CameraFeature* find_feature(const studio_CameraState& s, std::string_view name) {
  for (const auto& f : wire::view(s.features))
    if (wire::str(f.name) == name) return &f;
  return nullptr;
}

// Sends one sample to the readers of `writer` and waits until they acknowledged it.
template <class T>
Expected<void> send(const wire::Writer<T>& writer, const T& sample, Clock::time_point deadline,
                    const char* listeners) {
  return send_acked(writer, sample, deadline, listeners);
}

int capture(const std::string& verb, const Args& a) {
  const std::string what = "capture " + verb;
  const bool start = verb == "start";
  auto wait = seconds_flag(a, "--wait", 10, 0.1, 600);
  if (!wait) return complain(what, wait.error().message, 2);
  auto lead = count_flag(a, "--lead", 50);
  if (!lead) return complain(what, lead.error().message, 2);
  std::optional<uint64_t> at;
  if (const auto* v = a.value("--at-frame")) {
    auto n = parse_count("--at-frame", *v);
    if (!n) return complain(what, n.error().message, 2);
    at = *n;
  }
  std::string take = a.value("--take") ? *a.value("--take") : "";
  if (!take.empty() && !valid_take_name(take))
    return complain(
        what, "--take: '" + take + "' is not a take name (1..63 of letters, digits, _ - .)", 2);
  if (!a.positional.empty())
    return complain(what, "unexpected argument '" + a.positional[0] + "'", 2);

  auto p = open_participant(a.common);
  if (!p) return complain(what, p.error().message);
  auto states = States::open(*p);
  if (!states) return complain(what, states.error().message);
  auto topic = wire::Topic<studio_CaptureCommand>::create(*p);
  if (!topic) return complain(what, topic.error().message);
  auto writer = wire::Writer<studio_CaptureCommand>::create(*p, *topic);
  if (!writer) return complain(what, writer.error().message);
  const auto deadline = Clock::now() + to_ns(*wait);

  // The cameras (transient-local state: every capture service's cameras arrive at once).
  const bool need_frame = !at.has_value();
  const bool need_take = !start && take.empty();
  states->poll_until(deadline, [&](auto& latest, auto&) {
    if (latest.empty()) return false;
    for (auto& [id, s] : latest)
      if ((need_frame && s->frame == 0) || (need_take && wire::str(s->take).empty())) return false;
    return true;
  });
  if (need_frame || need_take) {
    if (states->latest().empty())
      return complain(what, "no camera reported its state on studio/camera/state within " +
                                std::to_string(*wait).substr(0, 4) + " s");
    uint64_t newest = 0;
    for (auto& [id, s] : states->latest()) {
      newest = std::max(newest, s->frame);
      if (need_take && take.empty()) take = std::string(wire::str(s->take));
    }
    if (need_frame) at = newest + *lead;
    if (take.empty()) return complain(what, "no camera reports a take to stop; give --take NAME");
  }
  if (take.empty()) take = default_take_name();

  wire::Owned<studio_CaptureCommand> c;
  wire::set(c->take, take);
  c->action = start ? studio_CAPTURE_START : studio_CAPTURE_STOP;
  c->at_frame = *at;
  c->capture_ns = realtime_ns();
  if (auto r = send(*writer, *c, deadline, "capture service"); !r)
    return complain(what, r.error().message);

  // Read-back: each camera names the take (pending or recording) or reports an error naming it.
  auto settled = [&](const studio_CameraState& s) {
    const std::string_view err = wire::str(s.error);
    if (err.find(take) != std::string_view::npos) return true;
    // start: the camera names the take (pending, then recording); stop: its state after the
    // command carries no error naming the take.
    return !start || wire::str(s.take) == take;
  };
  states->poll_until(deadline, [&](auto& latest, auto& fresh) {
    if (latest.empty()) return false;
    for (auto& [id, s] : latest)
      if (!fresh.count(id) || !settled(*s)) return false;
    return true;
  });
  int errors = 0;
  for (auto& [id, s] : states->latest()) {
    const std::string err(wire::str(s->error));
    const bool problem = err.find(take) != std::string::npos || !settled(*s);
    errors += problem;
    if (a.common.json) {
      Printer pr(Printer::Mode::json);
      pr.begin_object();
      pr.key("camera_id");
      pr.string(id);
      pr.key("take");
      pr.string(take);
      pr.key("action");
      pr.string(start ? "CAPTURE_START" : "CAPTURE_STOP");
      pr.key("at_frame");
      pr.number(*at);
      pr.key("frame");
      pr.number(s->frame);
      pr.key("recording");
      pr.number(bool(s->recording));
      pr.key("ok");
      pr.number(!problem);
      pr.key("error");
      pr.string(problem && err.empty() ? "no read-back within --wait" : err);
      pr.end_object();
      emit(pr.take());
    } else if (problem) {
      emit(id + ": " + (err.empty() ? "no read-back within --wait" : err));
    } else {
      emit(id + ": take " + take + (start ? " starts" : " stops") + " at frame " +
           std::to_string(*at) + " (camera at frame " + std::to_string(s->frame) +
           (s->recording ? ", recording)" : ")"));
    }
  }
  if (errors)
    return complain(what, std::to_string(errors) + " camera(s) did not accept the command");
  return 0;
}

void feature_json(Printer& pr, const std::string& cam, const studio_CameraFeature& f) {
  pr.begin_object();
  pr.key("camera_id");
  pr.string(cam);
  pr.key("name");
  pr.string(wire::str(f.name));
  pr.key("value");
  pr.number(f.value);
  pr.key("min");
  pr.number(f.min);
  pr.key("max");
  pr.number(f.max);
  pr.end_object();
}

std::string feature_text(const studio_CameraFeature& f) {
  char buf[192];
  std::snprintf(buf, sizeof buf, "%-20s %g (range %g .. %g)",
                std::string(wire::str(f.name)).c_str(), f.value, f.min, f.max);
  return buf;
}

int camera(const std::string& verb, const Args& a) {
  const std::string what = "camera " + verb;
  const bool set = verb == "set";
  const std::size_t want = set ? 3 : a.positional.size() == 2 ? 2 : 1;
  if (a.positional.size() != want || (!set && a.positional.size() > 2))
    return complain(
        what,
        set ? "expected CAM FEATURE VALUE (see --help)" : "expected CAM [FEATURE] (see --help)", 2);
  const std::string cam = a.positional[0];
  const std::string feature = a.positional.size() > 1 ? a.positional[1] : "";
  if (cam.size() > 63 || feature.size() > 63)
    return complain(what, "names are at most 63 characters", 2);
  double value = 0;
  if (set) {
    auto v = parse_number("VALUE", a.positional[2]);
    if (!v) return complain(what, v.error().message, 2);
    value = *v;
  }
  auto wait = seconds_flag(a, "--wait", 10, 0.1, 600);
  if (!wait) return complain(what, wait.error().message, 2);

  auto p = open_participant(a.common);
  if (!p) return complain(what, p.error().message);
  auto states = States::open(*p);
  if (!states) return complain(what, states.error().message);
  const auto deadline = Clock::now() + to_ns(*wait);
  if (!states->poll_until(deadline, [&](auto& latest, auto&) { return latest.count(cam) > 0; }))
    return complain(what, "camera '" + cam + "' did not report its state within " +
                              std::to_string(*wait).substr(0, 4) + " s");

  if (!set) {
    const auto& s = *states->latest().at(cam);
    if (!feature.empty() && !find_feature(s, feature)) {
      std::string known;
      for (const auto& f : wire::view(s.features))
        known += (known.empty() ? "" : ", ") + std::string(wire::str(f.name));
      return complain(what, cam + " has no feature '" + feature + "' (it reports: " + known + ")");
    }
    for (const auto& f : wire::view(s.features)) {
      if (!feature.empty() && wire::str(f.name) != feature) continue;
      if (a.common.json) {
        Printer pr(Printer::Mode::json);
        feature_json(pr, cam, f);
        emit(pr.take());
      } else {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g", f.value);
        emit(feature.empty() ? feature_text(f) : std::string(buf));
      }
    }
    return 0;
  }

  const studio_CameraFeature* before = find_feature(*states->latest().at(cam), feature);
  const bool reported = before != nullptr;
  const double old_value = reported ? before->value : NAN;

  auto topic = wire::Topic<studio_CameraControl>::create(*p);
  if (!topic) return complain(what, topic.error().message);
  auto writer = wire::Writer<studio_CameraControl>::create(*p, *topic);
  if (!writer) return complain(what, writer.error().message);
  wire::Owned<studio_CameraControl> c;
  wire::set(c->camera_id, cam);
  wire::set(c->feature, feature);
  c->value = value;
  c->capture_ns = realtime_ns();
  states->poll_until(Clock::now(),
                     [](auto&, auto&) { return true; });  // drain: only later states count
  if (auto r = send(*writer, *c, deadline, "capture service"); !r)
    return complain(what, r.error().message);

  // The camera publishes its state right after handling a control: the first fresh state that
  // shows the value (or a change, when the camera clamped it) or an error naming the feature.
  // A feature without read-back (a command such as KeyerPlate) has no value to wait for: a
  // periodic state may arrive before the control was handled, so every state of the next
  // second is checked for an error naming it.
  std::string error;
  bool done = false;
  const auto settle = std::min(deadline, Clock::now() + std::chrono::seconds(1));
  states->poll_until(reported ? deadline : settle, [&](auto& latest, auto& fresh) {
    if (!fresh.count(cam)) return false;
    const auto& s = *latest.at(cam);
    const std::string err(wire::str(s.error));
    if (err.find("'" + feature + "'") != std::string::npos ||
        err.find(feature + ":") != std::string::npos ||
        err.find(feature + " ") != std::string::npos) {
      error = err;
      return true;
    }
    const studio_CameraFeature* f = find_feature(s, feature);
    if (!reported) return false;  // keep watching until `settle`
    if (f && (f->value == value || f->value != old_value)) return done = true;
    return false;
  });
  if (!error.empty()) return complain(what, cam + ": " + error);
  if (!reported) done = true;  // no error within the settle time
  if (!done)
    return complain(what, cam + ": no read-back of " + feature + " within " +
                              std::to_string(*wait).substr(0, 4) + " s");
  const studio_CameraFeature* f = find_feature(*states->latest().at(cam), feature);
  if (a.common.json) {
    Printer pr(Printer::Mode::json);
    if (f) {
      feature_json(pr, cam, *f);
    } else {
      pr.begin_object();
      pr.key("camera_id");
      pr.string(cam);
      pr.key("name");
      pr.string(feature);
      pr.key("sent");
      pr.number(value);
      pr.end_object();
    }
    emit(pr.take());
  } else if (f) {
    emit(cam + " " + feature_text(*f) +
         (f->value != value ? "  (asked for " + std::to_string(value) + ", the camera clamped it)"
                            : ""));
  } else {
    emit(cam + " " + feature + ": sent " + std::to_string(value) +
         " (the camera reports no read-back for it; no error)");
  }
  return 0;
}

}  // namespace

int capture_command(const std::vector<std::string>& argv) {
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h") {
    std::fputs(kCaptureHelp, argv.empty() ? stderr : stdout);
    return argv.empty() ? 2 : 0;
  }
  const std::string verb = argv[0];
  if (verb != "start" && verb != "stop")
    return complain("capture", "unknown verb '" + verb + "' (start, stop)", 2);
  auto a = parse_args({argv.begin() + 1, argv.end()}, {"--take", "--at-frame", "--lead", "--wait"});
  if (!a) return complain("capture " + verb, a.error().message, 2);
  if (a->help) {
    std::fputs(kCaptureHelp, stdout);
    return 0;
  }
  return capture(verb, *a);
}

int camera_command(const std::vector<std::string>& argv) {
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h") {
    std::fputs(kCameraHelp, argv.empty() ? stderr : stdout);
    return argv.empty() ? 2 : 0;
  }
  const std::string verb = argv[0];
  if (verb != "get" && verb != "set")
    return complain("camera", "unknown verb '" + verb + "' (get, set)", 2);
  auto a = parse_args({argv.begin() + 1, argv.end()}, {"--wait"});
  if (!a) return complain("camera " + verb, a.error().message, 2);
  if (a->help) {
    std::fputs(kCameraHelp, stdout);
    return 0;
  }
  return camera(verb, *a);
}

}  // namespace studio::ctl
