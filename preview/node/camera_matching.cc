#include "camera_matching.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "core/clock.h"

namespace studio::preview {

Expected<SentMatch> match_cameras(PreviewNode& node, ViewPipeline& pipeline, double min_change) {
  const BalanceSnapshot rig = pipeline.rig_colour_balance();
  const BalanceSnapshot rb =
      rig.balance.frames >= kMatchRigFrames ? rig : pipeline.colour_balance();
  const offline::ColourBalance& b = rb.balance;
  if (b.frames < rb.min_frames)
    return fail("match cameras: the colour balance has pooled " + std::to_string(b.frames) +
                " frames (" + std::to_string(rb.min_frames) + " needed)");
  // The largest linked set (ties: the one named by the smallest index).
  std::map<int, int> size;
  for (std::size_t i = 0; i < rb.cameras.size() && i < b.linked_set.size(); ++i)
    if (b.linked_set[i] >= 0) ++size[b.linked_set[i]];
  if (size.empty()) return fail("match cameras: the colour balance has linked no cameras yet");
  int set = size.begin()->first;
  for (const auto& [s, n] : size)
    if (n > size[set]) set = s;
  std::map<std::string, Eigen::Vector3f> estimated;
  std::set<std::string> matched;
  for (std::size_t i = 0; i < rb.cameras.size() && i < b.linked_set.size(); ++i)
    if (b.linked_set[i] == set) {
      estimated[rb.cameras[i]] = b.estimated[i];
      matched.insert(rb.cameras[i]);
    }
  // Every other camera publishing controls takes the rig's level only (estimate 1): the set's
  // level moves by k, and a camera left where it was would be k off the rig it is later linked to.
  for (const CameraStateView& s : node.camera_states())
    estimated.try_emplace(s.camera_id, Eigen::Vector3f::Ones());

  std::vector<CameraControls> controls;
  for (const CameraStateView& s : node.camera_states()) {
    CameraControls c;
    c.camera = s.camera_id;
    for (const CameraFeatureView& f : s.features) {
      const ControlValue v{f.value, f.min, f.max};
      if (f.name == "Gain") c.gain_db = v;
      if (f.name == "BalanceRatioRed") c.ratio_red = v;
      if (f.name == "BalanceRatioBlue") c.ratio_blue = v;
      // GenICam Gamma (delivered = sensor^Gamma) acts after Gain and white balance.
      if (f.name == "Gamma" && f.value > 0 && std::isfinite(f.value)) c.exponent = 1 / f.value;
    }
    if (c.gain_db || c.ratio_red || c.ratio_blue) controls.push_back(std::move(c));
  }
  if (std::none_of(controls.begin(), controls.end(),
                   [&](const CameraControls& c) { return matched.count(c.camera) > 0; }))
    return fail("match cameras: no linked camera publishes Gain or BalanceRatio controls");
  auto plan = plan_camera_match(estimated, controls, min_change);
  if (!plan) return std::unexpected(plan.error());
  for (const ControlChange& c : plan->changes)
    if (auto ok = node.send_control(c.camera, c.feature, c.to); !ok)
      return fail("match cameras: " + c.camera + " " + c.feature + ": " + ok.error().message);
  if (!plan->changes.empty())
    pipeline.restart_colour_balance(
        realtime_ns() + std::chrono::duration_cast<std::chrono::nanoseconds>(kMatchSettle).count());
  return SentMatch{std::move(*plan), {matched.begin(), matched.end()}};
}

std::string json_text(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out + "\"";
}

std::string camera_match_json(const SentMatch& sent) {
  const CameraMatch& m = sent.plan;
  char b[256];
  std::snprintf(b, sizeof b, "{\"level_db\":%.4f,\"matched\":[", m.level_db);
  std::string out = b;
  for (std::size_t i = 0; i < sent.matched.size(); ++i)
    out += (i ? "," : "") + json_text(sent.matched[i]);
  out += "],\"changes\":[";
  for (std::size_t i = 0; i < m.changes.size(); ++i) {
    const ControlChange& c = m.changes[i];
    std::snprintf(b, sizeof b, ",\"from\":%.5f,\"to\":%.5f}", c.from, c.to);
    out += (i ? ",{\"camera\":" : "{\"camera\":") + json_text(c.camera) +
           ",\"feature\":" + json_text(c.feature) + b;
  }
  out += "],\"left\":{";
  bool first = true;
  for (const auto& [id, g] : m.left) {
    std::snprintf(b, sizeof b, ":[%.4f,%.4f,%.4f]", g.x(), g.y(), g.z());
    out += (first ? "" : ",") + json_text(id) + b;
    first = false;
  }
  return out + "}}";
}

std::string camera_match_text(const SentMatch& sent) {
  const CameraMatch& m = sent.plan;
  std::set<std::string> cameras;
  for (const ControlChange& c : m.changes) cameras.insert(c.camera);
  char b[160];
  std::snprintf(b, sizeof b, "%zu controls sent to %zu cameras (%zu matched, level %+.2f dB)",
                m.changes.size(), cameras.size(), sent.matched.size(), m.level_db);
  std::string out = b;
  std::string left;
  for (const auto& [id, g] : m.left)
    if ((g.array() - 1).abs().maxCoeff() > 0.005f) {
      std::snprintf(b, sizeof b, " %s %.3f %.3f %.3f", id.c_str(), g.x(), g.y(), g.z());
      left += b;
    }
  return out + (left.empty() ? "" : "; left to the preview's balance:" + left);
}

}  // namespace studio::preview
