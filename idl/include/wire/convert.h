#pragma once
// Conversions between wire samples and core types, shared by every node (DESIGN §2 rule 1: the
// algorithms see only core types). Identity and time fields (camera_id, frame, capture_ns) are
// the caller's; these functions convert the payload.
//
// Inputs come from a wire::Reader, so they passed the type's validator already; the to_core
// functions still return an Error instead of trusting that (a codec payload is only fully
// checked by decoding it).

#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/mask_codec.h"
#include "core/rig.h"
#include "core/run_mask.h"
#include "studio.h"

namespace studio::wire {

// AlphaMask (either encoding) → RunMask. `reuse` lends its storage (frame after frame).
Expected<RunMask> to_core(const studio_AlphaMask& sample, RunMask reuse = RunMask(0, 0));
// RunMask → AlphaMask payload (width, height, encoding, runs or codec bytes).
// MASK_CODEC uses the default coding of core/mask_codec.h.
void from_core(const RunMask& mask, studio_MaskEncoding encoding, studio_AlphaMask& sample);

// CameraCalibration → Camera (id, size, K, the paper's radial model, cam_from_world).
Expected<Camera> to_core(const studio_CameraCalibration& sample);
// Camera → CameraCalibration. Fails for a distortion the wire cannot carry (OpenCV's model:
// convert the camera explicitly with to_paper_model, core/distortion_fit.h, first).
Expected<bool> from_core(const Camera& camera, studio_CameraCalibration& sample);

// ProjectorMask (the viewpoint-cut actor mask of a projector) ↔ RunMask; `step` is the caller's.
Expected<RunMask> to_core(const studio_ProjectorMask& sample);
void from_core(const RunMask& mask, studio_ProjectorMask& sample);
// Projector (K, pose, size, screen corners) + its screen->pixel homography (row-major, scaled
// so h[8] = 1) → ProjectorCalibration (projector_id = camera id). Fails for a projector with
// lens distortion (the topic has no distortion fields) or a homography with h[8] = 0.
Expected<void> from_core(const Projector& projector, const Eigen::Matrix3d& pixel_from_screen,
                         studio_ProjectorCalibration& sample);
// ProjectorCalibration → Projector (no distortion).
Expected<Projector> to_core(const studio_ProjectorCalibration& sample);

// studio/projector/frame's blackout mask: RunMask → width, height, mask_row_start, mask_runs
// (and back; the sample's validator has checked the runs).
void from_core(const RunMask& mask, studio_ProjectorFrame& sample);
Expected<RunMask> to_core(const studio_ProjectorFrame& sample);

}  // namespace studio::wire
