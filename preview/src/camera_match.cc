#include "preview/camera_match.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace studio::preview {
namespace {

bool valid(const std::optional<ControlValue>& c) {
  return !c || (std::isfinite(c->value) && std::isfinite(c->min) && std::isfinite(c->max) &&
                c->min <= c->max);
}

// The ratio control's new value for a wanted factor, clamped to its range; `taken` the factor
// it applies.
double ratio_to(const ControlValue& c, double factor, double* taken) {
  const double to = std::clamp(c.value * factor, c.min, c.max);
  *taken = to / c.value;  // c.value > 0 (the caller's)
  return to;
}

}  // namespace

Expected<CameraMatch> plan_camera_match(const std::map<std::string, Eigen::Vector3f>& estimated,
                                        const std::vector<CameraControls>& controls,
                                        double min_change) {
  if (!(min_change >= 0)) return fail("camera match: min_change must be >= 0");
  for (const auto& [id, e] : estimated)
    if (!e.allFinite() || (e.array() <= 0).any())
      return fail("camera match: camera " + id + ": estimate is not finite and positive");
  for (const CameraControls& c : controls) {
    if (!valid(c.gain_db) || !valid(c.ratio_red) || !valid(c.ratio_blue))
      return fail("camera match: camera " + c.camera +
                  ": a control's range is empty or not finite");
    if (!(c.exponent > 0) || !std::isfinite(c.exponent))
      return fail("camera match: camera " + c.camera + ": exponent must be finite and > 0");
  }

  // The cameras taking part, and the gain change each wants before the common level k, both in
  // the controls' terms (the estimate raised to the camera's exponent; k is a level of the
  // delivered values, each camera takes it to its own exponent).
  struct Wanted {
    const CameraControls* c;
    Eigen::Vector3d e;  // the estimate, on the delivered values
    double db;          // the Gain change it asks for, dB
  };
  std::vector<Wanted> wanted;
  for (const CameraControls& c : controls)
    if (auto e = estimated.find(c.camera); e != estimated.end())
      wanted.push_back(
          {&c, e->second.cast<double>(), 20 * c.exponent * std::log10(double(e->second.y()))});

  // k (dB on the delivered values): nearest 0 within every Gain's bounds (lo .. hi); the
  // midpoint when they conflict. Camera c's Gain moves by db_c + exponent_c k.
  double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Wanted& w : wanted)
    if (const auto& g = w.c->gain_db) {
      lo = std::max(lo, (g->min - g->value - w.db) / w.c->exponent);
      hi = std::min(hi, (g->max - g->value - w.db) / w.c->exponent);
    }
  CameraMatch out;
  out.level_db = !std::isfinite(lo) && !std::isfinite(hi) ? 0
                 : lo <= hi                               ? std::clamp(0.0, lo, hi)
                                                          : 0.5 * (lo + hi);
  const double gain_step_db = 20 * std::log10(1 + min_change);
  for (const Wanted& w : wanted) {
    const CameraControls& c = *w.c;
    // Wanted factors per channel on the delivered values, the rig's level included; what the
    // controls take of them (on the delivered values too: a control factor to 1 / exponent).
    const double x = c.exponent;
    const Eigen::Vector3d want = w.e * std::pow(10.0, out.level_db / 20);
    Eigen::Vector3d taken = Eigen::Vector3d::Ones();
    if (c.gain_db) {
      const double to =
          std::clamp(c.gain_db->value + w.db + x * out.level_db, c.gain_db->min, c.gain_db->max);
      if (std::abs(to - c.gain_db->value) > x * gain_step_db) {
        out.changes.push_back({c.camera, "Gain", c.gain_db->value, to});
        taken.setConstant(std::pow(10.0, (to - c.gain_db->value) / (20 * x)));
      }
    }
    const double green = taken.y();
    auto ratio = [&](const std::optional<ControlValue>& r, const char* name, int channel) {
      if (!r || !(r->value > 0)) return;  // a channel switched off is not a balance to scale
      double factor = 1;                  // the control's
      const double to = ratio_to(*r, std::pow(want[channel] / want.y(), x), &factor);
      factor = std::pow(factor, 1 / x);  // on the delivered values
      if (std::abs(factor - 1) <= min_change) return;
      out.changes.push_back({c.camera, name, r->value, to});
      taken[channel] = green * factor;
    };
    ratio(c.ratio_red, "BalanceRatioRed", 0);
    ratio(c.ratio_blue, "BalanceRatioBlue", 2);
    out.left[c.camera] = (want.array() / taken.array()).cast<float>();
  }
  return out;
}

}  // namespace studio::preview
