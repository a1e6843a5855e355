// The generated printers on crafted samples: JSON that parses and keeps the IDL's member order,
// strings escaped (quotes, newlines, control bytes), non-finite numbers as null, enums by name
// (an out-of-range value as its number), sequences in full in JSON and summarised in text, bounded
// strings read only up to their bound; the key function joins the @key members.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "studioctl/testing/json.h"
#include "studioctl/topic_reader.h"
#include "wire/sample.h"

namespace studio::ctl {
namespace {

using testing::Json;
using testing::JsonReader;

TEST(StudioctlPrinter, EveryIdlStructHasADescriptorAndAPrinter) {
  for (const auto& row : wire::topic_table()) {
    const IdlType* t = find_type(row.descriptor);
    ASSERT_NE(t, nullptr) << row.name;
    EXPECT_EQ(std::string_view(t->name), idl_name(row.descriptor));
  }
}

TEST(StudioctlPrinter, JsonEscapesAndNonFiniteAndEnums) {
  wire::Owned<studio_ServiceStatus> s;
  wire::set(s->service, "hull");
  wire::set(s->instance, "a\"b\\c\nd\x01");
  wire::set(s->host, "h");
  s->state = static_cast<studio_ServiceState>(99);
  s->latency_ms = NAN;
  s->input_hz = 25.5;
  s->pid = -3;
  std::vector<studio_Counter> counters(2);
  wire::set(counters[0].name, "frames");
  counters[0].value = 1e300;
  wire::set(counters[1].name, "drops");
  counters[1].value = INFINITY;
  wire::assign(s->counters, counters);

  const IdlType* t = find_type(&studio_ServiceStatus_desc);
  ASSERT_NE(t, nullptr);
  const std::string line = print_sample(*t, s.get(), true);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  auto j = JsonReader::parse(line);
  ASSERT_TRUE(j) << line;
  EXPECT_EQ(j->keys(),
            (std::vector<std::string>{"service", "instance", "frame", "capture_ns", "state", "host",
                                      "pid", "input_hz", "output_hz", "latency_ms", "counters"}));
  EXPECT_EQ(j->find("instance")->string, "a\"b\\c\nd\x01");
  EXPECT_EQ(j->find("state")->kind, Json::Kind::number);  // out of the enum: its number
  EXPECT_EQ(j->find("state")->number, 99);
  EXPECT_EQ(j->find("latency_ms")->kind, Json::Kind::null);
  EXPECT_EQ(j->find("input_hz")->number, 25.5);
  EXPECT_EQ(j->find("pid")->number, -3);
  const Json* c = j->find("counters");
  ASSERT_EQ(c->array.size(), 2u);
  EXPECT_EQ(c->array[0].find("name")->string, "frames");
  EXPECT_EQ(c->array[0].find("value")->number, 1e300);
  EXPECT_EQ(c->array[1].find("value")->kind, Json::Kind::null);
  EXPECT_EQ(t->key(s.get()), "hull/a\"b\\c\nd\x01");

  s->state = studio_SERVICE_DEGRADED;
  auto k = JsonReader::parse(print_sample(*t, s.get(), true));
  ASSERT_TRUE(k);
  EXPECT_EQ(k->find("state")->string, "SERVICE_DEGRADED");
  const std::string text = print_sample(*t, s.get(), false);
  EXPECT_NE(text.find("state: SERVICE_DEGRADED\n"), std::string::npos) << text;
  EXPECT_NE(text.find("counters:\n  - name: frames\n    value: 1e+300\n"), std::string::npos)
      << text;
}

TEST(StudioctlPrinter, BulkyArraysInFullInJsonSummarisedInText) {
  wire::Owned<studio_ActorMesh> m;
  wire::set(m->actor_id, "actor0");
  std::vector<float> v(3000);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(i) * 0.5f;
  wire::assign(m->vertices, v);
  const IdlType* t = find_type(&studio_ActorMesh_desc);
  auto j = JsonReader::parse(print_sample(*t, m.get(), true));
  ASSERT_TRUE(j);
  const Json* verts = j->find("vertices");
  ASSERT_EQ(verts->array.size(), 3000u);
  EXPECT_EQ(verts->array[2999].number, 1499.5);
  EXPECT_TRUE(j->find("normals")->array.empty());
  const std::string text = print_sample(*t, m.get(), false);
  EXPECT_NE(text.find("vertices: [0, 0.5, 1, 1.5, 2, 2.5, 3, 3.5, ... (3000 values)]\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("normals: []\n"), std::string::npos) << text;
  EXPECT_LT(text.size(), 400u);

  wire::Owned<studio_CameraImage> im;
  wire::set(im->camera_id, "cam0");
  std::vector<uint8_t> bytes(5000, 7);
  wire::assign(im->data, bytes);
  const std::string image_text =
      print_sample(*find_type(&studio_CameraImage_desc), im.get(), false);
  EXPECT_NE(image_text.find("data: <5000 bytes>\n"), std::string::npos) << image_text;
  EXPECT_NE(image_text.find("format: IMAGE_JPEG\n"), std::string::npos) << image_text;
}

TEST(StudioctlPrinter, BoundedStringsStopAtTheirBound) {
  wire::Owned<studio_HeadPose> h;
  std::memset(h->actor_id, 'x', sizeof h->actor_id);  // no terminator at all
  auto j = JsonReader::parse(print_sample(*find_type(&studio_HeadPose_desc), h.get(), true));
  ASSERT_TRUE(j);
  EXPECT_EQ(j->find("actor_id")->string, std::string(sizeof h->actor_id, 'x'));
  EXPECT_EQ(j->find("position")->array.size(), 3u);
}

}  // namespace
}  // namespace studio::ctl
