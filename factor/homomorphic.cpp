// HomomorphicFactorization evaluation and description (see homomorphic.h).
#include "factor/homomorphic.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bf {

size_t FactorTerm::mask_count() const {
  size_t n = 0;
  for (uint8_t m : mask) n += m;
  return n;
}

double FactorTerm::lookup(int c, const Eigen::Vector2d& s) const {
  const Bilinear b = bilinear(s, proj.res);
  const std::vector<float>& t = texels[c];
  return b.w[0] * t[b.idx[0]] + b.w[1] * t[b.idx[1]] + b.w[2] * t[b.idx[2]] +
         b.w[3] * t[b.idx[3]];
}

HomomorphicFactorization::HomomorphicFactorization(std::vector<FactorTerm> terms, Rgb A,
                                                   double eps, bool subtract_eps,
                                                   std::string method,
                                                   std::optional<LogRange> log_range)
    : terms_(std::move(terms)), A_(A), eps_(eps), subtract_eps_(subtract_eps),
      method_(std::move(method)), log_range_(log_range) {
  if (log_range_)
    for (int c = 0; c < 3; ++c) {
      const auto& r = (*log_range_)[c];
      if (!std::isfinite(r[0]) || !std::isfinite(r[1]) || !(r[0] <= r[1]))
        throw std::invalid_argument("factorization: log_range[" + std::to_string(c) +
                                    "] must be finite with lo <= hi, found [" +
                                    std::to_string(r[0]) + ", " + std::to_string(r[1]) + "]");
    }
  for (const FactorTerm& t : terms_) {
    const size_t n = size_t(t.proj.res) * t.proj.res;
    for (int c = 0; c < 3; ++c)
      if (t.texels[c].size() != n)
        throw std::invalid_argument("factorization: term texture has " +
                                    std::to_string(t.texels[c].size()) + " texels, expected " +
                                    std::to_string(n));
  }
  if (!A_.isFinite().all() || (A_ <= 0).any())
    throw std::invalid_argument("factorization: A must be finite and > 0");
}

Rgb HomomorphicFactorization::eval_log(const Vec3& wi, const Vec3& wo) const {
  Vec4 x[2];
  bool have[2] = {false, false};
  Rgb s = Rgb::Zero();
  for (const FactorTerm& t : terms_) {
    const int k = t.proj.param == Parameterization::WiWo ? 0 : 1;
    if (!have[k]) {
      x[k] = to_point(t.proj.param, wi, wo);
      have[k] = true;
    }
    const Eigen::Vector2d st = t.proj.texel_coords(x[k]);
    for (int c = 0; c < 3; ++c) s[c] += t.lookup(c, st);
    if (t.reciprocal) {
      const Eigen::Vector2d sc = t.proj.conjugate().texel_coords(x[k]);
      for (int c = 0; c < 3; ++c) s[c] += t.lookup(c, sc);
    }
  }
  return s;
}

Rgb HomomorphicFactorization::clamp_log(Rgb s) const {
  if (log_range_)
    for (int c = 0; c < 3; ++c) s[c] = std::clamp(s[c], (*log_range_)[c][0], (*log_range_)[c][1]);
  return s;
}

Rgb HomomorphicFactorization::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  const Rgb s = clamp_log(eval_log(wi, wo));
  Rgb f = A_ * s.exp();
  if (subtract_eps_) f -= eps_ * A_;
  // exp overflow cannot produce NaN here; clamp to the representable, non-negative range.
  return f.max(0.0).min(std::numeric_limits<double>::max());
}

bool HomomorphicFactorization::reciprocal() const {
  for (const FactorTerm& t : terms_)
    if (!t.reciprocal && !t.proj.self_conjugate()) return false;
  return true;
}

size_t HomomorphicFactorization::storage_floats() const {
  size_t n = log_range_ ? 10 : 4;
  for (const FactorTerm& t : terms_) n += 3 * t.mask_count();
  return n;
}

std::string HomomorphicFactorization::to_string() const {
  std::ostringstream os;
  os << method_ << "(" << terms_.size() << " terms, A=" << A_.transpose() << ", eps=" << eps_
     << ")";
  return os.str();
}

nlohmann::json HomomorphicFactorization::describe() const {
  nlohmann::json j;
  j["method"] = method_;
  j["form"] =
      "f = A * exp(sum over terms of t(pi(x)) [+ t(pi*(x)) if reciprocal]) [- eps*A], per RGB "
      "channel, clamped at 0; t = bilinear lookup of the term's log-space texture";
  j["A"] = {A_[0], A_[1], A_[2]};
  j["eps"] = eps_;
  j["subtract_eps"] = subtract_eps_;
  if (log_range_) {
    j["log_range"] = {{(*log_range_)[0][0], (*log_range_)[0][1]},
                      {(*log_range_)[1][0], (*log_range_)[1][1]},
                      {(*log_range_)[2][0], (*log_range_)[2][1]}};
    j["form"] = j["form"].get<std::string>() +
                "; the sum is clamped to log_range[c] = [lo, hi] before exp";
  }
  j["storage_floats"] = storage_floats();
  nlohmann::json terms = nlohmann::json::array();
  for (const FactorTerm& t : terms_) {
    nlohmann::json tj;
    tj["parameterization"] = bf::to_string(t.proj.param);
    tj["resolution"] = t.proj.res;
    tj["matrix"] = {{t.proj.P(0, 0), t.proj.P(0, 1), t.proj.P(0, 2), t.proj.P(0, 3)},
                    {t.proj.P(1, 0), t.proj.P(1, 1), t.proj.P(1, 2), t.proj.P(1, 3)}};
    const Eigen::Vector2d sc = t.proj.row_scale();
    tj["row_scale"] = {sc[0], sc[1]};
    tj["texel_coords"] = "s_r = ((P x)_r * row_scale_r + 1) / 2 * (resolution - 1); texel (i, j) at s = (i, j)";
    tj["reciprocal"] = t.reciprocal;
    tj["mask_texels"] = t.mask_count();
    if (t.rotation) tj["quaternion_pair"] = *t.rotation;
    terms.push_back(tj);
  }
  j["terms"] = terms;
  return j;
}

}  // namespace bf
