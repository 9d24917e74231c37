// The homomorphic (log-space) factorization of McCool / Cole:
//   f(wi, wo) ~= A * exp( sum_j  t_j(pi_j(x)) [+ t_j(pi_j*(x)) if reciprocal] )  [- eps*A]
// per RGB channel, with x the point of (wi, wo) in the term's parameterization,
// t_j the term's log-space texture read with bilinear interpolation, and A the
// per-channel mean of f over the fitted samples (docs/design.md §2). With a
// log range [lo_c, hi_c] (the fit's, docs/design.md §3.2 "log-range clamp"),
// the summed log value is clamped to it before exp:
//   f_c = A_c * exp(clamp(s_c, lo_c, hi_c)) [- eps*A_c].
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "factor/factorization.h"
#include "factor/projection.h"

namespace bf {

struct FactorTerm {
  Projection proj;
  bool reciprocal = false;  // texture also read through proj.conjugate()
  // Log-space texels, per channel, res*res floats (index j*res+i). Stored as
  // float: this is exactly what the EXR export holds, so a reloaded export
  // evaluates bit-identically. Texels outside `mask` are 0 and never read by
  // points inside the 4-cube.
  std::array<std::vector<float>, 3> texels;
  std::vector<uint8_t> mask;  // projection_mask(proj), 1 = unknown of the fit
  // Where the projection came from, if from a 4D rotation: the quaternion pair
  // (S, T), each [w, x, y, z]. Informational (export, manifest).
  std::optional<std::array<double, 8>> rotation;

  size_t mask_count() const;
  // Bilinear lookup of the log texture, channel c, at texture coordinates s.
  double lookup(int c, const Eigen::Vector2d& s) const;
};

// Per channel [lo, hi] of the log-space sum s (see the header comment).
using LogRange = std::array<std::array<double, 2>, 3>;

class HomomorphicFactorization final : public Factorization {
 public:
  // log_range: none = no clamp. Throws std::invalid_argument unless every
  // bound is finite and lo <= hi.
  HomomorphicFactorization(std::vector<FactorTerm> terms, Rgb A, double eps, bool subtract_eps,
                           std::string method, std::optional<LogRange> log_range = std::nullopt);

  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  // Log-space model value sum_j t_j(...) per channel (no A, no eps, no clamp).
  Rgb eval_log(const Vec3& wi, const Vec3& wo) const;
  // s clamped to the log range (s itself when there is none).
  Rgb clamp_log(Rgb s) const;
  std::string name() const override { return method_; }
  std::string to_string() const override;
  bool reciprocal() const override;
  bool isotropic() const override { return false; }
  std::string method() const override { return method_; }
  // Masked texels x 3 channels for every term, + 3 (A) + 1 (eps) [+ 6 (log range)].
  size_t storage_floats() const override;
  nlohmann::json describe() const override;
  // Outputs (factor/factorization.h), defined in factor/export.cpp.
  ExportedFiles write_export_files(const std::string& dir, const std::string& stem,
                                   const std::string& origin) const override;
  std::string glsl(const std::string& stem, const std::string& origin) const override;
  std::optional<ShaderView> viewer_data() const override;

  const std::vector<FactorTerm>& terms() const { return terms_; }
  const Rgb& A() const { return A_; }
  double eps() const { return eps_; }
  bool subtract_eps() const { return subtract_eps_; }
  const std::optional<LogRange>& log_range() const { return log_range_; }

 private:
  std::vector<FactorTerm> terms_;
  Rgb A_;
  double eps_;
  bool subtract_eps_;
  std::string method_;
  std::optional<LogRange> log_range_;
};

}  // namespace bf
