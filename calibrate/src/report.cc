#include "calibrate/report.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include "calibrate/text.h"

namespace studio::calibrate {
namespace {

std::string quote(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') out += std::string("\\") + ch;
    else if (c < 0x20) out += format("\\u{:04x}", static_cast<int>(c));
    else out += ch;
  }
  return out + "\"";
}

std::string num(double v) { return std::isfinite(v) ? format("{:.6g}", v == 0 ? 0.0 : v) : "null"; }

}  // namespace

std::string report_json(const CalibrationResult& r) {
  std::string j = "{\n";
  j += format("  \"rms_px\": {},\n  \"observations\": {},\n", num(r.rms_px), r.observations);
  j += format("  \"heldout\": {{\"rms_px\": {}, \"observations\": {}}},\n",
                   num(r.heldout_rms_px), r.heldout_observations);
  j += format("  \"kfold\": {{\"rms_px\": {}, \"observations\": {}}},\n", num(r.kfold_rms_px),
                   r.kfold_observations);
  j += format("  \"iterations\": {},\n  \"seconds\": {},\n  \"gauge\": {},\n", r.iterations,
                   num(r.seconds), quote(r.gauge));
  j += "  \"cameras\": [";
  for (size_t i = 0; i < r.per_camera.size(); ++i) {
    const CameraStats& s = r.per_camera[i];
    const Camera& c = r.cameras[i];
    const Eigen::Vector3d centre = c.centre_in_world();
    j += format(
        "{}\n    {{\"id\": {}, \"observations\": {}, \"outliers\": {}, \"rms_px\": {}, "
        "\"heldout_observations\": {}, \"heldout_rms_px\": {}, \"fx\": {}, \"fy\": {}, "
        "\"cx\": {}, \"cy\": {}, \"rd3\": {}, \"rd5\": {}, \"centre\": [{}, {}, {}]}}",
        i ? "," : "", quote(s.id), s.observations, s.outliers, num(s.rms_px),
        s.heldout_observations, num(s.heldout_rms_px), num(c.intrinsics.fx), num(c.intrinsics.fy),
        num(c.intrinsics.cx), num(c.intrinsics.cy), num(c.distortion.rd3), num(c.distortion.rd5),
        num(centre.x()), num(centre.y()), num(centre.z()));
  }
  j += "\n  ],\n  \"frames\": [";
  for (size_t i = 0; i < r.per_frame.size(); ++i) {
    const FrameStats& f = r.per_frame[i];
    j += format("{}\n    {{\"id\": {}, \"placement\": \"{}\", \"held_out\": {}, "
                     "\"observations\": {}, \"rms_px\": {}}}",
                     i ? "," : "", quote(f.id), to_string(f.placement),
                     f.held_out ? "true" : "false", f.observations, num(f.rms_px));
  }
  j += "\n  ],\n  \"outliers\": [";
  for (size_t i = 0; i < r.outliers.size(); ++i) {
    const ScoredObservation& o = r.outliers[i];
    j += format("{}\n    {{\"camera\": {}, \"frame\": {}, \"point\": {}, \"u\": {}, "
                     "\"v\": {}, \"residual_px\": {}}}",
                     i ? "," : "", quote(o.camera_id), quote(o.frame_id), o.point,
                     num(o.pixel.x()), num(o.pixel.y()), num(o.residual.norm()));
  }
  j += "\n  ]\n}\n";
  return j;
}

Expected<std::vector<std::string>> write_residual_plots(const CalibrationResult& r,
                                                        const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail(dir + ": " + ec.message());
  std::vector<std::string> files;
  for (size_t i = 0; i < r.cameras.size(); ++i) {
    const Camera& cam = r.cameras[i];
    const CameraStats& st = r.per_camera[i];
    const double scale = 800.0 / std::max(1, std::max(cam.width, cam.height));
    const int w = std::max(1, static_cast<int>(cam.width * scale));
    const int h = std::max(1, static_cast<int>(cam.height * scale));
    const int panel = h;  // square scatter panel on the right
    cv::Mat img(h + 40, w + panel, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::rectangle(img, cv::Rect(0, 0, w, h), cv::Scalar(0, 0, 0));
    const double magnify = 40;  // residual vectors drawn 40x
    double max_res = std::max(0.5, 3 * st.rms_px);
    auto draw = [&](const std::vector<ScoredObservation>& v, cv::Scalar colour) {
      for (const auto& o : v) {
        if (o.camera_id != st.id) continue;
        const cv::Point2d p(o.pixel.x() * scale, o.pixel.y() * scale);
        const cv::Point2d q = p + cv::Point2d(o.residual.x(), o.residual.y()) * magnify * scale;
        cv::line(img, p, q, colour, 1, cv::LINE_AA);
        cv::circle(img, p, 1, colour, cv::FILLED);
        // Scatter: residual (px) at the panel centre, ±max_res across the panel.
        const cv::Point2d c(w + panel / 2.0, h / 2.0);
        const double k = (panel / 2.0 - 4) / max_res;
        const cv::Point2d s = c + cv::Point2d(std::clamp(o.residual.x() * k, -panel / 2.0, panel / 2.0),
                                              std::clamp(o.residual.y() * k, -panel / 2.0, panel / 2.0));
        cv::circle(img, s, 1, colour, cv::FILLED);
      }
    };
    draw(r.inliers, cv::Scalar(0, 160, 0));
    draw(r.heldout, cv::Scalar(200, 80, 0));
    draw(r.outliers, cv::Scalar(0, 0, 220));
    const cv::Point c(w + panel / 2, h / 2);
    const double k = (panel / 2.0 - 4) / max_res;
    cv::circle(img, c, std::max(1, static_cast<int>(st.rms_px * k)), cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    cv::line(img, cv::Point(w, h / 2), cv::Point(w + panel, h / 2), cv::Scalar(180, 180, 180));
    cv::line(img, cv::Point(w + panel / 2, 0), cv::Point(w + panel / 2, h), cv::Scalar(180, 180, 180));
    cv::putText(img,
                format("{}: rms {:.3f} px ({} obs), held-out {:.3f} px, {} outliers; "
                            "vectors x{:.0f}, scatter +-{:.2f} px",
                            st.id, st.rms_px, st.observations, st.heldout_rms_px, st.outliers, magnify,
                            max_res),
                cv::Point(6, h + 26), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    const std::string file = (std::filesystem::path(dir) / ("residuals_" + st.id + ".png")).string();
    if (!cv::imwrite(file, img)) return fail(file + ": cannot write PNG");
    files.push_back(file);
  }
  return files;
}

}  // namespace studio::calibrate
