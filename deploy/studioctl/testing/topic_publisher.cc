// studioctl_topic_publisher (test-only program, not a service): publishes a valid sample of every
// topic of the wire table (tests/harness/wire_samples.h fill(), seeds 0..3 so keyed topics carry
// four instances) at --rate HZ (default 10), sends READY=1 on $NOTIFY_SOCKET once its writers
// exist, and runs until SIGTERM/SIGINT. The DDS domain comes from the environment like every
// service ($STUDIO_DDS_DOMAIN, $CYCLONEDDS_URI).
#include <signal.h>

#include <charconv>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "harness/wire_samples.h"
#include "runtime/notify.h"
#include "runtime/signals.h"
#include "wire/endpoint.h"

namespace {

using namespace studio;

struct Publisher {
  virtual ~Publisher() = default;
  virtual void publish(int seed) = 0;
  virtual const char* topic_name() const = 0;
};

template <wire::WireType T>
struct TypedPublisher : Publisher {
  wire::Topic<T> topic;
  wire::Writer<T> writer;
  explicit TypedPublisher(const wire::Participant& p)
      : topic(wire::Topic<T>::create(p).value()),
        writer(wire::Writer<T>::create(p, topic).value()) {}
  void publish(int seed) override {
    auto s = testing::make<T>(seed);
    (void)writer.write(*s);
  }
  const char* topic_name() const override { return wire::TopicTraits<T>::name(); }
};

template <class... T>
std::vector<std::unique_ptr<Publisher>> publishers(const wire::Participant& p) {
  std::vector<std::unique_ptr<Publisher>> out;
  (out.push_back(std::make_unique<TypedPublisher<T>>(p)), ...);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  runtime::SignalWatcher signals({SIGINT, SIGTERM});
  double rate = 10;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--rate" && i + 1 < argc) {
      rate = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: studioctl_topic_publisher [--rate HZ]\n");
      return a == "--help" ? 0 : 2;
    }
  }
  if (!(rate > 0 && rate <= 1000)) {
    std::fprintf(stderr, "studioctl_topic_publisher: --rate: expected 0 < HZ <= 1000\n");
    return 2;
  }
  auto p = wire::Participant::create();
  if (!p) {
    std::fprintf(stderr, "studioctl_topic_publisher: %s\n", p.error().message.c_str());
    return 1;
  }
  auto all = publishers<studio_CameraCalibration, studio_AlphaMask, studio_CameraImage,
                        studio_CameraState, studio_CameraControl, studio_CaptureCommand,
                        studio_SegmentSet, studio_ActorMesh, studio_HeadPose, studio_SceneNode,
                        studio_SceneCommand, studio_SceneState, studio_ProjectorCalibration,
                        studio_ServiceStatus, studio_ProjectorMask, studio_ProjectorFrame,
                        studio_ImageRequest, studio_ImageReply>(*p);
  // A topic of the table this program does not publish would make studioctl's coverage test
  // fail for the wrong reason: say so here.
  for (const auto& row : wire::topic_table()) {
    bool found = false;
    for (const auto& pub : all) found = found || std::strcmp(pub->topic_name(), row.name) == 0;
    if (!found) {
      std::fprintf(stderr,
                   "studioctl_topic_publisher: no publisher for %s (add its type to "
                   "deploy/studioctl/testing/topic_publisher.cc)\n",
                   row.name);
      return 1;
    }
  }
  runtime::notify("READY=1");
  const auto period = std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(1.0 / rate));
  for (int seed = 0;; ++seed) {
    for (auto& pub : all) pub->publish(seed % 4);
    if (signals.wait(std::chrono::duration_cast<std::chrono::milliseconds>(period))) break;
  }
  return 0;
}
