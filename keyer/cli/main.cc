// studio-keyer key: key a folder of camera images into a folder of PNG masks.
// studio-keyer --config keyer.yaml: the standalone keyer service (keyer/node/keyer_node.h).
//
//   studio-keyer key --input DIR --output DIR [--key blue|green|difference] [--plate FILE]
//                    [--config keyer.yaml] [--alpha DIR] [--json]
//
// Every PNG/JPEG in DIR (sorted by name) is keyed; the mask goes to OUTPUT/<stem>.png
// (0 = backing, 255 = actor). With --alpha, soft alpha PNGs go to that folder too. Progress on
// stderr; with --json a summary (frames, mean encoded mask bytes, keying ms per frame) on stdout.
// Bad input (missing folder, unreadable image, plate of another size, bad config) ends the run
// with exit status 1 and one line on stderr; bad usage with status 2.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "core/mask_codec.h"
#include "keyer/config/image_io.h"
#include "keyer/keyer.h"
#include "keyer_node.h"
#include "keyer/config/keyer_yaml.h"
#include "runtime/service.h"

namespace fs = std::filesystem;
using namespace studio;
using namespace studio::keyer;

namespace {

constexpr const char* kUsage = R"(usage: studio-keyer key --input DIR --output DIR [options]
       studio-keyer --config keyer.yaml     the keyer service (DDS; keys below)

Keys every PNG/JPEG image in DIR and writes one PNG mask (0 backing, 255 actor) per image, with
the same name (extension .png), into the output folder (created if missing).

options:
  --input DIR            folder of camera images (PNG or JPEG)
  --output DIR           folder for the masks
  --key blue|green|difference
                         colour-difference key for a blue (default) or green backing, or a
                         difference key against the clean plate given by --plate
  --plate FILE           clean plate image (the backing without actor), same size as the images
  --config FILE          keyer.yaml with the keyer options (see keyer/keyer.example.yaml);
                         --key overrides its `key`
  --alpha DIR            also write soft alpha PNGs (0..255) into DIR
  --json                 print a JSON summary on stdout
  -h, --help             this text
)";

int bad_usage(const std::string& msg) {
  std::cerr << "studio-keyer: " << msg << " (see studio-keyer --help)\n";
  return 2;
}
int bad_input(const std::string& msg) {
  std::cerr << "studio-keyer: " << msg << "\n";
  return 1;
}

bool is_image(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

int run_key(const std::vector<std::string>& args) {
  std::string input, output, key, plate, config, alpha_dir;
  bool json = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string& out) {
      if (i + 1 >= args.size()) return false;
      out = args[++i];
      return true;
    };
    bool ok = true;
    if (a == "--input") ok = value(input);
    else if (a == "--output") ok = value(output);
    else if (a == "--key") ok = value(key);
    else if (a == "--plate") ok = value(plate);
    else if (a == "--config") ok = value(config);
    else if (a == "--alpha") ok = value(alpha_dir);
    else if (a == "--json") json = true;
    else if (a == "-h" || a == "--help") { std::cout << kUsage; return 0; }
    else return bad_usage("unknown option '" + a + "'");
    if (!ok) return bad_usage("option " + a + " needs a value");
  }
  if (input.empty() || output.empty()) return bad_usage("key needs --input DIR and --output DIR");

  KeyerOptions options;
  if (!config.empty()) {
    auto loaded = load_keyer_options(config);
    if (!loaded) return bad_input(loaded.error().message);
    options = *loaded;
  }
  if (!key.empty()) {
    auto mode = parse_key_mode(key);
    if (!mode) return bad_usage(mode.error().message);
    options.mode = *mode;
  }
  if (options.mode == KeyMode::kDifference && plate.empty())
    return bad_usage("--key difference needs --plate FILE");

  std::error_code ec;
  if (!fs::is_directory(input, ec)) return bad_input("input folder '" + input + "' does not exist");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(input, ec))
    if (entry.is_regular_file() && is_image(entry.path())) files.push_back(entry.path());
  if (ec) return bad_input("cannot list input folder '" + input + "': " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) return bad_input("input folder '" + input + "' holds no PNG or JPEG images");
  for (const std::string& dir : {output, alpha_dir}) {
    if (dir.empty()) continue;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir, ec)) return bad_input("cannot create output folder '" + dir + "'");
  }

  auto keyer = Keyer::create(options);
  if (!keyer) return bad_input(keyer.error().message);
  Image<Rgb8> plate_image;
  if (options.mode == KeyMode::kDifference) {
    auto p = read_rgb(plate);
    if (!p) return bad_input(p.error().message);
    plate_image = std::move(*p);
    if (auto r = keyer->capture_plate(plate_image.view()); !r) return bad_input(r.error().message);
  }

  RunMask mask;
  std::vector<uint8_t> encoded;
  double key_seconds = 0, total_bytes = 0;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string name = files[i].string();
    auto image = read_rgb(name);
    if (!image) return bad_input(image.error().message);
    if (options.mode == KeyMode::kDifference &&
        (image->width() != plate_image.width() || image->height() != plate_image.height()))
      return bad_input("image '" + name + "' is " + size_text(image->width(), image->height()) +
                       " but the clean plate '" + plate + "' is " +
                       size_text(plate_image.width(), plate_image.height()));
    const auto t0 = std::chrono::steady_clock::now();
    auto r = keyer->key(image->view(), mask);
    key_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!r) return bad_input(name + ": " + r.error().message);
    encode_mask(mask, MaskCoding::kRowDelta, encoded);
    total_bytes += double(encoded.size());
    const fs::path stem = files[i].stem();
    if (auto w = write_mask_png((fs::path(output) / stem).string() + ".png", mask.to_mask()); !w)
      return bad_input(w.error().message);
    if (!alpha_dir.empty()) {
      Mask alpha(image->width(), image->height());
      if (auto a = keyer->soft_alpha(image->view(), alpha.view()); !a) return bad_input(a.error().message);
      if (auto w = write_mask_png((fs::path(alpha_dir) / stem).string() + ".png", alpha); !w)
        return bad_input(w.error().message);
    }
    if (files.size() >= 10 && (i + 1) % 10 == 0)
      std::fprintf(stderr, "studio-keyer: keyed %zu/%zu\n", i + 1, files.size());
  }
  const double n = double(files.size());
  if (json) {
    std::printf("{\"frames\": %zu, \"key\": \"%s\", \"mean_mask_bytes\": %.1f, \"key_ms_per_frame\": %.4f}\n",
                files.size(), std::string(key_mode_name(options.mode)).c_str(), total_bytes / n,
                1e3 * key_seconds / n);
  } else {
    std::fprintf(stderr, "studio-keyer: keyed %zu images into %s (mean encoded mask %.0f bytes)\n",
                 files.size(), output.c_str(), total_bytes / n);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty() || args[0] == "-h" || args[0] == "--help") {
      const auto service = keyer_service_definition();
      std::cout << kUsage << "\nService config (studio-keyer --config FILE): " << service.summary << "\n"
                << service.config_help
                << "  plus the common service keys: instance, domain, dds_config, status_period, log\n";
      return args.empty() ? 2 : 0;
    }
    if (args[0] == "--config" || args[0].starts_with("--config="))
      return studio::runtime::service_main(argc, argv, keyer_service_definition());
    if (args[0] == "key") return run_key({args.begin() + 1, args.end()});
    return bad_usage("unknown command '" + args[0] + "'");
  } catch (const std::exception& e) {
    std::cerr << "studio-keyer: internal error: " << e.what() << "\n";
    return 3;
  }
}
