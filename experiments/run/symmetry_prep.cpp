#include "experiments/run/symmetry_prep.h"

namespace bf {

SymmetryChoice choose_symmetries(const SamplingVariant& s, const SampleSet& samples) {
  SymmetryChoice c;
  c.key = s.symmetries;
  c.declared = samples.symmetries;
  if (c.key == "off" || c.key == "none") return c;
  if (c.key == "auto") {
    if (s.kind == "measured" || s.kind == "file") c.used = c.declared;
    return c;
  }
  // Validated when the config was read (config.cpp), so this does not throw there.
  c.declared = parse_symmetries(c.key, s.where + ": sampling.symmetries");
  c.used = c.declared;
  return c;
}

SampleSet fit_set(const SampleSet& train, const SymmetryChoice& c, OrbitInfo* info) {
  if (!c.used.any()) {
    if (info) *info = {1, 1, train.valid_count(), train.valid_count()};
    return train;
  }
  return expand_orbit(train, c.used, {}, info);
}

}  // namespace bf
