// Scene-weighted fits ([scene] weight_fit = "image", docs/design.md §4.2): a
// weight per (wi, wo) sample from how much the pairs the scene's pixels use
// near it contribute to the image, so the sample-based fits spend their
// accuracy where the picture needs it.
#pragma once

#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/sampleset.h"
#include "experiments/plan/plan.h"

namespace bf {

// One (wi, wo) pair a pixel of the scene reads, in the local frame, with its
// weight a = C c (f + e)^2: c the factor multiplying f in the pixel's
// radiance (intensity cos / d^2 for the point light; L(wi) cos dw for one
// quadrature node under SH lighting), C the sum of c over the pixel's pairs,
// f the original's value (mean over RGB) and e = 1% of the original's mean
// over the pairs. By Cauchy-Schwarz the pixel's squared error is at most
// sum a (log-space error)^2 to first order, so a is what a log-space fit
// should weight that pair by.
struct ScenePair {
  Vec3 wi, wo;
  double a = 0;
};
// The pairs of the scene's sphere (render.h geometry) on a pixel grid of
// min(scene.size, 64) (point light) or min(scene.size, 24) with 8 x 16
// hemisphere nodes per pixel (SH lighting). Negative SH radiance counts 0.
std::vector<ScenePair> scene_pairs(const Brdf& original, const SceneSettings& scene);

// Per sample k of s: the scene density s_k = sum_p a_p K(k, p) / sum_j K(j, p)
// (each pair's weight shared among the valid samples near it, Gaussian kernel
// in the chord distance |wi_k - wi_p|^2 + |wo_k - wo_p|^2 with bandwidth
// h = (4 pi^2 / N)^(1/4), N the valid samples, cut at 3h), then
// factor_k = floor + (1 - floor) s_k / mean(s) (mean over valid samples, so
// the factors average 1). Returns s with weight_k = its old weight * factor_k.
// floor in [0, 1]; throws std::invalid_argument naming `weight_floor` when it
// is not, or when no pair reaches any sample (std::runtime_error).
SampleSet scene_weighted(const SampleSet& s, const std::vector<ScenePair>& pairs, double floor);

}  // namespace bf
