#pragma once
// Synthetic blue/green-screen frames with a known true mask, for the keyer's tests and benchmark
// (the simulated studio in capture/ is the full-realism source; this is a small, self-contained
// one). An actor made of ellipses (head, torso in dark clothes, legs in black, arms in skin) on a
// shaded backing with sensor noise; boundary pixels mix actor and backing by their coverage
// (4x4 supersampling); the true mask is coverage >= 0.5.

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "core/image.h"

namespace studio::keyer::testing {

struct SyntheticFrame {
  Image<Rgb8> image;
  Mask truth;
};

inline SyntheticFrame make_frame(int w, int h, double phase, bool green = false, double noise = 3.0,
                                 unsigned seed = 1) {
  struct Part {
    double cx, cy, rx, ry;
    Rgb8 colour;
  };
  const double s = std::sin(phase), c = std::cos(phase);
  const Part parts[] = {
      {0.50 + 0.01 * s, 0.17, 0.035, 0.06, {200, 150, 120}},           // head, skin
      {0.50, 0.40, 0.075, 0.19, {28, 30, 52}},                          // torso, navy
      {0.46 + 0.02 * s, 0.74, 0.028, 0.21, {14, 14, 16}},               // legs, black
      {0.54 - 0.02 * s, 0.74, 0.028, 0.21, {14, 14, 16}},
      {0.60 + 0.03 * c, 0.33, 0.10, 0.022, {190, 140, 110}},            // arm, skin
      {0.40 - 0.02 * c, 0.45, 0.022, 0.11, {120, 30, 30}},              // arm, red sleeve
  };
  SyntheticFrame f{Image<Rgb8>(w, h), Mask(w, h, 0)};
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise);
  auto clamp8 = [](double v) { return uint8_t(std::clamp(std::lround(v), 0l, 255l)); };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double cover = 0, ar = 0, ag = 0, ab = 0;
      for (int sy = 0; sy < 4; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          const double u = (x + (sx + 0.5) / 4) / w, v = (y + (sy + 0.5) / 4) / h;
          for (const Part& p : parts) {
            const double dx = (u - p.cx) / p.rx, dy = (v - p.cy) / p.ry;
            if (dx * dx + dy * dy <= 1.0) {
              cover += 1.0 / 16;
              ar += p.colour.r / 16.0, ag += p.colour.g / 16.0, ab += p.colour.b / 16.0;
              break;
            }
          }
        }
      const double shade = 0.8 + 0.3 * double(x) / w - 0.1 * double(y) / h;  // uneven backing
      const double br = 35 * shade, bg = (green ? 190 : 75) * shade, bb = (green ? 60 : 205) * shade;
      const double k = 1.0 - cover;
      f.image(x, y) = Rgb8{clamp8(ar + k * br + n(rng)), clamp8(ag + k * bg + n(rng)),
                           clamp8(ab + k * bb + n(rng))};
      f.truth(x, y) = cover >= 0.5 ? 255 : 0;
    }
  return f;
}

// Foreground pixels with a 4-neighbour in the background.
inline std::vector<std::pair<int, int>> boundary(const Mask& m) {
  std::vector<std::pair<int, int>> out;
  const int w = m.width(), h = m.height();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!m(x, y)) continue;
      if ((x > 0 && !m(x - 1, y)) || (x + 1 < w && !m(x + 1, y)) || (y > 0 && !m(x, y - 1)) ||
          (y + 1 < h && !m(x, y + 1)))
        out.push_back({x, y});
    }
  return out;
}

// Symmetric mean distance (pixels) between the boundaries of two masks. Brute force, for tests.
inline double boundary_error(const Mask& a, const Mask& b) {
  const auto ba = boundary(a), bb = boundary(b);
  if (ba.empty() || bb.empty()) return ba.empty() && bb.empty() ? 0.0 : 1e9;
  auto mean_nearest = [](const auto& from, const auto& to) {
    double sum = 0;
    for (auto [x, y] : from) {
      long best = -1;
      for (auto [u, v] : to) {
        const long d = long(x - u) * (x - u) + long(y - v) * (y - v);
        if (best < 0 || d < best) best = d;
        if (best == 0) break;
      }
      sum += std::sqrt(double(best));
    }
    return sum / double(from.size());
  };
  return 0.5 * (mean_nearest(ba, bb) + mean_nearest(bb, ba));
}

}  // namespace studio::keyer::testing
