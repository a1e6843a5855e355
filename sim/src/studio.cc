// The simulated studio: options, per-camera caches (rays, cyclorama background), sensor noise,
// and threading over cameras (sim/studio.h). The per-frame actor work is in render.cc.
#include "sim/studio.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <thread>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "clean_upper.h"
#include "projector_light_impl.h"
#include "studio_impl.h"

#include "message.h"

namespace studio::sim {

using detail::CameraCache;
using detail::Rect;

Expected<void> StudioOptions::validate() const {
  if (auto ok = actor.validate(); !ok) return ok;
  if (!(fps > 0 && fps <= 1000)) return fail(detail::cat("studio fps ", fps, " outside (0, 1000]"));
  if (!(cyclorama_half_width >= 1.5 && cyclorama_half_width <= 50)) {
    return fail(detail::cat("cyclorama_half_width ", cyclorama_half_width, " m outside [1.5, 50] (must enclose the acting area)"));
  }
  if (!(cyclorama_height >= 3 && cyclorama_height <= 50)) {
    return fail(detail::cat("cyclorama_height ", cyclorama_height, " m outside [3, 50]"));
  }
  auto unit = [](double v) { return v >= 0 && v <= 1; };
  if (!(noise_sigma >= 0 && noise_sigma <= 40)) {
    return fail(detail::cat("noise_sigma ", noise_sigma, " outside [0, 40] grey levels"));
  }
  if (!unit(cloth_falloff) || !unit(spill) || !unit(shadow) || !unit(ring_light) ||
      !unit(projection_strength) || !unit(shutter)) {
    return fail("cloth_falloff, spill, shadow, ring_light, projection_strength and shutter must "
                "lie in [0, 1]");
  }
  if (blur_samples < 2 || blur_samples > 64) {
    return fail(detail::cat("blur_samples ", blur_samples, " outside [2, 64]"));
  }
  if (aa_samples < 2 || aa_samples > 64) {
    return fail(detail::cat("aa_samples ", aa_samples, " outside [2, 64]"));
  }
  if (threads < 1 || threads > 64) return fail(detail::cat("threads ", threads, " outside [1, 64]"));
  for (std::size_t i = 0; i < camera_response.size(); ++i)
    for (double g : camera_response[i])
      if (!(g >= 0.25 && g <= 4))
        return fail(detail::cat("camera_response[", i, "]: gain ", g, " outside [0.25, 4]"));
  return projector_light.validate();
}

namespace detail {

Rect CameraCache::project_hull(const Eigen::Vector3d* points, int n, int margin) const {
  const int W = camera.width, H = camera.height;
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (int k = 0; k < n; ++k) {
    if (!(points[k].z() > 0.05)) return {0, 0, W, H};
    const double x = points[k].x() / points[k].z(), y = points[k].y() / points[k].z();
    xmin = std::min(xmin, x);
    xmax = std::max(xmax, x);
    ymin = std::min(ymin, y);
    ymax = std::max(ymax, y);
  }
  const auto& k = camera.intrinsics;
  double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
  auto add = [&](double x, double y) {
    if (!pinhole) {
      const Eigen::Vector2d o = distort(camera.distortion, Eigen::Vector2d(x, y));
      x = o.x();
      y = o.y();
    }
    const double u = k.fx * x + k.skew * y + k.cx, v = k.fy * y + k.cy;
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  };
  const int steps = pinhole ? 1 : 16;
  for (int s = 0; s <= steps; ++s) {
    const double a = static_cast<double>(s) / steps;
    add(xmin + a * (xmax - xmin), ymin);
    add(xmin + a * (xmax - xmin), ymax);
    add(xmin, ymin + a * (ymax - ymin));
    add(xmax, ymin + a * (ymax - ymin));
  }
  if (!pinhole) margin += 2;
  auto clampi = [](double v, int lo, int hi) {
    return static_cast<int>(std::clamp(v, static_cast<double>(lo), static_cast<double>(hi)));
  };
  return {clampi(std::floor(umin) - margin, 0, W), clampi(std::floor(vmin) - margin, 0, H),
          clampi(std::ceil(umax) + margin + 1, 0, W), clampi(std::ceil(vmax) + margin + 1, 0, H)};
}

}  // namespace detail

namespace {

// Deterministic value noise in [-1, 1] on a 2-D lattice (cloth weave irregularity).
double hash01(int64_t i, int64_t j, uint64_t salt) {
  uint64_t h = static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ull ^
               (static_cast<uint64_t>(j) + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full ^ salt;
  h ^= h >> 31;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 29;
  return static_cast<double>(h >> 11) / static_cast<double>(1ull << 53) * 2 - 1;
}
double value_noise(double x, double y, uint64_t salt) {
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  const int64_t i = static_cast<int64_t>(fx), j = static_cast<int64_t>(fy);
  const double sx = ax * ax * (3 - 2 * ax), sy = ay * ay * (3 - 2 * ay);
  const double a = hash01(i, j, salt), b = hash01(i + 1, j, salt), c = hash01(i, j + 1, salt),
               d = hash01(i + 1, j + 1, salt);
  return (a * (1 - sx) + b * sx) * (1 - sy) + (c * (1 - sx) + d * sx) * sy;
}

// The built-in projected picture: a sky gradient, a sun and a chequered ground, 256x192.
Image<Rgb8> builtin_projection() {
  Image<Rgb8> img(256, 192);
  for (int y = 0; y < 192; ++y) {
    for (int x = 0; x < 256; ++x) {
      Rgb8 c;
      if (y < 120) {
        c = {static_cast<uint8_t>(120 + y), static_cast<uint8_t>(160 + y / 2), 230};
        const double dx = x - 190, dy = y - 40;
        if (dx * dx + dy * dy < 400) c = {255, 230, 120};
      } else {
        c = ((x / 32 + (y - 120) / 24) % 2) ? Rgb8{200, 180, 120} : Rgb8{90, 140, 60};
      }
      img(x, y) = c;
    }
  }
  return img;
}

// Cyclorama background for one camera (static, cached).
void build_background(const StudioOptions& o, const Image<Rgb8>& projection, CameraCache* cam) {
  const int W = cam->camera.width, H = cam->camera.height;
  cam->background = Image<Rgb8>(W, H);
  cam->surface = Image<uint8_t>(W, H);
  const double hw = o.cyclorama_half_width, ht = o.cyclorama_height;
  const Eigen::Matrix3d Rt = cam->R.transpose();
  const Eigen::Vector3d C = cam->centre;
  const double d_ref = std::max(1.0, C.norm());
  // The floor point of every floor pixel, for the per-frame shadow (make_shadow: no map without
  // a shadow): the world ray scaled to reach y = 0, the arithmetic the shadow did per frame.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  cam->floor_xz.assign(o.shadow > 0 ? static_cast<std::size_t>(W) * H : 0,
                       Eigen::Vector2d(kNaN, kNaN));
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const Eigen::Vector3d d_cam = cam->ray(u, v);
      const Eigen::Vector3d world = Rt * d_cam;
      const Eigen::Vector3d dir = world.normalized();
      // Nearest of the floor and the four walls, within their extents.
      double best = 1e300;
      int surface = detail::kNone;
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      auto consider = [&](double t, const Eigen::Vector3d& n, int kind) {
        if (!(t > 1e-9 && t < best)) return;
        const Eigen::Vector3d x = C + t * dir;
        const double eps = 1e-9;
        if (std::abs(x.x()) > hw + eps || std::abs(x.z()) > hw + eps || x.y() < -eps ||
            x.y() > ht + eps) {
          return;
        }
        best = t;
        surface = kind;
        normal = n;
      };
      if (dir.y() != 0) consider(-C.y() / dir.y(), Eigen::Vector3d::UnitY(), detail::kFloor);
      for (int axis : {0, 2}) {
        if (dir[axis] == 0) continue;
        for (double side : {-hw, hw}) {
          Eigen::Vector3d n = Eigen::Vector3d::Zero();
          n[axis] = side > 0 ? -1 : 1;
          consider((side - C[axis]) / dir[axis], n, detail::kWall);
        }
      }
      cam->surface(u, v) = static_cast<uint8_t>(surface);
      if (surface == detail::kFloor && !cam->floor_xz.empty() && world.y() < 0) {
        const double t = -C.y() / world.y();
        cam->floor_xz[static_cast<std::size_t>(v) * W + u] = {C.x() + t * world.x(),
                                                              C.z() + t * world.z()};
      }
      if (surface == detail::kNone) {
        const uint8_t g = static_cast<uint8_t>(std::clamp(28.0 + 10 * dir.y(), 0.0, 255.0));
        cam->background(u, v) = {g, g, static_cast<uint8_t>(g + 4)};
        continue;
      }
      const Eigen::Vector3d x = C + best * dir;
      // Retro-reflection of the lens's LED ring: vignetting, distance and incidence angle.
      const double cos_axis = d_cam.z() / d_cam.norm();
      const double vignette = std::pow(cos_axis, 3);
      const double distance = std::pow(d_ref / std::max(best, 0.5), 0.5);
      const double incidence = 0.7 + 0.3 * std::abs(normal.dot(dir));
      double g = std::min(1.1, vignette * distance * incidence);
      double f = 1 - o.cloth_falloff * (1 - g);
      // Cloth: weave irregularity, darker seams every 1.2 m on the walls, a darker floor.
      const Eigen::Vector2d uv = surface == detail::kFloor ? Eigen::Vector2d(x.x(), x.z())
                                 : std::abs(normal.x()) > 0 ? Eigen::Vector2d(x.z(), x.y())
                                                            : Eigen::Vector2d(x.x(), x.y());
      f *= 1 + 0.025 * value_noise(uv.x() * 6, uv.y() * 6, surface) +
           0.015 * value_noise(uv.x() * 25, uv.y() * 25, 7 + surface);
      if (surface == detail::kWall) {
        const double m = std::fmod(std::abs(uv.x()) + 0.6, 1.2);
        if (m < 0.012) f *= 0.88;
      } else {
        f *= 0.94;
      }
      double rgb[3] = {o.cloth.r * f, o.cloth.g * f, o.cloth.b * f};
      if (o.projected_image && surface == detail::kWall && normal.z() > 0.5 && !projection.pixels().empty()) {
        // Back wall screen x in [-1.5, 1.5], y in [0.2, 2.8] (the acting area's width).
        const double px = (x.x() + 1.5) / 3.0, py = (2.8 - x.y()) / 2.6;
        if (px >= 0 && px < 1 && py >= 0 && py < 1) {
          const Rgb8& p = projection(static_cast<int>(px * projection.width()),
                                     static_cast<int>(py * projection.height()));
          rgb[0] += o.projection_strength * p.r;
          rgb[1] += o.projection_strength * p.g;
          rgb[2] += o.projection_strength * p.b;
        }
      }
      cam->background(u, v) = {static_cast<uint8_t>(std::clamp(rgb[0] + 0.5, 0.0, 255.0)),
                               static_cast<uint8_t>(std::clamp(rgb[1] + 0.5, 0.0, 255.0)),
                               static_cast<uint8_t>(std::clamp(rgb[2] + 0.5, 0.0, 255.0))};
    }
  }
  const ProjectorLight& light = o.projector_light;
  if (!light.empty() || light.ring_level != 1 || light.exposure != 1) {
    detail::light_background(light, {hw, ht}, cam->camera, &cam->background, &cam->surface);
  }
  if (cam->response != std::array<float, 3>{1, 1, 1}) {
    // The background is display values: a linear gain g is g^(1/2.2) there (the shader's gamma).
    float f[3];
    for (int k = 0; k < 3; ++k) f[k] = std::pow(cam->response[std::size_t(k)], 1 / 2.2f);
    for (Rgb8& p : cam->background.pixels()) {
      uint8_t* c = &p.r;
      for (int k = 0; k < 3; ++k)
        c[k] = static_cast<uint8_t>(std::clamp(c[k] * f[k] + 0.5f, 0.0f, 255.0f));
    }
  }
}

uint64_t mix(uint64_t a, uint64_t b) {
  uint64_t h = a * 0x9E3779B97F4A7C15ull + b + 0x7F4A7C15ull;
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDull;
  h ^= h >> 33;
  h *= 0xC4CEB9FE1A85EC53ull;
  return h ^ (h >> 33);
}

// Table noise on n bytes with saturation: out = clamp(in + noise, 0, 255); out may be in.
void add_noise(uint8_t* out, const uint8_t* in, const int8_t* noise, std::size_t n) {
  std::size_t i = 0;
#if defined(__SSE2__)
  const __m128i bias = _mm_set1_epi8(static_cast<char>(0x80));
  for (; i + 16 <= n; i += 16) {
    const __m128i v =
        _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i)), bias);
    const __m128i z = _mm_loadu_si128(reinterpret_cast<const __m128i*>(noise + i));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm_xor_si128(_mm_adds_epi8(v, z), bias));
  }
#endif
  for (; i < n; ++i) out[i] = static_cast<uint8_t>(std::clamp(in[i] + noise[i], 0, 255));
}
void add_noise(uint8_t* data, const int8_t* noise, std::size_t n) {
  add_noise(data, data, noise, n);
}

// The image's first write of a frame: background + noise (noise may be null: none) over the
// byte range [b0, b1) of a row, or a plain background copy when `plain`.
void fill_span(uint8_t* out, const uint8_t* bg, const int8_t* noise, std::size_t b0, std::size_t b1,
               bool plain) {
  if (b1 <= b0) return;
  if (plain || noise == nullptr) {
    if (out != bg) std::memcpy(out + b0, bg + b0, b1 - b0);
  } else {
    add_noise(out + b0, bg + b0, noise + b0, b1 - b0);
  }
}

// Thread's mask when the caller wants none (the renderer needs one for its edges).
thread_local Mask scratch_mask;

constexpr std::size_t kNoiseWindow = 1 << 20;

}  // namespace

struct SimulatedStudio::Impl {
  StudioOptions options;
  Actor actor;
  std::vector<Camera> cameras;
  std::vector<CameraCache> caches;
  std::vector<int8_t> noise;  // N(0, sigma) per byte, kNoiseWindow longer than any image
  Image<Rgb8> projection;     // the image on the projection wall (backgrounds are rebuilt)

  // Camera `i`'s cache: its undistorted rays and its view of the empty studio.
  void build_cache(std::size_t i) {
    CameraCache& cache = caches[i];
    cache = CameraCache{};
    cache.camera = cameras[i];
    if (!options.camera_response.empty())
      for (int k = 0; k < 3; ++k)
        cache.response[std::size_t(k)] = float(options.camera_response[i][std::size_t(k)]);
    cache.pinhole = cache.camera.distortion.is_identity();
    cache.R = cache.camera.cam_from_world.R();
    cache.t = cache.camera.cam_from_world.translation;
    cache.centre = cache.camera.centre_in_world();
    if (!cache.pinhole) {
      const auto& k = cache.camera.intrinsics;
      cache.rays.resize(static_cast<std::size_t>(cache.camera.width) * cache.camera.height);
      for (int v = 0; v < cache.camera.height; ++v) {
        for (int u = 0; u < cache.camera.width; ++u) {
          const double y = (v - k.cy) / k.fy;
          cache.rays[static_cast<std::size_t>(v) * cache.camera.width + u] = undistort(
              cache.camera.distortion, Eigen::Vector2d((u - k.cx - k.skew * y) / k.fx, y));
        }
      }
    }
    build_background(options, projection, &cache);
  }

  explicit Impl(const StudioOptions& o) : options(o), actor(o.actor) {}

  detail::PreparedFrame prepare(int64_t frame) const {
    detail::PreparedFrame f;
    f.truth.frame = frame;
    f.truth.time = static_cast<double>(frame) / options.fps;
    f.truth.pose = actor.pose_at(f.truth.time);
    f.truth.body = actor.body(f.truth.pose, f.truth.time);
    if (options.motion_blur) {
      const double exposure = options.shutter / options.fps;
      for (int k = 0; k < options.blur_samples; ++k) {
        const double t =
            f.truth.time + exposure * ((k + 0.5) / options.blur_samples - 0.5);
        f.blur_bodies.push_back(actor.body_at(t));
      }
    }
    f.shadow = detail::make_shadow(f.truth.body, options.shadow);
    return f;
  }

  const int8_t* noise_of(int64_t frame, int index) const {
    if (!(options.noise_sigma > 0)) return nullptr;
    const uint64_t key =
        mix(mix(options.seed, static_cast<uint64_t>(frame)), static_cast<uint64_t>(index));
    return noise.data() + key % kNoiseWindow;
  }

  // The same pixels as render_reference, with the background copy and the noise fused into one
  // pass outside the rectangle the actor and its shadow may touch (detail::touched_rect), only
  // that rectangle noised after the actor is drawn, and no fresh mask when none is wanted.
  void render(int index, const detail::PreparedFrame& f, Image<Rgb8>* image, Mask* mask,
              Image<uint8_t>* matte) const {
    if (options.reference_renderer) return render_reference(index, f, image, mask, matte);
    const CameraCache& cam = caches.at(index);
    const int W = cam.camera.width, H = cam.camera.height;
    Image<Rgb8> local_image;
    if (image == nullptr) image = &local_image;
    if (mask == nullptr) mask = &scratch_mask;
    // A new image starts as a copy of the background (no zero fill first); a reused one is
    // written row by row below.
    const bool fresh = image->width() != W || image->height() != H;
    if (fresh) *image = cam.background;
    if (mask->width() != W || mask->height() != H) *mask = Mask(W, H);
    std::memset(mask->data(), 0, static_cast<std::size_t>(W) * H);
    if (matte) *matte = Image<uint8_t>(W, H, 0);
    const detail::Rect D = detail::touched_rect(options, cam, f);
    const int8_t* noise_base = noise_of(f.truth.frame, index);
    auto* out = reinterpret_cast<uint8_t*>(image->data());
    const auto* bg =
        reinterpret_cast<const uint8_t*>(fresh ? image->data() : cam.background.data());
    const std::size_t row = sizeof(Rgb8) * W;
    const std::size_t d0 = sizeof(Rgb8) * std::max(0, D.x0), d1 = sizeof(Rgb8) * std::min(W, D.x1);
    for (int y = 0; y < H; ++y) {
      const std::size_t o = row * y;
      const int8_t* nz = noise_base ? noise_base + o : nullptr;
      if (D.empty() || y < D.y0 || y >= D.y1) {
        fill_span(out + o, bg + o, nz, 0, row, false);
      } else {
        fill_span(out + o, bg + o, nz, 0, d0, false);
        fill_span(out + o, bg + o, nz, d0, d1, true);  // noised after the actor is drawn
        fill_span(out + o, bg + o, nz, d1, row, false);
      }
    }
    detail::render_actor(options, cam, f, image, mask, matte);
    if (noise_base && !D.empty()) {
      for (int y = std::max(0, D.y0); y < std::min(H, D.y1); ++y) {
        const std::size_t o = row * y;
        add_noise(out + o + d0, noise_base + o + d0, d1 - d0);
      }
    }
  }

  // The renderer before issue 20 (StudioOptions::reference_renderer).
  void render_reference(int index, const detail::PreparedFrame& f, Image<Rgb8>* image, Mask* mask,
                        Image<uint8_t>* matte) const {
    const CameraCache& cam = caches.at(index);
    const int W = cam.camera.width, H = cam.camera.height;
    Image<Rgb8> local_image;
    Mask local_mask;
    if (image == nullptr) image = &local_image;
    if (mask == nullptr) mask = &local_mask;
    if (image->width() != W || image->height() != H) *image = Image<Rgb8>(W, H);
    if (mask->width() != W || mask->height() != H) *mask = Mask(W, H);
    std::memcpy(image->data(), cam.background.data(), sizeof(Rgb8) * W * H);
    std::memset(mask->data(), 0, static_cast<std::size_t>(W) * H);
    if (matte) *matte = Image<uint8_t>(W, H, 0);
    detail::render_actor(options, cam, f, image, mask, matte);
    if (const int8_t* noise_base = noise_of(f.truth.frame, index)) {
      add_noise(reinterpret_cast<uint8_t*>(image->data()), noise_base, sizeof(Rgb8) * W * H);
    }
  }
};

SimulatedStudio::SimulatedStudio(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
std::vector<std::array<double, 3>> random_camera_response(int cameras, uint64_t seed,
                                                          double exposure_spread,
                                                          double balance_spread) {
  std::mt19937_64 rng(mix(seed, 0x5E5501));
  std::uniform_real_distribution<double> unit(-1, 1);
  const double e = std::clamp(exposure_spread, 0.0, 0.5), b = std::clamp(balance_spread, 0.0, 0.5);
  std::vector<std::array<double, 3>> out(std::size_t(std::max(0, cameras)));
  for (auto& g : out) {
    const double exposure = 1 + e * unit(rng), red = 1 + b * unit(rng), blue = 1 + b * unit(rng);
    g = {exposure * red, exposure, exposure * blue};
  }
  return out;
}

std::vector<std::array<double, 3>> balancing_gains(
    const std::vector<std::array<double, 3>>& camera_response) {
  std::vector<std::array<double, 3>> out(camera_response.size());
  for (std::size_t k = 0; k < 3; ++k) {
    double mean_log = 0;
    for (const auto& g : camera_response) mean_log += std::log(g[k]);
    mean_log /= double(std::max<std::size_t>(1, camera_response.size()));
    for (std::size_t c = 0; c < out.size(); ++c)
      out[c][k] = std::exp((mean_log - std::log(camera_response[c][k])) / 2.2);
  }
  return out;
}

SimulatedStudio::SimulatedStudio(SimulatedStudio&&) noexcept = default;
SimulatedStudio& SimulatedStudio::operator=(SimulatedStudio&&) noexcept = default;
SimulatedStudio::~SimulatedStudio() = default;

Expected<SimulatedStudio> SimulatedStudio::create(std::vector<Camera> cameras,
                                                  const StudioOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  if (cameras.empty()) return fail("simulated studio needs at least one camera");
  if (!options.camera_response.empty() && options.camera_response.size() != cameras.size()) {
    return fail(detail::cat("camera_response has ", options.camera_response.size(), " entries for ",
                            cameras.size(), " cameras"));
  }
  std::size_t max_bytes = 0;
  for (const Camera& c : cameras) {
    const auto& k = c.intrinsics;
    if (c.width < 1 || c.height < 1 || c.width > 16384 || c.height > 16384) {
      return fail(detail::cat("camera '", c.id, "': size ", c.width, "x", c.height, " outside [1, 16384]"));
    }
    if (!(k.fx > 0 && k.fy > 0 && std::isfinite(k.cx) && std::isfinite(k.cy) &&
          std::isfinite(k.skew))) {
      return fail(detail::cat("camera '", c.id, "': focal lengths must be positive and finite"));
    }
    if (!c.cam_from_world.translation.allFinite() || !c.cam_from_world.rotation.coeffs().allFinite()) {
      return fail(detail::cat("camera '", c.id, "': cam_from_world is not finite"));
    }
    max_bytes = std::max(max_bytes, sizeof(Rgb8) * c.width * c.height);
  }
  auto impl = std::make_unique<Impl>(options);
  impl->cameras = std::move(cameras);
  if (options.noise_sigma > 0) {
    impl->noise.resize(max_bytes + kNoiseWindow);
    std::mt19937_64 rng(mix(options.seed, 0xC0FFEE));
    std::normal_distribution<double> gauss(0.0, options.noise_sigma);
    for (int8_t& v : impl->noise) v = static_cast<int8_t>(std::clamp(std::lround(gauss(rng)), -127L, 127L));
  }
  impl->projection =
      options.projection.pixels().empty() ? builtin_projection() : options.projection;
  impl->caches.resize(impl->cameras.size());
  // Backgrounds are independent per camera: build them on the worker threads too.
  std::atomic<std::size_t> next{0};
  auto build = [&] {
    for (std::size_t i; (i = next++) < impl->cameras.size();) impl->build_cache(i);
  };
  {
    std::vector<std::jthread> workers;
    for (int t = 1; t < options.threads; ++t) workers.emplace_back(build);
    build();
  }
  return SimulatedStudio(std::move(impl));
}

Expected<void> SimulatedStudio::set_camera(int index, const Camera& camera) {
  if (index < 0 || index >= camera_count()) return fail(detail::cat("no camera ", index));
  const Camera& old = impl_->cameras[std::size_t(index)];
  if (camera.width != old.width || camera.height != old.height)
    return fail(detail::cat("camera '", old.id, "': a moved camera keeps its size"));
  const auto& k = camera.intrinsics;
  if (!(k.fx > 0 && k.fy > 0 && std::isfinite(k.cx) && std::isfinite(k.cy) &&
        std::isfinite(k.skew)) ||
      !camera.cam_from_world.translation.allFinite() ||
      !camera.cam_from_world.rotation.coeffs().allFinite())
    return fail(detail::cat("camera '", old.id, "': bad intrinsics or pose"));
  impl_->cameras[std::size_t(index)] = camera;
  impl_->build_cache(std::size_t(index));
  return {};
}

const StudioOptions& SimulatedStudio::options() const { return impl_->options; }
const Actor& SimulatedStudio::actor() const { return impl_->actor; }
const std::vector<Camera>& SimulatedStudio::cameras() const { return impl_->cameras; }
const Image<Rgb8>& SimulatedStudio::background(int camera) const {
  return impl_->caches.at(camera).background;
}

FrameTruth SimulatedStudio::truth(int64_t frame) const {
  FrameTruth t;
  t.frame = frame;
  t.time = time_of(frame);
  t.pose = impl_->actor.pose_at(t.time);
  t.body = impl_->actor.body(t.pose, t.time);
  return t;
}

void SimulatedStudio::render(int camera, int64_t frame, Image<Rgb8>* image, Mask* true_mask,
                             Image<uint8_t>* true_matte) const {
  detail::clean_avx_upper_state();  // clean_upper.h: legacy SSE at full speed
  impl_->render(camera, impl_->prepare(frame), image, true_mask, true_matte);
}

FrameTruth SimulatedStudio::render_all(int64_t frame, std::vector<Image<Rgb8>>* images,
                                       std::vector<Mask>* true_masks,
                                       std::vector<Image<uint8_t>>* true_mattes) const {
  detail::clean_avx_upper_state();  // clean_upper.h (worker threads start clean)
  const detail::PreparedFrame f = impl_->prepare(frame);
  const int n = camera_count();
  if (images) images->resize(n);
  if (true_masks) true_masks->resize(n);
  if (true_mattes) true_mattes->resize(n);
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i; (i = next++) < n;) {
      impl_->render(i, f, images ? &(*images)[i] : nullptr, true_masks ? &(*true_masks)[i] : nullptr,
                    true_mattes ? &(*true_mattes)[i] : nullptr);
    }
  };
  {
    std::vector<std::jthread> workers;
    for (int t = 1; t < std::min(impl_->options.threads, n); ++t) workers.emplace_back(work);
    work();
  }
  return f.truth;
}

}  // namespace studio::sim
