// studio-capture against a GenICam camera with white balance, over real GigE Vision: Aravis'
// arv-fake-gv-camera-0.8 on 127.0.0.1, inside a private network namespace (ctest runs this binary
// through run_in_netns.sh), serving Aravis' own fake-camera description extended with SFNC's
// BalanceRatioSelector + BalanceRatio (one register per channel, selected by pIndex) and a
// read-only Gamma. Aravis' fake camera has no white balance of its own (the refusal:
// aravis_source_test AravisFake.FeaturesReadBackAndClamp); this is the positive path: the
// service offers BalanceRatioRed / BalanceRatioBlue with the camera's range on
// studio/camera/state, applies CameraControl through the selector (each channel its own
// register), clamps to the range, and publishes Gamma (the preview's Match cameras reads it,
// preview/camera_match.h CameraControls::exponent).
#include <arv.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <thread>

#include "capture/aravis_source.h"
#include "harness/fixture.h"
#include "testing/private_netns.h"
#include "wire/endpoint.h"

namespace studio::capture {
namespace {

using namespace std::chrono_literals;
constexpr char kDeviceId[] = "Aravis-Fake-GV01";

// The nodes a colour GenICam camera adds (names and meaning from SFNC; registers in the fake
// device's free memory above its own). Register value 0 reads as ratio 1 (and Gamma 0.5), so the
// camera starts neutral: BalanceRatio = raw / 1000 + 1.
constexpr char kWhiteBalanceNodes[] = R"(
  <Enumeration Name="BalanceRatioSelector" NameSpace="Standard">
    <EnumEntry Name="Red" NameSpace="Standard"><Value>0</Value></EnumEntry>
    <EnumEntry Name="Green" NameSpace="Standard"><Value>1</Value></EnumEntry>
    <EnumEntry Name="Blue" NameSpace="Standard"><Value>2</Value></EnumEntry>
    <pValue>BalanceRatioSelectorRegister</pValue>
  </Enumeration>
  <IntReg Name="BalanceRatioSelectorRegister" NameSpace="Custom">
    <Address>0x1000</Address><Length>4</Length><AccessMode>RW</AccessMode>
    <pPort>Device</pPort><Sign>Unsigned</Sign><Endianess>BigEndian</Endianess>
  </IntReg>
  <Float Name="BalanceRatio" NameSpace="Standard">
    <pValue>BalanceRatioConverter</pValue><Min>0.5</Min><Max>3</Max>
  </Float>
  <Converter Name="BalanceRatioConverter" NameSpace="Custom">
    <FormulaTo>(FROM - 1) * 1000</FormulaTo><FormulaFrom>TO / 1000 + 1</FormulaFrom>
    <pValue>BalanceRatioRegister</pValue>
  </Converter>
  <IntReg Name="BalanceRatioRegister" NameSpace="Custom">
    <Address>0x1010</Address><pIndex Offset="4">BalanceRatioSelectorRegister</pIndex>
    <Length>4</Length><AccessMode>RW</AccessMode><pPort>Device</pPort>
    <Sign>Signed</Sign><Endianess>BigEndian</Endianess>
  </IntReg>
  <Float Name="Gamma" NameSpace="Standard">
    <pValue>GammaConverter</pValue><Min>0.25</Min><Max>4</Max>
  </Float>
  <Converter Name="GammaConverter" NameSpace="Custom">
    <FormulaTo>(FROM - 0.5) * 1000</FormulaTo><FormulaFrom>TO / 1000 + 0.5</FormulaFrom>
    <pValue>GammaRegister</pValue>
  </Converter>
  <IntReg Name="GammaRegister" NameSpace="Custom">
    <Address>0x1020</Address><Length>4</Length><AccessMode>RW</AccessMode>
    <pPort>Device</pPort><Sign>Signed</Sign><Endianess>BigEndian</Endianess>
  </IntReg>
)";

// Aravis' fake-camera description (read from the library, not copied) with the nodes above
// inserted before its end; empty when Aravis gives none.
std::string white_balance_camera_xml() {
  ArvFakeCamera* fake = arv_fake_camera_new("description");
  size_t size = 0;
  const char* xml = fake ? arv_fake_camera_get_genicam_xml(fake, &size) : nullptr;
  std::string text = xml ? std::string(xml, size) : std::string();
  if (fake) g_object_unref(fake);
  const auto end = text.rfind("</RegisterDescription>");
  if (end == std::string::npos) return {};
  return text.insert(end, kWhiteBalanceNodes);
}

class CaptureGvTest : public testing::ProcessTest {
 protected:
  void SetUp() override {
    ProcessTest::SetUp();
    if (!only_loopback())
      GTEST_SKIP() << "not in a private network namespace; run through ctest (run_in_netns.sh)";
    participant_.emplace(wire::Participant::create().value());
  }

  // The fake GigE camera serving `xml`, discovered on lo.
  void start_camera(const std::string& xml) {
    const auto path = dir_ / "camera.xml";
    std::ofstream(path) << xml;
    auto p = testing::Process::start({.name = "gv-camera",
                                      .binary = "/usr/bin/arv-fake-gv-camera-0.8",
                                      .args = {"-i", "127.0.0.1", "-g", path.string()},
                                      .env = {},
                                      .dir = dir_});
    ASSERT_TRUE(p.has_value()) << p.error().message;
    processes_.push_back(std::move(*p));
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    while (std::chrono::steady_clock::now() < deadline) {
      const auto ids = list_aravis_devices({"GigEVision"});
      if (std::find(ids.begin(), ids.end(), kDeviceId) != ids.end()) return;
      std::this_thread::sleep_for(100ms);
    }
    FAIL() << kDeviceId << " not discovered on lo\n" << processes_.back().log();
  }

  // Latest state of camera gv0, polled until pred(state) or timeout.
  template <class Pred>
  bool wait_state(wire::Reader<studio_CameraState>& r, wire::Owned<studio_CameraState>& state,
                  Pred pred, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    bool have = false;
    while (std::chrono::steady_clock::now() < deadline) {
      for (auto& s : r.take())
        if (s.meta.valid_data && wire::str(s.data->camera_id) == "gv0") {
          state = std::move(s.data);
          have = true;
        }
      if (have && pred(*state)) return true;
      std::this_thread::sleep_for(20ms);
    }
    return false;
  }

  static const studio_CameraFeature* feature(const studio_CameraState& s, const std::string& name) {
    for (const auto& f : wire::view(s.features))
      if (wire::str(f.name) == name) return &f;
    return nullptr;
  }
  static double value(const studio_CameraState& s, const std::string& name) {
    const studio_CameraFeature* f = feature(s, name);
    return f ? f->value : NAN;
  }

  std::optional<wire::Participant> participant_;
};

TEST_F(CaptureGvTest, WhiteBalanceIsOfferedAppliedPerChannelAndClamped) {
  const std::string xml = white_balance_camera_xml();
  ASSERT_FALSE(xml.empty()) << "Aravis gave no fake-camera description";
  start_camera(xml);
  if (HasFatalFailure()) return;

  auto state_topic = wire::Topic<studio_CameraState>::create(*participant_).value();
  auto states = wire::Reader<studio_CameraState>::create(*participant_, state_topic).value();
  auto control_topic = wire::Topic<studio_CameraControl>::create(*participant_).value();
  auto control = wire::Writer<studio_CameraControl>::create(*participant_, control_topic).value();
  const auto config = dir_ / "capture.yaml";
  std::ofstream(config) << "state_period: 0.2\ncameras:\n  - id: gv0\n    source: {type: aravis, "
                           "device: Aravis-Fake-GV01, interfaces: [GigEVision], pixel_format: "
                           "BayerRG8, width: 320, height: 240, fps: 25}\n";
  auto& capture = spawn("capture", "capture/studio-capture", {"--config", config.string()});
  ASSERT_TRUE(capture.wait_ready(30s)) << capture.log();

  // Offered with the camera's range, neutral at start; Gamma published read-only.
  wire::Owned<studio_CameraState> st;
  ASSERT_TRUE(wait_state(
      states, st,
      [](const studio_CameraState& s) {
        return feature(s, "BalanceRatioRed") && feature(s, "BalanceRatioBlue") &&
               feature(s, "Gamma");
      },
      10s))
      << capture.log();
  for (const char* name : {"BalanceRatioRed", "BalanceRatioBlue"}) {
    const studio_CameraFeature* f = feature(*st, name);
    EXPECT_NEAR(f->value, 1.0, 1e-9) << name;
    EXPECT_NEAR(f->min, 0.5, 1e-9) << name;
    EXPECT_NEAR(f->max, 3.0, 1e-9) << name;
  }
  EXPECT_NEAR(value(*st, "Gamma"), 0.5, 1e-9);
  EXPECT_NEAR(feature(*st, "Gamma")->max, 4.0, 1e-9);

  // Each channel through the selector into its own register: red up, blue down, read back apart.
  ASSERT_TRUE(control.wait_for_readers(1, 10s));
  auto send = [&](const char* name, double v) {
    wire::Owned<studio_CameraControl> c;
    wire::set(c->camera_id, "gv0");
    wire::set(c->feature, name);
    c->value = v;
    ASSERT_TRUE(control.write(*c));
  };
  send("BalanceRatioRed", 1.3);
  send("BalanceRatioBlue", 0.7);
  EXPECT_TRUE(wait_state(
      states, st,
      [](const studio_CameraState& s) {
        return std::abs(value(s, "BalanceRatioRed") - 1.3) < 1e-6 &&
               std::abs(value(s, "BalanceRatioBlue") - 0.7) < 1e-6;
      },
      10s))
      << "red " << value(*st, "BalanceRatioRed") << ", blue " << value(*st, "BalanceRatioBlue")
      << "\n"
      << capture.log();
  // Beyond the camera's range: clamped to it, the other channel untouched.
  send("BalanceRatioBlue", 5.0);
  EXPECT_TRUE(wait_state(
      states, st,
      [](const studio_CameraState& s) {
        return std::abs(value(s, "BalanceRatioBlue") - 3.0) < 1e-6 &&
               std::abs(value(s, "BalanceRatioRed") - 1.3) < 1e-6;
      },
      10s))
      << "red " << value(*st, "BalanceRatioRed") << ", blue " << value(*st, "BalanceRatioBlue");
  // Gamma is not remotely controllable (the capture service's allow-list): unchanged.
  // Gamma is published, not remotely controllable (the service's allow-list): refused in the
  // state's error, unchanged.
  send("Gamma", 1.0);
  EXPECT_TRUE(wait_state(
      states, st,
      [](const studio_CameraState& s) {
        return std::string(wire::str(s.error)).find("'Gamma' is not allowed") != std::string::npos;
      },
      10s))
      << wire::str(st->error);
  EXPECT_NEAR(value(*st, "Gamma"), 0.5, 1e-9);
  EXPECT_EQ(capture.stop(), 0) << capture.log();
}

}  // namespace
}  // namespace studio::capture
