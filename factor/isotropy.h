// Isotropy detection by an azimuthal-invariance test on samples:
// an isotropic BRDF is unchanged when wi and wo rotate together about the
// normal, f(Rz(a) wi, Rz(a) wo) = f(wi, wo) for every angle a. The test draws
// random pairs (wi, wo) on the upper hemisphere and random angles and records
// the largest relative change
//   dev = |f(Rz wi, Rz wo) - f(wi, wo)| / (max(|f(Rz wi, Rz wo)|, |f(wi, wo)|) + floor)
// per channel, floor = floor_fraction * (mean of f over the drawn pairs), so
// that near-zero values (numerical noise far from a lobe) cannot decide.
// The BRDF counts as isotropic when dev <= rel_tol. It tests the function,
// not its isotropic() flag: a measured table that only approximately has the
// symmetry (interpolation on an anisotropic grid) may be reported anisotropic,
// which is the safe side (SH-K then keeps the full view table).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>

#include "brdfs/brdf.h"

namespace bf {

struct IsotropyOptions {
  int pairs = 256;              // random (wi, wo) pairs
  int angles = 3;               // random rotation angles per pair
  double rel_tol = 1e-3;        // isotropic when the largest relative change is <= rel_tol
  double floor_fraction = 1e-3; // floor = floor_fraction * mean f
  uint64_t seed = 1;
  void validate() const;        // throws std::invalid_argument naming the field
};

struct IsotropyResult {
  bool isotropic = true;
  double max_rel_change = 0;    // the dev above, over all pairs, angles, channels
  Vec3 worst_wi = Vec3::UnitZ(), worst_wo = Vec3::UnitZ();
  double worst_angle = 0;       // radians
  int evaluations = 0;
  int skipped = 0;              // pairs with a non-finite value (not counted)
  nlohmann::json describe() const;
};

IsotropyResult test_isotropy(const Brdf& brdf, const IsotropyOptions& opt = {});

}  // namespace bf
