// Real orthonormal spherical harmonics (SH) and normalized associated Legendre
// functions, evaluated with the stable three-term recurrences in double
// precision (accurate to l = 60 and well beyond; no factorials, no overflow).
//
// Conventions (docs/design.md §9), fixed for the whole toolkit:
//  - Order F is a band limit: l = 0..F, (F+1)^2 coefficients. Kautz et al.'s
//    "fifth order, 25 coefficients" is F = 4 here.
//  - Flat index i = l*(l+1) + m, m = -l..l.
//  - Normalized Legendre p_lm(x), 0 <= m <= l, WITHOUT the Condon-Shortley
//    phase, normalized so that 2*pi * integral_{-1}^{1} p_lm(x)^2 dx = 1:
//      p_00 = 1/sqrt(4 pi);  p_mm = sqrt((2m+1)/(2m)) sin(theta) p_{m-1,m-1};
//      p_{m+1,m} = sqrt(2m+3) x p_mm;
//      p_lm = a_lm (x p_{l-1,m} - b_lm p_{l-2,m}),
//      a_lm = sqrt((4l^2-1)/(l^2-m^2)),  b_lm = sqrt(((l-1)^2-m^2)/(4(l-1)^2-1)).
//    (p_lm equals the papers' f_lm = N_lm P_lm(cos theta) up to the sign (-1)^m.)
//  - Real SH, theta from +z, phi from +x towards +y (docs/design.md §2):
//      y_{l,0}  = p_l0(cos theta)
//      y_{l,m}  = sqrt(2) p_lm(cos theta) cos(m phi)   (m > 0)
//      y_{l,-m} = sqrt(2) p_lm(cos theta) sin(m phi)   (m > 0)
//    so y_00 = 1/sqrt(4 pi), y_{1,-1} = sqrt(3/(4 pi)) y, y_{1,0} = sqrt(3/(4 pi)) z,
//    y_{1,1} = sqrt(3/(4 pi)) x (positive signs: no Condon-Shortley phase).
//    Orthonormal over the unit sphere: integral y_i y_j ds = delta_ij.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace bf {

// Number of coefficients of an order-F expansion: (F+1)^2.
constexpr int sh_count(int order) { return (order + 1) * (order + 1); }
// Flat index of (l, m), |m| <= l: l*(l+1) + m.
constexpr int sh_index(int l, int m) { return l * (l + 1) + m; }
// Index of p_lm (0 <= m <= l) in a triangular Legendre table: l*(l+1)/2 + m.
constexpr int legendre_index(int l, int m) { return l * (l + 1) / 2 + m; }

// p_lm(x) for l = m..lmax into out[l - m] (lmax - m + 1 values); x = cos(theta)
// in [-1, 1], sin(theta) = sqrt((1-x)(1+x)) >= 0. Requires 0 <= m <= lmax.
void legendre_normalized_column(int m, int lmax, double x, double* out);
// All p_lm(x), 0 <= m <= l <= lmax, into out[legendre_index(l, m)]
// ((lmax+1)(lmax+2)/2 values).
void legendre_normalized(int lmax, double x, double* out);
// Unnormalized Legendre polynomial P_l(x) (Bonnet's recurrence), P_l(1) = 1.
double legendre_p(int l, double x);

// Real SH basis of one order with the recurrence coefficients precomputed:
// the fast path for evaluating many directions (same values as sh_eval()).
class ShBasis {
 public:
  // order F in 0..2000; throws std::invalid_argument otherwise.
  explicit ShBasis(int order);
  int order() const { return order_; }
  int size() const { return sh_count(order_); }
  // y_i(w), i < size(), into y. w: direction (normalized internally; w != 0).
  void eval(const Eigen::Vector3d& w, double* y) const;
  Eigen::VectorXd eval(const Eigen::Vector3d& w) const;
  // p_lm(x), 0 <= m <= l <= order, into p[legendre_index(l, m)]; sin(theta) = s.
  void legendre(double x, double s, double* p) const;

 private:
  int order_;
  std::vector<double> a_, b_;  // a_lm, b_lm at legendre_index(l, m), l >= m + 2
  std::vector<double> diag_;   // sqrt((2m+1)/(2m)), m >= 1
};

// y_i(w) for one direction, order F ((F+1)^2 values). Convenience wrapper
// around ShBasis for the occasional call.
Eigen::VectorXd sh_eval(int order, const Eigen::Vector3d& w);

}  // namespace bf
