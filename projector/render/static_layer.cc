#include "static_layer.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace studio::projector_render {

Expected<StaticLayer> StaticLayer::create(const projector::ProjectorView& view,
                                          const projector::OffAxisOptions& off_axis,
                                          const projector::SceneCacheOptions& options, int width,
                                          int height) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  auto bound = projector::StaticShiftBound::create(view, off_axis);
  if (!bound) return std::unexpected(bound.error());
  auto target = scene_render::RenderTarget::create(width, height);
  if (!target) return std::unexpected(target.error());
  return StaticLayer(std::move(*bound), options, std::move(*target), view);
}

StaticLayer::StaticLayer(projector::StaticShiftBound bound, projector::SceneCacheOptions options,
                         scene_render::RenderTarget target, const projector::ProjectorView& view)
    : bound_(std::move(bound)),
      options_(options),
      target_(std::move(target)),
      screen_(view.screen()),
      screen_from_pixel_(view.screen_from_pixel()),
      projector_height_(view.camera().height) {}

double StaticLayer::shift_px(std::uint64_t version, const Eigen::Vector3d& eye) const {
  if (!valid_ || version != version_) return std::numeric_limits<double>::infinity();
  return bound_.shift_px(heights_, eye_, eye);
}

namespace {
void blit(unsigned from, unsigned to, int w, int h) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, from);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, to);
  glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}
}  // namespace

void StaticLayer::restore(const scene_render::RenderTarget& into) {
  ++served_;
  const bool scissor = glIsEnabled(GL_SCISSOR_TEST);  // the blit honours the scissor box
  if (scissor) glDisable(GL_SCISSOR_TEST);
  blit(target_.framebuffer(), into.framebuffer(), into.width(), into.height());
  if (scissor) glEnable(GL_SCISSOR_TEST);
  into.bind();
}

void StaticLayer::store(const scene_render::RenderTarget& from, std::uint64_t version,
                        const Eigen::Vector3d& eye, const DepthModel& model) {
  const bool scissor = glIsEnabled(GL_SCISSOR_TEST);
  if (scissor) glDisable(GL_SCISSOR_TEST);
  blit(from.framebuffer(), target_.framebuffer(), from.width(), from.height());
  if (scissor) glEnable(GL_SCISSOR_TEST);
  from.bind();
  const auto [bx, by, bw, bh] = model.box;
  depth_.resize(std::size_t(std::max(bw, 0)) * std::size_t(std::max(bh, 0)));
  if (!depth_.empty()) {
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(bx, by, bw, bh, GL_DEPTH_COMPONENT, GL_FLOAT, depth_.data());
  }
  // Eye view distance of a depth value: window depth -> NDC z' (-> the eye's NDC z = z' k in the
  // single pass) -> glFrustum's z = 2 f n / ((f + n) - ndc_z (f - n)); height = h_e - z.
  const double n = model.near, f = model.far, h_e = screen_.signed_distance(eye);
  // k = w' / w at the screen point a pixel lights: both clip w are linear in the screen point's
  // homogeneous coordinates M (s, t, 1) ~ M screen_from_pixel (u, v, 1), so k = (p . q) / (e . q).
  Eigen::Matrix<double, 4, 3> M;
  M << screen_.right, screen_.up, screen_.origin, 0, 0, 1;
  const Eigen::RowVector3d e_row = model.eye_clip_from_world.row(3) * M * screen_from_pixel_;
  const Eigen::RowVector3d p_row =
      model.projector_clip_from_world
          ? Eigen::RowVector3d(model.projector_clip_from_world->row(3) * M * screen_from_pixel_)
          : Eigen::RowVector3d::Zero();
  // Per 16 x 16 tile: the range of window depths drawn (branch-free min / max, vectorised), and
  // of k over the tile (a linear-fractional function of the pixel: its extremes over a rectangle
  // are at its corners); the eye's NDC z range is the products' range (k > 0), z grows with it.
  // Conservative within a tile (k varies by ~0.1 % across one), exact for the eye texture (k = 1).
  auto k_at = [&](double x, double y) {
    if (!model.projector_clip_from_world) return 1.0;
    const Eigen::Vector3d q(x, projector_height_ - 1 - y, 1.0);
    return p_row.dot(q) / e_row.dot(q);
  };
  auto z_of = [&](double ndc) { return 2 * f * n / ((f + n) - ndc * (f - n)); };
  double z_min = std::numeric_limits<double>::infinity(), z_max = 0;
  constexpr int kTile = 16;
  for (int ty = 0; ty < bh; ty += kTile)
    for (int tx = 0; tx < bw; tx += kTile) {
      const int ey = std::min(bh, ty + kTile), ex = std::min(bw, tx + kTile);
      float dmin = 1.0f, dmax = 0.0f;
      for (int y = ty; y < ey; ++y) {
        const float* row = depth_.data() + std::size_t(y) * bw;
        for (int x = tx; x < ex; ++x) {
          const float d = row[x];
          const bool drawn = d > 0.0f && d < 1.0f;  // not the black around, not the clear
          dmin = std::min(dmin, drawn ? d : 1.0f);
          dmax = std::max(dmax, drawn ? d : 0.0f);
        }
      }
      if (dmin > dmax) continue;  // nothing drawn in the tile
      double kmin = 1, kmax = 1;
      if (model.projector_clip_from_world) {
        kmin = std::numeric_limits<double>::infinity();
        kmax = 0;
        for (const int cx : {bx + tx, bx + ex - 1})
          for (const int cy : {by + ty, by + ey - 1}) {
            const double k = k_at(cx, cy);
            kmin = std::min(kmin, k);
            kmax = std::max(kmax, k);
          }
      }
      const double lo = 2.0 * dmin - 1.0, hi = 2.0 * dmax - 1.0;
      const double ndc_lo = std::min({lo * kmin, lo * kmax}),
                   ndc_hi = std::max({hi * kmin, hi * kmax});
      z_min = std::min(z_min, z_of(ndc_lo));
      z_max = std::max(z_max, z_of(std::min(ndc_hi, 1.0)));
    }
  heights_ = z_max > 0 ? projector::HeightRange{h_e - z_max, h_e - z_min}
                       : projector::HeightRange{1, 0};  // nothing static shown: hi < lo
  version_ = version;
  eye_ = eye;
  served_ = 0;
  valid_ = true;
}

}  // namespace studio::projector_render
