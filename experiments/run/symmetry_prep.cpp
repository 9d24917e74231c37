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
  SampleSet orbit = expand_orbit(train, c.used, kRunOrbit, info);
  SampleSet out;
  out.description = orbit.description + "; each sample also fitted itself at " +
                    std::to_string(static_cast<int>(kRawShare * 100)) + "% of its weight";
  const size_t n = train.valid_count() + orbit.size();
  out.wi.reserve(n);
  out.wo.reserve(n);
  out.value.reserve(n);
  out.weight.reserve(n);
  for (size_t k = 0; k < train.size(); ++k)
    if (train.valid[k]) out.push(train.wi[k], train.wo[k], train.value[k], kRawShare * train.weight_of(k));
  for (size_t k = 0; k < orbit.size(); ++k)
    out.push(orbit.wi[k], orbit.wo[k], orbit.value[k], (1.0 - kRawShare) * orbit.weight_of(k));
  out.validate();
  if (info) info->samples_out = out.size();
  return out;
}

}  // namespace bf
