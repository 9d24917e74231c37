// Homomorphic fits (McCool's fixed projections, configured projections) sized
// by one tolerance: the smallest texture resolution of a ladder, with the
// smallest number of terms there, whose fit reaches an error target (docs/design.md
// §9; the SVD counterpart is select_svd_size in factor/svd_baseline.h).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "factor/homomorphic_fit.h"
#include "factor/metrics.h"
#include "factor/svd_baseline.h"

namespace bf {

// For each resolution res of `ladder` (ascending), for J = min_terms ..
// max_terms: fit the first J of terms_at(res) (fit_homomorphic, the full
// schedule) and score tol.metric on `samples` with `lt`; stop at the first
// (res, J) reaching tol. Nothing reaches: the lowest error tried, reached =
// false. knob "terms", texture_size = the resolution, errors_after_term = the
// chosen fit's rel_mse after each term, result a HomomorphicFactorization.
// terms_at(res) must return at least max_terms terms at resolution res.
// Throws std::invalid_argument for a bad ladder or term range.
SizeChoice select_homomorphic_size(const FitData& data, const SampleSet& samples, const LogTransform& lt,
                                   const std::function<std::vector<TermSpec>(int res)>& terms_at,
                                   int min_terms, int max_terms, const FitOptions& opt,
                                   const std::string& method, const Tolerance& tol,
                                   const std::vector<int>& ladder);

// The terms of `terms` at another resolution (same projections, texture res).
std::vector<TermSpec> terms_at_resolution(std::vector<TermSpec> terms, int res);

}  // namespace bf
