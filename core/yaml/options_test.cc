#include "yaml_io/options.h"

#include <gtest/gtest.h>

namespace studio::yaml {
namespace {

enum class Axis { x, y, z };

struct Inner {
  double gain = 1.0;
  std::vector<int> ports;
};

struct Options {
  std::string rig;
  int grid = 64;
  double margin = 0.02;
  bool timing = false;
  Axis axis = Axis::y;
  std::string key = "blue";
  std::vector<double> box = {-1, 0, -1, 1, 2, 1};
  std::vector<std::string> cameras;
  std::uint64_t epoch_ns = 0;
  Inner inner;

  Expected<void> validate() const {
    if (box[3] <= box[0]) return fail("box: x1 must exceed x0");
    return {};
  }
};

const Schema<Inner> inner_schema{
    field("gain", &Inner::gain).range(0, 10),
    field("ports", &Inner::ports).min(1).max(65535),
};

const Schema<Options> schema{
    field("rig", &Options::rig).required().relative_path(),
    field("grid", &Options::grid).range(8, 1024),
    field("margin", &Options::margin).min(0),
    field("timing", &Options::timing),
    enum_field("axis", &Options::axis, {{"x", Axis::x}, {"y", Axis::y}, {"z", Axis::z}}),
    field("key", &Options::key).one_of({"blue", "green", "difference"}),
    field("box", &Options::box).size(6),
    field("cameras", &Options::cameras),
    field("epoch_ns", &Options::epoch_ns),
    field("inner", &Options::inner, inner_schema),
};

Expected<Options> read(const std::string& text) {
  Expected<Node> root = parse(text, "/etc/studio/hull.yaml");
  if (!root) return std::unexpected(root.error());
  return schema.read(*root);
}

std::string error_of(const Expected<Options>& o) {
  return o ? std::string("<ok>") : o.error().message;
}

TEST(YamlOptions, ReadsDeclaredFieldsAndKeepsDefaults) {
  Expected<Options> o = read(
      "rig: rigs/studio.yaml\ngrid: 128\naxis: z\ncameras: [cam0, cam1]\n"
      "epoch_ns: 1700000000000000000\ninner: {ports: [7400, 7401]}\n");
  ASSERT_TRUE(o) << o.error().message;
  EXPECT_EQ(o->rig, "/etc/studio/rigs/studio.yaml");
  EXPECT_EQ(o->grid, 128);
  EXPECT_EQ(o->margin, 0.02);
  EXPECT_EQ(o->axis, Axis::z);
  EXPECT_EQ(o->key, "blue");
  EXPECT_EQ(o->cameras, (std::vector<std::string>{"cam0", "cam1"}));
  EXPECT_EQ(o->epoch_ns, 1700000000000000000ull);
  EXPECT_EQ(o->inner.gain, 1.0);
  EXPECT_EQ(o->inner.ports, (std::vector<int>{7400, 7401}));
  Expected<Options> absolute = read("rig: /data/rig.yaml\n");
  ASSERT_TRUE(absolute);
  EXPECT_EQ(absolute->rig, "/data/rig.yaml");
}

TEST(YamlOptions, EveryKindOfBadInputNamesFileLineAndField) {
  EXPECT_EQ(error_of(read("grid: 64\n")), "/etc/studio/hull.yaml:1: rig: missing required key");
  EXPECT_EQ(error_of(read("rig: r\ngrid: 4\n")),
            "/etc/studio/hull.yaml:2: grid: must be in [8, 1024], got 4");
  EXPECT_EQ(error_of(read("rig: r\ngrid: many\n")),
            "/etc/studio/hull.yaml:2: grid: expected an integer, got 'many'");
  EXPECT_EQ(error_of(read("rig: r\nmargin: -1\n")),
            "/etc/studio/hull.yaml:2: margin: must be at least 0, got -1");
  EXPECT_EQ(error_of(read("rig: r\nmargin: .nan\n")),
            "/etc/studio/hull.yaml:2: margin: non-finite number '.nan'");
  EXPECT_EQ(error_of(read("rig: r\ntiming: 1\n")),
            "/etc/studio/hull.yaml:2: timing: expected true or false, got '1'");
  EXPECT_EQ(error_of(read("rig: r\naxis: w\n")),
            "/etc/studio/hull.yaml:2: axis: expected one of x, y, z, got 'w'");
  EXPECT_EQ(error_of(read("rig: r\nkey: red\n")),
            "/etc/studio/hull.yaml:2: key: expected one of blue, green, difference, got 'red'");
  EXPECT_EQ(error_of(read("rig: r\nbox: [0, 0, 0, 1, 1]\n")),
            "/etc/studio/hull.yaml:2: box: expected 6 numbers, got 5");
  EXPECT_EQ(error_of(read("rig: r\nbox: 3\n")),
            "/etc/studio/hull.yaml:2: box: expected a sequence of numbers");
  EXPECT_EQ(error_of(read("rig: r\nepoch_ns: -5\n")),
            "/etc/studio/hull.yaml:2: epoch_ns: must not be negative, got -5");
  EXPECT_EQ(error_of(read("rig: r\ngird: 64\n")), "/etc/studio/hull.yaml:2: gird: unknown key");
  EXPECT_EQ(error_of(read("rig: r\ninner:\n  gain: 11\n")),
            "/etc/studio/hull.yaml:3: inner.gain: must be in [0, 10], got 11");
  EXPECT_EQ(error_of(read("rig: r\ninner:\n  ports: [0]\n")),
            "/etc/studio/hull.yaml:3: inner.ports[0]: must be in [1, 65535], got 0");
  EXPECT_EQ(error_of(read("rig: r\ninner:\n  extra: 1\n")),
            "/etc/studio/hull.yaml:3: inner.extra: unknown key");
  EXPECT_EQ(error_of(read("rig: r\ninner: 5\n")),
            "/etc/studio/hull.yaml:2: inner: expected a mapping");
  EXPECT_EQ(error_of(read("rig: [a]\n")), "/etc/studio/hull.yaml:1: rig: expected a scalar");
  EXPECT_EQ(error_of(read("rig: r\nbox: [1, 0, 0, 0, 1, 1]\n")),
            "/etc/studio/hull.yaml:1: box: x1 must exceed x0");
  EXPECT_EQ(error_of(read("- a\n")), "/etc/studio/hull.yaml:1: expected a mapping");
  Expected<Options> missing = schema.read_file("/nonexistent/hull.yaml");
  EXPECT_EQ(error_of(missing), "/nonexistent/hull.yaml: cannot open file");
}

}  // namespace
}  // namespace studio::yaml
