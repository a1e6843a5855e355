#pragma once
// Sub-pixel edge decision: moves the binary cut of a key to the contour where the actor covers
// half of a pixel, whatever the backing's brightness and the clothes' colour.
//
// Why. The key cuts each pixel by its own colour against fixed levels (keyer_options.h), so at
// an edge the cut wanders: the backing darkens towards the image corners and in the actor's
// shadow, the excess K - max(O1, O2) is not linear in the mix of actor and backing colours, and
// bright clothes reach the threshold at a different coverage than dark ones. Area-integrating
// sensors (and anti-aliased or motion-blurred edges) make an edge pixel the linear mix
// I = c F + (1 - c) B of the actor colour F and the backing colour B behind it, c = coverage.
//
// What. At every transition of the mask between 4-neighbours p (actor) and q = p + d (backing)
// whose outer neighbours F = p - d (actor) and B = q + d (backing) agree with the mask and differ
// in colour by at least min_contrast (Euclidean, 8-bit RGB), p and q are unmixed along that
// local colour line,
//     c(x) = (I(x) - I(B)) . (I(F) - I(B)) / |I(F) - I(B)|^2,
// and re-decided: p stays actor iff c(p) >= threshold, q becomes actor iff c(q) >= threshold.
// A pixel on several transitions takes the decision of the one with the largest contrast
// |I(F) - I(B)| (its outer pixels are the least mixed: across a steep edge the row's neighbours
// are mixed, the column's are not; ties: actor). Decisions all read the input mask, so the
// result does not depend on the order of the transitions.
//
// Why threshold < 1/2 by default: at a silhouette the actor's surface turns away from the camera
// and mirrors the backing (blue spill; issue 4), so a half-covered edge pixel unmixes to ~0.4.
//
// Cost: per transition (the mask's perimeter) two look-ups in a row's runs (a few per row);
// decisions are merged per row from three sorted streams, no sort over the frame; the image is
// read only around transitions. About as much as the SIMD key itself (BENCHMARKS.md).

#include <cstdint>
#include <vector>

#include "core/image.h"
#include "core/run_mask.h"

namespace studio::keyer {

struct EdgeRefineOptions {
  float threshold = 0.4f;     // actor fraction at and above which an edge pixel is actor
  float min_contrast = 20.0f; // |I(F) - I(B)| below this: not an actor/backing edge, left alone
};

struct EdgeRefineScratch {
  struct Flip {  // a decision on pixel x of a row
    int32_t x;
    int32_t contrast;  // |I(F) - I(B)|^2 of the transition that decided
    bool actor;        // decided
    bool was_actor;    // in the input mask
  };
  std::vector<Flip> current, next;  // decisions on the row being finished and on the next one
  std::vector<Flip> resolved;       // the row's changes
  std::vector<Run> row;
};

struct EdgeRefineStats {
  int added = 0;    // backing pixels that became actor
  int removed = 0;  // actor pixels that became backing
};

// `out` may not alias `in`; `image` has the mask's size (checked by the caller). Rgb8 and Bgr8
// give the same result (the unmixing does not depend on the channel order).
EdgeRefineStats refine_edges(ImageView<const Rgb8> image, const RunMask& in,
                             const EdgeRefineOptions& options, RunMask& out,
                             EdgeRefineScratch& scratch);
EdgeRefineStats refine_edges(ImageView<const Bgr8> image, const RunMask& in,
                             const EdgeRefineOptions& options, RunMask& out,
                             EdgeRefineScratch& scratch);

}  // namespace studio::keyer
