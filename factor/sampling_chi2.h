// A chi-squared goodness-of-fit test of a direction sampler against its own
// pdf (in the spirit of Mitsuba 3's chi2 test, written here): n samples for
// one wo are histogrammed on a (theta_i, phi_i) grid, uniform in theta_i over
// [0, pi/2] and in the azimuth of wi relative to that of wo over [0, 2 pi)
// (the tabulated sampler's own cells are then unions of histogram cells when
// the resolutions divide the sampler's theta_bins and phi_bins, so that the
// midpoint rule integrates its steps without error); each cell's expected count is n
// times the pdf integrated over the cell (a midpoint rule of `refine`^2
// points per cell, uniform in cos theta_i and phi_i). Cells expecting fewer
// than 5 samples are pooled, in order of increasing expectation, until each
// pool expects 5 or more. The p-value is that of Pearson's statistic with
// (cells - 1) degrees of freedom. A sample whose returned pdf differs from
// pdf(wi, wo) (relative 1e-9), or a positive pdf below the horizon, or a
// sample in a cell expecting none, makes p = 0.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "factor/sampling.h"

namespace bf {

struct Chi2Options {
  size_t samples = 100000;
  uint64_t seed = 1;
  int theta_res = 16, phi_res = 32;  // histogram cells
  int refine = 12;                   // pdf integration points per cell and axis
  // The pdf the expected counts integrate; empty = the sampler's own pdf.
  std::function<double(const Vec3& wi, const Vec3& wo)> pdf;
};

struct Chi2Result {
  double chi2 = 0, p = 0;
  int dof = 0;
  size_t valid = 0;             // samples with pdf > 0
  int max_theta = 0, max_phi = 0;  // the histogram cell expecting the most samples
  std::string problem;          // why p = 0 by rule, empty otherwise
};

Chi2Result chi2_test(const BrdfSampler& s, const Vec3& wo, const Chi2Options& o = {});

// Upper regularized incomplete gamma function Q(a, x), a > 0, x >= 0.
double gamma_q(double a, double x);
// Sidak's correction: the probability that the smallest of n independent
// p-values is <= p_min, 1 - (1 - p_min)^n. A set of n tests passes at level
// alpha when sidak(min p, n) > alpha.
double sidak(double p_min, int n);

}  // namespace bf
