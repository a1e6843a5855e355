#include "gui.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "camera_matching.h"
#include "panels.h"
#include "runtime/metrics.h"
#include "status_ticker.h"
#include "view_pipeline.h"
#include "wire/entity.h"

namespace studio::preview {
namespace {

using Clock = std::chrono::steady_clock;

int error(const std::string& message, int status = 1) {
  std::fprintf(stderr, "studio-preview: %s\n", message.c_str());
  return status;
}

// The test hook (gui.h): actions run between frames.
class Script {
 public:
  static Expected<Script> open(const std::string& path) {
    Script s;
    if (path.empty()) return s;
    std::ifstream in(path);
    if (!in) return fail("--test-script: cannot read '" + path + "'");
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && line[0] != '#') s.lines_.push_back(line);
    return s;
  }

  // Runs the actions that are due; false when the script says quit (or failed).
  bool step(PanelState& panels, Viewpoint& view, const ViewPipeline& pipeline, int width,
            int height, bool& screenshot_due, std::string& screenshot_path) {
    while (next_ < lines_.size()) {
      std::istringstream in(lines_[next_]);
      std::string verb;
      in >> verb;
      if (verb == "wait_meshes") {
        uint64_t n = 0;
        in >> n;
        if (pipeline.counts().meshes < n && Clock::now() - since_ < std::chrono::seconds(30))
          return true;
      } else if (verb == "wait") {
        double s = 0;
        in >> s;
        if (Clock::now() - since_ < std::chrono::duration<double>(s)) return true;
      } else if (verb == "open") {
        std::string p;
        in >> p;
        bool* flag = p == "cameras"      ? &panels.cameras
                     : p == "capture"    ? &panels.capture
                     : p == "animation"  ? &panels.animation
                     : p == "services"   ? &panels.services
                     : p == "view"       ? &panels.view
                     : p == "projectors" ? &panels.projectors
                                         : nullptr;
        if (!flag) return failed("open: unknown panel '" + p + "'");
        *flag = true;
      } else if (verb == "set") {
        std::string cam, feature;
        double value = 0;
        if (!(in >> cam >> feature >> value)) return failed("set: expected CAMERA FEATURE VALUE");
        panels.scripted[cam + "/" + feature] = value;
      } else if (verb == "press") {
        std::string button;
        in >> button;
        if (button != "match_cameras") return failed("press: unknown button '" + button + "'");
        panels.press_match = true;
      } else if (verb == "viewpoint") {
        std::string text;
        in >> text;
        auto v = parse_viewpoint(text);
        if (!v) return failed(v.error().message);
        view = *v;
      } else if (verb == "screenshot") {
        in >> screenshot_path;
        screenshot_due = true;
      } else if (verb == "quit") {
        return false;
      } else {
        return failed("unknown action '" + verb + "'");
      }
      ++next_;
      since_ = Clock::now();
      if (verb == "screenshot" || verb == "open" || verb == "set" || verb == "press")
        return true;  // draw first
    }
    (void)width;
    (void)height;
    return true;
  }
  bool ok() const { return ok_; }

 private:
  bool failed(const std::string& why) {
    std::fprintf(stderr, "studio-preview: test script line %zu: %s\n", next_ + 1, why.c_str());
    ok_ = false;
    return false;
  }
  std::vector<std::string> lines_;
  std::size_t next_ = 0;
  Clock::time_point since_ = Clock::now();
  bool ok_ = true;
};

bool write_screenshot(const std::string& path, int w, int h, const PanelState& panels,
                      const PipelineCounts& counts) {
  std::vector<uint8_t> rgba(std::size_t(w) * h * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  cv::Mat image(h, w, CV_8UC4, rgba.data()), bgr;
  cv::cvtColor(image, bgr, cv::COLOR_RGBA2BGR);
  cv::flip(bgr, bgr, 0);  // GL rows are bottom first
  bool ok = false;
  try {
    ok = cv::imwrite(path, bgr);
  } catch (const cv::Exception&) {
  }
  std::ofstream json(path + ".json");
  auto rect = [&](const ItemRect& r, bool value) {
    json << "[" << r.x << "," << r.y << "," << r.w << "," << r.h;
    if (value) json << "," << r.value;
    json << "]";
  };
  json << "{\"windows\":{";
  bool first = true;
  for (const auto& [k, r] : panels.windows) {
    json << (first ? "" : ",") << "\"" << k << "\":";
    rect(r, false);
    first = false;
  }
  json << "},\"items\":{";
  first = true;
  for (const auto& [k, r] : panels.items) {
    json << (first ? "" : ",") << "\"" << k << "\":";
    rect(r, true);
    first = false;
  }
  json << "},\"view\":{\"meshes\":" << counts.meshes << ",\"textured\":" << counts.textured
       << ",\"match\":" << json_text(panels.match_result)
       << ",\"match_source\":" << json_text(panels.match_source) << "}}\n";
  return ok && json.good();
}

}  // namespace

int run_gui(const PreviewConfig& config, const std::string& script_path) {
  auto script = Script::open(script_path);
  if (!script) return error(script.error().message, 2);
  if (!glfwInit())
    return error("no display: GLFW could not initialise (set DISPLAY, or use --headless)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  GLFWwindow* window =
      glfwCreateWindow(config.width, config.height, ("studio preview: " + config.instance).c_str(),
                       nullptr, nullptr);
  if (!window) {
    glfwTerminate();
    return error("cannot open an OpenGL 3.3 core window");
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // the layout is the program's, not a file's
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  int status = 0;
  {
    auto participant = wire::Participant::create(
        config.domain >= 0 ? dds_domainid_t(config.domain) : wire::default_domain(),
        config.dds_config);
    if (!participant) return error(participant.error().message);
    runtime::Metrics metrics;
    runtime::NodeContext context{*participant, metrics, config.instance};
    PreviewNode node(context, config.instance + "-" + std::to_string(::getpid()));
    if (auto ok = node.start(); !ok) return error(ok.error().message);
    auto service_status = StatusTicker::create(context, node);
    if (!service_status) return error(service_status.error().message);
    PipelineOptions po;
    po.blend = config.blend;
    po.blend_options.cameras = config.blend_cameras;
    po.wait = std::chrono::milliseconds(config.wait_ms);
    po.asset_root = config.asset_root;
    po.overlays = config.overlays;
    po.carve_all_masks = config.carve_masks;
    po.colour_balance = config.colour_balance;
    po.balance_every = config.colour_balance_every;
    po.balance_rig_every =
        std::chrono::milliseconds(std::lround(1000 * config.colour_balance_rig_s));
    auto pipeline = ViewPipeline::create(node, po);
    if (!pipeline) return error(pipeline.error().message);
    service_status->before_publish([&] { (*pipeline)->report(metrics); });
    PanelState panels;
    std::snprintf(panels.take, sizeof panels.take, "%s", config.take.c_str());
    Viewpoint view = config.viewpoint;
    const auto start = Clock::now();
    double last_x = 0, last_y = 0;
    bool running = true, screenshot_due = false;
    std::string screenshot_path;
    while (running && !glfwWindowShouldClose(window)) {
      glfwPollEvents();
      service_status->tick();
      int w = 0, h = 0;
      glfwGetFramebufferSize(window, &w, &h);
      if (w < 1 || h < 1) continue;
      // Mouse and keys move the view when no panel wants them.
      ImGuiIO& io = ImGui::GetIO();
      double x = 0, y = 0;
      glfwGetCursorPos(window, &x, &y);
      if (!io.WantCaptureMouse) {
        Orbit o = Orbit::from(view);
        if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS)
          o.rotate(-(x - last_x) * 0.01, (y - last_y) * 0.01);
        if (io.MouseWheel != 0) o.zoom(std::pow(0.9, io.MouseWheel));
        view = o.viewpoint();
        if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS)
          view = fly(view, Eigen::Vector3d(-(x - last_x) * 0.005, (y - last_y) * 0.005, 0));
      }
      if (!io.WantCaptureKeyboard) {
        const double step = 0.05;
        auto key = [&](int k) { return glfwGetKey(window, k) == GLFW_PRESS ? step : 0.0; };
        const Eigen::Vector3d d(key(GLFW_KEY_D) - key(GLFW_KEY_A),
                                key(GLFW_KEY_E) - key(GLFW_KEY_Q),
                                key(GLFW_KEY_W) - key(GLFW_KEY_S));
        if (d.norm() > 0) view = fly(view, d);
      }
      last_x = x;
      last_y = y;
      const double now_s = std::chrono::duration<double>(Clock::now() - start).count();
      running = script->step(panels, view, **pipeline, w, h, screenshot_due, screenshot_path);

      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      (*pipeline)->render(view, w, h, false);
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      draw_panels(panels, node, **pipeline, view, now_s);
      ImGui::Render();
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      glViewport(0, 0, w, h);
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      if (screenshot_due) {
        screenshot_due = false;
        if (!write_screenshot(screenshot_path, w, h, panels, (*pipeline)->counts())) {
          status = error("cannot write '" + screenshot_path + "'");
          running = false;
        }
      }
      glfwSwapBuffers(window);
    }
    if (!script->ok()) status = 2;
    service_status->stopping();
    node.stop();
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return status;
}

}  // namespace studio::preview
