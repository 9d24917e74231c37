// Real orthonormal spherical harmonics by the normalized recurrences (see sh.h).
#include "solvers/sh.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bf {

namespace {
constexpr double kInvSqrt4Pi = 0.28209479177387814347;  // 1/sqrt(4 pi)

double sin_of_cos(double x) {
  const double s2 = (1.0 - x) * (1.0 + x);
  return s2 > 0.0 ? std::sqrt(s2) : 0.0;
}
}  // namespace

void legendre_normalized_column(int m, int lmax, double x, double* out) {
  if (m < 0 || m > lmax)
    throw std::invalid_argument("legendre: expected 0 <= m <= lmax, found m=" +
                                std::to_string(m) + ", lmax=" + std::to_string(lmax));
  const double s = sin_of_cos(x);
  double pmm = kInvSqrt4Pi;
  for (int k = 1; k <= m; ++k) pmm *= std::sqrt((2.0 * k + 1.0) / (2.0 * k)) * s;
  out[0] = pmm;
  if (lmax == m) return;
  out[1] = std::sqrt(2.0 * m + 3.0) * x * pmm;
  for (int l = m + 2; l <= lmax; ++l) {
    const double l2 = double(l) * l, m2 = double(m) * m, lm1 = l - 1.0;
    const double a = std::sqrt((4.0 * l2 - 1.0) / (l2 - m2));
    const double b = std::sqrt((lm1 * lm1 - m2) / (4.0 * lm1 * lm1 - 1.0));
    out[l - m] = a * (x * out[l - 1 - m] - b * out[l - 2 - m]);
  }
}

void legendre_normalized(int lmax, double x, double* out) {
  std::vector<double> col(lmax + 1);
  for (int m = 0; m <= lmax; ++m) {
    legendre_normalized_column(m, lmax, x, col.data());
    for (int l = m; l <= lmax; ++l) out[legendre_index(l, m)] = col[l - m];
  }
}

double legendre_p(int l, double x) {
  if (l < 0) throw std::invalid_argument("legendre_p: expected l >= 0, found " + std::to_string(l));
  if (l == 0) return 1.0;
  double p0 = 1.0, p1 = x;
  for (int k = 2; k <= l; ++k) {
    const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  return p1;
}

ShBasis::ShBasis(int order) : order_(order) {
  if (order < 0 || order > 2000)
    throw std::invalid_argument("sh order: expected 0..2000, found " + std::to_string(order));
  const int n = legendre_index(order, order) + 1;
  a_.assign(n, 0.0);
  b_.assign(n, 0.0);
  for (int m = 0; m <= order; ++m)
    for (int l = m + 2; l <= order; ++l) {
      const double l2 = double(l) * l, m2 = double(m) * m, lm1 = l - 1.0;
      a_[legendre_index(l, m)] = std::sqrt((4.0 * l2 - 1.0) / (l2 - m2));
      b_[legendre_index(l, m)] = std::sqrt((lm1 * lm1 - m2) / (4.0 * lm1 * lm1 - 1.0));
    }
  diag_.assign(order + 1, 0.0);
  for (int m = 1; m <= order; ++m) diag_[m] = std::sqrt((2.0 * m + 1.0) / (2.0 * m));
}

void ShBasis::legendre(double x, double s, double* p) const {
  double pmm = kInvSqrt4Pi;
  for (int m = 0; m <= order_; ++m) {
    if (m > 0) pmm *= diag_[m] * s;
    p[legendre_index(m, m)] = pmm;
    if (m == order_) break;
    double p2 = pmm, p1 = std::sqrt(2.0 * m + 3.0) * x * pmm;
    p[legendre_index(m + 1, m)] = p1;
    for (int l = m + 2; l <= order_; ++l) {
      const int k = legendre_index(l, m);
      const double p0 = a_[k] * (x * p1 - b_[k] * p2);
      p[k] = p0;
      p2 = p1;
      p1 = p0;
    }
  }
}

void ShBasis::eval(const Eigen::Vector3d& w, double* y) const {
  const double n = w.norm();
  const double x = w.x() / n, yy = w.y() / n, z = w.z() / n;
  const double rho = std::hypot(x, yy);
  // Unit azimuth vector (cos phi, sin phi); at the poles every m > 0 term has
  // the factor sin^m(theta) = 0, so any phi works.
  const double c1 = rho > 0.0 ? x / rho : 1.0;
  const double s1 = rho > 0.0 ? yy / rho : 0.0;
  // Stack buffer for small orders, heap otherwise.
  constexpr int kStack = 32;
  double stack[(kStack + 1) * (kStack + 2) / 2];
  std::vector<double> heap;
  double* p = stack;
  if (order_ > kStack) {
    heap.resize(legendre_index(order_, order_) + 1);
    p = heap.data();
  }
  legendre(std::clamp(z, -1.0, 1.0), rho, p);
  constexpr double kSqrt2 = 1.41421356237309504880;
  double cm = 1.0, sm = 0.0;  // cos(m phi), sin(m phi)
  for (int m = 0; m <= order_; ++m) {
    if (m > 0) {
      const double c = cm * c1 - sm * s1;
      sm = sm * c1 + cm * s1;
      cm = c;
    }
    for (int l = m; l <= order_; ++l) {
      const double v = p[legendre_index(l, m)];
      if (m == 0) {
        y[sh_index(l, 0)] = v;
      } else {
        y[sh_index(l, m)] = kSqrt2 * v * cm;
        y[sh_index(l, -m)] = kSqrt2 * v * sm;
      }
    }
  }
}

Eigen::VectorXd ShBasis::eval(const Eigen::Vector3d& w) const {
  Eigen::VectorXd y(size());
  eval(w, y.data());
  return y;
}

Eigen::VectorXd sh_eval(int order, const Eigen::Vector3d& w) { return ShBasis(order).eval(w); }

}  // namespace bf
