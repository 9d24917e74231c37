// The search's stratified subsample (SearchOptions::search_samples).
//
// Above `n` samples the projection search evaluates its candidates (screening,
// Powell, polish: every inner-loop fit) on a subset of n samples; the final fit
// at texture_size and every metric use all samples (search_factorization).
//
// Strata: cells of the half/difference angles of each sample, read off its
// halfdiff point (parabolic h, parabolic d): theta_h in kThetaHBins bins spaced
// as sqrt(theta_h / 90 deg) (as MERL's table: the first bins are 0.35, 1.4,
// 3.2 deg wide, so the highlight has strata of its own), phi_h, theta_d and
// phi_d in kAngleBins uniform bins each; when that makes more than n / 2
// non-empty strata, every bin count is halved (coarser strata) until it does
// not, so each stratum keeps at least about two samples. Every non-empty stratum keeps
// min(count, cap) samples, cap the largest that fits n (the n - sum left over
// go one each to strata above the cap, in a seeded order), chosen by a seeded
// partial shuffle; each kept sample's weight is scaled so that its stratum
// keeps its total weight (so W, the smoothing scale and each region's share of
// the objective are those of all samples). The log transform, the log range
// (clamp) and the extrapolation prior are the full data's. Deterministic for
// (data, n, seed); kept samples stay in their original order.
#pragma once

#include <cstdint>

#include "factor/homomorphic_fit.h"

namespace bf {

struct SubsampleInfo {
  size_t samples = 0;  // samples kept
  size_t of = 0;       // samples of the full data
  uint64_t seed = 0;
  size_t strata = 0;   // non-empty strata
  size_t cap = 0;      // samples kept per stratum at most (one more for some)
  int coarsen = 0;     // bin counts divided by 2^coarsen
};

inline constexpr int kThetaHBins = 16;
inline constexpr int kAngleBins = 8;

// The stratum of a halfdiff point, in [0, kThetaHBins * kAngleBins^3), with
// every bin count divided by 2^coarsen (at least 1 bin).
size_t subsample_stratum(const Vec4& x_halfdiff, int coarsen = 0);

// The subset of d described above. Requires 1 <= n < d.size()
// (std::invalid_argument otherwise).
FitData stratified_subsample(const FitData& d, size_t n, uint64_t seed, SubsampleInfo* info = nullptr);

}  // namespace bf
