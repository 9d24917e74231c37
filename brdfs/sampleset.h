// SampleSet: BRDF samples as a structure of arrays (directions, RGB values,
// optional weights, validity), and the builders that make one from a BRDF
// (regular parabolic grid, stratified random) or a sample-list CSV.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/symmetry.h"

namespace bf {

struct SampleSet {
  // Per sample k (all vectors have size() entries):
  std::vector<Vec3> wi;       // unit, local frame, towards the light
  std::vector<Vec3> wo;       // unit, local frame, towards the viewer
  std::vector<Rgb> value;     // f(wi, wo) in 1/sr; meaningful only where valid
  std::vector<double> weight; // empty = every weight is 1; else >= 0 per sample
  std::vector<uint8_t> valid; // 1 = used by fits and metrics, 0 = masked
  std::string description;    // provenance, e.g. "grid 16^4 of bluepaint"
  // What the data guarantee of the BRDF they sample (brdfs/symmetry.h):
  // readers declare what their format guarantees (ASTM, pbrt .brdf: all
  // three; MERL cells: isotropic + reciprocal; CSV: none), a config or
  // bf.SampleSet may declare more. Sets of a BRDF's values (sample_grid,
  // sample_stratified, evaluate_into) declare what that BRDF claims
  // (symmetries_of: isotropic(), reciprocal(), bilateral()).
  Symmetries symmetries;
  // True when a sample's position is its orbit's representative by the
  // format's convention, not where it was measured: a MERL cell is stored at
  // phi_h = 0 because the format drops phi_h, and stands for every azimuth
  // alike. Runs score such samples over their orbit (docs/design.md §4.3).
  bool representatives = false;

  // Counts of masked samples by reason (filled by validate()).
  size_t invalid_value = 0;    // NaN, Inf or negative in any channel
  size_t invalid_horizon = 0;  // wi.z <= 0 or wo.z <= 0
  size_t invalid_weight = 0;   // NaN, Inf or negative weight

  size_t size() const { return wi.size(); }
  size_t valid_count() const;
  double weight_of(size_t k) const { return weight.empty() ? 1.0 : weight[k]; }
  void push(const Vec3& i, const Vec3& o, const Rgb& v, double w = 1.0);
  // Recomputes valid[] and the invalid_* counts from the data. Never throws.
  void validate();
  // "43264 samples (0 masked)" or "1439 samples (12 masked: 12 value, 0 horizon, 0 weight)".
  std::string summary() const;
  // Keeps only the valid samples (in order).
  SampleSet compacted() const;
};

// Regular res^4 grid: res points per parabolic axis at cell centres
// (-1 + (k + 0.5) * 2 / res), kept where both parabolic points lie in the unit
// disk. res = 16 gives 208 directions per disk and 43,264 pairs.
// Throws std::invalid_argument for res < 2 or res > kMaxSampleGridResolution
// (bounded memory: about 1e7 pairs at 64).
inline constexpr int kMaxSampleGridResolution = 64;
SampleSet sample_grid(const Brdf& brdf, int res);
// Directions of the res x res grid that lie in the disk (the per-disk set above).
std::vector<Vec3> grid_directions(int res);

// count pairs, Latin-hypercube stratified in (cos theta_i, phi_i, cos theta_o,
// phi_o), uniform in solid angle; deterministic for a seed.
// Throws std::invalid_argument for count == 0 or count > kMaxStratifiedCount
// (bounded memory: about 200 bytes per pair while sampling).
inline constexpr size_t kMaxStratifiedCount = 10000000;
SampleSet sample_stratified(const Brdf& brdf, size_t count, uint64_t seed);

// Evaluates brdf at the given direction pairs (values of an existing set are
// replaced) and declares brdf's symmetries (symmetries_of) for the set.
void evaluate_into(const Brdf& brdf, SampleSet& s);
// Masks (value -1, invalid) every valid sample of s at which `truth` has no
// data (Brdf::defined_at false: e.g. a MERL table's missing cells) and returns
// how many it masked. A set of truth values scored against is then scored
// only where the truth holds.
size_t mask_undefined(const Brdf& truth, SampleSet& s);

}  // namespace bf
