// studio-sim-snapshot: writes the simulated studio's camera images and true masks as PNGs for a
// person to look at (and for tools that read mask folders, DESIGN §6).
//   studio-sim-snapshot --out DIR [--frames A:B] [--seed N] [--motion NAME] [--cameras N]
//                       [--blur] [--projection] [--target]
// Layout: DIR/<frame>/<camera_id>.png (image), DIR/<frame>/<camera_id>_mask.png (true mask),
// DIR/<frame>/truth.json (time, head centre). --target also writes DIR/target_<camera_id>.png.
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "sim/cameras.h"
#include "sim/studio.h"
#include "sim/target.h"

namespace {

constexpr const char* kUsage =
    "usage: studio-sim-snapshot --out DIR [--frames A:B] [--seed N] [--motion NAME] [--cameras N]\n"
    "                           [--blur] [--projection] [--target]\n"
    "Writes simulated studio images and true masks: DIR/<frame>/<camera_id>.png and\n"
    "<camera_id>_mask.png, plus truth.json (time, head centre). Defaults: frames 0:1 (one frame),\n"
    "seed 1, motion sequence, 6 cameras (5 on a ring, 1 overhead) at 704x576.\n";

int fail(const std::string& message) {
  std::cerr << "studio-sim-snapshot: " << message << "\n";
  return 2;
}

bool parse_int(const std::string& s, long long* v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool write_png(const std::filesystem::path& path, const studio::Image<studio::Rgb8>& img) {
  cv::Mat m(img.height(), img.width(), CV_8UC3, const_cast<studio::Rgb8*>(img.data()));
  cv::Mat bgr;
  cv::cvtColor(m, bgr, cv::COLOR_RGB2BGR);
  return cv::imwrite(path.string(), bgr);
}

}  // namespace


int main(int argc, char** argv) {
  std::string out;
  long long first = 0, last = 1, seed = 1, cameras = 6;
  std::string motion = "sequence";
  bool blur = false, projection = false, target = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    } else if (a == "--out") {
      const char* v = value();
      if (!v) return fail("--out needs a directory");
      out = v;
    } else if (a == "--frames") {
      const char* v = value();
      const std::string s = v ? v : "";
      const auto colon = s.find(':');
      if (colon == std::string::npos || !parse_int(s.substr(0, colon), &first) ||
          !parse_int(s.substr(colon + 1), &last) || last <= first || first < 0) {
        return fail("--frames expects A:B with 0 <= A < B");
      }
    } else if (a == "--seed") {
      const char* v = value();
      if (!v || !parse_int(v, &seed) || seed < 0) return fail("--seed expects a non-negative integer");
    } else if (a == "--cameras") {
      const char* v = value();
      if (!v || !parse_int(v, &cameras) || cameras < 1 || cameras > 64) {
        return fail("--cameras expects an integer in [1, 64]");
      }
    } else if (a == "--motion") {
      const char* v = value();
      if (!v) return fail("--motion needs a name");
      motion = v;
    } else if (a == "--blur") {
      blur = true;
    } else if (a == "--projection") {
      projection = true;
    } else if (a == "--target") {
      target = true;
    } else {
      return fail("unknown argument '" + a + "' (see --help)");
    }
  }
  if (out.empty()) return fail("--out DIR is required (see --help)");
  const auto m = studio::sim::parse_motion(motion);
  if (!m) return fail(m.error().message);
  studio::sim::StudioOptions options;
  options.seed = static_cast<uint64_t>(seed);
  options.actor.seed = static_cast<uint64_t>(seed);
  options.actor.motion = *m;
  options.motion_blur = blur;
  options.projected_image = projection;
  studio::sim::RingOptions ring;
  ring.count = static_cast<int>(cameras);
  auto studio = studio::sim::SimulatedStudio::create(studio::sim::ring_cameras(ring), options);
  if (!studio) return fail(studio.error().message);
  std::error_code ec;
  std::vector<studio::Image<studio::Rgb8>> images;
  std::vector<studio::Mask> masks;
  for (long long f = first; f < last; ++f) {
    const std::filesystem::path dir = std::filesystem::path(out) / std::to_string(f);
    std::filesystem::create_directories(dir, ec);
    if (ec) return fail("cannot create " + dir.string() + ": " + ec.message());
    const auto truth = studio->render_all(f, &images, &masks);
    for (int c = 0; c < studio->camera_count(); ++c) {
      const std::string id = studio->cameras()[c].id;
      cv::Mat mask(masks[c].height(), masks[c].width(), CV_8UC1, masks[c].data());
      if (!write_png(dir / (id + ".png"), images[c]) || !cv::imwrite((dir / (id + "_mask.png")).string(), mask)) {
        return fail("cannot write PNGs into " + dir.string());
      }
    }
    const Eigen::Vector3d h = truth.head_centre();
    std::ofstream json(dir / "truth.json");
    json << "{\"frame\": " << f << ", \"time\": " << truth.time << ", \"head_centre\": [" << h.x()
         << ", " << h.y() << ", " << h.z() << "]}\n";
    std::fprintf(stderr, "frame %lld/%lld\n", f - first + 1, last - first);
  }
  if (target) {
    const auto board = studio::sim::Target::create(studio::sim::TargetSpec{});
    if (!board) return fail(board.error().message);
    const auto& cam = studio->cameras()[0];
    // The board 2.5 m in front of cam0, facing it.
    const studio::Rigid3 world_from_cam = cam.cam_from_world.inverse();
    const studio::Rigid3 cam_from_target(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())),
                                         Eigen::Vector3d(-0.55, -0.55, 2.5));
    studio::Image<studio::Rgb8> img;
    board->render(cam, world_from_cam * cam_from_target, {}, &img);
    if (!write_png(std::filesystem::path(out) / ("target_" + cam.id + ".png"), img)) {
      return fail("cannot write the target PNG");
    }
  }
  return 0;
}
