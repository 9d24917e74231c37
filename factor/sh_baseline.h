// Spherical-harmonic baselines (docs/design.md §9):
//  - SH-K (Kautz, Sloan & Snyder 2002): per view direction v on a parabolic
//    grid, the SH coefficients of the product function f*(s, v) = f(s, v) max(0, s.z),
//    any BRDF including anisotropic and measured ones;
//  - SH-R (Ramamoorthi & Hanrahan 2002): an isotropic BRDF's product function
//    reparameterized about the reflection vector, as coefficients rho_lpq with
//    orders (F, P) chosen as the smallest capturing 1 - eps of the energy; plus
//    the radially symmetric ("1D") case used for Phong's order rule.
// Both represent f* = f cos(theta_i), so score them on cos_rmse: eval() returns
// f*/max(cos theta_i, min_cos) only because the Brdf interface wants f, and
// dividing by cos at grazing angles amplifies their error (pitfall P4).
// Orders are band limits: order F means l = 0..F, (F+1)^2 coefficients
// (Kautz's "25 coefficients, fifth order" is F = 4).
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "factor/svd_baseline.h"  // DiskGrid, Tolerance, SizeChoice
#include "solvers/sh.h"

namespace bf {

// ================================================================ SH-K

struct ShkOptions {
  // Ranges checked by validate() (and shown by the config reader and docs).
  static constexpr int kMaxOrder = 100, kMaxTextureSize = 512, kMaxThetaNodes = 4096, kMaxPhiNodes = 8192;
  int order = 4;            // band limit F >= 0: (F+1)^2 coefficients per view texel
  int view_res = 32;        // texture_size: view_res x view_res parabolic view grid (DiskGrid), 2..512
  // Quadrature over the upper hemisphere of s: theta_nodes Gauss-Legendre nodes
  // in cos(theta) on [0, 1] times phi_nodes uniform nodes in phi. It is exact
  // when f*(., v) has order <= G on the hemisphere and
  // theta_nodes >= (F + G)/2 + 1, phi_nodes >= F + G + 1.
  int theta_nodes = 0;      // 0 = auto: max(2F + 2, 24)
  int phi_nodes = 0;        // 0 = auto: max(4F + 4, 48)
  double rim_inset = 1e-4;  // DiskGrid: view texels beyond radius 1 - rim_inset are pulled in; (0, 0.1]
  double min_cos = 1e-2;    // eval() divides f* by max(cos theta_i, min_cos); (0, 1]
  bool float_textures = false;  // round coefficients to float (what an EXR export holds)
  // Reduced storage for an isotropic BRDF: only the views of azimuth phi_v = 0,
  // view_res texels at parabolic radii r_j = j/(view_res - 1) (pulled in to
  // 1 - rim_inset like DiskGrid), linear in r; a view of azimuth phi_v reads
  // c(wo) = D(R_z(phi_v)) c(r(wo)) (exact for isotropic f: rotating wi and wo
  // together about n leaves f unchanged). fit_shk checks the BRDF with
  // test_isotropy (factor/isotropy.h) and throws when it is anisotropic.
  bool reduced = false;
  int auto_theta_nodes() const;
  int auto_phi_nodes() const;
  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
};

// c_i(v) = integral over the upper hemisphere of y_i(s) f(s, v) s.z ds, i < (F+1)^2,
// tabulated at the view texels of a DiskGrid and read by bilinear
// interpolation in p(v); f*(s, v) ~= sum_i c_i(v) y_i(s) for s on the whole
// sphere (the projection of a function that is 0 below the horizon, i.e. the
// least-squares fit over the sphere; Kautz et al. §3).
class ShkFactorization final : public Factorization {
 public:
  // coeffs[c]: (F+1)^2 x grid.count(), column a = view texel grid.texels[a];
  // reduced: (F+1)^2 x view_res, column j = radius r_j on the phi_v = 0 line.
  ShkFactorization(const ShkOptions& opt, DiskGrid grid, std::array<Eigen::MatrixXd, 3> coeffs,
                   double seconds);

  // f*/max(cos theta_i, min_cos); 0 when wi or wo is below the horizon.
  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  // The SH series f*(wi, wo) = sum_i c_i(p(wo)) y_i(wi) for any unit wi (below
  // the horizon it is the leak of the truncated series); 0 when wo.z <= 0. Not clamped.
  Rgb eval_product(const Vec3& wi, const Vec3& wo) const;
  // Coefficients at a view direction (bilinear in p(wo)); 3 columns (RGB).
  Eigen::MatrixXd coefficients_at(const Vec3& wo) const;
  std::string name() const override { return "sh-k"; }
  std::string to_string() const override;
  bool isotropic() const override { return opt_.reduced; }
  bool reciprocal() const override { return false; }
  std::string method() const override { return "sh-k"; }
  // Masked view texels x (F+1)^2 x 3; reduced: view_res x (F+1)^2 x 3.
  size_t storage_floats() const override;
  nlohmann::json describe() const override;
  // Outputs (factor/factorization.h), defined in factor/baseline_export.cpp.
  ExportedFiles write_export_files(const std::string& dir, const std::string& stem,
                                   const std::string& origin) const override;
  std::string glsl(const std::string& stem, const std::string& origin) const override;
  std::optional<ShaderView> viewer_data() const override;

  int order() const { return opt_.order; }
  const ShkOptions& options() const { return opt_; }
  const DiskGrid& grid() const { return grid_; }
  // (F+1)^2 x grid().count() coefficient matrix of channel c.
  const Eigen::MatrixXd& coefficients(int c) const { return coeffs_[c]; }
  // Full view_res^2 texture of coefficient i (sh_index(l, m)), channel c, 0 outside the mask
  // (reduced: coefficients_at evaluated at the masked texels' directions).
  std::vector<double> texture(int c, int i) const;
  // The order-k prefix (k <= order()): same projections, fewer bands.
  std::shared_ptr<ShkFactorization> truncated(int k) const;
  double seconds() const { return seconds_; }
  // Ringing check (pitfall P1), filled by fit_shk: over the view texels inside
  // the disk and the quadrature nodes, the smallest reconstructed f* and the
  // fraction of (view, node, channel) triples where it is < 0.
  double min_product = 0, negative_fraction = 0;

 private:
  ShkOptions opt_;
  DiskGrid grid_;
  ShBasis basis_;
  std::array<Eigen::MatrixXd, 3> coeffs_;
  double seconds_ = 0;
};

// Projects brdf (any, including anisotropic; a measured BRDF is resampled by
// its own eval) at every view texel. Cost: view texels x theta_nodes x
// phi_nodes BRDF evaluations plus one matrix product of that size x (F+1)^2.
// Throws std::invalid_argument from opt.validate() or when the BRDF returns a
// negative or non-finite value.
std::shared_ptr<ShkFactorization> fit_shk(const Brdf& brdf, const ShkOptions& opt);

// Smallest order F <= max_order whose SH-K approximation scores <= tol on
// samples. Fits at F = 2, 6, 14, 30, ... (capped at max_order, e.g. the
// scene's lighting band limit) and scores the truncations F' <= F not yet
// scored, stopping at the first that reaches tol: the work is at most about
// twice that of a fit at the chosen order. base.order is ignored.
SizeChoice select_shk_order(const Brdf& brdf, const SampleSet& samples, const ShkOptions& base,
                            const Tolerance& tol, int max_order);

// ================================================================ SH-R

// Reparameterization about the reflection vector (Ramamoorthi & Hanrahan
// 2002 §3.1; construction of notes §1.3.2): with R = z, V = (sin to, 0, cos to),
// L = (sin ti cos phi, -sin ti sin phi, cos ti) and N = normalize(R + V), the
// product function is rho_hat(ti, to, phi) = f(L, V) max(0, N.L), L and V
// expressed in a tangent frame of N. to = 2 theta_v lies in [0, pi).
struct ShrOptions {
  // Ranges checked by validate() (and shown by the config reader and docs).
  static constexpr int kMaxOrder = 200, kMaxViewOrder = 32, kMaxNodes = 100000;
  int max_order = 60;       // F cap: l = 0..F over theta_i' (about R)
  int max_view_order = 8;   // P cap: p = 0..P over theta_o'
  // Orders: the smallest (F, P) capturing 1 - energy_eps of the energy in
  // every channel (notes §2.5: P minimal at F = max_order, then F minimal),
  // unless order and view_order are both >= 0 (fixed orders, <= the caps).
  double energy_eps = 0.03;
  int order = -1, view_order = -1;
  // Quadrature: Gauss-Legendre in cos theta_i' on [-1, 1], Gauss-Legendre in
  // cos theta_o' on [-1, 1] (never at the singular to = pi), uniform phi.
  int theta_i_nodes = 0;    // 0 = auto: max(4 max_order + 4, 160)
  int theta_o_nodes = 0;    // 0 = auto: max(8 max_view_order + 8, 96)
  int phi_nodes = 0;        // 0 = auto: max(4 max_order + 4, 128)
  double min_cos = 1e-2;    // eval() divides rho_hat by max(cos theta_i, min_cos)
  int auto_theta_i_nodes() const;
  int auto_theta_o_nodes() const;
  int auto_phi_nodes() const;
  void validate() const;
};

// rho_hat(ti, to, phi) = sum_{l<=F} sum_{p<=P} sum_{q=0}^{min(l,p)} U_q rho_lpq p_lq(cos ti) p_pq(cos to) cos(q phi),
// U_0 = 1, U_q = 2, p_lq the normalized Legendre functions of solvers/sh.h;
// rho_lpq = 2 pi * integral rho_hat p_lq p_pq cos(q phi) d(cos ti) d(cos to) dphi.
// Parseval: sum over l, p and q = -min..min of rho_lpq^2 equals the energy
// 2 pi * integral rho_hat^2 (notes §1.3.3).
struct ShrCoefficients {
  int F = 0, P = 0;                       // orders held (the caps)
  std::array<std::vector<double>, 3> rho; // per channel, index(l, p, q); 0 where q > min(l, p)
  Rgb energy = Rgb::Zero();               // total energy per channel (same quadrature)
  double seconds = 0;
  int index(int l, int p, int q) const { return (l * (P + 1) + p) * (P + 1) + q; }
  double at(int c, int l, int p, int q) const { return rho[c][index(l, p, q)]; }
  // Energy captured by orders (f, p) over total, the smallest over the channels
  // (a channel with zero energy counts as 1).
  double accuracy(int f, int p) const;
};
// Throws std::invalid_argument for an anisotropic BRDF (use SH-K) or invalid options.
ShrCoefficients shr_coefficients(const Brdf& brdf, const ShrOptions& opt);

struct ShrOrders {
  int F = 0, P = 0;
  double accuracy = 0;  // ShrCoefficients::accuracy(F, P)
  bool reached = false; // accuracy >= 1 - eps; false: (F, P) are the caps
};
// Notes §2.5: P minimal with accuracy(F_cap, P) >= 1 - eps, then F minimal with
// accuracy(F, P) >= 1 - eps.
ShrOrders select_shr_orders(const ShrCoefficients& coeffs, double eps);
// Stored coefficients (q >= 0) of orders (F, P): sum_p [p(p+1)/2 + (F-p+1)(p+1)].
size_t shr_coefficient_count(int F, int P);

class ShrFactorization final : public Factorization {
 public:
  // Keeps the coefficients of orders (F, P) <= the caps of `all`.
  ShrFactorization(const ShrCoefficients& all, int F, int P, double min_cos, double eps_used,
                   double seconds);
  // rho_hat/max(cos theta_i, min_cos); 0 below the horizon.
  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  // rho_hat(wi, wo): the series above (clamped cosine included), any unit wi; not clamped.
  Rgb eval_product(const Vec3& wi, const Vec3& wo) const;
  std::string name() const override { return "sh-r"; }
  std::string to_string() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }
  std::string method() const override { return "sh-r"; }
  // shr_coefficient_count(F, P) x 3.
  size_t storage_floats() const override;
  nlohmann::json describe() const override;
  // Outputs (factor/factorization.h), defined in factor/baseline_export.cpp.
  ExportedFiles write_export_files(const std::string& dir, const std::string& stem,
                                   const std::string& origin) const override;
  std::string glsl(const std::string& stem, const std::string& origin) const override;
  std::optional<ShaderView> viewer_data() const override;
  int order() const { return F_; }
  int view_order() const { return P_; }
  double accuracy() const { return accuracy_; }
  // rho_lpq of channel c (0 <= q <= min(l, p)).
  double coefficient(int c, int l, int p, int q) const;

 private:
  int F_, P_;
  std::array<std::vector<double>, 3> rho_;  // index (l * (P+1) + p) * (P+1) + q
  double min_cos_, eps_used_, accuracy_, seconds_;
  Rgb energy_;
};

// Coefficients at the caps, orders by energy (or fixed), factorization.
std::shared_ptr<ShrFactorization> fit_shr(const Brdf& brdf, const ShrOptions& opt);

// Orders (F, P) by a metric tolerance on samples instead of the energy rule:
// one projection at the caps (opt.max_order, e.g. the scene's lighting band
// limit, and opt.max_view_order), then P minimal with (F_cap, P) scoring <= tol,
// then F minimal at that P by bisection (assumes the error does not grow with
// F). Not reached: (F_cap, best P). value = F, view_order = P.
// opt.order/view_order/energy_eps are ignored.
SizeChoice select_shr_orders_by_metric(const Brdf& brdf, const SampleSet& samples,
                                       const ShrOptions& opt, const Tolerance& tol);

// Radially symmetric ("1D") product functions rho_hat(u), u = cos of the angle
// to the lobe axis (Phong: (s+1)/(2 pi) u^s about R): coefficients
// rho_l = 2 pi * integral_{u_min}^{1} rho_hat(u) p_l0(u) du, l <= order, and the
// energy 2 pi * integral rho_hat^2 du, by `nodes`-point Gauss-Legendre on
// [u_min, 1] (rho_hat = 0 below u_min; exact for a polynomial rho_hat of
// degree d when nodes >= (d + order)/2 + 1).
struct ZonalCoefficients {
  std::vector<double> rho;  // order + 1 values
  double energy = 0;
  // Smallest F with sum_{l<=F} rho_l^2 >= (1 - eps) energy; -1 if none <= order.
  int order_for_energy(double eps) const;
};
ZonalCoefficients zonal_coefficients(const std::function<double(double)>& rho_hat, int order,
                                     int nodes, double u_min = -1.0);

}  // namespace bf
