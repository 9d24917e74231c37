// SampleSet and its builders (see sampleset.h).
#include "brdfs/sampleset.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

#include "brdfs/directions.h"

namespace bf {

size_t SampleSet::valid_count() const {
  return static_cast<size_t>(std::count(valid.begin(), valid.end(), uint8_t{1}));
}

void SampleSet::push(const Vec3& i, const Vec3& o, const Rgb& v, double w) {
  wi.push_back(i);
  wo.push_back(o);
  value.push_back(v);
  if (!weight.empty() || w != 1.0) {
    if (weight.empty()) weight.assign(wi.size() - 1, 1.0);
    weight.push_back(w);
  }
  valid.push_back(1);
}

void SampleSet::validate() {
  invalid_value = invalid_horizon = invalid_weight = 0;
  valid.assign(size(), 1);
  for (size_t k = 0; k < size(); ++k) {
    if (!(wi[k].z() > 0.0) || !(wo[k].z() > 0.0) || !wi[k].allFinite() || !wo[k].allFinite()) {
      ++invalid_horizon;
      valid[k] = 0;
    } else if (!value[k].isFinite().all() || (value[k] < 0.0).any()) {
      ++invalid_value;
      valid[k] = 0;
    } else if (!weight.empty() && (!std::isfinite(weight[k]) || weight[k] < 0.0)) {
      ++invalid_weight;
      valid[k] = 0;
    }
  }
}

std::string SampleSet::summary() const {
  std::ostringstream os;
  const size_t masked = size() - valid_count();
  os << size() << " samples (" << masked << " masked";
  if (masked)
    os << ": " << invalid_value << " value, " << invalid_horizon << " horizon, " << invalid_weight
       << " weight";
  os << ")";
  return os.str();
}

SampleSet SampleSet::compacted() const {
  SampleSet out;
  out.description = description;
  out.symmetries = symmetries;
  out.representatives = representatives;
  for (size_t k = 0; k < size(); ++k)
    if (valid[k]) out.push(wi[k], wo[k], value[k], weight_of(k));
  out.validate();
  return out;
}

std::vector<Vec3> grid_directions(int res) {
  if (res < 2 || res > 256)
    throw std::invalid_argument("grid resolution: expected 2..256, found " + std::to_string(res));
  std::vector<Vec3> dirs;
  for (int j = 0; j < res; ++j)
    for (int i = 0; i < res; ++i) {
      const Vec2 p(-1.0 + (i + 0.5) * 2.0 / res, -1.0 + (j + 0.5) * 2.0 / res);
      if (p.squaredNorm() <= 1.0) dirs.push_back(parabolic_inverse(p));
    }
  return dirs;
}

void evaluate_into(const Brdf& brdf, SampleSet& s) {
  s.value.resize(s.size());
  for (size_t k = 0; k < s.size(); ++k) s.value[k] = brdf.eval(s.wi[k], s.wo[k]);
  s.symmetries = symmetries_of(brdf);  // the values are brdf's: what it claims, they hold
  s.validate();
}

size_t mask_undefined(const Brdf& truth, SampleSet& s) {
  size_t n = 0;
  for (size_t k = 0; k < s.size(); ++k)
    if (s.valid[k] && !truth.defined_at(s.wi[k], s.wo[k])) {
      s.value[k] = Rgb::Constant(-1.0);
      ++n;
    }
  if (n > 0) s.validate();
  return n;
}

SampleSet sample_grid(const Brdf& brdf, int res) {
  if (res < 2 || res > kMaxSampleGridResolution)
    throw std::invalid_argument("grid resolution: expected 2.." + std::to_string(kMaxSampleGridResolution) +
                                " for a sample grid (res^4 pairs: 64 gives about 1e7), found " +
                                std::to_string(res));
  const std::vector<Vec3> dirs = grid_directions(res);
  SampleSet s;
  s.wi.reserve(dirs.size() * dirs.size());
  s.wo.reserve(dirs.size() * dirs.size());
  for (const Vec3& i : dirs)
    for (const Vec3& o : dirs) {
      s.wi.push_back(i);
      s.wo.push_back(o);
    }
  s.description = "grid " + std::to_string(res) + "^4 (" + std::to_string(dirs.size()) +
                  " directions per disk) of " + brdf.to_string();
  evaluate_into(brdf, s);
  return s;
}

SampleSet sample_stratified(const Brdf& brdf, size_t count, uint64_t seed) {
  // About 200 bytes per pair while building (stratification tables and the set).
  if (count == 0 || count > kMaxStratifiedCount)
    throw std::invalid_argument("stratified count: expected 1.." + std::to_string(kMaxStratifiedCount) +
                                " (about 2 GB while sampling), found " + std::to_string(count));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<std::vector<double>> u(4, std::vector<double>(count));
  for (int d = 0; d < 4; ++d) {
    std::vector<size_t> perm(count);
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), rng);
    for (size_t k = 0; k < count; ++k) u[d][k] = (perm[k] + U(rng)) / double(count);
  }
  SampleSet s;
  for (size_t k = 0; k < count; ++k) {
    // z in (0, 1]: uniform solid angle on the hemisphere; keep z away from 0.
    const double zi = std::max(1.0 - u[0][k], 1e-9), zo = std::max(1.0 - u[2][k], 1e-9);
    s.wi.push_back(from_spherical(std::acos(zi), 2.0 * M_PI * u[1][k]));
    s.wo.push_back(from_spherical(std::acos(zo), 2.0 * M_PI * u[3][k]));
  }
  s.description = "stratified " + std::to_string(count) + " (seed " + std::to_string(seed) +
                  ") of " + brdf.to_string();
  evaluate_into(brdf, s);
  return s;
}

}  // namespace bf
