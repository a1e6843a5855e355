#pragma once
// "Match cameras": the preview's colour balance (preview/rig_balance.h) sent to the cameras'
// own controls (preview/camera_match.h: Gain, BalanceRatioRed, BalanceRatioBlue as CameraControl
// on studio/camera/control), so that every consumer of the images sees matched cameras, not only
// this preview's blend. The View panel's button and `studio-preview --headless --match-cameras`.
//
// The estimate sent is the rig samples' once kMatchRigFrames are pooled (every camera linked),
// else the view's live one. The cameras matched are those of its largest linked set (cameras
// linked by shared surface points; gains across sets are not comparable) whose controls the capture
// servers publish on studio/camera/state (with GenICam Gamma when published: the controls act
// before it, CameraControls::exponent); every other camera publishing a Gain takes the rig's new
// level only (plan_camera_match's k), so that it stays where it was against the rig. After sending,
// the balance starts afresh and pools only meshes captured kSettle after the changes (frames on the
// way still have the old colours), so what it learns next is what the controls did not take
// (clamped, or a camera without white balance).
#include <chrono>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "preview/camera_match.h"
#include "preview_node.h"
#include "view_pipeline.h"

namespace studio::preview {

inline constexpr std::chrono::milliseconds kMatchSettle{250};
// --match-cameras waits for this many pooled frames: the estimate after 8 frames strays by a few
// percent more than after a second of meshes (preview_quality_test, rig_balance.h).
inline constexpr int kMatchAutoFrames = 24;
// Match cameras sends the rig samples' estimate (every camera: PipelineOptions::balance_rig_every)
// once it has pooled this many samples since the last match, else the view's live estimate (its
// texturing cameras' linked set); --match-cameras waits for them when the rig is sampled.
// Measured on the seed-3 rig with cam1 two thirds of a stop up (preview_studio_test
// PreviewMatchTest.MovesTheBalanceIntoTheCameras), the whole rig's worst camera pair against the
// truth after the match: 2.5-6.3 % (6 runs; the view's set alone 8.3-10.3 %: the cameras it did not
// link keep their spread; fewer samples, 4 or 8, left up to 11 %).
inline constexpr int kMatchRigFrames = 16;
// --match-cameras acts only when some camera's estimate is this far off 1 (any channel): on
// cameras that agree the live estimate drifts by up to ~4 % over a run (preview_studio_test
// MatchCamerasLeavesAgreeingCamerasAlone: a trigger at 3 % matched in 2 of 6 runs, controls
// moved by 1-5 %), and a match sent on that drift would move cameras that agree. A rig that
// differs by more is matched whole.
inline constexpr float kMatchAutoOffset = 0.08f;
// --match-cameras matches again while the balance, pooled afresh, still applies, up to this many
// rounds (a camera the first estimate had not linked, the first estimate's own error).
inline constexpr int kMatchRounds = 3;

struct SentMatch {
  CameraMatch plan;
  std::vector<std::string> matched;  // the linked set's cameras; the others took the level only
};

// Plans and sends the match; fails (nothing sent) while the balance has pooled fewer frames than
// its gains wait for (BalanceSnapshot::min_frames) or linked no cameras, when no linked camera
// publishes its controls, or on a send that fails (the changes before it were sent).
Expected<SentMatch> match_cameras(PreviewNode& node, ViewPipeline& pipeline,
                                  double min_change = 0.005);

// `text` as a JSON string, quotes included (quotes and backslashes escaped, control characters
// dropped): for camera ids and messages in the preview's JSON.
std::string json_text(std::string_view text);

// {"level_db", "matched": [ids], "changes": [{"camera", "feature", "from", "to"}],
//  "left": {id: [r, g, b]}}
std::string camera_match_json(const SentMatch& match);
// One line for people: "5 controls sent to 3 cameras (3 matched, level +1.20 dB); left to the
// preview's balance: cam3 ..."
std::string camera_match_text(const SentMatch& match);

}  // namespace studio::preview
