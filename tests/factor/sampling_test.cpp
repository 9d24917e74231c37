// Importance sampling (factor/sampling.h): the chi-squared test of each
// sampler against its own pdf, on an analytic, a pbrt-v1 and a measured BRDF
// at normal, 45 degree and grazing views; a wrong pdf fails it. (Every method
// kind: tests/experiments/sampling_kinds_test.cpp.)
#include "test_common.h"
#include <cmath>

#include "brdfs/catalogue.h"
#include "factor/sampling.h"
#include "factor/sampling_chi2.h"
#include "solvers/option_error.h"

using namespace bf;

namespace {

Vec3 view(double theta_deg, double phi_deg = 30.0) {
  const double t = theta_deg * M_PI / 180, p = phi_deg * M_PI / 180;
  return Vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
}

// Small tables: the default suite stays fast.
SamplerOptions small() {
  SamplerOptions o;
  o.view_bins = 8, o.theta_bins = 16, o.phi_bins = 32, o.cell_samples = 1;
  return o;
}

// The smallest p over theta_o in {0, 45, 80} degrees, Sidak-corrected for the three views.
double corrected_p(const BrdfSampler& s, size_t n, uint64_t seed = 1) {
  double pmin = 1;
  for (double t : {0.0, 45.0, 80.0}) {
    Chi2Options o;
    o.samples = n, o.seed = seed;
    const Chi2Result r = chi2_test(s, view(t), o);
    INFO("theta_o " << t << ": chi2 " << r.chi2 << ", dof " << r.dof << ", p " << r.p << " " << r.problem);
    CHECK(r.problem.empty());
    CHECK(r.valid > n / 2);
    pmin = std::min(pmin, r.p);
  }
  return sidak(pmin, 3);
}

const char* const kCookTorrance = "cook-torrance:kd=0.1,ks=0.9,m=0.2,f0=0.1";

}  // namespace

TEST_CASE("sampling: gamma_q matches closed forms") {
  CHECK(gamma_q(1.0, 2.0) == Approx(std::exp(-2.0)).epsilon(1e-12));
  CHECK(gamma_q(1.0, 40.0) == Approx(std::exp(-40.0)).epsilon(1e-10));
  // Q(1/2, x) = erfc(sqrt x)
  CHECK(gamma_q(0.5, 0.3) == Approx(std::erfc(std::sqrt(0.3))).epsilon(1e-12));
  CHECK(gamma_q(0.5, 9.0) == Approx(std::erfc(3.0)).epsilon(1e-10));
  CHECK(gamma_q(50.0, 50.0) == Approx(0.48119).margin(1e-4));
}

TEST_CASE("sampling: chi2 passes for the table and the model sampler on three BRDFs at three views") {
  for (const char* spec : {kCookTorrance, "bluepaint", "krylon-blue"}) {
    INFO(spec);
    const BrdfPtr f = Catalogue::builtin().make(spec);
    SamplerOptions o = small();
    o.method = "tabulated";
    const auto tab = make_sampler(*f, o);
    CHECK(tab->method() == "tabulated");
    CHECK(tab->storage_floats() == 8u * (17 + 16 * 33));
    CHECK(corrected_p(*tab, 20000) > 0.01);
  }
  const auto model = make_sampler(*Catalogue::builtin().make(kCookTorrance));
  CHECK(model->method() == "model");
  CHECK(corrected_p(*model, 20000) > 0.01);
  CHECK(corrected_p(*cosine_sampler(), 20000) > 0.01);
}

// One view azimuth bin of a BRDF that does not say it is isotropic (a
// factorization of an isotropic one, in a run): the table is the mean over
// view azimuths, still exact for what it draws.
TEST_CASE("sampling: one azimuth bin of an anisotropic BRDF passes chi2") {
  const BrdfPtr f = Catalogue::builtin().make("ward:ax=0.1,ay=0.3");
  REQUIRE(!f->isotropic());
  SamplerOptions o = small();
  o.method = "tabulated";
  o.view_phi_bins = 1;
  const auto tab = make_sampler(*f, o);
  CHECK(tab->storage_floats() == 8u * (17 + 16 * 33));
  CHECK(corrected_p(*tab, 20000) > 0.01);
}

TEST_CASE("sampling: chi2 passes with a million samples per view", "[slow]") {
  for (const char* spec : {kCookTorrance, "bluepaint", "krylon-blue"}) {
    INFO(spec);
    const BrdfPtr f = Catalogue::builtin().make(spec);
    SamplerOptions o;
    o.method = "tabulated";
    CHECK(corrected_p(*make_sampler(*f, o), 1000000, 7) > 0.01);
    CHECK(corrected_p(*make_sampler(*f), 1000000, 7) > 0.01);
  }
}

TEST_CASE("sampling: a pdf 1.1 times too large in one cell fails the chi2 test") {
  const BrdfPtr f = Catalogue::builtin().make(kCookTorrance);
  for (const char* method : {"tabulated", "auto"}) {
    INFO(method);
    SamplerOptions so = small();
    so.method = method;
    const auto s = make_sampler(*f, so);
    const Vec3 wo = view(45);
    Chi2Options o;
    o.samples = 200000;
    o.theta_res = 8, o.phi_res = 16;  // fewer cells: more power against one wrong cell
    const Chi2Result good = chi2_test(*s, wo, o);
    CHECK(good.p > 0.01);
    // Scale the pdf by 1.1 inside the histogram cell that expects the most samples.
    const int T = o.theta_res, P = o.phi_res, mr = good.max_theta, mc = good.max_phi;
    o.pdf = [&](const Vec3& wi, const Vec3& w) {
      const double th = std::acos(std::min(1.0, wi.z()));
      double ph = std::atan2(wi.y(), wi.x()) - std::atan2(w.y(), w.x());
      while (ph < 0) ph += 2 * M_PI;
      const bool in = std::min(static_cast<int>(th / (M_PI / 2) * T), T - 1) == mr &&
                      std::min(static_cast<int>(ph / (2 * M_PI) * P), P - 1) == mc;
      return s->pdf(wi, w) * (in ? 1.1 : 1.0);
    };
    const Chi2Result bad = chi2_test(*s, wo, o);
    INFO("chi2 " << bad.chi2 << " dof " << bad.dof);
    CHECK(sidak(bad.p, 3) < 0.01);
  }
}

TEST_CASE("sampling: pdf is positive over the hemisphere and sample returns its own pdf") {
  // A BRDF that is zero in most directions still gets a pdf > 0 everywhere above the horizon.
  const BrdfPtr f = Catalogue::builtin().make("cook-torrance:kd=0,ks=1,f0=1,m=0.05");
  const auto s = make_sampler(*f, [] { SamplerOptions o = small(); o.method = "tabulated"; return o; }());
  for (double t : {0.0, 45.0, 80.0, 89.9}) {
    for (double ti : {0.0, 30.0, 60.0, 89.0})
      for (double pi : {0.0, 100.0, 250.0}) CHECK(s->pdf(view(ti, pi), view(t)) > 0);
    CHECK(s->pdf(Vec3(0.6, 0, -0.8), view(t)) == 0);
    for (double u : {0.0, 0.05, 0.5, 0.999999}) {
      const DirectionSample d = s->sample(view(t), u, 1 - u);
      CHECK(d.wi.z() > 0);
      CHECK(std::abs(d.wi.norm() - 1) < 1e-12);
      CHECK(d.pdf == Approx(s->pdf(d.wi, view(t))));
    }
  }
  // Below the horizon: no sample.
  CHECK(s->sample(Vec3(0, 0.6, -0.8), 0.3, 0.3).pdf == 0);
  CHECK(s->pdf(Vec3(0, 0, 1), Vec3(0, 0.6, -0.8)) == 0);
}

TEST_CASE("sampling: invalid sampler options name the option") {
  const BrdfPtr f = Catalogue::builtin().make("bluepaint");
  SamplerOptions o;
  o.theta_bins = 1;
  CHECK_THROWS_AS(make_sampler(*f, o), OptionError);
  o = {};
  o.cosine_fraction = 0;
  try {
    make_sampler(*f, o);
    FAIL("no error");
  } catch (const OptionError& e) {
    CHECK(e.field() == "cosine_fraction");
  }
  o = {};
  o.method = "bogus";
  CHECK_THROWS_AS(make_sampler(*f, o), OptionError);
}
