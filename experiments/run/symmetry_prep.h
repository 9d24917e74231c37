// Symmetries as data preparation for a run (docs/design.md §4.3
// "symmetries"): which symmetries the fit's samples stand for, and the
// training set with each raw sample replaced by its orbit (brdfs/symmetry.h).
// The fitters see an ordinary weighted SampleSet; the held-out split stays
// on the raw samples, and so do training and held-out metrics, except for
// samples that are their orbit's representatives (scored_set).
#pragma once

#include <optional>
#include <string>

#include "brdfs/sampleset.h"
#include "brdfs/symmetry.h"
#include "experiments/plan/plan.h"

namespace bf {

// The sampling key `symmetries` (experiments.md): "auto" (default): the
// symmetries the samples declare, for raw samples (kinds measured and file)
// only; grid and stratified sets already cover the domain and are left as
// they are. "off" (or "none"): no expansion. Names joined by '+'
// ("isotropic+reciprocal+bilateral"): the user declares these for the
// samples (e.g. a CSV, which declares none) and the fit uses them, whatever
// the kind.
struct SymmetryChoice {
  Symmetries declared;  // what the samples declare (after the key's declaration)
  Symmetries used;      // what the orbit expansion uses
  std::string key;      // the key's value
  // The samples are their orbit's representatives (SampleSet::representatives,
  // a MERL table's cells) and the fit uses symmetries: metrics score each
  // sample over its orbit (scored_set).
  bool score_orbit = false;
};
SymmetryChoice choose_symmetries(const SamplingVariant& s, const SampleSet& samples);

// The samples a run's training and held-out metrics are scored on: `s`
// itself, or, when c.score_orbit, each valid sample's orbit under c.used
// (expand_orbit with kRunOrbit; every copy at weight / |orbit|, so each
// sample keeps its weight). A MERL cell's position phi_h = 0 is the format's
// convention, and the fit that uses its orbit is not meant to be better
// there than at any other azimuth; scored at phi_h = 0 alone its error read
// up to 3.4x below the same fit's whole-domain error (docs/design.md §4.3).
// `storage` holds the expansion; the result refers to it or to `s`.
const SampleSet& scored_set(const SampleSet& s, const SymmetryChoice& c, std::optional<SampleSet>& storage);
// "training and held-out samples scored over their orbit (isotropic+reciprocal),
// not at the table's phi_h = 0 alone" (the `validation` column and run.json).
std::string scored_over_orbit_note(const SymmetryChoice& c);

// The orbit a run's fit uses (kRunOrbit) and the share of each measured
// sample's weight that stays on the sample (kRawShare) are defined beside
// SamplingVariant (experiments/plan/plan.h), where they enter the sampling's
// identity, so a change to them changes the run ids and no cached run is reused.

// The set the fit sees: `train` itself (a copy) when nothing is used, else
// the valid training samples at kRawShare of their weight followed by
// expand_orbit(train, used, kRunOrbit) at the rest. info describes the
// expansion (samples_out counts both parts).
SampleSet fit_set(const SampleSet& train, const SymmetryChoice& c, OrbitInfo* info);

// The whole-domain fill (docs/design.md §4.5). Raw samples cover part of the
// domain; the whole-domain truth there is their interpolant, which extends
// the nearest measurements. The fill appends `pairs` stratified pairs (seed)
// of `truth`, the interpolant of the TRAINING samples only (never of held-out
// ones), at `share` of the fit set's total weight, so the fit follows that
// extension where nothing was measured instead of its smoothing alone.
struct FillChoice {
  const Brdf* truth = nullptr;  // nullptr: no fill
  double share = 0.0;
  size_t pairs = 0;
  uint64_t seed = 0;
  std::string why;              // when there is no fill: why (for the record)
  nlohmann::json describe() const;
};
// The sampling's `fill` (plan.h: -1 auto, 0 off, else a share) for a run
// whose training BRDF is `training` (the measured BRDF made of the training
// samples, or nullptr) and whose fit uses the symmetries `sym`. "auto" fills
// (kFillShare) when that BRDF holds over the whole domain (the interpolant of
// samples declaring all three symmetries, a MERL table) and the fit uses the
// symmetries (with symmetries = "off" the fit sees the records alone, as the
// thesis's); a share the user set needs a training BRDF that holds over the
// whole domain, else std::invalid_argument naming sampling.fill.
FillChoice choose_fill(const SamplingVariant& s, const Brdf* training, const SymmetryChoice& sym, uint64_t seed);
// `fit` followed by the fill's pairs (fit itself when there is none). Throws
// std::invalid_argument naming sampling.fill when `fit` has no weight to take
// a share of, or the truth gives no pair a value (never a silent no-fill).
SampleSet with_fill(SampleSet fit, const FillChoice& f);

}  // namespace bf
