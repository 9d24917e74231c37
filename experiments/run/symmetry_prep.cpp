#include "experiments/run/symmetry_prep.h"

#include <cmath>
#include <stdexcept>

namespace bf {

SymmetryChoice choose_symmetries(const SamplingVariant& s, const SampleSet& samples) {
  SymmetryChoice c;
  c.key = s.symmetries;
  c.declared = samples.symmetries;
  if (c.key == "off" || c.key == "none") return c;
  if (c.key == "auto") {
    if (s.raw()) c.used = c.declared;
  } else {
    // Validated when the config was read (config.cpp), so this does not throw there.
    c.declared = parse_symmetries(c.key, s.where + ": sampling.symmetries");
    c.used = c.declared;
  }
  c.score_orbit = samples.representatives && c.used.any();
  return c;
}

const SampleSet& scored_set(const SampleSet& s, const SymmetryChoice& c, std::optional<SampleSet>& storage) {
  if (!c.score_orbit) return s;
  storage = expand_orbit(s, c.used, kRunOrbit);
  return *storage;
}

std::string scored_over_orbit_note(const SymmetryChoice& c) {
  return "training and held-out samples scored over their orbit (" + c.used.to_string() +
         "), not at the table's phi_h = 0 alone";
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

nlohmann::json FillChoice::describe() const {
  if (!truth) return {{"used", false}, {"why", why}};
  return {{"used", true}, {"share", share}, {"pairs", pairs}, {"seed", seed}, {"truth", truth->to_string()}};
}

FillChoice choose_fill(const SamplingVariant& s, const Brdf* training, const SymmetryChoice& sym, uint64_t seed) {
  FillChoice f;
  if (s.kind != "measured" || s.fill == 0.0) {
    f.why = s.kind != "measured" ? "not raw measured samples" : "fill = \"off\"";
    return f;
  }
  std::string why = "no measured BRDF made of the training samples";
  const bool whole = training && training->whole_domain(&why);
  if (s.fill < 0.0) {
    if (!whole || !sym.used.any()) {
      f.why = !whole ? why
                     : "the fit uses no symmetries (symmetries = \"" + sym.key +
                           "\"): fill = \"auto\" fills only fits of the samples' orbit";
      return f;
    }
    f.share = kFillShare;
  } else {
    if (!whole)
      throw std::invalid_argument(s.where + ": sampling.fill: expected a measured BRDF whose interpolant holds "
                                  "over the whole domain, found: " + why + " (use fill = \"off\" or \"auto\")");
    f.share = s.fill;
  }
  f.truth = training;
  f.pairs = kFillPairs;
  f.seed = seed;
  return f;
}

SampleSet with_fill(SampleSet fit, const FillChoice& f) {
  if (!f.truth) return fit;
  double total = 0.0;
  for (size_t k = 0; k < fit.size(); ++k)
    if (fit.valid[k]) total += fit.weight_of(k);
  const SampleSet pairs = sample_stratified(*f.truth, f.pairs, f.seed);
  const size_t n = pairs.valid_count();
  if (!(total > 0.0))
    throw std::invalid_argument("sampling.fill: the fit set (" + fit.description +
                                ") has no valid sample of positive weight to add the fill's share to");
  if (n == 0)
    throw std::invalid_argument("sampling.fill: none of the " + std::to_string(f.pairs) +
                                " fill pairs has a value of the training BRDF (" + f.truth->name() +
                                "): expected a BRDF that holds over the whole domain");
  // The fill's pairs carry `share` of the final total: w n = share (total + w n).
  const double w = f.share / (1.0 - f.share) * total / double(n);
  for (size_t k = 0; k < pairs.size(); ++k)
    if (pairs.valid[k]) fit.push(pairs.wi[k], pairs.wo[k], pairs.value[k], w);
  fit.description += "; whole-domain fill: " + std::to_string(n) + " pairs of the training interpolant at " +
                     std::to_string(static_cast<int>(std::lround(f.share * 100))) + "% of the weight";
  fit.validate();
  return fit;
}

}  // namespace bf
