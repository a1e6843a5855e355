#include "frame_output.h"

#include "core/log.h"

namespace studio::projector {

projector_render::FrameRendererOptions frame_renderer_options(const ProjectorNodeOptions& options) {
  projector_render::FrameRendererOptions fo;
  fo.form = options.form;
  fo.eye_texture_size = {options.eye_texture[0], options.eye_texture[1]};
  fo.eye_texture_scale = options.eye_texture_scale;
  fo.thumb_width = options.thumbnail[0];
  fo.thumb_height = options.thumbnail[1];
  fo.scene_cache = options.scene_cache;
  return fo;
}

Expected<projector_render::FrameRenderer> open_frame_output(const ProjectorNodeOptions& options,
                                                            const ProjectorView& view,
                                                            const std::string& projector_id,
                                                            FrameOutput& out) {
  std::string renderer;
  if (options.output == OutputKind::window) {
    auto w = WindowOutput::create(options.monitor, "studio-projector " + projector_id);
    if (!w) return std::unexpected(w.error());
    renderer = w->renderer() + ", full-screen window on monitor " + w->monitor() + " (" +
               std::to_string(w->width()) + "x" + std::to_string(w->height()) + ")";
    out.window.emplace(std::move(*w));
  } else {
    auto context = scene_render::HeadlessContext::create();
    if (!context) return std::unexpected(context.error());
    renderer = context->renderer() + ", headless";
    out.headless.emplace(std::move(*context));
  }
  auto fr = projector_render::FrameRenderer::create(view, frame_renderer_options(options));
  if (!fr) return fr;
  STUDIO_LOG(info, "projector") << "rendering " << fr->width() << "x" << fr->height() << " on "
                                << renderer;
  return fr;
}

void publish_frame(projector_render::FrameRenderer& fr, projector_render::Readback& rb,
                   const FrameInfo& facts, runtime::Output<studio_ProjectorFrame>& out,
                   FrameStages& stages) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  fr.read(rb);
  const auto t1 = Clock::now();
  stages.add(FrameStages::readback, std::chrono::duration<double>(t1 - t0).count());
  wire::Owned<studio_ProjectorFrame> f;
  fill_frame(facts, rb, *f);
  (void)out.write(*f);
  stages.add(FrameStages::publish, std::chrono::duration<double>(Clock::now() - t1).count());
}

}  // namespace studio::projector
