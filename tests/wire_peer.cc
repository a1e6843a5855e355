// wire_peer: the other end of the wire integration tests and of dds_bench (test-only program,
// not a service). Joins the domain of the loopback profile ($STUDIO_DDS_DOMAIN, CYCLONEDDS_URI),
// sends READY=1 on $NOTIFY_SOCKET once its endpoints exist, and runs until SIGTERM/SIGINT.
//
//   wire_peer echo        every topic T of the table: take from T's topic, write the sample
//                         unchanged to "<T's topic>/echo" (same QoS row)
//   wire_peer publisher   publishes calibrations (cam0 twice, cam1) and scene nodes node0..2
//                         (transient-local), then serves SceneCommands: REMOVE_NODE disposes a
//                         node; LOAD_SET "malformed" writes malformed samples followed by a valid
//                         sentinel calibration "cam2"
//   wire_peer bench-echo [--listener]  AlphaMask from "studio/bench/ping" back to
//                                      "studio/bench/pong" (from a waitset or the listener)
//   wire_peer udp-echo PORT   baseline: echoes UDP datagrams on 127.0.0.1:PORT

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "harness/wire_samples.h"
#include "runtime/notify.h"
#include "runtime/signals.h"
#include "wire/endpoint.h"

namespace {

using namespace studio;
using namespace std::chrono_literals;

struct Pump {
  virtual ~Pump() = default;
  virtual void pump() = 0;
  virtual const wire::ReaderBase& source() const = 0;  // the reader whose data drives pump()
};

template <wire::WireType T>
struct Echo : Pump {
  wire::Topic<T> in_topic, out_topic;
  wire::Reader<T> reader;
  wire::Writer<T> writer;
  Echo(const wire::Participant& p, const std::string& in, const std::string& out)
      : in_topic(wire::Topic<T>::create(p, in).value()),
        out_topic(wire::Topic<T>::create(p, out).value()),
        reader(wire::Reader<T>::create(p, in_topic).value()),
        writer(wire::Writer<T>::create(p, out_topic).value()) {}
  const wire::ReaderBase& source() const override { return reader; }
  void pump() override {
    reader.visit([&](const T& s, const wire::SampleMeta& m) {
      if (m.valid_data) (void)writer.write(s);
    });
  }
};

template <wire::WireType T>
std::unique_ptr<Pump> echo_of(const wire::Participant& p) {
  const std::string name = wire::TopicTraits<T>::name();
  return std::make_unique<Echo<T>>(p, name, name + "/echo");
}

// Runs `pumps` whenever one of their readers has data, until the guard fires.
int serve(const wire::Participant& p, std::vector<Pump*> pumps, runtime::SignalWatcher& signals) {
  auto guard = wire::GuardCondition::create(p).value();
  auto ws = wire::WaitSet::create(p).value();
  for (std::size_t i = 0; i < pumps.size(); ++i)
    ws.attach(pumps[i]->source(), dds_attach_t(i)).value();
  constexpr dds_attach_t kStop = 1 << 30;
  ws.attach(guard, kStop).value();
  std::thread watcher([&] {
    signals.wait(std::chrono::milliseconds(-1));
    guard.trigger();
  });
  runtime::notify("READY=1");
  bool stop = false;
  while (!stop) {
    for (dds_attach_t token : ws.wait(std::chrono::seconds(1))) {
      if (token == kStop) {
        stop = true;
      } else {
        pumps[std::size_t(token)]->pump();
      }
    }
  }
  runtime::notify("STOPPING=1");
  watcher.join();
  return 0;
}

int run_echo(runtime::SignalWatcher& signals) {
  auto p = wire::Participant::create().value();
  std::vector<std::unique_ptr<Pump>> owned;
  owned.push_back(echo_of<studio_CameraCalibration>(p));
  owned.push_back(echo_of<studio_AlphaMask>(p));
  owned.push_back(echo_of<studio_CameraImage>(p));
  owned.push_back(echo_of<studio_CameraState>(p));
  owned.push_back(echo_of<studio_CameraControl>(p));
  owned.push_back(echo_of<studio_CaptureCommand>(p));
  owned.push_back(echo_of<studio_SegmentSet>(p));
  owned.push_back(echo_of<studio_ActorMesh>(p));
  owned.push_back(echo_of<studio_HeadPose>(p));
  owned.push_back(echo_of<studio_SceneNode>(p));
  owned.push_back(echo_of<studio_SceneCommand>(p));
  owned.push_back(echo_of<studio_ProjectorCalibration>(p));
  owned.push_back(echo_of<studio_ServiceStatus>(p));
  owned.push_back(echo_of<studio_SceneState>(p));
  owned.push_back(echo_of<studio_ProjectorMask>(p));
  owned.push_back(echo_of<studio_ProjectorFrame>(p));
  owned.push_back(echo_of<studio_ImageRequest>(p));
  owned.push_back(echo_of<studio_ImageReply>(p));
  std::vector<Pump*> pumps;
  for (auto& e : owned) pumps.push_back(e.get());
  return serve(p, pumps, signals);
}

struct Publisher : Pump {
  const wire::Participant& p;
  wire::Topic<studio_CameraCalibration> calib_topic =
      wire::Topic<studio_CameraCalibration>::create(p).value();
  wire::Topic<studio_SceneNode> node_topic = wire::Topic<studio_SceneNode>::create(p).value();
  wire::Topic<studio_SceneCommand> cmd_topic = wire::Topic<studio_SceneCommand>::create(p).value();
  wire::Topic<studio_AlphaMask> mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  wire::Topic<studio_ActorMesh> mesh_topic = wire::Topic<studio_ActorMesh>::create(p).value();
  wire::Writer<studio_CameraCalibration> calib =
      wire::Writer<studio_CameraCalibration>::create(p, calib_topic).value();
  wire::Writer<studio_SceneNode> nodes =
      wire::Writer<studio_SceneNode>::create(p, node_topic).value();
  wire::Writer<studio_AlphaMask> masks =
      wire::Writer<studio_AlphaMask>::create(p, mask_topic).value();
  wire::Writer<studio_ActorMesh> meshes =
      wire::Writer<studio_ActorMesh>::create(p, mesh_topic).value();
  wire::Reader<studio_SceneCommand> commands =
      wire::Reader<studio_SceneCommand>::create(p, cmd_topic).value();

  explicit Publisher(const wire::Participant& participant) : p(participant) {
    // cam0 twice (seed 0, then seed 4: same key, newer contents), then cam1.
    for (int seed : {0, 4, 1}) calib.write(*testing::make<studio_CameraCalibration>(seed)).value();
    for (int seed : {0, 1, 2}) nodes.write(*testing::make<studio_SceneNode>(seed)).value();
  }

  const wire::ReaderBase& source() const override { return commands; }
  void pump() override {
    for (auto& c : commands.take()) {
      if (!c.meta.valid_data) continue;
      if (c.data->verb == studio_SCENE_REMOVE_NODE) {
        wire::Owned<studio_SceneNode> key;
        wire::set(key->node_id, wire::str(c.data->target));
        nodes.dispose(*key).value();
      } else if (c.data->verb == studio_SCENE_LOAD_SET && wire::str(c.data->path) == "malformed") {
        write_malformed();
      }
    }
  }

  void write_malformed() {
    auto bad_calib = testing::make<studio_CameraCalibration>(3);  // cam3
    bad_calib->K[0] = std::nan("");
    calib.write(*bad_calib).value();
    auto bad_mesh = testing::make<studio_ActorMesh>(1);
    wire::view(bad_mesh->triangles)[4] = 1000000;  // index past the vertices
    meshes.write(*bad_mesh).value();
    for (int i = 0; i < 3; ++i) {
      auto bad_mask = testing::make<studio_AlphaMask>(1);
      wire::view(bad_mask->runs)[1] = bad_mask->width + 5;  // a run leaving the image
      bad_mask->frame += i;
      masks.write(*bad_mask).value();
      std::this_thread::sleep_for(20ms);
    }
    calib.write(*testing::make<studio_CameraCalibration>(2)).value();  // sentinel cam2
  }
};

int run_publisher(runtime::SignalWatcher& signals) {
  auto p = wire::Participant::create().value();
  Publisher pub(p);
  return serve(p, {&pub}, signals);
}

// --listener: echo from the reader's data-available callback on Cyclone's receive thread
// instead of a waitset on the main thread (one wake-up per sample instead of two).
int run_bench_echo(bool listener, runtime::SignalWatcher& signals) {
  auto p = wire::Participant::create().value();
  Echo<studio_AlphaMask> echo(p, "studio/bench/ping", "studio/bench/pong");
  if (!listener) return serve(p, {&echo}, signals);
  echo.reader.on_data_available([&echo] { echo.pump(); }).value();
  runtime::notify("READY=1");
  signals.wait(std::chrono::milliseconds(-1));
  runtime::notify("STOPPING=1");
  echo.reader.on_data_available(nullptr).value();
  return 0;
}

int run_udp_echo(int port, runtime::SignalWatcher& signals) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    std::fprintf(stderr, "wire_peer: cannot bind udp port %d: %s\n", port, std::strerror(errno));
    return 1;
  }
  runtime::notify("READY=1");
  std::vector<char> buf(65536);
  for (;;) {
    pollfd fds[2] = {{fd, POLLIN, 0}, {signals.fd(), POLLIN, 0}};
    if (poll(fds, 2, -1) < 0 && errno != EINTR) break;
    if (fds[1].revents) break;
    if (fds[0].revents) {
      sockaddr_in from{};
      socklen_t len = sizeof from;
      const ssize_t n =
          recvfrom(fd, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&from), &len);
      if (n > 0) sendto(fd, buf.data(), size_t(n), 0, reinterpret_cast<sockaddr*>(&from), len);
    }
  }
  close(fd);
  return 0;
}

void usage(FILE* out) {
  std::fputs(
      "usage: wire_peer echo | publisher | bench-echo [--listener] | udp-echo PORT\n"
      "Test peer for the wire integration tests and dds_bench (joins $STUDIO_DDS_DOMAIN with\n"
      "$CYCLONEDDS_URI, sends READY=1 to $NOTIFY_SOCKET, runs until SIGTERM).\n",
      out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage(stderr);
    return 2;
  }
  const std::string mode = argv[1];
  if (mode == "--help" || mode == "-h") {
    usage(stdout);
    return 0;
  }
  runtime::SignalWatcher signals;  // before any thread (Cyclone's included)
  try {
    if (mode == "echo") return run_echo(signals);
    if (mode == "publisher") return run_publisher(signals);
    if (mode == "bench-echo" && argc <= 3)
      return run_bench_echo(argc == 3 && std::string(argv[2]) == "--listener", signals);
    if (mode == "udp-echo" && argc == 3) return run_udp_echo(std::atoi(argv[2]), signals);
  } catch (const std::bad_expected_access<studio::Error>& e) {
    std::fprintf(stderr, "wire_peer: %s\n", e.error().message.c_str());
    return 1;
  }
  std::fprintf(stderr, "wire_peer: unknown mode '%s' (see --help)\n", mode.c_str());
  return 2;
}
