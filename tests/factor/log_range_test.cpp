// Tests of the log-range clamp (FitOptions::clamp_log_range, docs/design.md
// §3.2): the factorization clamps its summed log value to the range of the
// fit's training targets, which never increases a training sample's error and
// bounds the factorization where no sample constrains it.
#include <cmath>
#include <random>

#include "brdfs/catalogue.h"
#include "brdfs/sampleset.h"
#include "factor/homomorphic_fit.h"
#include "factor/metrics.h"
#include "extrapolation_helpers.h"
#include "fit_helpers.h"
#include "test_common.h"

using namespace bf;
using Catch::Matchers::Contains;

using namespace bf_test;

TEST_CASE("log range: the fit records min and max of its log targets, and the clamp leaves the texels alone") {
  const bf_test::PlantedBrdf brdf;
  const SampleSet s = sparse_samples(brdf, 800, 60.0, 0.3, 3);
  FitOptions opt;
  REQUIRE(opt.clamp_log_range);  // the default
  const FitData d(s, opt.eps);
  for (int c = 0; c < 3; ++c) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (size_t k = 0; k < s.size(); ++k) {
      lo = std::min(lo, d.transform.g(c, s.value[k][c]));
      hi = std::max(hi, d.transform.g(c, s.value[k][c]));
    }
    CHECK(d.log_range[c][0] == lo);
    CHECK(d.log_range[c][1] == hi);
  }
  const auto on = fit_homomorphic(d, random_wiwo_terms(10, 4), opt);
  opt.clamp_log_range = false;
  const auto off = fit_homomorphic(d, random_wiwo_terms(10, 4), opt);
  REQUIRE(on->log_range());
  CHECK(*on->log_range() == d.log_range);
  CHECK(!off->log_range());
  for (size_t t = 0; t < 2; ++t)
    for (int c = 0; c < 3; ++c) CHECK(on->terms()[t].texels[c] == off->terms()[t].texels[c]);
}

TEST_CASE("log range: the clamp never increases any training sample's error") {
  // Fits whose model overshoots the targets' range at some training samples
  // (the test requires that it does, else it proves nothing): a highlight
  // that two random wiwo terms cannot represent, and a planted 3-factor BRDF
  // with 30% log-normal noise, on samples in part of the domain.
  const bf_test::PlantedBrdf planted;
  const BrdfPtr phong = Catalogue::builtin().make("blinn-phong");
  for (int which = 0; which < 4; ++which) {
    const Brdf& brdf = which < 2 ? static_cast<const Brdf&>(*phong) : planted;
    const SampleSet s = sparse_samples(brdf, 800, 60.0, which < 2 ? 0.0 : 0.3, 3 + which);
    FitOptions opt;
    opt.smoothing = which % 2 ? 1e-1 : 1e-3;
    const FitData d(s, opt.eps);
    const auto terms = random_wiwo_terms(10, 4 + which);
    const auto on = fit_homomorphic(d, terms, opt);
    opt.clamp_log_range = false;
    const auto off = fit_homomorphic(d, terms, opt);
    size_t worse = 0, better = 0;
    for (size_t k = 0; k < s.size(); ++k) {
      const Rgb a = on->eval(s.wi[k], s.wo[k]), b = off->eval(s.wi[k], s.wo[k]);
      for (int c = 0; c < 3; ++c) {
        const double f = s.value[k][c];
        const double ea = std::abs(a[c] - f), eb = std::abs(b[c] - f);
        const double la = std::abs(d.transform.g(c, a[c]) - d.transform.g(c, f)),
                     lb = std::abs(d.transform.g(c, b[c]) - d.transform.g(c, f));
        worse += ea > eb * (1 + 1e-12) || la > lb + 1e-12;
        better += ea < eb;
      }
    }
    const double mse_on = evaluate_metrics(*on, s, d.transform).rel_mse,
                 mse_off = evaluate_metrics(*off, s, d.transform).rel_mse;
    INFO("case " << which << ": " << better << " sample channels clamped closer, " << worse
                 << " worse; rel_mse " << mse_on << " clamped, " << mse_off << " unclamped");
    CHECK(worse == 0);
    CHECK(mse_on <= mse_off);
    // Measured: the highlight cases clamp 585 and 609 of 2400 sample channels
    // closer (rel_mse 0.0787 and 0.146 clamped); the planted ones stay inside
    // their range (0 clamped: the noise widens it).
    if (which < 2) CHECK(better > 0);
  }
}

TEST_CASE("log range: a fit on a sparse sample set stays bounded over the whole domain by default") {
  // Samples in part of the domain only (wi in one plane, theta up to 45
  // degrees); the 12^4 grid covers the whole hemisphere pair.
  const BrdfPtr b = Catalogue::builtin().make("blinn-phong");
  const SampleSet s = sparse_samples(*b, 1500, 45.0, 0.0, 5);
  for (int which = 0; which < 2; ++which) {
    const std::vector<TermSpec> terms = which == 0 ? mccool_terms(16) : random_wiwo_terms(16, 3);
    FitOptions opt;  // defaults: clamp on, prior off
    const FitData d(s, opt.eps);
    const double on = max_ratio(*fit_homomorphic(d, terms, opt), *b);
    opt.clamp_log_range = false;
    const double off = max_ratio(*fit_homomorphic(d, terms, opt), *b);
    INFO((which == 0 ? "McCool" : "2 random wiwo terms") << ": max approx/max(original) over 12^4 pairs: " << on
                                                          << " clamped, " << off << " unclamped");
    // Measured: 0.997 clamped for both (the data's own peak); 397 (McCool) and
    // 2758 (random wiwo) unclamped.
    CHECK(on <= 10.0);
    CHECK(off > 100.0);  // without the clamp (and the prior) it explodes
  }
}

TEST_CASE("log range: a non-finite or inverted range is refused naming the channel") {
  const bf_test::PlantedBrdf brdf;
  const SampleSet s = sparse_samples(brdf, 200, 60.0, 0.0, 1);
  FitOptions opt;
  const FitData d(s, opt.eps);
  const auto f = fit_homomorphic(d, random_wiwo_terms(6, 2), opt);
  LogRange r = d.log_range;
  r[1] = {1.0, 0.0};
  CHECK_THROWS_WITH(HomomorphicFactorization(f->terms(), f->A(), f->eps(), true, "fit", r),
                    Contains("log_range[1]") && Contains("lo <= hi"));
  r = d.log_range;
  r[2][0] = std::nan("");
  CHECK_THROWS_WITH(HomomorphicFactorization(f->terms(), f->A(), f->eps(), true, "fit", r),
                    Contains("log_range[2]") && Contains("finite"));
}
