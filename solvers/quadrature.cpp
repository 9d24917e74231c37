// Gauss-Legendre rules and spherical product rules (see quadrature.h).
#include "solvers/quadrature.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bf {

GaussLegendre gauss_legendre(int n, double a, double b) {
  if (n < 1 || n > 100000)
    throw std::invalid_argument("gauss_legendre: expected 1 <= n <= 100000, found " +
                                std::to_string(n));
  if (!(a < b))
    throw std::invalid_argument("gauss_legendre: expected a < b, found a=" + std::to_string(a) +
                                ", b=" + std::to_string(b));
  GaussLegendre r;
  r.x.assign(n, 0.0);
  r.w.assign(n, 0.0);
  const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
  // P_n(x) and P_n'(x) by the three-term recurrence (p0 = P_{n-1}, p1 = P_n).
  auto legendre_and_derivative = [n](double x, double& p, double& dp) {
    double p0 = 1.0, p1 = x;
    for (int j = 2; j <= n; ++j) {
      const double p2 = ((2.0 * j - 1.0) * x * p1 - (j - 1.0) * p0) / j;
      p0 = p1;
      p1 = p2;
    }
    p = p1;
    dp = n * (x * p1 - p0) / (x * x - 1.0);
  };
  // Roots are symmetric: compute the upper half (k = 0 is the largest root)
  // by Newton from Tricomi's initial guess, mirror the rest.
  for (int k = 0; k < (n + 1) / 2; ++k) {
    double x = std::cos(M_PI * (k + 0.75) / (n + 0.5));
    double p = 0.0, dp = 1.0;
    // Quadratic convergence: once a step is below 1e-13, one more step reaches
    // the rounding floor.
    bool close = false;
    for (int it = 0; it < 100; ++it) {
      legendre_and_derivative(x, p, dp);
      const double dx = p / dp;
      x -= dx;
      if (close) break;
      close = std::abs(dx) < 1e-13;
    }
    legendre_and_derivative(x, p, dp);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    r.x[n - 1 - k] = mid + half * x;
    r.x[k] = mid - half * x;
    r.w[n - 1 - k] = r.w[k] = half * w;
  }
  if (n % 2 == 1) r.x[n / 2] = mid;  // exact centre node
  return r;
}

SphereRule sphere_rule(int n_z, int n_phi, double z_min, double z_max) {
  if (n_z < 1) throw std::invalid_argument("sphere_rule: n_z must be >= 1, found " + std::to_string(n_z));
  if (n_phi < 1)
    throw std::invalid_argument("sphere_rule: n_phi must be >= 1, found " + std::to_string(n_phi));
  if (!(z_min >= -1.0 && z_min < z_max && z_max <= 1.0))
    throw std::invalid_argument("sphere_rule: expected -1 <= z_min < z_max <= 1, found z_min=" +
                                std::to_string(z_min) + ", z_max=" + std::to_string(z_max));
  const GaussLegendre gl = gauss_legendre(n_z, z_min, z_max);
  SphereRule r;
  r.n_z = n_z;
  r.n_phi = n_phi;
  r.dir.reserve(size_t(n_z) * n_phi);
  r.w.reserve(size_t(n_z) * n_phi);
  const double dphi = 2.0 * M_PI / n_phi;
  for (int i = 0; i < n_z; ++i) {
    const double z = gl.x[i];
    const double s = std::sqrt(std::max(0.0, (1.0 - z) * (1.0 + z)));
    for (int j = 0; j < n_phi; ++j) {
      const double phi = dphi * (j + 0.5);
      r.dir.emplace_back(s * std::cos(phi), s * std::sin(phi), z);
      r.w.push_back(gl.w[i] * dphi);
    }
  }
  return r;
}

}  // namespace bf
