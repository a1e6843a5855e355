#pragma once
// Where the projector's frames go (projector_node.h `output:`): headless (EGL surfaceless) or a
// full-screen window on a named monitor (window_output.h); either way the GL context is made
// current on the calling thread (the render thread) and the FrameRenderer is created in it, so
// the same rendering code serves both.

#include <optional>

#include "frame_stages.h"
#include "projector_node.h"
#include "projector_wire.h"
#include "runtime/service_loop.h"
#include "projector_render/frame_renderer.h"
#include "scene_render/egl_context.h"
#include "window_output.h"

namespace studio::projector {

struct FrameOutput {
  std::optional<scene_render::HeadlessContext> headless;
  std::optional<WindowOutput> window;  // set for output: window (show each frame there)
};

// The renderer's options from the node's (the frame's renderer and the scene thread's).
projector_render::FrameRendererOptions frame_renderer_options(const ProjectorNodeOptions& options);

// Opens the output (into `out`, which must outlive the renderer) and creates the renderer.
// Errors: no EGL / no display / unknown monitor / renderer resources (one line each).
Expected<projector_render::FrameRenderer> open_frame_output(const ProjectorNodeOptions& options,
                                                            const ProjectorView& view,
                                                            const std::string& projector_id,
                                                            FrameOutput& out);

// Reads the frame back (blackout runs, thumbnail) and publishes it on studio/projector/frame;
// stages readback and publish timed.
void publish_frame(projector_render::FrameRenderer& fr, projector_render::Readback& rb,
                   const FrameInfo& facts, runtime::Output<studio_ProjectorFrame>& out,
                   FrameStages& stages);

}  // namespace studio::projector
