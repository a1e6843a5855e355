#include "core/mask_codec.h"

#include <bit>
#include <stdexcept>
#include <string>

namespace studio {
namespace {

// ---- byte-level varints -------------------------------------------------------------------

void put_varint(std::vector<uint8_t>& out, uint32_t v) {
  while (v >= 0x80) {
    out.push_back(uint8_t(v | 0x80));
    v >>= 7;
  }
  out.push_back(uint8_t(v));
}

// Reads a varint of at most 5 bytes whose value fits in 32 bits; false on truncation, overflow
// and overlong (non-canonical) forms.
bool get_varint(std::span<const uint8_t> in, std::size_t& pos, uint32_t& v) {
  uint64_t value = 0;
  for (int shift = 0; shift < 35; shift += 7) {
    if (pos >= in.size()) return false;
    const uint8_t b = in[pos++];
    value |= uint64_t(b & 0x7F) << shift;
    if (!(b & 0x80)) {
      if (value > 0xFFFFFFFFull || (b == 0 && shift > 0)) return false;  // too big or overlong
      v = uint32_t(value);
      return true;
    }
  }
  return false;
}

// ---- bit stream, MSB first ----------------------------------------------------------------

class BitWriter {
 public:
  explicit BitWriter(std::vector<uint8_t>& out) : out_(out) {}
  void put(uint32_t bits, int n) {  // n <= 32
    acc_ = (acc_ << n) | (uint64_t(bits) & ((uint64_t(1) << n) - 1));
    count_ += n;
    while (count_ >= 8) {
      count_ -= 8;
      out_.push_back(uint8_t(acc_ >> count_));
    }
  }
  // Exp-Golomb of order k for v >= 0 (v < 2^30).
  void put_eg(uint32_t v, int k) {
    const uint32_t x = (v >> k) + 1;
    const int len = std::bit_width(x);  // x has len bits; prefix len-1 zeros
    put(0, len - 1);
    put(x, len);
    if (k) put(v, k);
  }
  void flush() {
    if (count_ > 0) put(0, 8 - count_);
  }

 private:
  std::vector<uint8_t>& out_;
  uint64_t acc_ = 0;
  int count_ = 0;
};

class BitReader {
 public:
  explicit BitReader(std::span<const uint8_t> in) : in_(in) {}
  bool overrun() const { return overrun_; }
  uint32_t bit() {
    if (avail_ == 0 && !refill()) return 0;
    --avail_;
    return uint32_t(acc_ >> avail_) & 1u;
  }
  uint32_t bits(int n) {  // n <= 24
    uint32_t v = 0;
    for (int i = 0; i < n; ++i) v = (v << 1) | bit();
    return v;
  }
  // Exp-Golomb of order k; at most 24 prefix zeros (values here are < 2^17).
  uint32_t eg(int k) {
    int zeros = 0;
    while (bit() == 0) {
      if (overrun_ || ++zeros > 24) {
        overrun_ = true;
        return 0;
      }
    }
    const uint32_t x = (1u << zeros) | bits(zeros);
    return ((x - 1) << k) | bits(k);
  }
  // After decoding: the rest of the current byte is zero and no bytes follow.
  bool at_clean_end() const {
    if (overrun_ || pos_ != in_.size()) return false;
    return (acc_ & ((uint64_t(1) << avail_) - 1)) == 0;
  }

 private:
  bool refill() {
    if (pos_ >= in_.size()) {
      overrun_ = true;
      return false;
    }
    acc_ = in_[pos_++];
    avail_ = 8;
    return true;
  }
  std::span<const uint8_t> in_;
  std::size_t pos_ = 0;
  uint64_t acc_ = 0;
  int avail_ = 0;
  bool overrun_ = false;
};

// ---- encoders -----------------------------------------------------------------------------

void encode_runs(const RunMask& mask, std::vector<uint8_t>& out) {
  for (int y = 0; y < mask.height(); ++y) {
    const auto row = mask.row(y);
    put_varint(out, uint32_t(row.size()));
    int32_t prev_end = -1;
    for (const Run& r : row) {
      put_varint(out, uint32_t(r.begin - prev_end - 1));
      put_varint(out, uint32_t(r.end - r.begin - 1));
      prev_end = r.end;
    }
  }
}

void encode_row_delta(const RunMask& mask, std::vector<uint8_t>& out) {
  BitWriter w(out);
  std::span<const Run> above;
  for (int y = 0; y < mask.height(); ++y) {
    const auto row = mask.row(y);
    if (row.size() == above.size()) {
      w.put(0, 1);
      for (std::size_t i = 0; i < row.size(); ++i) {
        const int32_t d[2] = {row[i].begin - above[i].begin, row[i].end - above[i].end};
        for (int32_t v : d) {
          if (v == 0) {
            w.put(0, 1);
          } else {
            w.put(v < 0 ? 3u : 2u, 2);  // '1' then the sign bit
            w.put_eg(uint32_t(v < 0 ? -v : v) - 1, 0);
          }
        }
      }
    } else {
      w.put(1, 1);
      w.put_eg(uint32_t(row.size()), 0);
      int32_t prev = -1;
      for (const Run& r : row) {
        w.put_eg(uint32_t(r.begin - prev - 1), 2);
        w.put_eg(uint32_t(r.end - r.begin - 1), 2);
        prev = r.end;
      }
    }
    above = row;
  }
  w.flush();
}

// ---- decoders -----------------------------------------------------------------------------

// Internal decoders return an error line, empty on success (see read_header on clang 14).
std::string decode_runs(std::span<const uint8_t> in, std::size_t pos, RunMask& out) {
  const int64_t w = out.width();
  for (int y = 0; y < out.height(); ++y) {
    uint32_t n = 0;
    if (!get_varint(in, pos, n)) return std::string("mask codec: truncated run count in row " + std::to_string(y));
    if (int64_t(n) > (w + 1) / 2) return std::string("mask codec: row " + std::to_string(y) + " has too many runs");
    int64_t prev_end = -1;
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t gap = 0, len = 0;
      if (!get_varint(in, pos, gap) || !get_varint(in, pos, len))
        return std::string("mask codec: truncated run in row " + std::to_string(y));
      const int64_t begin = prev_end + 1 + int64_t(gap);
      const int64_t end = begin + int64_t(len) + 1;
      if (end > w) return std::string("mask codec: run leaves row " + std::to_string(y));
      out.push_run(y, int32_t(begin), int32_t(end));
      prev_end = end;
    }
  }
  if (pos != in.size()) return std::string("mask codec: trailing bytes after the last row");
  return {};
}

std::string decode_row_delta(std::span<const uint8_t> in, std::size_t pos, RunMask& out) {
  BitReader r(in.subspan(pos));
  const int64_t w = out.width();
  std::size_t above_begin = 0, above_end = 0;  // runs of the row above, as indices into out
  for (int y = 0; y < out.height(); ++y) {
    const std::size_t row_begin = out.runs().size();
    if (r.bit() == 0) {
      int64_t prev_end = -1;
      for (std::size_t i = above_begin; i < above_end; ++i) {
        int64_t t[2];
        for (int k = 0; k < 2; ++k) {
          const Run& a = out.runs()[i];
          int64_t v = 0;
          if (r.bit()) {
            const bool negative = r.bit();
            v = int64_t(r.eg(0)) + 1;
            if (negative) v = -v;
          }
          t[k] = (k == 0 ? a.begin : a.end) + v;
        }
        if (r.overrun()) return std::string("mask codec: truncated data in row " + std::to_string(y));
        if (t[0] <= prev_end || t[1] <= t[0] || t[1] > w)
          return std::string("mask codec: malformed runs in row " + std::to_string(y));
        out.push_run(y, int32_t(t[0]), int32_t(t[1]));
        prev_end = t[1];
      }
    } else {
      const uint32_t n = r.eg(0);
      if (r.overrun()) return std::string("mask codec: truncated data in row " + std::to_string(y));
      if (int64_t(n) > (w + 1) / 2) return std::string("mask codec: row " + std::to_string(y) + " has too many runs");
      if (n == above_end - above_begin)  // the encoder codes such a row as deltas: not canonical
        return std::string("mask codec: explicit row " + std::to_string(y) + " repeats the run count above");
      int64_t prev_end = -1;
      for (uint32_t i = 0; i < n; ++i) {
        const int64_t begin = prev_end + 1 + int64_t(r.eg(2));
        const int64_t end = begin + 1 + int64_t(r.eg(2));
        if (r.overrun()) return std::string("mask codec: truncated data in row " + std::to_string(y));
        if (end > w) return std::string("mask codec: run leaves row " + std::to_string(y));
        out.push_run(y, int32_t(begin), int32_t(end));
        prev_end = end;
      }
    }
    if (r.overrun()) return std::string("mask codec: truncated data in row " + std::to_string(y));
    above_begin = row_begin;
    above_end = out.runs().size();
  }
  if (!r.at_clean_end()) return std::string("mask codec: trailing data after the last row");
  return {};
}

// Not Expected<void>: clang 14 (the fuzz preset) cannot destroy a std::expected whose value type
// is trivially destructible (or void) and whose error type is not (no P0848).
struct Header {
  int width = 0;
  int height = 0;
  MaskCoding coding = MaskCoding::kRowDelta;
};

std::string read_header(std::span<const uint8_t> in, Header& h, std::size_t& pos) {
  if (in.size() < 2) return std::string("mask codec: input too short for a header");
  if (in[0] != kMaskMagic) return std::string("mask codec: bad magic byte");
  if (in[1] != uint8_t(MaskCoding::kRuns) && in[1] != uint8_t(MaskCoding::kRowDelta))
    return std::string("mask codec: unknown coding " + std::to_string(in[1]));
  h.coding = MaskCoding(in[1]);
  pos = 2;
  uint32_t w = 0, hh = 0;
  if (!get_varint(in, pos, w) || !get_varint(in, pos, hh)) return std::string("mask codec: truncated header");
  if (w > uint32_t(kMaxMaskSide) || hh > uint32_t(kMaxMaskSide))
    return std::string("mask codec: mask size " + std::to_string(w) + "x" + std::to_string(hh) +
                " over the limit " + std::to_string(kMaxMaskSide));
  h.width = int(w);
  h.height = int(hh);
  return {};
}

}  // namespace

void encode_mask(const RunMask& mask, MaskCoding coding, std::vector<uint8_t>& out) {
  if (mask.width() > kMaxMaskSide || mask.height() > kMaxMaskSide)
    throw std::invalid_argument("encode_mask: mask larger than kMaxMaskSide");
  out.clear();
  out.push_back(kMaskMagic);
  out.push_back(uint8_t(coding));
  put_varint(out, uint32_t(mask.width()));
  put_varint(out, uint32_t(mask.height()));
  switch (coding) {
    case MaskCoding::kRuns:
      encode_runs(mask, out);
      return;
    case MaskCoding::kRowDelta:
      encode_row_delta(mask, out);
      return;
  }
  throw std::invalid_argument("encode_mask: unknown coding");
}

std::vector<uint8_t> encode_mask(const RunMask& mask, MaskCoding coding) {
  std::vector<uint8_t> out;
  encode_mask(mask, coding, out);
  return out;
}

std::string detail::decode_mask_into(std::span<const uint8_t> bytes, RunMask& out) {
  Header h;
  std::size_t pos = 0;
  if (std::string e = read_header(bytes, h, pos); !e.empty()) return e;
  if (out.width() == h.width && out.height() == h.height &&
      out.row_start().size() == std::size_t(h.height) + 1)
    out.clear();
  else
    out = RunMask(h.width, h.height);
  std::string e = h.coding == MaskCoding::kRuns ? decode_runs(bytes, pos, out)
                                                : decode_row_delta(bytes, pos, out);
  if (e.empty()) out.finish();
  return e;
}

Expected<RunMask> decode_mask(std::span<const uint8_t> bytes, RunMask reuse) {
  if (std::string e = detail::decode_mask_into(bytes, reuse); !e.empty()) return fail(std::move(e));
  return reuse;  // implicitly moved
}

}  // namespace studio
