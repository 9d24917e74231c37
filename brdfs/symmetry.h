// Symmetries of a BRDF as data: what a model's formula gives, what a
// measurement format guarantees, what a user declares for a sample list. Fits
// of raw samples use them (expand_orbit: each sample stands for its orbit), and
// whole-domain validation against an interpolant needs them (docs/design.md
// §4.3).
//
// In the frame of brdf.h (n = +z):
//  - isotropic:  f(R wi, R wo) = f(wi, wo) for every rotation R about n;
//  - reciprocal: f(wo, wi) = f(wi, wo);
//  - bilateral:  f(M wi, M wo) = f(wi, wo) for the mirror M: y -> -y (with
//    isotropy, the mirror in every plane containing n).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "brdfs/brdf.h"

namespace bf {

struct SampleSet;

struct Symmetries {
  bool isotropic = false;
  bool reciprocal = false;
  bool bilateral = false;

  static Symmetries none() { return {}; }
  static Symmetries all() { return {true, true, true}; }
  bool any() const { return isotropic || reciprocal || bilateral; }
  // Every symmetry of o is one of these.
  bool covers(const Symmetries& o) const {
    return (isotropic || !o.isotropic) && (reciprocal || !o.reciprocal) && (bilateral || !o.bilateral);
  }
  Symmetries operator&(const Symmetries& o) const {
    return {isotropic && o.isotropic, reciprocal && o.reciprocal, bilateral && o.bilateral};
  }
  bool operator==(const Symmetries& o) const = default;
  // "isotropic+reciprocal+bilateral", or "none".
  std::string to_string() const;
};

// Parses "none" or names joined by '+' (isotropic, reciprocal, bilateral;
// each at most once). Throws std::invalid_argument naming `what`, the
// accepted names and what was found.
Symmetries parse_symmetries(const std::string& s, const std::string& what);

// What the BRDF claims: its isotropic(), reciprocal() and bilateral().
Symmetries symmetries_of(const Brdf& brdf);

// The symmetries that make a Marschner-space interpolant (MeasuredBrdf) equal
// to the measured BRDF over the whole domain: the interpolant is isotropic,
// reciprocal and bilateral by construction.
inline Symmetries interpolant_needs() { return Symmetries::all(); }

// Orbit expansion of raw samples (docs/design.md §4.3).
// Sample k (valid, weight w) is replaced by its orbit under `sym`:
//  - isotropic: rotations about n by 2 pi (j + u_k) / R, j = 0..R-1, where
//    u_k = frac(k * 0.6180339887...) staggers the angles of neighbouring
//    samples (so even R = 1 spreads the set over all azimuths);
//  - reciprocal: each of those and its swap (wi <-> wo);
//  - bilateral: each of those and its mirror (y -> -y).
// Each copy has weight w / (orbit size), so every measured sample keeps its
// total weight. R = clamp(floor(budget / (valid * m)), 1, max_rotations),
// m = (reciprocal ? 2 : 1) * (bilateral ? 2 : 1): the expansion holds at most
// about max(budget, valid * m) samples. Masked samples are dropped. With no
// symmetry the set is returned compacted. The result declares no symmetry
// (its copies already carry it) and its description says what was done.
struct OrbitOptions {
  int max_rotations = 24;
  size_t budget = 2'000'000;
};
struct OrbitInfo {
  int rotations = 1;      // R (1 when not isotropic)
  int orbit_size = 1;     // copies per sample
  size_t samples_in = 0;  // valid samples expanded
  size_t samples_out = 0;
  std::string describe() const;  // "orbit of 96 per sample (24 rotations x swap x mirror): 1295 -> 124320"
};
SampleSet expand_orbit(const SampleSet& s, const Symmetries& sym, const OrbitOptions& o = {},
                       OrbitInfo* info = nullptr);

}  // namespace bf
