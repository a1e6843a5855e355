#include "offline/texture.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>

#include "offline/view_sampling.h"

namespace studio::offline {
namespace {

// One worker runs on the caller's thread (no thread for a single-threaded call).
template <class F>
void run_on(std::vector<std::jthread>& pool, int workers, F&& f) {
  if (workers == 1) {
    f();
  } else {
    pool.emplace_back(std::forward<F>(f));
  }
}

// c^p; an integral p (the default 4) by multiplication, libm's pow() was a tenth of the blend.
double cos_power(double c, double p) {
  const int n = int(p);
  if (double(n) != p) return std::pow(c, p);
  double w = 1;
  for (int i = 0; i < n; ++i) w *= c;
  return w;
}

}  // namespace

Expected<void> TextureOptions::validate() const {
  if (!(min_cos >= 0 && min_cos < 1)) return fail("texture: min_cos must be in [0, 1)");
  if (edge_margin_px < 0 || edge_margin_px > 16)
    return fail("texture: edge_margin_px must be 0..16");
  if (!(depth_tolerance > 0 && depth_tolerance < 1))
    return fail("texture: depth_tolerance must be in (0, 1) m");
  if (!(sharpness >= 0 && sharpness <= 32)) return fail("texture: sharpness must be 0..32");
  if (threads < 1 || threads > 64) return fail("texture: threads must be 1..64");
  return {};
}

struct TextureBlend::Impl {
  TextureOptions options;
  std::vector<SampledView> cams;
  std::vector<DepthBuffer> buffers;
};

TextureBlend::TextureBlend(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TextureBlend::TextureBlend(TextureBlend&&) noexcept = default;
TextureBlend& TextureBlend::operator=(TextureBlend&&) noexcept = default;
TextureBlend::~TextureBlend() = default;

Expected<TextureBlend> TextureBlend::create(const hull::Mesh& occluder,
                                            std::span<const ColourView> views,
                                            const TextureOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  auto sampled = prepare_views(views, options.edge_margin_px);
  if (!sampled) return std::unexpected(sampled.error());
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->cams = std::move(*sampled);
  const std::vector<SampledView>& cams = impl->cams;
  std::vector<DepthBuffer>& buffers = impl->buffers;
  buffers.resize(cams.size());
  std::vector<std::jthread> pool;
  const int workers = std::max(1, std::min<int>(options.threads, int(cams.size())));
  for (int w = 0; w < workers; ++w) {
    run_on(pool, workers, [&, w] {
      for (std::size_t c = std::size_t(w); c < cams.size(); c += std::size_t(workers)) {
        buffers[c].reset(cams[c]);
        buffers[c].mesh(cams[c], occluder);
      }
    });
  }
  pool.clear();  // joins
  return TextureBlend(std::move(impl));
}

std::optional<Eigen::Vector3f> TextureBlend::colour(const Eigen::Vector3d& x,
                                                    const Eigen::Vector3d& n) const {
  const Impl& b = *impl_;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0;
  // Cameras in order (deterministic sums).
  for (std::size_t c = 0; c < b.cams.size(); ++c) {
    auto o = observe(b.cams[c], b.buffers[c], x, n, b.options.min_cos, b.options.depth_tolerance);
    if (!o) continue;
    const double w = cos_power(double(o->cos), b.options.sharpness);
    sum += w * o->colour.cast<double>();
    weight += w;
  }
  if (!(weight > 0)) return std::nullopt;
  return (sum / weight).cast<float>();
}

Expected<std::vector<Eigen::Vector3f>> vertex_colours(const hull::Mesh& mesh,
                                                      std::span<const ColourView> views,
                                                      const TextureOptions& options) {
  auto blend = TextureBlend::create(mesh, views, options);
  if (!blend) return std::unexpected(blend.error());
  const std::size_t nv = mesh.vertices.size();
  std::vector<Eigen::Vector3f> colour(nv, Eigen::Vector3f::Zero());
  std::vector<uint8_t> known(nv, 0);
  // Vertices in parallel (each its own entry: independent of the thread count).
  {
    std::vector<std::jthread> pool;
    const int workers = std::max(1, options.threads);
    const std::size_t chunk = (nv + std::size_t(workers) - 1) / std::size_t(workers);
    for (int w = 0; w < workers; ++w) {
      run_on(pool, workers, [&, w] {
        const std::size_t a = std::min(nv, std::size_t(w) * chunk), b = std::min(nv, a + chunk);
        for (std::size_t n = a; n < b; ++n) {
          const Eigen::Vector3d normal = mesh.normals[n].cast<double>();
          if (normal.squaredNorm() < 0.5) continue;
          if (auto c = blend->colour(mesh.vertices[n].cast<double>(), normal)) {
            colour[n] = *c;
            known[n] = 1;
          }
        }
      });
    }
  }
  // Fill the unseen vertices from their neighbours, ring by ring (Jacobi steps: deterministic).
  std::vector<std::vector<uint32_t>> adjacent(nv);
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      adjacent[t[k]].push_back(t[(k + 1) % 3]);
      adjacent[t[k]].push_back(t[(k + 2) % 3]);
    }
  }
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<std::pair<uint32_t, Eigen::Vector3f>> fill;
    for (std::size_t n = 0; n < nv; ++n) {
      if (known[n]) continue;
      Eigen::Vector3f s = Eigen::Vector3f::Zero();
      int count = 0;
      for (uint32_t m : adjacent[n]) {
        if (known[m]) s += colour[m], ++count;
      }
      if (count) fill.emplace_back(uint32_t(n), s / float(count));
    }
    for (const auto& [n, c] : fill) colour[n] = c, known[n] = 1, changed = true;
  }
  for (std::size_t n = 0; n < nv; ++n) {
    if (!known[n]) colour[n] = Eigen::Vector3f(128, 128, 128);
  }
  return colour;
}

}  // namespace studio::offline
