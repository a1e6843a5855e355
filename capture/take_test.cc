// Take format: CRC-32 check value, header round trip, scanning intact / corrupt / torn frames,
// index round trip, take.yaml text.
#include "capture/take.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "capture/crc32.h"

namespace studio::capture {
namespace {

std::string temp_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() /
             ("take_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::vector<uint8_t> frame_bytes(uint64_t frame, int w, int h) {
  std::vector<uint8_t> payload(std::size_t(w) * h * 3);
  for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = uint8_t(i * 7 + frame);
  FrameHeader hd{.frame = frame,
                 .capture_ns = int64_t(frame) * 40,
                 .width = uint32_t(w),
                 .height = uint32_t(h),
                 .format = PixelFormat::kRgb8,
                 .payload_size = payload.size()};
  uint8_t header[kFrameHeaderSize];
  encode_frame_header(hd, payload, header);
  std::vector<uint8_t> out(header, header + kFrameHeaderSize);
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

void write_file(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

TEST(Crc32, CheckValueAndIncremental) {
  const char* s = "123456789";
  EXPECT_EQ(crc32_update(0, s, 9), 0xCBF43926u);
  EXPECT_EQ(crc32_update(crc32_update(0, s, 4), s + 4, 5), 0xCBF43926u);
  EXPECT_EQ(crc32_update(0, s, 0), 0u);
  // Long input across the 8-byte fast path and the byte tail, against the bitwise definition.
  std::vector<uint8_t> data(1003);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = uint8_t(i * 31 + 5);
  uint32_t c = 0xFFFFFFFFu;
  for (uint8_t b : data) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
  }
  EXPECT_EQ(crc32(data), ~c);
}

TEST(FrameHeader, RoundTripAndRejects) {
  auto bytes = frame_bytes(42, 5, 3);
  auto h = decode_frame_header(std::span(bytes).first(kFrameHeaderSize));
  ASSERT_TRUE(h) << h.error().message;
  EXPECT_EQ(h->frame, 42u);
  EXPECT_EQ(h->capture_ns, 42 * 40);
  EXPECT_EQ(h->width, 5u);
  EXPECT_EQ(h->payload_size, 45u);
  EXPECT_TRUE(frame_crc_matches(std::span(bytes).first(kFrameHeaderSize),
                                std::span(bytes).subspan(kFrameHeaderSize)));
  auto bad = bytes;
  bad[kFrameHeaderSize + 3] ^= 1;
  EXPECT_FALSE(frame_crc_matches(std::span(bad).first(kFrameHeaderSize),
                                 std::span(bad).subspan(kFrameHeaderSize)));
  bad = bytes;
  bad[0] = 'X';
  EXPECT_FALSE(decode_frame_header(std::span(bad).first(kFrameHeaderSize)));
  bad = bytes;
  bad[32] = 44;  // payload size inconsistent with 5x3 RGB
  EXPECT_FALSE(decode_frame_header(std::span(bad).first(kFrameHeaderSize)));
  EXPECT_FALSE(decode_frame_header(std::span(bytes).first(20)));
}

TEST(ScanFrames, IntactCorruptAndTornTail) {
  const std::string dir = temp_dir("scan");
  std::vector<uint8_t> file;
  for (uint64_t f = 100; f < 105; ++f) {
    auto b = frame_bytes(f, 8, 4);
    if (f == 102) b[kFrameHeaderSize + 10] ^= 0x80;  // flipped payload bit
    file.insert(file.end(), b.begin(), b.end());
  }
  const std::size_t complete = file.size();
  auto torn = frame_bytes(105, 8, 4);
  file.insert(file.end(), torn.begin(), torn.begin() + 60);  // header + 12 payload bytes
  write_file(dir + "/frames.raw", file);

  auto r = scan_frames(dir);
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->intact.size(), 4u);
  EXPECT_EQ(r->intact[0], (IndexEntry{100, 0}));
  EXPECT_EQ(r->intact[2].frame, 103u);
  EXPECT_EQ(r->corrupt, 1u);
  EXPECT_EQ(r->valid_bytes, complete);
  EXPECT_EQ(r->file_bytes, complete + 60);
  EXPECT_NE(r->tail.find("partial frame 105"), std::string::npos) << r->tail;
  EXPECT_EQ(*r->first_frame, 100u);
  EXPECT_EQ(*r->last_frame, 104u);

  ASSERT_TRUE(write_index(dir, r->intact));
  auto idx = read_index(dir);
  ASSERT_TRUE(idx) << idx.error().message;
  EXPECT_EQ(*idx, r->intact);
  std::vector<uint8_t> pixels;
  auto fr = read_frame(dir, r->intact[3], pixels);
  ASSERT_TRUE(fr) << fr.error().message;
  EXPECT_EQ(fr->frame, 104u);
  EXPECT_EQ(pixels.size(), 96u);
  EXPECT_FALSE(read_frame(dir, IndexEntry{102, r->intact[1].offset + 144}, pixels));  // corrupt one

  // Garbage after the good frames stops the scan with a reason.
  file.resize(complete);
  file.insert(file.end(), 64, 0xAB);
  write_file(dir + "/frames.raw", file);
  r = scan_frames(dir);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->intact.size(), 4u);
  EXPECT_NE(r->tail.find("bad frame magic"), std::string::npos) << r->tail;

  EXPECT_FALSE(scan_frames(dir + "/missing"));
  std::filesystem::remove_all(dir);
}

TEST(ReadIndex, RejectsMalformed) {
  const std::string dir = temp_dir("index");
  write_file(dir + "/index", {'S', 'T', 'I', 'X', 1, 0, 0, 0, 1, 2, 3});
  auto r = read_index(dir);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("partial index entry"), std::string::npos);
  write_file(dir + "/index", {'X'});
  EXPECT_FALSE(read_index(dir));
  std::filesystem::remove_all(dir);
}

TEST(TakeYaml, FormatsEveryField) {
  TakeInfo t;
  t.take = "t1";
  t.camera_id = "cam0";
  t.width = 704;
  t.height = 576;
  t.period_ns = 40000000;
  t.start_frame = 10;
  t.stop_frame = 20;
  t.first_frame = 10;
  t.last_frame = 19;
  t.frames = 10;
  t.status = "error";
  t.error = "disk \"full\"";
  t.calibration_yaml = "  id: cam0\n  width: 704\n";
  const std::string s = format_take_yaml(t);
  EXPECT_NE(s.find("take: t1\ncamera: cam0\nformat: rgb8\n"), std::string::npos) << s;
  EXPECT_NE(s.find("first_frame: 10\nlast_frame: 19\nframes: 10\n"), std::string::npos) << s;
  EXPECT_NE(s.find("error: \"disk \\\"full\\\"\"\n"), std::string::npos) << s;
  EXPECT_NE(s.find("calibration:\n  id: cam0\n  width: 704\n"), std::string::npos) << s;
}

}  // namespace
}  // namespace studio::capture
