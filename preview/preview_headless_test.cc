// studio-preview --headless --every S against the running simulated studio (processes on
// loopback): the demo's low-rate pictures. At most one new mesh drawn per interval, the
// screenshot rewritten with each (a reader never sees half a PNG), only the drawn meshes' images
// requested from the capture servers, and SIGTERM ends the run with the picture written, exit 0.
#include <gtest/gtest.h>

#include <csignal>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <thread>

#include "testing/studio_fixture.h"
#include "wire/endpoint.h"
#include "wire/sample.h"

namespace studio::preview::testing {
namespace {

// The newest value of `counter` in the capture service's status, or -1.
double capture_counter(wire::Reader<studio_ServiceStatus>& reader, const std::string& counter,
                       double previous) {
  double v = previous;
  for (auto& s : reader.take()) {
    if (!s.meta.valid_data || std::string(s.data->service) != "capture") continue;
    for (const auto& c : wire::view(s.data->counters))
      if (std::string(c.name) == counter) v = double(c.value);
  }
  return v;
}

TEST_F(PreviewStudioTest, EveryIntervalDrawsFewMeshesAsksOnlyForThemAndEndsOnSigterm) {
  auto participant = wire::Participant::create().value();
  auto topic = wire::Topic<studio_ServiceStatus>::create(participant).value();
  auto status = wire::Reader<studio_ServiceStatus>::create(participant, topic).value();
  start_studio(false);
  const auto shot = dir_ / "shot.png";
  Process& p = spawn("preview", "preview/studio-preview",
                     {"--headless", "--config", preview_config("demo"), "--size", "320x180",
                      "--every", "1.5", "--screenshot", shot.string(), "--json"});
  double requests_before = -1;
  // The first picture appears (a mesh drawn and the PNG renamed into place).
  const auto first_deadline = std::chrono::steady_clock::now() + 60s;
  while (!std::filesystem::exists(shot) && std::chrono::steady_clock::now() < first_deadline) {
    requests_before = capture_counter(status, "image_requests_in", requests_before);
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(std::filesystem::exists(shot)) << p.log();
  const auto first = std::chrono::steady_clock::now();
  EXPECT_FALSE(cv::imread(shot.string(), cv::IMREAD_COLOR).empty());
  // ~7.5 s of 25 meshes/s: ~190 meshes arrive, about 5 are drawn.
  double requests = requests_before;
  while (std::chrono::steady_clock::now() - first < 7500ms) {
    requests = capture_counter(status, "image_requests_in", requests);
    EXPECT_FALSE(cv::imread(shot.string(), cv::IMREAD_COLOR).empty()) << "half-written PNG";
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_EQ(::kill(p.pid(), SIGTERM), 0);
  const auto code = p.wait_exit(30s);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 0) << p.log();
  std::smatch m;
  const std::string log = p.log();
  ASSERT_TRUE(std::regex_search(log, m, std::regex(R"re("meshes":(\d+))re"))) << log;
  const int drawn = std::stoi(m[1]);
  std::printf("--every 1.5 over ~7.5 s: %d meshes drawn; capture image requests %g\n%s\n", drawn,
              requests, log.c_str());
  EXPECT_GE(drawn, 4);  // the first + one per 1.5 s
  EXPECT_LE(drawn, 7);
  // Each drawn mesh asks at most the blend's 3 cameras; 25 meshes/s with prefetch would ask
  // ~500 over the run.
  ASSERT_GE(requests, 0) << "no capture status with image_requests_in";
  EXPECT_LE(requests, 3.0 * (drawn + 1));
  EXPECT_GE(requests, double(drawn));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "shot.png.part.png"));
}

}  // namespace
}  // namespace studio::preview::testing
