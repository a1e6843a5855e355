// Robustness of every camera-file decoder against corrupt input: thousands of seeded random
// mutations of valid files (byte flips, cuts, duplicated spans, inserted YAML syntax and special
// numbers). Each decode must return a rig or one single-line error — never crash or throw — and
// an accepted rig must be valid and survive a write/read cycle. (libFuzzer targets are not
// possible here: clang 14, which builds them, cannot destroy libstdc++ 12's std::expected with a
// non-trivial error type, and these decoders return Expected throughout. Run this test under the
// asan preset for memory errors.)
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "core/rig.h"
#include "yaml_io/opencv_yaml.h"
#include "yaml_io/rig_yaml.h"

namespace studio::yaml {
namespace {

const char* kRig = R"(units: metres
cameras:
  - id: cam0
    width: 704
    height: 576
    K: [700, 0.5, 352, 0, 700, 288, 0, 0, 1]
    radial: [-0.1, 0.01]
    cam_from_world: {R: [1, 0, 0, 0, 1, 0, 0, 0, 1], t: [0, 0, 4]}
  - id: cam1
    width: 704
    height: 576
    cahv: {C: [1, 2, 3], A: [0, 0, 1], H: [700, 0, 352], V: [0, 700, 288]}
  - id: cam2
    width: 704
    height: 576
    P: [700, 0, 352, 10, 0, 700, 288, 20, 0, 0, 1, 3]
    opencv: [-0.1, 0.01, 0.001, 0.002, 0]
projectors:
  - id: proj0
    width: 1920
    height: 1080
    K: [1500, 0, 960, 0, 1500, 540, 0, 0, 1]
    cam_from_world: {R: [1, 0, 0, 0, 1, 0, 0, 0, 1], t: [0, 0, 5]}
    screen: {corners: [[-2, 0, -1], [2, 0, -1], [2, 2.25, -1], [-2, 2.25, -1]]}
)";

const char* kOpenCv = R"(%YAML:1.0
---
image_width: 640
image_height: 480
K1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.1, 0.01, 0., 0., 0. ]
K2: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 510., 0., 330., 0., 505., 235., 0., 0., 1. ]
R: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 0.01, 0.2, -0.03 ]
T: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ -0.1, 0., 0.002 ]
)";

const char* kText =
    "2\nview1.png 500 0 320 0 500 240 0 0 1 1 0 0 0 1 0 0 0 1 0.1 0.2 3\n"
    "view2.png 500 0 320 0 500 240 0 0 1 0 0 -1 0 1 0 1 0 0 0 0 3\n";

std::string mutate(std::string s, std::mt19937& rng) {
  static const char* tokens[] = {"[",           "]",
                                 "{",           "}",
                                 ":",           ": ",
                                 "- ",          "\n",
                                 "\n  ",        ",",
                                 "#",           "&a ",
                                 "*a",          "!!opencv-matrix",
                                 "%YAML 1.2\n", "\"",
                                 "'",           ".inf",
                                 ".nan",        "-",
                                 "1e308",       "1e-320",
                                 "0",           "99999999999999999999",
                                 "~",           "K",
                                 "P",           "R",
                                 "t",           "cahv",
                                 "radial",      "id",
                                 "\t",          "\x01",
                                 "\xff"};
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits && !s.empty(); ++e) {
    const std::size_t at = rng() % s.size();
    switch (rng() % 5) {
      case 0:
        s[at] = static_cast<char>(rng() % 256);
        break;
      case 1:
        s.erase(at, 1 + rng() % 16);
        break;
      case 2:
        s.insert(at, s.substr(rng() % s.size(), 1 + rng() % 32));
        break;
      case 3:
        s.insert(at, tokens[rng() % std::size(tokens)]);
        break;
      default:
        s.resize(at);
        break;
    }
  }
  return s;
}

void expect_one_line(const Error& e) {
  EXPECT_FALSE(e.message.empty());
  EXPECT_EQ(e.message.find('\n'), std::string::npos) << e.message;
}

TEST(DecoderMutations, RigYaml) {
  std::mt19937 rng(20040101);
  int accepted = 0;
  for (int i = 0; i < 3000; ++i) {
    const std::string text = mutate(kRig, rng);
    Expected<Rig> rig = parse_rig(text, "m.yaml");
    if (!rig) {
      expect_one_line(rig.error());
      continue;
    }
    ++accepted;
    ASSERT_TRUE(rig->validate()) << text;
    Expected<Rig> again = parse_rig(format_rig(*rig), "again.yaml");
    ASSERT_TRUE(again) << again.error().message << "\n" << format_rig(*rig);
    ASSERT_EQ(again->cameras.size(), rig->cameras.size());
  }
  std::printf(
      "[ measured ] rig.yaml mutations: %d of 3000 still valid rigs, the rest one-line errors\n",
      accepted);
}

TEST(DecoderMutations, OpenCvYaml) {
  std::mt19937 rng(7);
  for (int i = 0; i < 3000; ++i) {
    const std::string text = mutate(kOpenCv, rng);
    Expected<Rig> rig = parse_opencv_yaml(text, "m.yml");
    if (!rig) {
      expect_one_line(rig.error());
      continue;
    }
    ASSERT_TRUE(rig->validate()) << text;
  }
}

TEST(DecoderMutations, TextImporters) {
  std::mt19937 rng(11);
  for (int i = 0; i < 3000; ++i) {
    const std::string text = mutate(kText, rng);
    for (const Expected<Rig>& rig : {parse_middlebury(text, "m_par.txt", 640, 480),
                                     parse_projection_matrices(text, "p.txt", 640, 480)}) {
      if (!rig) {
        expect_one_line(rig.error());
        continue;
      }
      ASSERT_TRUE(rig->validate()) << text;
    }
  }
}

TEST(DecoderMutations, PathologicalYaml) {
  // Deep nesting, alias fan-out and huge scalars end in an error, not a stack overflow.
  for (const std::string& text :
       {std::string(100000, '['), "cameras: " + std::string(50000, '{'),
        std::string(
            "a: &a [1, 2, 3, 4, 5, 6, 7, 8, 9]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
            "cameras: [*b, *b, *b, *b, *b, *b, *b, *b, *b]\n"),
        "cameras:\n  - id: " + std::string(1 << 20, 'x') + "\n"}) {
    Expected<Rig> rig = parse_rig(text, "p.yaml");
    ASSERT_FALSE(rig);
    expect_one_line(rig.error());
  }
}

}  // namespace
}  // namespace studio::yaml
