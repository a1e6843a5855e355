#include "yaml_io/node.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>

namespace studio::yaml {
namespace {

testing::AssertionResult FailsWith(const Expected<void>& r, const std::string& text) {
  if (r) return testing::AssertionFailure() << "succeeded, expected an error containing: " << text;
  if (r.error().message.find(text) == std::string::npos) {
    return testing::AssertionFailure()
           << "error '" << r.error().message << "' lacks '" << text << "'";
  }
  return testing::AssertionSuccess();
}

template <class T>
Expected<void> status(const Expected<T>& e) {
  if (e) return {};
  return std::unexpected(e.error());
}

TEST(YamlNode, MissingFileNamesTheFile) {
  EXPECT_TRUE(FailsWith(status(load_file("/nonexistent/dir/rig.yaml")),
                        "/nonexistent/dir/rig.yaml: cannot open file"));
}

TEST(YamlNode, SyntaxErrorsCarryTheLine) {
  EXPECT_TRUE(FailsWith(status(parse("a: 1\nb: [1, 2\nc: 3\n", "x.yaml")), "x.yaml:"));
  EXPECT_TRUE(FailsWith(status(parse("a: 1\nb: [1, 2\nc: 3\n", "x.yaml")), "not valid YAML"));
  EXPECT_TRUE(FailsWith(status(parse("a: 1\n  b: 2\n", "y.yaml")), "y.yaml:2: not valid YAML"));
  EXPECT_TRUE(FailsWith(status(parse("", "e.yaml")), "e.yaml: empty YAML document"));
  // Binary junk never crashes.
  std::string junk;
  for (int i = 0; i < 512; ++i) junk += static_cast<char>((i * 7919) % 256);
  (void)parse(junk, "junk.bin");
}

TEST(YamlNode, TypedScalarsAreStrict) {
  Expected<Node> root = parse(
      "i: 42\nf: 2.5\nbad: 4x\nfrac: 3.5\ninf: .inf\nnan: .nan\nbig: 99999999999999999999\n"
      "b: true\nnb: maybe\ncinf: inf\n",
      "s.yaml");
  ASSERT_TRUE(root);
  Expected<MapReader> map = MapReader::from(*root);
  ASSERT_TRUE(map);
  EXPECT_EQ(*map->required("i")->as_int(), 42);
  EXPECT_EQ(*map->required("f")->as_double(), 2.5);
  EXPECT_TRUE(FailsWith(status(map->required("bad")->as_double()),
                        "s.yaml:3: bad: expected a number, got '4x'"));
  EXPECT_TRUE(FailsWith(status(map->required("frac")->as_int()),
                        "s.yaml:4: frac: expected an integer, got '3.5'"));
  EXPECT_TRUE(
      FailsWith(status(map->required("inf")->as_double()), "s.yaml:5: inf: non-finite number"));
  EXPECT_TRUE(
      FailsWith(status(map->required("nan")->as_double()), "s.yaml:6: nan: non-finite number"));
  EXPECT_TRUE(
      FailsWith(status(map->required("big")->as_int()), "s.yaml:7: big: integer out of range"));
  EXPECT_EQ(*map->required("b")->as_bool(), true);
  EXPECT_TRUE(
      FailsWith(status(map->required("nb")->as_bool()), "s.yaml:9: nb: expected true or false"));
  EXPECT_TRUE(
      FailsWith(status(map->required("cinf")->as_double()), "s.yaml:10: cinf: non-finite number"));
  EXPECT_TRUE(map->finish());
}

TEST(YamlNode, MapReaderReportsUnknownMissingDuplicateAndAmbiguousKeys) {
  Expected<Node> root = parse("a: 1\nb:\n  c: [1, 2, 3]\n  d: x\nfoo: 2\n", "m.yaml");
  ASSERT_TRUE(root);
  Expected<MapReader> map = MapReader::from(*root);
  ASSERT_TRUE(map);
  EXPECT_TRUE(map->required("a"));
  EXPECT_TRUE(FailsWith(status(map->required("zz")), "m.yaml:1: zz: missing required key"));
  Expected<Node> b = map->required("b");
  ASSERT_TRUE(b);
  Expected<MapReader> bmap = MapReader::from(*b);
  ASSERT_TRUE(bmap);
  Expected<Node> c = bmap->required("c");
  EXPECT_TRUE(FailsWith(status(c->as_doubles(4)), "m.yaml:3: b.c: expected 4 numbers, got 3"));
  EXPECT_TRUE(FailsWith(status(bmap->required("d")->as_doubles()),
                        "m.yaml:4: b.d: expected numbers, got a scalar"));
  EXPECT_TRUE(
      FailsWith(status(bmap->required("missing")), "m.yaml:2: b.missing: missing required key"));
  EXPECT_TRUE(bmap->finish());
  EXPECT_TRUE(FailsWith(map->finish(), "m.yaml:5: foo: unknown key"));
  EXPECT_TRUE(FailsWith(status(map->one_of({"a", "foo"}, true)), "expected exactly one of a, foo"));
  EXPECT_TRUE(FailsWith(status(map->one_of({"x", "y"}, true)), "expected one of x, y"));
  EXPECT_TRUE(map->one_of({"x", "y"}, false));

  Expected<Node> dup = parse("a: 1\na: 2\n", "d.yaml");
  ASSERT_TRUE(dup);
  EXPECT_TRUE(FailsWith(status(dup->entries()), "d.yaml:2: a: duplicate key"));
  EXPECT_TRUE(FailsWith(status(MapReader::from(*parse("- 1\n- 2\n", "l.yaml"))),
                        "l.yaml:1: expected a mapping"));
  EXPECT_TRUE(FailsWith(status(MapReader::from(*parse("just text", "t.yaml"))),
                        "t.yaml:1: expected a mapping"));
}

TEST(YamlNode, ElementPathsAndLines) {
  Expected<Node> root = parse("list:\n  - 1\n  - [2, x]\n", "p.yaml");
  ASSERT_TRUE(root);
  Expected<MapReader> map = MapReader::from(*root);
  Expected<std::vector<Node>> items = map->required("list")->elements();
  ASSERT_TRUE(items);
  ASSERT_EQ(items->size(), 2u);
  EXPECT_EQ((*items)[1].path(), "list[1]");
  EXPECT_TRUE(FailsWith(status((*items)[1].as_doubles(2)),
                        "p.yaml:3: list[1][1]: expected a number, got 'x'"));
}

TEST(YamlNode, FormatDoubleRoundTripsExactly) {
  for (double x :
       {0.1, 1.0 / 3.0, -2.5e-300, 6.02214076e23, 704.0, -0.0, 1e-7, std::nextafter(1.0, 2.0)}) {
    const std::string s = format_double(x);
    Expected<Node> n = parse("v: " + s + "\n", "f.yaml");
    ASSERT_TRUE(n);
    Expected<MapReader> map = MapReader::from(*n);
    Expected<double> back = map->required("v")->as_double();
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(std::memcmp(&x, &*back, sizeof x), 0) << s;
  }
}

}  // namespace
}  // namespace studio::yaml
