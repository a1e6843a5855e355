// The renderer on Mesa llvmpipe (EGL surfaceless, headless): the default scene checked against the
// camera model (each named exhibit appears where its projected bounding box says, in its colour),
// visibility, high-contrast, the actor mask (flat, no depth test), render to texture, asset status.
#include <gtest/gtest.h>

#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "scene/view.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "scene_render/renderer.h"

using namespace studio;
using namespace studio::scene_render;

namespace {

const std::string kDefault = std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml";
constexpr int kW = 1280, kH = 720;
const char* kExhibits[] = {"exhibit_red_sphere",  "exhibit_green_torus",  "exhibit_blue_vase",
                           "exhibit_yellow_knot", "exhibit_magenta_cone", "exhibit_cyan_cube"};

int hue_of(const Eigen::Vector4f& rgba) {
  cv::Mat px(1, 1, CV_8UC3, cv::Scalar(rgba[2] * 255, rgba[1] * 255, rgba[0] * 255)), hsv;
  cv::cvtColor(px, hsv, cv::COLOR_BGR2HSV);
  return hsv.at<cv::Vec3b>(0, 0)[0];
}

class DefaultScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto ctx = HeadlessContext::create();
    ASSERT_TRUE(ctx) << ctx.error().message;
    context_ = new HeadlessContext(std::move(*ctx));
  }
  static void TearDownTestSuite() {
    delete context_;
    context_ = nullptr;
  }

  void SetUp() override {
    ASSERT_NE(context_, nullptr);
    auto d = scene_config::read_scene_file(kDefault);
    ASSERT_TRUE(d) << d.error().message;
    description_ = *d;
    auto s = scene_assets::build_scene(*d, cache_);
    ASSERT_TRUE(s) << s.error().message;
    scene_ = std::move(*s);
    auto r = Renderer::create();
    ASSERT_TRUE(r) << r.error().message;
    renderer_.emplace(std::move(*r));
    for (const auto& [path, a] : cache_.all()) ASSERT_TRUE(renderer_->upload(*a));
    auto t = RenderTarget::create(kW, kH);
    ASSERT_TRUE(t) << t.error().message;
    target_.emplace(std::move(*t));
    const auto& v = *description_.view;
    view_.cam_from_world =
        scene::look_at({v.eye[0], v.eye[1], v.eye[2]}, {v.at[0], v.at[1], v.at[2]});
    view_.clip_from_cam =
        scene::perspective(v.fov_deg * std::numbers::pi / 180, double(kW) / kH, 0.05, 200);
    museum_ = cache_.find(description_.set);
    ASSERT_NE(museum_, nullptr);
  }

  cv::Mat render() {
    target_->bind();
    renderer_->draw(scene_, view_);
    return read(*target_);
  }
  static cv::Mat read(const RenderTarget& t) {
    std::vector<std::uint8_t> rgba;
    t.read_rgba(rgba);
    cv::Mat bgr;
    cv::cvtColor(cv::Mat(t.height(), t.width(), CV_8UC4, rgba.data()), bgr, cv::COLOR_RGBA2BGR);
    return bgr;
  }

  // Pixel rectangle of an exhibit's projected world bounding box.
  cv::Rect box_of(const std::string& name) {
    const Eigen::AlignedBox3d b = scene_assets::world_bounds(scene_, "set/" + name, *museum_);
    EXPECT_FALSE(b.isEmpty()) << name;
    const Eigen::Matrix4d clip_from_world = view_.clip_from_cam * view_.cam_from_world;
    Eigen::AlignedBox2d r;
    for (int c = 0; c < 8; ++c) {
      bool in_front = false;
      r.extend(scene::project_to_pixel(clip_from_world,
                                       b.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)),
                                       kW, kH, &in_front));
      EXPECT_TRUE(in_front);
    }
    const int x0 = std::max(0, int(std::floor(r.min().x()))),
              y0 = std::max(0, int(std::floor(r.min().y())));
    const int x1 = std::min(kW, int(std::ceil(r.max().x()))),
              y1 = std::min(kH, int(std::ceil(r.max().y())));
    return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
  }
  int expected_hue(const std::string& name) {
    const int i = museum_->find_node(name);
    return hue_of(
        museum_->materials[museum_->meshes[museum_->nodes[i].meshes[0]].material].base_colour);
  }
  // Saturated pixels (S > 120 of 255) of hue within 6 (OpenCV units, 12 degrees) of `hue`.
  static cv::Mat matches(const cv::Mat& bgr, int hue) {
    cv::Mat hsv;
    cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
    cv::Mat m(bgr.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < hsv.rows; ++y)
      for (int x = 0; x < hsv.cols; ++x) {
        const cv::Vec3b p = hsv.at<cv::Vec3b>(y, x);
        int d = std::abs(int(p[0]) - hue);
        d = std::min(d, 180 - d);
        if (p[1] > 120 && p[2] > 40 && d <= 6) m.at<uchar>(y, x) = 255;
      }
    return m;
  }

  static HeadlessContext* context_;
  scene_assets::SceneDescription description_;
  scene_assets::AssetCache cache_;
  scene::Scene scene_;
  std::optional<Renderer> renderer_;
  std::optional<RenderTarget> target_;
  View view_;
  std::shared_ptr<const scene_assets::Asset> museum_;
};

HeadlessContext* DefaultScene::context_ = nullptr;

}  // namespace

TEST_F(DefaultScene, RunsOnMesa) {
  EXPECT_FALSE(context_->renderer().empty());
  std::printf("GL_RENDERER: %s\n", context_->renderer().c_str());
  EXPECT_TRUE(renderer_->check_assets(scene_).empty());
}

TEST_F(DefaultScene, ExhibitsAppearWhereTheCameraModelPutsThemInTheirColours) {
  const cv::Mat image = render();
  for (const char* name : kExhibits) {
    const cv::Rect box = box_of(name);
    ASSERT_GT(box.area(), 150) << name;
    const cv::Mat own = matches(image, expected_hue(name));
    const int inside = cv::countNonZero(own(box));
    // The exhibit's colour fills a good part of its box...
    EXPECT_GT(inside, 0.2 * box.area()) << name << " box " << box;
    // ...and nearly all pixels of that colour in the picture lie in the box (2 px tolerance).
    const cv::Rect grown = (box + cv::Size(4, 4) - cv::Point(2, 2)) & cv::Rect(0, 0, kW, kH);
    EXPECT_GT(cv::countNonZero(own(grown)), 0.9 * cv::countNonZero(own)) << name;
    // No other exhibit's colour rivals it there.
    for (const char* other : kExhibits) {
      if (std::string(other) == name) continue;
      EXPECT_LT(cv::countNonZero(matches(image, expected_hue(other))(box)), inside / 3)
          << name << " vs " << other;
    }
  }
}

TEST_F(DefaultScene, HiddenExhibitDisappearsAndHighContrastIsUnlit) {
  const std::string red = "set/exhibit_red_sphere";
  const cv::Rect box = box_of("exhibit_red_sphere");
  const int hue = expected_hue("exhibit_red_sphere");
  ASSERT_GT(cv::countNonZero(matches(render(), hue)(box)), 0.2 * box.area());  // positive control
  ASSERT_TRUE(scene_.apply({0, scene::SetVisible{red, false}}));
  EXPECT_LT(cv::countNonZero(matches(render(), hue)(box)), 0.02 * box.area());
  ASSERT_TRUE(scene_.apply({0, scene::SetVisible{red, true}}));
  scene::Material m = scene_.find(red)->material;
  m.high_contrast = true;
  ASSERT_TRUE(scene_.apply({0, scene::SetMaterial{red, m}}));
  const cv::Mat lit_off = render();
  // Unlit: every sphere pixel is exactly the base colour (0.90, 0.08, 0.08).
  const cv::Vec3b centre = lit_off.at<cv::Vec3b>(box.y + box.height / 2, box.x + box.width / 2);
  EXPECT_NEAR(centre[2], 0.90 * 255, 1.5);
  EXPECT_NEAR(centre[1], 0.08 * 255, 1.5);
  EXPECT_NEAR(centre[0], 0.08 * 255, 1.5);
}

TEST_F(DefaultScene, ActorMaskIsFlatBlackWithoutDepthTest) {
  // A box-shaped "actor" just behind the red sphere on the line of sight through its centre:
  // hidden by it with the depth test, but the mask pass draws it anyway.
  scene::ActorMesh actor;
  actor.actor_id = "actor0";
  const Eigen::Vector3d sphere(-7.5, 1.55, -8), eye(description_.view->eye.data());
  const Eigen::Vector3f c = (sphere + 0.8 * (sphere - eye).normalized()).cast<float>(),
                        h(0.3f, 0.3f, 0.1f);
  for (int k = 0; k < 8; ++k)
    actor.vertices.push_back(c + Eigen::Vector3f(k & 1 ? h.x() : -h.x(), k & 2 ? h.y() : -h.y(),
                                                 k & 4 ? h.z() : -h.z()));
  const std::array<std::uint32_t, 3> tris[] = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5},
                                               {0, 4, 5}, {0, 5, 1}, {2, 3, 7}, {2, 7, 6},
                                               {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
  actor.triangles.assign(std::begin(tris), std::end(tris));
  ASSERT_TRUE(renderer_->set_actor_mesh(actor));
  const cv::Rect box = box_of("exhibit_red_sphere");
  const cv::Point centre(box.x + box.width / 2, box.y + box.height / 2);
  const cv::Mat scene_only = render();
  ASSERT_GT(scene_only.at<cv::Vec3b>(centre)[2], 100);  // the sphere, in front of the actor
  target_->bind();
  renderer_->draw(scene_, view_);
  renderer_->draw_actor_flat("actor0", view_, 0.02f);
  const cv::Mat masked = read(*target_);
  EXPECT_EQ(masked.at<cv::Vec3b>(centre), cv::Vec3b(0, 0, 0));
  // Away from the actor nothing changed.
  const cv::Rect far(0, kH - 100, 200, 100);
  EXPECT_EQ(cv::norm(masked(far), scene_only(far), cv::NORM_INF), 0.0);
}

TEST_F(DefaultScene, RenderToTextureFeedsAnotherPass) {
  const cv::Mat first = render();
  auto second = RenderTarget::create(kW, kH);
  ASSERT_TRUE(second);
  second->bind();
  renderer_->draw_texture(target_->colour_texture());
  EXPECT_LE(cv::norm(read(*second), first, cv::NORM_INF), 1.0);
  // A homography on the texture coordinates: a vertical flip.
  Eigen::Matrix3f flip;
  flip << 1, 0, 0, 0, -1, 1, 0, 0, 1;
  second->bind();
  renderer_->draw_texture(target_->colour_texture(), flip);
  cv::Mat flipped;
  cv::flip(first, flipped, 0);
  EXPECT_LE(cv::norm(read(*second), flipped, cv::NORM_INF), 1.0);
}

// Untextured meshes are drawn by the lit program's untextured variant (no sampler: llvmpipe would
// fetch and filter for every fragment under a false uniform branch). It must give the picture
// the textured variant gives with a white texture: the ceiling and the exhibits (untextured in
// the museum) given a white 64x64 texture through their node material: 0 values differ, with
// both shadings. Positive control: a grey texture on the same nodes darkens the red sphere, so
// the textured variant really drew them.
TEST_F(DefaultScene, UntexturedVariantDrawsWhatAWhiteTextureDraws) {
  const std::string white = ::testing::TempDir() + "/render_test_white.png",
                    grey = ::testing::TempDir() + "/render_test_grey.png";
  ASSERT_TRUE(cv::imwrite(white, cv::Mat(64, 64, CV_8UC3, cv::Scalar(255, 255, 255))));
  ASSERT_TRUE(cv::imwrite(grey, cv::Mat(64, 64, CV_8UC3, cv::Scalar(128, 128, 128))));
  std::vector<std::string> untextured = {"set/ceiling"};
  for (const char* e : kExhibits) untextured.push_back(std::string("set/") + e);
  auto with_texture = [&](const std::string& path) {
    scene::Scene s = scene_;
    for (const std::string& id : untextured) {
      const scene::Node* n = s.find(id);
      EXPECT_NE(n, nullptr) << id;
      if (!n) continue;
      scene::Material m = n->material;
      EXPECT_TRUE(m.texture.empty()) << id;
      m.texture = path;
      EXPECT_TRUE(s.apply({0, scene::SetMaterial{id, m}}));
    }
    return s;
  };
  const scene::Scene white_scene = with_texture(white), grey_scene = with_texture(grey);
  const cv::Rect sphere = box_of("exhibit_red_sphere");
  for (const auto shading : {RendererOptions::Shading::fast, RendererOptions::Shading::reference}) {
    RendererOptions ro;
    ro.shading = shading;
    auto r = Renderer::create(ro);
    ASSERT_TRUE(r) << r.error().message;
    for (const auto& [path, a] : cache_.all()) ASSERT_TRUE(r->upload(*a));
    auto draw = [&](const scene::Scene& s) {
      target_->bind();
      r->draw(s, view_);
      return read(*target_);
    };
    const cv::Mat plain = draw(scene_), textured = draw(white_scene), darker = draw(grey_scene);
    EXPECT_EQ(cv::norm(plain, textured, cv::NORM_INF), 0.0);
    EXPECT_LT(cv::mean(darker(sphere))[2], 0.8 * cv::mean(plain(sphere))[2]);
  }
}

// Nearest-texel sampling (RendererOptions::TextureFilter::nearest, cheaper on llvmpipe; the
// projector's default) against the default bilinear one, fast shading: close over the whole
// frame (PSNR > 38 dB; 43.5 and 41.9 measured), from the scene's
// view and from an actor's eye, and not identical (the option really changes the sampler).
TEST_F(DefaultScene, NearestTexelsStayCloseToBilinear) {
  RendererOptions ro;
  ro.texture_filter = RendererOptions::TextureFilter::nearest;
  auto nearest = Renderer::create(ro);
  ASSERT_TRUE(nearest) << nearest.error().message;
  for (const auto& [path, a] : cache_.all()) ASSERT_TRUE(nearest->upload(*a));
  View actor_eye;
  actor_eye.cam_from_world = scene::look_at({0.1, 1.65, 1.2}, {0, 1.25, -2});
  actor_eye.clip_from_cam =
      scene::perspective(70 * std::numbers::pi / 180, double(kW) / kH, 0.05, 200);
  for (const View& v : {view_, actor_eye}) {
    target_->bind();
    renderer_->draw(scene_, v);
    const cv::Mat bilinear = read(*target_);
    target_->bind();
    nearest->draw(scene_, v);
    const cv::Mat near = read(*target_);
    const double psnr = cv::PSNR(near, bilinear);
    std::printf("nearest vs bilinear texels: PSNR %.1f dB\n", psnr);
    EXPECT_GT(psnr, 38.0);
    EXPECT_GT(cv::norm(near, bilinear, cv::NORM_L1), 0.0);
  }
}

// The fast shading (lighting per vertex, the default) against the reference (per fragment) on
// the default scene: close over the whole frame (PSNR over every pixel, 8-bit), from the
// scene's view and from an actor's eye in the acting area looking at the exhibits.
TEST_F(DefaultScene, FastShadingStaysCloseToTheReference) {
  RendererOptions ro;
  ro.shading = RendererOptions::Shading::reference;
  ro.lod_pixel_error = 0;  // the exact path: full meshes
  auto reference = Renderer::create(ro);
  ASSERT_TRUE(reference) << reference.error().message;
  auto fast_renderer = Renderer::create();  // the default: fast shading, levels of detail
  ASSERT_TRUE(fast_renderer) << fast_renderer.error().message;
  for (const auto& [path, a] : cache_.all()) {
    ASSERT_TRUE(reference->upload(*a));
    ASSERT_TRUE(fast_renderer->upload(*a));
  }
  View actor_eye;
  actor_eye.cam_from_world = scene::look_at({0.3, 1.7, 0.5}, {-1, 1.4, -8});
  actor_eye.clip_from_cam =
      scene::perspective(70 * std::numbers::pi / 180, double(kW) / kH, 0.05, 200);
  for (const View& v : {view_, actor_eye}) {
    target_->bind();
    fast_renderer->draw(scene_, v);
    const cv::Mat fast = read(*target_);
    target_->bind();
    reference->draw(scene_, v);
    const cv::Mat exact = read(*target_);
    const double psnr = cv::PSNR(fast, exact);
    std::printf("fast vs reference shading: PSNR %.1f dB\n", psnr);
    EXPECT_GT(psnr, 30.0);
    // And not identical: the two paths really differ (the test could not pass by drawing the
    // reference twice).
    EXPECT_GT(cv::norm(fast, exact, cv::NORM_L1), 0.0);
  }
}

// Culling (bounding spheres outside the frustum, the clip plane, a caller's frustum) and the
// nearest-first order change the work, not the picture: against the renderer drawing every mesh
// in scene order, from the scene's view and from an actor's eye looking at two exhibits (most of
// the hall behind the eye or outside the frustum: culling must drop meshes there).
TEST_F(DefaultScene, CullingAndSortingKeepTheImage) {
  RendererOptions ro;
  ro.lod_pixel_error = 0;  // full meshes in both (levels of detail: the next test)
  auto culled = Renderer::create(ro);
  ASSERT_TRUE(culled) << culled.error().message;
  ro.cull_and_sort = false;
  auto every = Renderer::create(ro);
  ASSERT_TRUE(every) << every.error().message;
  for (const auto& [path, a] : cache_.all()) {
    ASSERT_TRUE(every->upload(*a));
    ASSERT_TRUE(culled->upload(*a));
  }
  View close_up;
  close_up.cam_from_world = scene::look_at({-6, 1.7, -4.5}, {-6, 1.4, -8});
  close_up.clip_from_cam =
      scene::perspective(50 * std::numbers::pi / 180, double(kW) / kH, 0.05, 200);
  View clipped = view_;  // a clip plane: x >= -2
  clipped.clip_plane_world = Eigen::Vector4d(1, 0, 0, 2);
  // The caller's frustum: the close-up's centre (30 of its 50 degrees); only the picture inside
  // it counts.
  View narrowed = close_up;
  narrowed.cull_clip_from_world =
      scene::perspective(30 * std::numbers::pi / 180, double(kW) / kH, 0.05, 200) *
      close_up.cam_from_world;
  const double f = std::tan(15 * std::numbers::pi / 180) / std::tan(25 * std::numbers::pi / 180);
  const cv::Rect centre(int(kW * (1 - f) / 2) + 1, int(kH * (1 - f) / 2) + 1, int(kW * f) - 2,
                        int(kH * f) - 2);
  int fewer = 0;
  for (const View* v : {&view_, &close_up, &clipped, &narrowed}) {
    const cv::Rect region = v == &narrowed ? centre : cv::Rect(0, 0, kW, kH);
    target_->bind();
    every->draw(scene_, *v);
    const int all_calls = every->draw_calls_last_frame();
    const cv::Mat want = read(*target_)(region).clone();
    target_->bind();
    culled->draw(scene_, *v);
    const int calls = culled->draw_calls_last_frame();
    const cv::Mat got = read(*target_)(region).clone();
    const double psnr = cv::PSNR(got, want);
    cv::Mat diff;
    cv::absdiff(got, want, diff);
    cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
    std::printf("culled and sorted: %d of %d draw calls, %d of %d pixels differ, PSNR %.1f dB\n",
                calls, all_calls, cv::countNonZero(diff), region.area(), psnr);
    EXPECT_GE(psnr, 60.0);
    EXPECT_LE(calls, all_calls);
    fewer += calls < all_calls;
  }
  EXPECT_GE(fewer, 3);  // the close-up, the clip plane and the caller's frustum leave meshes out
}

// Levels of detail (the default: error <= 0.5 px at the mesh's nearest point) against the full
// meshes: the scene's view and an actor's eye (exhibits 8-10 m away: coarser levels), and a
// close-up of two exhibits (finer ones). Close over every pixel, and really fewer triangles.
TEST_F(DefaultScene, DetailLevelsStayCloseToTheFullMeshes) {
  RendererOptions ro;
  ro.lod_pixel_error = 0;
  auto full = Renderer::create(ro);
  ASSERT_TRUE(full) << full.error().message;
  for (const auto& [path, a] : cache_.all()) ASSERT_TRUE(full->upload(*a));
  View actor_eye;
  actor_eye.cam_from_world = scene::look_at({0.3, 1.7, 0.5}, {-1, 1.4, -8});
  actor_eye.clip_from_cam =
      scene::perspective(70 * std::numbers::pi / 180, double(kW) / kH, 0.05, 200);
  View close_up;
  close_up.cam_from_world = scene::look_at({-6, 1.7, -5.5}, {-6, 1.4, -8});
  close_up.clip_from_cam =
      scene::perspective(50 * std::numbers::pi / 180, double(kW) / kH, 0.05, 200);
  std::int64_t saved = 0;
  for (const View* v : {&view_, &actor_eye, &close_up}) {
    target_->bind();
    full->draw(scene_, *v);
    const std::int64_t all = full->triangles_last_frame();
    const cv::Mat want = read(*target_);
    target_->bind();
    renderer_->draw(scene_, *v);
    const std::int64_t drawn = renderer_->triangles_last_frame();
    const cv::Mat got = read(*target_);
    const double psnr = cv::PSNR(got, want);
    std::printf("levels of detail: %lld of %lld triangles, PSNR %.1f dB\n",
                static_cast<long long>(drawn), static_cast<long long>(all), psnr);
    EXPECT_GE(psnr, 40.0);
    EXPECT_LE(drawn, all);
    saved += all - drawn;
  }
  EXPECT_GT(saved, 20000);  // the exhibits' levels are really used
}

TEST_F(DefaultScene, MissingOrDifferentAssetsAreReported) {
  scene::Node other;
  other.id = "statue";
  other.kind = scene::NodeKind::model;
  other.asset = {"/assets/statue.glb", "00", {}};
  ASSERT_TRUE(scene_.apply({0, scene::AddNode{other}}));
  scene::Node changed = *scene_.find("set/exhibit_cyan_cube");
  changed.id = "cube_copy";
  changed.parent = "";
  changed.asset.sha256 = "ffff";
  ASSERT_TRUE(scene_.apply({0, scene::AddNode{changed}}));
  const auto status = renderer_->check_assets(scene_);
  ASSERT_EQ(status.size(), 2u);
  EXPECT_EQ(status[0].path, "/assets/statue.glb");
  EXPECT_EQ(status[0].state, AssetStatus::State::missing);
  EXPECT_EQ(status[1].path, museum_->path);
  EXPECT_EQ(status[1].state, AssetStatus::State::different);
  EXPECT_EQ(status[1].have_sha256, museum_->sha256);
  render();  // nodes with missing assets are skipped, not a crash
}

TEST_F(DefaultScene, FlyerMovesWithTheSceneClock) {
  const cv::Mat at0 = render();
  ASSERT_TRUE(scene_.apply({50, scene::Tick{}}));  // 2 s later
  const cv::Mat at50 = render();
  cv::Mat diff;
  cv::absdiff(at0, at50, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(diff > 30), 100);
}
