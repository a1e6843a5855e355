#include "keyer/config/kept_plates.h"

#include <filesystem>

#include "core/log.h"
#include "keyer/config/image_io.h"

namespace studio::keyer {

Expected<void> KeptPlates::prepare() const {
  if (!enabled()) return {};
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) return fail("plate_dir " + dir_ + ": " + ec.message());
  return {};
}

std::string KeptPlates::path(const std::string& camera) const {
  return (std::filesystem::path(dir_) / (camera + ".png")).string();
}

Expected<bool> KeptPlates::load(const std::string& camera, Keyer& keyer) const {
  if (!enabled()) return false;
  const std::string file = path(camera);
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return false;
  auto image = read_rgb(file);
  if (!image) return std::unexpected(image.error());
  keyer.clear_plate();
  if (auto r = keyer.capture_plate(image->view()); !r) return std::unexpected(r.error());
  return true;
}

Expected<void> KeptPlates::save(const std::string& camera, const Keyer& keyer) const {
  if (!enabled()) return {};
  return write_rgb_png(path(camera), keyer.plate());
}

void KeptPlates::remove(const std::string& camera) const {
  if (!enabled()) return;
  std::error_code ec;
  std::filesystem::remove(path(camera), ec);
}

void KeptPlates::restore(const std::string& camera, Keyer& keyer, std::string_view log) const {
  if (auto loaded = load(camera, keyer); !loaded)
    STUDIO_LOG(warn, log) << camera << ": kept plate not used: " << loaded.error().message;
  else if (*loaded)
    STUDIO_LOG(info, log) << camera << ": clean plate from " << path(camera);
}

bool KeptPlates::keep(const std::string& camera, const Keyer& keyer, std::string_view log) const {
  if (auto r = save(camera, keyer); !r) {
    STUDIO_LOG(warn, log) << camera << ": clean plate not kept: " << r.error().message;
    return false;
  }
  return true;
}

}  // namespace studio::keyer
