#include "panels.h"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <utility>

#include "camera_matching.h"
#include "studio.h"

namespace studio::preview {
namespace {

constexpr const char* kFeatures[] = {"Gain", "ExposureTime",    "Focus",           "Zoom",
                                     "Iris", "BalanceRatioRed", "BalanceRatioBlue"};
const ImVec4 kRed{1.0f, 0.25f, 0.25f, 1.0f};

void remember_window(PanelState& s, const char* title) {
  const ImVec2 p = ImGui::GetWindowPos(), z = ImGui::GetWindowSize();
  s.windows[title] = {p.x, p.y, z.x, z.y, 0};
}

void report(PanelState& s, const Expected<void>& r) { s.last_error = r ? "" : r.error().message; }

void cameras_panel(PanelState& s, PreviewNode& node) {
  if (!ImGui::Begin("Cameras", &s.cameras)) return ImGui::End();
  remember_window(s, "Cameras");
  for (const CameraStateView& c : node.camera_states()) {
    ImGui::PushID(c.camera_id.c_str());
    if (ImGui::CollapsingHeader(c.camera_id.c_str(), ImGuiTreeNodeFlags_DefaultOpen)) {
      if (!c.error.empty()) ImGui::TextColored(kRed, "%s", c.error.c_str());
      for (const CameraFeatureView& f : c.features) {
        if (std::find(std::begin(kFeatures), std::end(kFeatures), f.name) == std::end(kFeatures))
          continue;
        const std::string key = c.camera_id + "/" + f.name;
        double& v = s.edits.try_emplace(key, f.value).first->second;
        bool send = false;
        if (auto it = s.scripted.find(key); it != s.scripted.end()) {  // the test hook's edit
          v = it->second;
          s.scripted.erase(it);
          send = true;
        }
        ImGui::SetNextItemWidth(180);
        ImGui::SliderScalar(f.name.c_str(), ImGuiDataType_Double, &v, &f.min, &f.max, "%.3f");
        send = send || ImGui::IsItemDeactivatedAfterEdit();
        const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
        s.items[key] = {a.x, a.y, b.x - a.x, b.y - a.y, v};
        ImGui::SameLine();
        ImGui::Text("read-back %.3f [%.3g..%.3g]", f.value, f.min, f.max);
        if (send) report(s, node.send_control(c.camera_id, f.name, v));
      }
    }
    ImGui::PopID();
  }
  if (!s.last_error.empty()) ImGui::TextColored(kRed, "%s", s.last_error.c_str());
  ImGui::End();
}

void capture_panel(PanelState& s, PreviewNode& node) {
  if (!ImGui::Begin("Capture", &s.capture)) return ImGui::End();
  remember_window(s, "Capture");
  const auto states = node.camera_states();
  uint64_t now = 0;
  for (const auto& c : states) now = std::max(now, c.frame);
  if (s.at_frame <= 0) s.at_frame = (long long)now + 50;
  ImGui::InputText("take", s.take, sizeof s.take);
  ImGui::InputScalar("at frame", ImGuiDataType_S64, &s.at_frame);
  ImGui::Text("current frame %llu", (unsigned long long)now);
  if (ImGui::Button("Start at frame")) report(s, node.send_capture(s.take, true, s.at_frame));
  ImGui::SameLine();
  if (ImGui::Button("Stop at frame")) report(s, node.send_capture(s.take, false, s.at_frame));
  ImGui::SameLine();
  if (ImGui::Button("Now + 2 s")) s.at_frame = (long long)now + 50;
  if (ImGui::BeginTable("cams", 5, ImGuiTableFlags_Borders)) {
    for (const char* h : {"camera", "recording", "take", "fps", "drops"})
      ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const auto& c : states) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(c.camera_id.c_str());
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(c.recording ? "REC" : "-");
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(c.take.c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%.1f", c.fps);
      ImGui::TableNextColumn();
      if (c.drops)
        ImGui::TextColored(kRed, "%llu", (unsigned long long)c.drops);
      else
        ImGui::Text("0");
    }
    ImGui::EndTable();
  }
  if (!s.last_error.empty()) ImGui::TextColored(kRed, "%s", s.last_error.c_str());
  ImGui::End();
}

void animation_panel(PanelState& s, PreviewNode& node) {
  if (!ImGui::Begin("Animation", &s.animation)) return ImGui::End();
  remember_window(s, "Animation");
  if (ImGui::Button("Play")) report(s, node.send_scene(studio_SCENE_PLAY, "", 0));
  ImGui::SameLine();
  if (ImGui::Button("Pause")) report(s, node.send_scene(studio_SCENE_PAUSE, "", 0));
  const double lo = 0, hi = 120, slo = -4, shi = 4;
  ImGui::SliderScalar("seek s", ImGuiDataType_Double, &s.seek_s, &lo, &hi, "%.2f");
  if (ImGui::IsItemDeactivatedAfterEdit())
    report(s, node.send_scene(studio_SCENE_SEEK, "", s.seek_s));
  ImGui::SliderScalar("speed", ImGuiDataType_Double, &s.speed, &slo, &shi, "%.2f");
  if (ImGui::IsItemDeactivatedAfterEdit())
    report(s, node.send_scene(studio_SCENE_SPEED, "", s.speed));
  ImGui::InputText("node", s.node, sizeof s.node);
  ImGui::InputFloat3("position", s.move);
  if (ImGui::Button("Move node"))
    report(s, node.send_scene(studio_SCENE_MOVE_NODE, s.node, 0,
                              Eigen::Vector3d(s.move[0], s.move[1], s.move[2])));
  if (!s.last_error.empty()) ImGui::TextColored(kRed, "%s", s.last_error.c_str());
  ImGui::End();
}

void services_panel(PanelState& s, PreviewNode& node) {
  if (!ImGui::Begin("Services", &s.services)) return ImGui::End();
  remember_window(s, "Services");
  const auto now = std::chrono::steady_clock::now();
  if (ImGui::BeginTable("services", 5, ImGuiTableFlags_Borders)) {
    for (const char* h : {"service", "state", "in Hz", "out Hz", "latency ms"})
      ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const ServiceView& v : node.services()) {
      const bool missing =
          !v.alive || now - v.seen > std::chrono::seconds(3) || v.state == studio_SERVICE_FAILED;
      const ImVec4 colour = missing ? kRed : ImGui::GetStyleColorVec4(ImGuiCol_Text);
      static const char* kStates[] = {"starting", "running", "degraded", "stopping", "failed"};
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextColored(colour, "%s:%s", v.service.c_str(), v.instance.c_str());
      ImGui::TableNextColumn();
      ImGui::TextColored(colour, "%s",
                         missing && v.state != studio_SERVICE_FAILED
                             ? "MISSING"
                             : kStates[std::clamp(v.state, 0, 4)]);
      ImGui::TableNextColumn();
      ImGui::TextColored(colour, "%.1f", v.input_hz);
      ImGui::TableNextColumn();
      ImGui::TextColored(colour, "%.1f", v.output_hz);
      ImGui::TableNextColumn();
      ImGui::TextColored(colour, "%.1f", v.latency_ms);
    }
    ImGui::EndTable();
  }
  ImGui::End();
}

void view_panel(PanelState& s, PreviewNode& node, ViewPipeline& pipeline, Viewpoint& view,
                double now_s) {
  if (!ImGui::Begin("View", &s.view)) return ImGui::End();
  remember_window(s, "View");
  bool blend = pipeline.blend();
  if (ImGui::Checkbox("blend cameras (off: nearest)", &blend)) pipeline.set_blend(blend);
  bool balance = pipeline.colour_balance_on();
  if (ImGui::Checkbox("colour balance", &balance)) pipeline.set_colour_balance(balance);
  {
    const BalanceSnapshot rb = pipeline.colour_balance();
    const offline::ColourBalance& b = rb.balance;
    ImGui::SameLine();
    if (b.applied)
      ImGui::Text("applied (%d frames, %d camera pairs)", b.frames, b.pairs);
    else
      ImGui::Text("cameras agree within %.0f %% (%d frames, %d camera pairs)", 100 * rb.tolerance,
                  b.frames, b.pairs);
    if (ImGui::CollapsingHeader("colour gains (estimated R G B)"))
      for (std::size_t i = 0; i < rb.cameras.size() && i < b.estimated.size(); ++i)
        ImGui::Text("%-10s %.3f %.3f %.3f", rb.cameras[i].c_str(), b.estimated[i].x(),
                    b.estimated[i].y(), b.estimated[i].z());
    // The estimate sent to the cameras' Gain and white balance (node/camera_matching.h).
    if (ImGui::Button("Match cameras") || std::exchange(s.press_match, false)) {
      auto m = match_cameras(node, pipeline);
      s.match_result = m ? camera_match_text(*m) : m.error().message;
    }
    const ImVec2 a = ImGui::GetItemRectMin(), z = ImGui::GetItemRectMax();
    s.items["View/Match cameras"] = {a.x, a.y, z.x - a.x, z.y - a.y, 0};
    if (!s.match_result.empty()) {
      ImGui::SameLine();
      ImGui::TextWrapped("%s", s.match_result.c_str());
    }
    // What the button sends: the whole rig's estimate once its samples are in, else the view's.
    const offline::ColourBalance& rig = pipeline.rig_colour_balance().balance;
    char source[160];
    if (!pipeline.rig_sampling()) {
      std::snprintf(source, sizeof source, "sends this view's cameras (the rig is not sampled)");
    } else if (rig.frames >= kMatchRigFrames) {
      std::snprintf(source, sizeof source,
                    "sends the whole rig's estimate: %d cameras linked (%d samples)",
                    linked_cameras(rig), rig.frames);
    } else {
      std::snprintf(source, sizeof source,
                    "sends this view's cameras until the whole rig is sampled (%d / %d)",
                    rig.frames, kMatchRigFrames);
    }
    s.match_source = source;
    ImGui::TextUnformatted(source);
  }
  OverlayOptions& o = pipeline.overlays();
  ImGui::Checkbox("head marker", &o.head);
  ImGui::SameLine();
  ImGui::Checkbox("camera frusta", &o.camera_frusta);
  ImGui::Checkbox("projector frusta", &o.projector_frusta);
  ImGui::SameLine();
  ImGui::Checkbox("projector screens", &o.projector_screens);
  const PipelineCounts& c = pipeline.counts();
  ImGui::Text("meshes %llu: textured %llu, untextured %llu", (unsigned long long)c.meshes,
              (unsigned long long)c.textured, (unsigned long long)c.untextured);
  ImGui::Text("eye %.2f %.2f %.2f", view.eye.x(), view.eye.y(), view.eye.z());
  ImGui::InputText("bookmark", s.bookmark, sizeof s.bookmark);
  ImGui::SameLine();
  if (ImGui::Button("Save")) s.bookmarks.set(s.bookmark, view);
  for (const auto& [name, v] : s.bookmarks.all()) {
    if (ImGui::Button(("Go " + name).c_str())) view = v;
    ImGui::SameLine();
  }
  ImGui::NewLine();
  ImGui::Text("camera move: %zu keys", s.keys.size());
  if (ImGui::Button("Add key (+2 s)"))
    s.keys.push_back({s.keys.empty() ? 0.0 : s.keys.back().time + 2.0, view});
  ImGui::SameLine();
  if (ImGui::Button("Play move")) {
    auto m = CameraMove::create(s.keys);
    if (m) {
      s.move_playing = std::move(*m);
      s.move_start_s = now_s;
    } else {
      s.last_error = m.error().message;
    }
  }
  ImGui::SameLine();
  if (ImGui::Button("Clear")) s.keys.clear();
  if (s.move_playing) {
    const double t = now_s - s.move_start_s;
    view = s.move_playing->at(s.move_playing->keys().front().time + t);
    if (t > s.move_playing->duration()) s.move_playing.reset();
  }
  ImGui::End();
}

void projectors_panel(PanelState& s, PreviewNode& node, const ViewPipeline& pipeline) {
  if (!ImGui::Begin("Projectors", &s.projectors)) return ImGui::End();
  remember_window(s, "Projectors");
  const auto projectors = node.overlays().projectors();
  if (projectors.empty()) ImGui::TextUnformatted("no projector on the wire");
  for (const auto& [id, p] : projectors) {
    ImGui::Text("%s%s: frame %llu (mesh %llu), latency %.1f ms, margin %.0f mm", id.c_str(),
                p.calibrated ? "" : " (no calibration)", (unsigned long long)p.render_frame,
                (unsigned long long)p.mesh_frame, p.latency_ms, 1000 * p.margin_m);
    const ViewPipeline::Thumbnail t = pipeline.thumbnail(id);
    if (t.texture == 0) {
      ImGui::TextUnformatted("  no thumbnail yet");
      continue;
    }
    const float scale = 240.0f / float(t.width);
    ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(t.texture)),
                 ImVec2(240.0f, float(t.height) * scale));
    const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
    s.items["projector/" + id] = {a.x, a.y, b.x - a.x, b.y - a.y, double(p.render_frame)};
  }
  ImGui::End();
}

}  // namespace

void draw_panels(PanelState& s, PreviewNode& node, ViewPipeline& pipeline, Viewpoint& view,
                 double now_s) {
  s.windows.clear();
  s.items.clear();
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  if (s.view) view_panel(s, node, pipeline, view, now_s);
  ImGui::SetNextWindowPos(ImVec2(10, 200), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(560, 300), ImGuiCond_FirstUseEver);
  if (s.cameras) cameras_panel(s, node);
  ImGui::SetNextWindowPos(ImVec2(580, 10), ImGuiCond_FirstUseEver);
  if (s.capture) capture_panel(s, node);
  ImGui::SetNextWindowPos(ImVec2(580, 250), ImGuiCond_FirstUseEver);
  if (s.animation) animation_panel(s, node);
  ImGui::SetNextWindowPos(ImVec2(580, 450), ImGuiCond_FirstUseEver);
  if (s.services) services_panel(s, node);
  ImGui::SetNextWindowPos(ImVec2(10, 520), ImGuiCond_FirstUseEver);
  if (s.projectors) projectors_panel(s, node, pipeline);
}

}  // namespace studio::preview
