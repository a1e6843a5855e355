#pragma once
// The frame code the simulated actor wears (issue 16): horizontal bands around the torso whose
// colours spell the studio frame number modulo kModulus, so a test can read the frame back from
// any image of the actor — in particular from the director's preview, which textures the hull
// with camera images: the code in the preview's pixels says which frame's image was used.
//
// Layout: the torso ellipsoid (PartId::torso), in its unit-sphere coordinates u (u = 0 at the
// centre, |u| = 1 on the surface, u.y along the spine), carries kBands rings stacked along u.y
// in [kLow, kHigh); ring b holds digit b (base 3, band 0 least significant) of frame mod 81.
// A ring runs all the way round, so it faces every camera. Digits are red, green and yellow:
// no blue, so the blue-screen keyer keeps them (foreground), and the digit is the ratio of green
// to red, which lighting and the display gamma scale alike (lighting-invariant).
// Enabled by StudioOptions::frame_code (off by default: other tests see the plain shirt).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "sim/actor.h"

namespace studio::sim::frame_code {

inline constexpr int kBands = 4;
inline constexpr int kModulus = 81;  // 3^kBands
inline constexpr double kLow = -0.7, kHigh = 0.5;

// Band of a torso unit-sphere height u.y, or -1 outside the code.
int band_of(double unit_y);
// Digit (0 red, 1 green, 2 yellow) of band `band` for `frame`.
int digit(int64_t frame, int band);
Albedo albedo(int digit);
// Digit of an observed display colour (0..255 per channel), or -1 when it is none of the three
// (too dark, bluish, or between the classes).
int classify(double r, double g, double b);
// frame mod kModulus from kBands digits (band order); nullopt when one is -1.
std::optional<int> decode(std::span<const int> digits);

// World point of band `band` on the torso's surface, on the side facing `eye` (the direction
// from the torso's axis to the eye, perpendicular to the axis), at `along` of the band's height
// (0 its lower edge, 0.5 its centre, 1 its upper edge).
Eigen::Vector3d band_point(const ActorBody& body, int band, const Eigen::Vector3d& eye,
                           double along = 0.5);

}  // namespace studio::sim::frame_code
