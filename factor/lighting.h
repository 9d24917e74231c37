// Scene lighting for the SH baselines (notes in
// docs/design.md §9.4-9.5):
//  - lat-long environment maps (.exr, or Radiance .hdr / .pic),
//    projected onto real SH (solvers/sh.h convention) with exact quadrature
//    weights for the equiangular grid;
//  - the lighting band limit: the smallest order L capturing 1 - eps of the
//    map's energy (eq. 5.16), which caps SH orders (F_B = min(F_L, F_rho));
//  - shading of one surface point under band-limited lighting, used by the
//    shade_rmse metric (original and approximation with the same quadrature);
//  - the SHRM of Ramamoorthi & Hanrahan 2002 (reflected-radiance coefficients
//    B_lmpq = Lambda_l rho_lpq L_lm) and its evaluation B(alpha, beta, theta_o, phi_o).
//
// Lat-long convention (docs/design.md §2 angles, world frame): pixel (x, y) of a
// W x H map, W = 2H, row y = 0 at the top, holds the radiance in direction
// theta = pi (y + 1/2) / H from +z, phi = 2 pi (x + 1/2) / W from +x towards
// +y: w = (sin theta cos phi, sin theta sin phi, cos theta). Texel values are
// point samples at those centres.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "factor/sh_baseline.h"
#include "solvers/quadrature.h"
#include "solvers/sh_rotation.h"

namespace bf {

struct LatLongMap {
  int width = 0, height = 0;   // width = 2 height
  std::vector<Rgb> texels;     // row-major, y = 0 at the top
  std::string path;            // file it came from ("" when made in memory)
  const Rgb& at(int x, int y) const { return texels[size_t(y) * width + x]; }
  static Vec3 direction(int x, int y, int width, int height);
};

// Reads an environment map. Throws std::invalid_argument "<path>: ..." when
// the file is missing or unreadable, not 2:1 (W = 2H), smaller than 8 x 4,
// has channels other than R, G, B or a single grey one, or holds a NaN,
// infinite or negative texel (named by x, y and channel). A .exr is read with
// OpenEXR, a .hdr / .pic as Radiance RGBE; other extensions are refused.
LatLongMap read_latlong(const std::string& path);
// Writes a map as 32-bit float RGB (format from the extension: .exr, .hdr);
// throws std::runtime_error naming the path on failure.
void write_latlong(const std::string& path, const LatLongMap& map);
// Samples radiance(w) at the texel centres.
LatLongMap make_latlong(int width, int height, const std::function<Rgb(const Vec3&)>& radiance);

// Fejer's first rule on the equiangular rows theta_j = pi (j + 1/2) / n:
// weights w_j with sum_j w_j g(cos theta_j) = integral_{-1}^{1} g(z) dz exactly
// for polynomials g of degree <= n - 1 (all weights > 0, sum 2). These are the
// solid-angle weights of an equiangular map that make SH projection exact.
std::vector<double> fejer_weights(int n);

// Band-limited lighting: L_c(w) = sum_i coeffs[c][i] y_i(w), i < (order+1)^2.
struct ShLighting {
  int order = 0;
  std::array<Eigen::VectorXd, 3> coeffs;
  std::string source;          // "env:<path>" or "directional"
  Rgb energy = Rgb::Zero();    // integral of L_c^2 over the sphere (the map's, before truncation)
  // Cumulative captured energy fraction, worst channel, for l = 0..order
  // (fraction[l] = min_c sum_{l' <= l} sum_m coeffs^2 / energy_c; a channel
  // with zero energy counts as 1).
  std::vector<double> fraction;
  int band_limit = -1;         // measured: smallest l with fraction[l] >= 1 - eps (-1: not measured)
  double band_eps = 0;         // the eps it was measured with
  bool band_limit_reached = true;  // false: not reached up to the projection order (band_limit = that order)

  // Smallest l <= order with fraction[l] >= 1 - eps; -1 if none.
  int order_for_energy(double eps) const;
  // The first (k+1)^2 coefficients (k <= order; energy and fraction kept).
  ShLighting truncated(int k) const;
  Rgb radiance(const Vec3& w) const;
  nlohmann::json describe() const;
};

// Projection of a lat-long map up to max_order (<= H - 1 and <= W/2 - 1 so the
// rule is exact for the products y_i y_j; throws std::invalid_argument naming
// the map otherwise) with Fejer weights in theta and the uniform rule in phi.
// Exact (to rounding) for maps sampled from an SH function of order N when
// N + max_order <= H - 1 and <= W - 1. energy = the same rule applied to L^2.
// Cost O(max_order * W * H + max_order^2 * H).
ShLighting project_latlong(const LatLongMap& map, int max_order);
// Projects and measures the band limit with eps (0 < eps < 1): the returned
// lighting is truncated at the band limit (or max_order when not reached).
ShLighting environment_lighting(const LatLongMap& map, double eps, int max_order);

// A distant point light of irradiance E from direction d (unit), band-limited
// to `order`: coeffs = E y_i(d) (a delta function's projection; it rings).
ShLighting directional_lighting(const Vec3& d, const Rgb& irradiance, int order);

// Reflected radiance at a surface point under SH lighting:
//   B = sum_k w_k L(M s_k) f(s_k, wo) s_k.z,   M = [t b n] (local -> world),
// over a hemisphere rule s_k (Gauss-Legendre in cos theta x uniform phi).
// The lighting is rotated into the local frame once (ShFastRotator, O(L^3))
// and evaluated separably at the nodes. f is Brdf::eval (a factorization's
// eval, i.e. its f, multiplied back by cos theta_i here). Non-finite BRDF
// values count in *nonfinite and contribute 0.
class LitShader {
 public:
  // nodes_theta = 0: auto max(16, L + 8); nodes_phi = 0: auto 2 nodes_theta.
  explicit LitShader(std::shared_ptr<const ShLighting> lighting, int nodes_theta = 0, int nodes_phi = 0);
  Rgb shade(const Brdf& f, const Vec3& n, const Vec3& t, const Vec3& b, const Vec3& wo_world,
            size_t* nonfinite = nullptr) const;
  // Local-frame lighting coefficients D(M^T) L per channel ((L+1)^2 each).
  std::array<Eigen::VectorXd, 3> local_coefficients(const Eigen::Matrix3d& M) const;
  const SphereRule& rule() const { return rule_; }
  const ShLighting& lighting() const { return *lighting_; }

 private:
  std::shared_ptr<const ShLighting> lighting_;
  ShFastRotator rot_;
  SphereRule rule_;
  int nz_ = 0, nphi_ = 0;
  Eigen::MatrixXd plm_;            // nz x legendre count: p_lm(z_j)
  Eigen::MatrixXd cosm_, sinm_;    // nphi x (L+1)
};

// ================================================================ SHRM

// Spherical-harmonic reflection map (Ramamoorthi & Hanrahan 2002 §4, App. A,
// in this toolkit's real SH): with the isotropic coefficients rho_lpq of
// sh-r (ShrFactorization) and lighting L_lm,
//   B_lmpq = Lambda_l rho_{l p |q|} L_lm,   Lambda_l = sqrt(4 pi / (2l + 1)),
// l <= F_B = min(F, L), |m| <= l, p <= P, |q| <= min(l, p). For a reflection
// direction R = (alpha, beta) (polar, azimuth), frame M = R_z(beta) R_y(alpha)
// (M z = R) and the view in that frame V = M^T v = (theta_o, phi_o):
//   B_pq(alpha, beta) = sum_{l,m} Lambda_l^{-1} B_lmpq D^l_{qm}(M^T)
//   B(alpha, beta, theta_o, phi_o) = sum_{p,q} B_pq(alpha, beta) y_pq(theta_o, phi_o)
// which equals the integral of L(w) rho_hat(w, v) over the sphere for the
// truncated rho_hat series (the real-SH form of 004 eq. 6 / App. A; derivation
// in docs/experiments.md "SHRM").
class Shrm {
 public:
  Shrm(const ShrFactorization& shr, const ShLighting& lighting);
  int order() const { return F_; }
  int view_order() const { return P_; }
  // Stored coefficients B_lmpq per channel (3 x count).
  size_t coefficient_count() const;
  size_t storage_floats() const { return 3 * coefficient_count(); }
  double coefficient(int c, int l, int m, int p, int q) const;
  // B for reflection direction R (unit) and global view v (unit).
  Rgb eval(const Vec3& R, const Vec3& v) const;
  // Same with the angles of R and the view in the R frame.
  Rgb eval_angles(double alpha, double beta, double theta_o, double phi_o) const;
  // Shading of a surface point: R = reflect(v) about n; 0 when n.v <= 0.
  Rgb shade(const Vec3& n, const Vec3& v) const;
  nlohmann::json to_json() const;  // coefficients and conventions (the export)
  double seconds() const { return seconds_; }

 private:
  int F_ = 0, P_ = 0;
  // B_[c][(l^2 + l + m) * Npq + pq], pq = p^2 + p + q (|q| <= p; 0 where |q| > l).
  std::array<std::vector<double>, 3> B_;
  // Evaluation matrix: row sh_index(l, m), column c * Npq + pq, B_lmpq / Lambda_l.
  Eigen::MatrixXd Bs_;
  int npq_ = 0;
  ShFastRotator rot_;
  double seconds_ = 0;
};

}  // namespace bf
