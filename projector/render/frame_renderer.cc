#include "projector_render/frame_renderer.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "projector/camera_clip.h"
#include "scene_render/render_target.h"
#include "static_layer.h"

namespace studio::projector_render {
namespace {
const std::string kFrameId = "\x01screen-frame";
}  // namespace

Expected<void> FrameRendererOptions::validate() const {
  if (auto ok = off_axis.validate(); !ok) return ok;
  if (auto ok = renderer.validate(); !ok) return ok;
  if (auto ok = scene_cache.validate(); !ok) return ok;
  if (eye_texture_size.x() < 0 || eye_texture_size.y() < 0 || eye_texture_size.x() > 8192 ||
      eye_texture_size.y() > 8192 || (eye_texture_size.x() == 0) != (eye_texture_size.y() == 0))
    return fail("eye_texture: both sides 1..8192, or both 0 (suggested size)");
  if (!(eye_texture_scale >= 0.1 && eye_texture_scale <= 1))
    return fail("eye_texture_scale: 0.1..1");
  if (thumb_width < 0 || thumb_height < 0 || thumb_width > 1024 || thumb_height > 1024 ||
      (thumb_width == 0) != (thumb_height == 0))
    return fail("thumbnail: both sides 1..1024, or both 0 (none)");
  return {};
}

namespace {
// The first pixel at or after x whose alpha is zero (zero = true) or not (zero = false), or
// width: four pixels at a time while none of them changes (SSE2), then one at a time.
int next_alpha(const std::uint8_t* row, int x, int width, bool zero) {
#if defined(__SSE2__)
  const __m128i z = _mm_setzero_si128();
  const int none = zero ? 0 : 0x8888;  // alpha bytes' compare bits when no pixel changes
  for (; x + 4 <= width; x += 4) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 4 * x));
    if ((_mm_movemask_epi8(_mm_cmpeq_epi8(v, z)) & 0x8888) != none) break;
  }
#endif
  while (x < width && (row[4 * x + 3] == 0) != zero) ++x;
  return x;
}

}  // namespace

// Rows are summed per column first (16-bit lanes: vectorised), then each block's columns.
bool box_thumbnail(std::span<const std::uint8_t> rgba, int w, int h, int tw, int th,
                   std::vector<std::uint8_t>& out) {
  if (tw <= 0 || th <= 0 || w <= 0 || h <= 0 || w % tw != 0 || h % th != 0 ||
      rgba.size() != std::size_t(w) * h * 4)
    return false;
  const int fx = w / tw, fy = h / th;
  if (fy > 257) return false;
  const std::uint32_t n = std::uint32_t(fx) * std::uint32_t(fy);
  out.assign(std::size_t(tw) * th * 3, 0);
  std::vector<std::uint16_t> column(std::size_t(w) * 4);
  for (int ty = 0; ty < th; ++ty) {
    std::fill(column.begin(), column.end(), std::uint16_t(0));
    std::uint16_t* col = column.data();
    const std::size_t m = column.size();
    for (int r = 0; r < fy; ++r) {
      const std::uint8_t* row = rgba.data() + std::size_t(h - 1 - (ty * fy + r)) * w * 4;
      std::size_t k = 0;
#if defined(__SSE2__)
      const __m128i zero = _mm_setzero_si128();
      for (; k + 16 <= m; k += 16) {  // 16 bytes widened to two 8 x 16-bit sums
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + k));
        __m128i* c = reinterpret_cast<__m128i*>(col + k);
        _mm_storeu_si128(c, _mm_add_epi16(_mm_loadu_si128(c), _mm_unpacklo_epi8(v, zero)));
        _mm_storeu_si128(c + 1,
                         _mm_add_epi16(_mm_loadu_si128(c + 1), _mm_unpackhi_epi8(v, zero)));
      }
#endif
      for (; k < m; ++k) col[k] = std::uint16_t(col[k] + row[k]);
    }
    std::uint8_t* dst = out.data() + std::size_t(ty) * tw * 3;
    for (int tx = 0; tx < tw; ++tx) {
      std::uint32_t sum[3] = {0, 0, 0};
      const std::uint16_t* c = column.data() + std::size_t(tx) * fx * 4;
      for (int k = 0; k < fx; ++k)
        for (int ch = 0; ch < 3; ++ch) sum[ch] += c[4 * k + ch];
      for (int ch = 0; ch < 3; ++ch) dst[3 * tx + ch] = std::uint8_t((sum[ch] + n / 2) / n);
    }
  }
  return true;
}

namespace {

// The run mask of alpha-0 pixels of `rgba` (`width` x `height`); bottom_up: GL's row order
// (the image's top row last), else the image's.
RunMask blackout_rows(std::span<const std::uint8_t> rgba, int width, int height, bool bottom_up) {
  RunMask mask(width, height);
  for (int y = 0; y < height; ++y) {
    const int src = bottom_up ? height - 1 - y : y;
    const std::uint8_t* row = rgba.data() + std::size_t(src) * width * 4;
    int x = 0;
    while (x < width) {
      x = next_alpha(row, x, width, true);
      if (x >= width) break;
      const int begin = x;
      x = next_alpha(row, x, width, false);
      mask.push_run(y, begin, x);
    }
  }
  mask.finish();
  return mask;
}
}  // namespace

RunMask blackout_of(std::span<const std::uint8_t> rgba, int width, int height) {
  return blackout_rows(rgba, width, height, false);
}

struct FrameRenderer::Impl {
  projector::ProjectorView view;
  FrameRendererOptions options;
  scene_render::Renderer renderer;
  scene_render::RenderTarget target;
  std::optional<scene_render::RenderTarget> eye_target;  // two pass
  scene_render::View mask_view;
  // The screen rectangle's bounding box in the projector target (GL window coordinates: x, y
  // from the bottom left, width, height); the single pass draws the scene only there.
  std::array<int, 4> screen_box;
  // The screen rectangle's corners in the projector target, 2 px out from their centre,
  // normalised (x right, y up); none when a corner is not in front of the projector.
  std::optional<std::array<Eigen::Vector2f, 4>> screen_quad;
  std::vector<std::string> mask_ids;
  scene::ActorMesh scratch;
  std::vector<std::uint8_t> rgba;
  std::optional<StaticLayer> layer;         // scene_cache enabled
  std::optional<Eigen::Vector3d> last_eye;  // of the previous layered frame
  bool clear_texture = false;               // glClearTexSubImage (GL 4.4 or ARB_clear_texture)

  Expected<FrameInfo> render(const scene::Scene& still, std::uint64_t version,
                             const scene::Scene* moving, const Eigen::Vector3d& eye,
                             std::span<const projector::ActorMesh> masks, bool cache);
  int draw_masks(std::span<const projector::ActorMesh> masks);
  // The masks as occluders at depth 0 before the scene (FrameRendererOptions::masks_first).
  int draw_mask_occluders(std::span<const projector::ActorMesh> masks);
  // Mask i's mesh into the renderer (its actor id "\x01mask<i>"); false if the renderer refused it.
  bool upload_mask(std::size_t i, const projector::ActorMesh& m);
  // The target's RGBA as GL gives it (bottom row first), into `out` (resized).
  void read_pixels(std::vector<std::uint8_t>& out);
};

FrameRenderer::FrameRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FrameRenderer::FrameRenderer(FrameRenderer&&) noexcept = default;
FrameRenderer& FrameRenderer::operator=(FrameRenderer&&) noexcept = default;
FrameRenderer::~FrameRenderer() = default;

namespace {
// Whether the current context has glClearTexSubImage (GL 4.4 core, or ARB_clear_texture; Mesa's
// llvmpipe gives 4.5 for the 3.3 core context asked for).
bool has_clear_texture() {
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (major > 4 || (major == 4 && minor >= 4)) return true;
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i) {
    const auto* e = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)));
    if (e && std::string_view(e) == "GL_ARB_clear_texture") return true;
  }
  return false;
}
}  // namespace

scene::ActorMesh screen_surround(const projector::Screen& screen, const std::string& actor_id) {
  const auto c = screen.corners();
  const Eigen::Vector3d centre = 0.25 * (c[0] + c[1] + c[2] + c[3]);
  scene::ActorMesh frame;
  frame.actor_id = actor_id;
  for (const auto& k : c) frame.vertices.push_back(k.cast<float>());
  for (const auto& k : c)
    frame.vertices.push_back((centre + (k - centre).normalized() * 50.0).cast<float>());
  for (std::uint32_t i = 0; i < 4; ++i) {
    const std::uint32_t j = (i + 1) % 4;
    frame.triangles.push_back({i, j, 4 + j});
    frame.triangles.push_back({i, 4 + j, 4 + i});
  }
  frame.normals.assign(frame.vertices.size(), screen.normal.cast<float>());
  return frame;
}

Expected<FrameRenderer> FrameRenderer::create(const projector::ProjectorView& view,
                                              const FrameRendererOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  const Camera& cam = view.camera();
  if (options.form == Form::two_pass && cam.distortion.model != Distortion::Model::none)
    return fail("projector " + cam.id +
                ": two-pass form with lens distortion needs the exact warp map (not supported by "
                "this renderer); use a distortion-free calibration");
  if (options.form == Form::single_pass && cam.distortion.model != Distortion::Model::none)
    return fail("projector " + cam.id + ": the single-pass form cannot fold lens distortion");
  auto renderer = scene_render::Renderer::create(options.renderer);
  if (!renderer) return std::unexpected(renderer.error());
  // Outside the screen: the screen's plane around the rectangle, out to 50 m, drawn black from
  // the projector after a single pass (whose projection extends past the cloth; the two-pass warp
  // is black there by construction).
  if (auto ok = renderer->set_actor_mesh(screen_surround(view.screen(), kFrameId)); !ok)
    return std::unexpected(ok.error());
  auto target = scene_render::RenderTarget::create(cam.width, cam.height);
  if (!target) return std::unexpected(target.error());
  std::optional<scene_render::RenderTarget> eye_target;
  if (options.form == Form::two_pass) {
    Eigen::Vector2i size = options.eye_texture_size;
    if (size.x() == 0)
      size = (view.suggested_texture_size().cast<double>() * options.eye_texture_scale)
                 .array()
                 .ceil()
                 .cast<int>()
                 .min(8192)
                 .max(16);
    auto t = scene_render::RenderTarget::create(size.x(), size.y());
    if (!t) return std::unexpected(t.error());
    eye_target.emplace(std::move(*t));
  }
  scene_render::View mask_view;
  mask_view.clip_from_cam = projector::clip_from_world(cam, 0.05, 100.0);
  std::array<int, 4> box{0, 0, cam.width, cam.height};
  std::optional<std::array<Eigen::Vector2f, 4>> quad;
  {  // the corners' pixels, 2 px of slack around them (pixel centre conventions, rounding)
    Eigen::AlignedBox2d b;
    bool all = true;
    std::array<Eigen::Vector2d, 4> px;
    for (int i = 0; i < 4; ++i) {
      all = all && cam.project(view.screen().corners()[static_cast<std::size_t>(i)], &px[i]);
      b.extend(px[i]);
    }
    if (all) {
      const Eigen::Vector2d centre = 0.25 * (px[0] + px[1] + px[2] + px[3]);
      quad.emplace();
      for (std::size_t i = 0; i < 4; ++i) {
        const Eigen::Vector2d out = px[i] + 2.0 * (px[i] - centre).normalized();
        (*quad)[i] = Eigen::Vector2f(float(out.x() / cam.width), float(1.0 - out.y() / cam.height));
      }
    }
    if (all) {
      const int x0 = std::clamp(int(std::floor(b.min().x())) - 2, 0, cam.width);
      const int x1 = std::clamp(int(std::ceil(b.max().x())) + 2, 0, cam.width);
      const int y0 = std::clamp(int(std::floor(b.min().y())) - 2, 0, cam.height);
      const int y1 = std::clamp(int(std::ceil(b.max().y())) + 2, 0, cam.height);
      box = {x0, cam.height - y1, x1 - x0, y1 - y0};
    }
  }
  std::optional<StaticLayer> layer;
  if (options.scene_cache.enabled) {
    const scene_render::RenderTarget& t = eye_target ? *eye_target : *target;
    auto l =
        StaticLayer::create(view, options.off_axis, options.scene_cache, t.width(), t.height());
    if (!l) return std::unexpected(l.error());
    layer.emplace(std::move(*l));
  }
  return FrameRenderer(std::unique_ptr<Impl>(new Impl{view,
                                                      options,
                                                      std::move(*renderer),
                                                      std::move(*target),
                                                      std::move(eye_target),
                                                      mask_view,
                                                      box,
                                                      quad,
                                                      {},
                                                      {},
                                                      {},
                                                      std::move(layer),
                                                      std::nullopt,
                                                      has_clear_texture()}));
}

scene_render::Renderer& FrameRenderer::renderer() { return impl_->renderer; }
const projector::ProjectorView& FrameRenderer::view() const { return impl_->view; }
unsigned FrameRenderer::colour_texture() const { return impl_->target.colour_texture(); }
unsigned FrameRenderer::framebuffer() const { return impl_->target.framebuffer(); }
int FrameRenderer::width() const { return impl_->target.width(); }
int FrameRenderer::height() const { return impl_->target.height(); }

Expected<int> FrameRenderer::render(const scene::Scene& scene, const Eigen::Vector3d& eye,
                                    std::span<const projector::ActorMesh> masks) {
  auto info = impl_->render(scene, 0, nullptr, eye, masks, false);
  if (!info) return std::unexpected(info.error());
  return info->masks;
}

Expected<FrameInfo> FrameRenderer::render(const LayeredScene& scene, const Eigen::Vector3d& eye,
                                          std::span<const projector::ActorMesh> masks) {
  return impl_->render(scene.still, scene.still_version, scene.moving, eye, masks, true);
}

Expected<FrameInfo> FrameRenderer::prepare(const LayeredScene& scene, const Eigen::Vector3d& eye) {
  auto info = impl_->render(scene.still, scene.still_version, scene.moving, eye, {}, true);
  glFlush();  // llvmpipe starts rasterising now, not at the frame's glFinish
  return info;
}

Expected<FrameInfo> FrameRenderer::prepare(const scene::Scene& scene, const Eigen::Vector3d& eye) {
  auto info = impl_->render(scene, 0, nullptr, eye, {}, false);
  glFlush();
  return info;
}

int FrameRenderer::draw_masks(std::span<const projector::ActorMesh> masks) {
  impl_->target.bind();
  return impl_->draw_masks(masks);
}

Expected<FrameInfo> FrameRenderer::Impl::render(const scene::Scene& still, std::uint64_t version,
                                                const scene::Scene* moving,
                                                const Eigen::Vector3d& eye,
                                                std::span<const projector::ActorMesh> masks,
                                                bool cache) {
  Impl& r = *this;
  StaticLayer* const l = cache && r.layer ? &*r.layer : nullptr;
  FrameInfo info;
  info.shift_px = l ? l->shift_px(version, eye) : std::numeric_limits<double>::infinity();
  info.from_cache = l && info.shift_px <= l->options().max_error_px;
  // Beyond the bound, a layer may still serve hold_frames frames after it was drawn.
  info.held = l && !info.from_cache && l->holds(version);
  info.from_cache = info.from_cache || info.held;
  // A re-rendered static layer is kept (a blit and a depth read, ~a fifth of a frame) only when
  // it may serve the next frame: a new static version, nothing cached yet, an eye that moved
  // less than the bound since the previous frame (a still eye), or frames to hold it for. An
  // eye moving every frame by more than the bound (a walking actor, tracker noise) without a
  // hold costs no more than a full render.
  const bool keep =
      l && !info.from_cache &&
      (l->options().hold_frames > 0 || !l->valid() || l->version() != version || !r.last_eye ||
       l->bound().shift_px(l->heights(), *r.last_eye, eye) <= l->options().max_error_px);
  r.last_eye = eye;
  const double near = r.options.off_axis.near_m, far = r.options.off_axis.far_m;
  if (r.options.form == Form::single_pass) {
    auto pass = r.view.single_pass(eye, r.options.off_axis);
    if (!pass) return std::unexpected(pass.error());
    scene_render::View v;
    v.clip_from_cam = pass->clip_from_world;
    v.eye_in_world = eye;
    v.clip_plane_world = pass->eye_clip_plane;
    // Only what the eye sees through the screen rectangle reaches the frame.
    v.cull_clip_from_world = pass->eye.clip_from_world;
    v.clear = false;
    if (info.from_cache) {
      l->restore(r.target);
    } else {
      r.target.bind();
      const Eigen::Vector4f& cc = r.options.renderer.clear_colour;
      glClearColor(cc[0], cc[1], cc[2], cc[3]);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      // The masks first when nothing of this frame is kept for later frames (masks_first), then
      // black around the screen, both at depth 0, each only where nothing lies yet (a mask's
      // pixels stay transparent black as when laid last): the scene is then shaded only on the
      // screen (inside the rectangle's bounding box, and there where the depth test lets it
      // through) and not under the actor.
      const bool first = r.options.masks_first && !keep && !masks.empty();
      if (first) {
        info.masks = draw_mask_occluders(masks);
        masks = {};
      }
      r.renderer.draw_actor_occluder(kFrameId, r.mask_view, Eigen::Vector4f(0, 0, 0, 1), first);
      glEnable(GL_SCISSOR_TEST);
      glScissor(r.screen_box[0], r.screen_box[1], r.screen_box[2], r.screen_box[3]);
      r.renderer.draw(still, v);
      glDisable(GL_SCISSOR_TEST);
      if (keep)
        l->store(r.target, version, eye,
                 {pass->eye.clip_from_world, pass->clip_from_world, near, far, r.screen_box});
    }
    if (moving) {
      glEnable(GL_SCISSOR_TEST);
      glScissor(r.screen_box[0], r.screen_box[1], r.screen_box[2], r.screen_box[3]);
      r.renderer.draw(*moving, v);
      glDisable(GL_SCISSOR_TEST);
    }
  } else {
    auto pass = r.view.two_pass(eye, r.options.off_axis);
    if (!pass) return std::unexpected(pass.error());
    scene_render::View v;
    v.clip_from_cam = pass->eye.clip_from_world;
    v.eye_in_world = eye;
    if (info.from_cache) {
      l->restore(*r.eye_target);
    } else {
      r.eye_target->bind();
      r.renderer.draw(still, v);
      if (keep)
        l->store(*r.eye_target, version, eye,
                 {pass->eye.clip_from_world,
                  std::nullopt,
                  near,
                  far,
                  {0, 0, r.eye_target->width(), r.eye_target->height()}});
    }
    if (moving) {
      v.clear = false;
      r.renderer.draw(*moving, v);
    }
    r.target.bind();
    // The quad's coordinates p in [0, 1]^2 are NDC (2p - 1): texture = texture_from_ndc * ndc.
    Eigen::Matrix3d ndc_from_unit;
    ndc_from_unit << 2, 0, -1, 0, 2, -1, 0, 0, 1;
    const Eigen::Matrix3f tex_from_unit = (pass->texture_from_ndc * ndc_from_unit).cast<float>();
    if (r.options.warp_screen_only && r.screen_quad) {
      // Outside the screen's image the warp would write black: clear to it instead and warp
      // only the quad (a quarter of the frame less to filter on llvmpipe).
      glClearColor(0, 0, 0, 1);
      glClear(GL_COLOR_BUFFER_BIT);
      r.renderer.draw_texture(r.eye_target->colour_texture(), tex_from_unit, r.screen_quad);
    } else {
      r.renderer.draw_texture(r.eye_target->colour_texture(), tex_from_unit);
    }
  }
  if (!masks.empty()) info.masks = draw_masks(masks);
  info.stored = keep;
  return info;
}

bool FrameRenderer::Impl::upload_mask(std::size_t i, const projector::ActorMesh& m) {
  if (mask_ids.size() <= i) mask_ids.push_back("\x01mask" + std::to_string(i));
  scratch.actor_id = mask_ids[i];
  scratch.vertices = m.vertices;
  scratch.triangles = m.triangles;
  scratch.normals.assign(m.vertices.size(), Eigen::Vector3f::UnitZ());  // unused: unlit
  return renderer.set_actor_mesh(scratch).has_value();
}

int FrameRenderer::Impl::draw_mask_occluders(std::span<const projector::ActorMesh> masks) {
  int drawn = 0;
  for (std::size_t i = 0; i < masks.size(); ++i) {
    if (!masks[i].validate() || !upload_mask(i, masks[i])) continue;
    // Transparent black, as draw_masks() lays it: the read-back's blackout is alpha 0.
    renderer.draw_actor_occluder(mask_ids[i], mask_view, Eigen::Vector4f::Zero(), true);
    ++drawn;
  }
  return drawn;
}

int FrameRenderer::Impl::draw_masks(std::span<const projector::ActorMesh> masks) {
  Impl& r = *this;
  int drawn = 0;
  for (std::size_t i = 0; i < masks.size(); ++i) {
    const projector::ActorMesh& m = masks[i];
    if (!m.validate()) continue;
    const auto& rects = m.image_rects;
    if (rects && r.clear_texture && rects->width == r.target.width() &&
        rects->height == r.target.height()) {
      // Made in this frame's image (grow_outline): its pixels cleared to transparent black,
      // the very pixels its quads would cover (GL's rows bottom first). llvmpipe fills them
      // with memset after the frame's pending drawing: 0.07 ms for 132k px against ~1.2 ms to
      // rasterise the quads (projector_bench SceneImageFrame_720p).
      static constexpr GLubyte kClear[4] = {0, 0, 0, 0};
      const GLuint texture = r.target.colour_texture();
      const int h = r.target.height();
      for (const auto& [x0, y0, x1, y1] : rects->rects)
        glClearTexSubImage(texture, 0, x0, h - y1, 0, x1 - x0, y1 - y0, 1, GL_RGBA,
                           GL_UNSIGNED_BYTE, kClear);
      ++drawn;
      continue;
    }
    if (!r.upload_mask(i, m)) continue;
    r.renderer.draw_actor_flat(r.mask_ids[i], r.mask_view, 0.0f, Eigen::Vector4f::Zero(),
                               rects.has_value());
    ++drawn;
  }
  return drawn;
}

double FrameRenderer::cache_allowed_move_m(const Eigen::Vector3d& eye) const {
  const StaticLayer* l = impl_->layer ? &*impl_->layer : nullptr;
  if (!l || !l->valid()) return 0;
  return l->bound().allowed_move_m(l->heights(), eye, l->options().max_error_px);
}

void FrameRenderer::finish() { glFinish(); }

void FrameRenderer::Impl::read_pixels(std::vector<std::uint8_t>& out) {
  const int w = target.width(), h = target.height();
  out.resize(std::size_t(w) * h * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
}

void FrameRenderer::read_image(std::vector<std::uint8_t>& rgba) { impl_->read_pixels(rgba); }

bool FrameRenderer::load_image(std::span<const std::uint8_t> rgba) {
  Impl& r = *impl_;
  const int w = r.target.width(), h = r.target.height();
  if (rgba.size() != std::size_t(w) * h * 4) return false;
  glBindTexture(GL_TEXTURE_2D, r.target.colour_texture());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  glBindTexture(GL_TEXTURE_2D, 0);
  r.target.bind();
  return true;
}

void FrameRenderer::read(Readback& out, bool keep_rgba) {
  Impl& r = *impl_;
  const int w = r.target.width(), h = r.target.height();
  // GL's rows as they come (bottom first): the blackout runs are taken bottom-up and only the
  // thumbnail (and a kept frame) is flipped, instead of swapping 2 x 3.7 MB of rows of a 720p
  // frame into image order first (RenderTarget::read_rgba).
  r.read_pixels(r.rgba);
  out.blackout = blackout_rows(r.rgba, w, h, true);
  out.thumb_width = r.options.thumb_width;
  out.thumb_height = r.options.thumb_height;
  const cv::Mat full(h, w, CV_8UC4, r.rgba.data());
  if (out.thumb_width == 0) {
    out.thumbnail.clear();
  } else if (!box_thumbnail(r.rgba, w, h, out.thumb_width, out.thumb_height, out.thumbnail)) {
    cv::Mat small, rgb;
    cv::resize(full, small, cv::Size(out.thumb_width, out.thumb_height), 0, 0, cv::INTER_AREA);
    cv::flip(small, small, 0);
    cv::cvtColor(small, rgb, cv::COLOR_RGBA2RGB);
    out.thumbnail.assign(rgb.data, rgb.data + rgb.total() * 3);
  }
  if (keep_rgba) {
    out.rgba.resize(r.rgba.size());
    cv::Mat top_first(h, w, CV_8UC4, out.rgba.data());
    cv::flip(full, top_first, 0);
  }
}

}  // namespace studio::projector_render
