#include "key_kernels.h"

#include <bit>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define STUDIO_KEYER_X86 1
// The AVX2 helpers pass __m256i by value between functions of the same target; no ABI crosses.
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace studio::keyer::detail {

ChromaParams make_chroma_params(int k, int o1, int o2, uint8_t max_excess) {
  ChromaParams p;
  p.k = k;
  p.o1 = o1;
  p.o2 = o2;
  p.max_excess = max_excess;
  const int offsets[3] = {k, o1, o2};
  for (int plane = 0; plane < 3; ++plane)
    for (int chunk = 0; chunk < 3; ++chunk)
      for (int i = 0; i < 16; ++i) {
        const int byte = 3 * i + offsets[plane];  // byte of pixel i's channel in the 48 bytes
        p.shuffle[plane][chunk][i] = byte / 16 == chunk ? uint8_t(byte % 16) : uint8_t(0x80);
      }
  return p;
}

namespace {

inline void set_bit(uint64_t* bits, int x) { bits[x >> 6] |= uint64_t(1) << (x & 63); }

void chroma_tail(const uint8_t* px, int from, int width, const ChromaParams& p, uint64_t* bits) {
  for (int x = from; x < width; ++x) {
    const uint8_t* q = px + 3 * x;
    const int other = q[p.o1] > q[p.o2] ? q[p.o1] : q[p.o2];
    const int excess = q[p.k] - other;
    if (excess <= int(p.max_excess)) set_bit(bits, x);
  }
}

void diff_tail(const uint8_t* px, const uint8_t* plate, int from, int width, uint8_t min_diff,
               uint64_t* bits) {
  for (int x = from; x < width; ++x) {
    int d = 0;
    for (int c = 0; c < 3; ++c) {
      const int v = px[3 * x + c] - plate[3 * x + c];
      const int a = v < 0 ? -v : v;
      d = a > d ? a : d;
    }
    if (d >= min_diff) set_bit(bits, x);
  }
}

void clear_bits(uint64_t* bits, int width) { std::memset(bits, 0, sizeof(uint64_t) * ((width + 63) / 64)); }

void chroma_scalar(const uint8_t* px, int width, const ChromaParams& p, uint64_t* bits) {
  clear_bits(bits, width);
  chroma_tail(px, 0, width, p, bits);
}

void diff_scalar(const uint8_t* px, const uint8_t* plate, int width, uint8_t min_diff, uint64_t* bits) {
  clear_bits(bits, width);
  diff_tail(px, plate, 0, width, min_diff, bits);
}

#ifdef STUDIO_KEYER_X86

// 16 bits for pixels [x, x+16) (x a multiple of 16) into the little-endian bit words.
inline void store16(uint64_t* bits, int x, uint32_t m) {
  const uint16_t v = uint16_t(m);
  std::memcpy(reinterpret_cast<uint8_t*>(bits) + x / 8, &v, 2);
}
inline void store32(uint64_t* bits, int x, uint32_t m) {
  std::memcpy(reinterpret_cast<uint8_t*>(bits) + x / 8, &m, 4);
}

__attribute__((target("ssse3,sse4.1"))) inline __m128i gather_plane(__m128i v0, __m128i v1, __m128i v2,
                                                                    const uint8_t (*m)[16]) {
  const __m128i a = _mm_shuffle_epi8(v0, _mm_load_si128(reinterpret_cast<const __m128i*>(m[0])));
  const __m128i b = _mm_shuffle_epi8(v1, _mm_load_si128(reinterpret_cast<const __m128i*>(m[1])));
  const __m128i c = _mm_shuffle_epi8(v2, _mm_load_si128(reinterpret_cast<const __m128i*>(m[2])));
  return _mm_or_si128(_mm_or_si128(a, b), c);
}

__attribute__((target("ssse3,sse4.1"))) void chroma_ssse3(const uint8_t* px, int width,
                                                          const ChromaParams& p, uint64_t* bits) {
  clear_bits(bits, width);
  const __m128i thr = _mm_set1_epi8(char(p.max_excess));
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    const uint8_t* q = px + 3 * x;
    const __m128i v0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
    const __m128i v1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q + 16));
    const __m128i v2 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q + 32));
    const __m128i k = gather_plane(v0, v1, v2, p.shuffle[0]);
    const __m128i o = _mm_max_epu8(gather_plane(v0, v1, v2, p.shuffle[1]),
                                   gather_plane(v0, v1, v2, p.shuffle[2]));
    const __m128i excess = _mm_subs_epu8(k, o);
    const __m128i fg = _mm_cmpeq_epi8(_mm_min_epu8(excess, thr), excess);
    store16(bits, x, uint32_t(_mm_movemask_epi8(fg)));
  }
  chroma_tail(px, x, width, p, bits);
}

__attribute__((target("ssse3,sse4.1"))) void diff_ssse3(const uint8_t* px, const uint8_t* plate,
                                                        int width, uint8_t min_diff, uint64_t* bits) {
  static const ChromaParams planes = make_chroma_params(0, 1, 2, 0);
  clear_bits(bits, width);
  const __m128i lo = _mm_set1_epi8(char(min_diff));
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    __m128i d[3];
    for (int i = 0; i < 3; ++i) {
      const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(px + 3 * x + 16 * i));
      const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(plate + 3 * x + 16 * i));
      d[i] = _mm_or_si128(_mm_subs_epu8(a, b), _mm_subs_epu8(b, a));
    }
    const __m128i m = _mm_max_epu8(_mm_max_epu8(gather_plane(d[0], d[1], d[2], planes.shuffle[0]),
                                                gather_plane(d[0], d[1], d[2], planes.shuffle[1])),
                                   gather_plane(d[0], d[1], d[2], planes.shuffle[2]));
    const __m128i fg = _mm_cmpeq_epi8(_mm_max_epu8(m, lo), m);
    store16(bits, x, uint32_t(_mm_movemask_epi8(fg)));
  }
  diff_tail(px, plate, x, width, min_diff, bits);
}

// AVX2: lane 0 holds pixels [x, x+16), lane 1 pixels [x+16, x+32), so the SSSE3 masks apply per lane.
__attribute__((target("avx2"))) inline __m256i load_lanes(const uint8_t* q) {
  return _mm256_inserti128_si256(
      _mm256_castsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(q))),
      _mm_loadu_si128(reinterpret_cast<const __m128i*>(q + 48)), 1);
}
__attribute__((target("avx2"))) inline __m256i gather_plane2(__m256i v0, __m256i v1, __m256i v2,
                                                             const uint8_t (*m)[16]) {
  const __m256i m0 = _mm256_broadcastsi128_si256(_mm_load_si128(reinterpret_cast<const __m128i*>(m[0])));
  const __m256i m1 = _mm256_broadcastsi128_si256(_mm_load_si128(reinterpret_cast<const __m128i*>(m[1])));
  const __m256i m2 = _mm256_broadcastsi128_si256(_mm_load_si128(reinterpret_cast<const __m128i*>(m[2])));
  return _mm256_or_si256(_mm256_or_si256(_mm256_shuffle_epi8(v0, m0), _mm256_shuffle_epi8(v1, m1)),
                         _mm256_shuffle_epi8(v2, m2));
}

__attribute__((target("avx2"))) void chroma_avx2(const uint8_t* px, int width, const ChromaParams& p,
                                                 uint64_t* bits) {
  clear_bits(bits, width);
  const __m256i thr = _mm256_set1_epi8(char(p.max_excess));
  int x = 0;
  for (; x + 32 <= width; x += 32) {
    const uint8_t* q = px + 3 * x;
    const __m256i v0 = load_lanes(q), v1 = load_lanes(q + 16), v2 = load_lanes(q + 32);
    const __m256i k = gather_plane2(v0, v1, v2, p.shuffle[0]);
    const __m256i o = _mm256_max_epu8(gather_plane2(v0, v1, v2, p.shuffle[1]),
                                      gather_plane2(v0, v1, v2, p.shuffle[2]));
    const __m256i excess = _mm256_subs_epu8(k, o);
    const __m256i fg = _mm256_cmpeq_epi8(_mm256_min_epu8(excess, thr), excess);
    store32(bits, x, uint32_t(_mm256_movemask_epi8(fg)));
  }
  // The upper YMM state cleared by hand: GCC 12 turns the tail call below into a jump without
  // the vzeroupper it owes, and the dirty state then made the caller's legacy-SSE code (the
  // capture server's simulator, built for x86-64-v2) run 1.8x slower (issue 20, session 11).
  _mm256_zeroupper();
  chroma_tail(px, x, width, p, bits);
}

__attribute__((target("avx2"))) void diff_avx2(const uint8_t* px, const uint8_t* plate, int width,
                                               uint8_t min_diff, uint64_t* bits) {
  static const ChromaParams planes = make_chroma_params(0, 1, 2, 0);
  clear_bits(bits, width);
  const __m256i lo = _mm256_set1_epi8(char(min_diff));
  int x = 0;
  for (; x + 32 <= width; x += 32) {
    __m256i d[3];
    for (int i = 0; i < 3; ++i) {
      const __m256i a = load_lanes(px + 3 * x + 16 * i), b = load_lanes(plate + 3 * x + 16 * i);
      d[i] = _mm256_or_si256(_mm256_subs_epu8(a, b), _mm256_subs_epu8(b, a));
    }
    const __m256i m =
        _mm256_max_epu8(_mm256_max_epu8(gather_plane2(d[0], d[1], d[2], planes.shuffle[0]),
                                        gather_plane2(d[0], d[1], d[2], planes.shuffle[1])),
                        gather_plane2(d[0], d[1], d[2], planes.shuffle[2]));
    const __m256i fg = _mm256_cmpeq_epi8(_mm256_max_epu8(m, lo), m);
    store32(bits, x, uint32_t(_mm256_movemask_epi8(fg)));
  }
  _mm256_zeroupper();  // as in chroma_avx2: the tail call would leave the upper state dirty
  diff_tail(px, plate, x, width, min_diff, bits);
}

#endif  // STUDIO_KEYER_X86

const Kernels kScalar{chroma_scalar, diff_scalar, "scalar"};

Kernels pick() {
#ifdef STUDIO_KEYER_X86
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) return {chroma_avx2, diff_avx2, "avx2"};
  if (__builtin_cpu_supports("ssse3") && __builtin_cpu_supports("sse4.1"))
    return {chroma_ssse3, diff_ssse3, "ssse3"};
#endif
  return kScalar;
}

}  // namespace

const Kernels& best_kernels() {
  static const Kernels k = pick();
  return k;
}
const Kernels& scalar_kernels() { return kScalar; }

void bits_to_runs(const uint64_t* bits, int width, int y, RunMask& out) {
  const int words = (width + 63) / 64;
  uint64_t carry = 0;  // the previous pixel's bit
  bool inside = false;
  int32_t begin = 0;
  for (int i = 0; i < words; ++i) {
    const uint64_t w = bits[i];
    uint64_t t = w ^ ((w << 1) | carry);  // bit x set where pixel x differs from pixel x-1
    carry = w >> 63;
    while (t) {
      const int32_t x = i * 64 + std::countr_zero(t);
      if (inside) out.push_run(y, begin, x); else begin = x;
      inside = !inside;
      t &= t - 1;
    }
  }
  if (inside) out.push_run(y, begin, width);
}

}  // namespace studio::keyer::detail
