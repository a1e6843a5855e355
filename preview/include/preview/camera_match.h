#pragma once
// Matching the studio cameras' colours at the cameras (issue 16's camera panel, beyond the
// paper). The colour balance the preview learns (rig_balance.h) corrects only this preview's
// blend; the cameras' own controls correct every consumer at once: the keyer, the hull's masks,
// recorded takes, the offline reconstruction and every other preview instance. A studio matches
// its cameras this way (a camera control unit's gain and white balance per camera).
//
// From the balance's estimate e_c = (R, G, B) for camera c (factors for its 8-bit colours that
// bring it to the rig) to GenICam controls (SFNC names as the capture service publishes them,
// capture/frame_source.h):
//   Gain (dB, every channel)           += 20 log10(e_G) + k
//   BalanceRatioRed  (against green)   *= e_R / e_G
//   BalanceRatioBlue (against green)   *= e_B / e_G
// k is common to every camera: the estimate fixes only the cameras' ratios (its geometric mean
// is 1), not the rig's level. k is the value nearest 0 that keeps every camera's Gain within its
// range (a camera already at its lowest gain cannot be darkened: the others are brightened to
// it); when no k keeps them all, the midpoint of the violated bounds, and each Gain is clamped.
// What a camera's controls cannot take (a clamp, a control the camera does not have) is reported
// as the factor left per channel: the preview's balance goes on correcting that part. A camera
// whose controls act before a transfer curve (GenICam Gamma) takes each factor to the power
// CameraControls::exponent; the figures above are then on its delivered values.
//
// Pure library: the node reads the features back from studio/camera/state and sends the changes
// as CameraControl (preview/node/camera_matching.h).
#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::preview {

// A control as read back: its value and range.
struct ControlValue {
  double value = 0, min = 0, max = 0;
};

// One camera's controls that take part (absent: the camera does not have it).
struct CameraControls {
  std::string camera;
  std::optional<ControlValue> gain_db, ratio_red, ratio_blue;
  // The estimate is a factor f on the colours as delivered (8-bit, display-encoded); the
  // controls scale what the camera has before its own transfer curve. The control's factor is
  // f^exponent: 1 when the controls act on the delivered values (the simulated camera), 1 /
  // Gamma for a camera applying GenICam's Gamma (delivered = sensor^Gamma) after them.
  double exponent = 1;
};

struct ControlChange {
  std::string camera, feature;  // "Gain", "BalanceRatioRed", "BalanceRatioBlue"
  double from = 0, to = 0;
};

struct CameraMatch {
  std::vector<ControlChange> changes;  // in the order of the cameras given, then the features
  double level_db = 0;                 // k
  // Per camera given an estimate: the factor per channel its controls could not take (1 = all).
  std::map<std::string, Eigen::Vector3f> left;
};

// `estimated`: the balance's estimate per camera id (cameras not in it are left alone);
// `controls`: the cameras' controls as read back. Changes smaller than `min_change` (a relative
// factor: 0.005 = 0.5 %) are not made. Fails (one line) on an estimate that is not finite and
// positive, a control whose range is empty or not finite, a non-positive exponent, or a negative
// min_change.
Expected<CameraMatch> plan_camera_match(const std::map<std::string, Eigen::Vector3f>& estimated,
                                        const std::vector<CameraControls>& controls,
                                        double min_change = 0.005);

}  // namespace studio::preview
