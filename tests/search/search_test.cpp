// Tests of the Powell search and the greedy term builder.
#include <random>

#include "brdfs/sampleset.h"
#include "factor/fit_helpers.h"
#include "factor/metrics.h"
#include "search/powell.h"
#include "search/term_search.h"
#include "test_common.h"

using namespace bf;

namespace {
// f = exp(h(P_true x)) with x the wiwo point: exactly one term under the
// projection of a known rotation.
class OneTermBrdf final : public Brdf {
 public:
  explicit OneTermBrdf(const Rotation4& r) : P_(r.projection(Parameterization::WiWo, 8).P) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0 || wo.z() <= 0) return Rgb::Zero();
    const Eigen::Vector2d u = P_ * to_point(Parameterization::WiWo, wi, wo);
    return Rgb(1.0, 0.8, 0.6) * std::exp(1.5 * u.x() - 2.0 * u.y() * u.y() + 0.5 * u.x() * u.y());
  }
  std::string name() const override { return "one-term"; }
  std::string to_string() const override { return "one-term"; }

 private:
  Mat24 P_;
};
}  // namespace

TEST_CASE("powell: finds the minimum of a smooth function of the rotation") {
  std::mt19937_64 rng(9);
  const Rotation4 target = Rotation4::random(rng);
  // Squared distance between projections' first rows and second rows (smooth, min 0).
  const auto f = [&](const Rotation4& r) {
    const Eigen::Matrix4d A = r.matrix(), B = target.matrix();
    return (A.leftCols<2>() - B.leftCols<2>()).squaredNorm();
  };
  PowellOptions opt;
  opt.ftol = 1e-10;
  opt.line_tol = 1e-6;
  const PowellResult res = powell_minimize(f, Rotation4::identity(), opt);
  INFO("value " << res.value << " after " << res.evaluations << " evaluations");
  CHECK(res.value < 1e-6);
  CHECK(res.value <= f(Rotation4::identity()));
}

TEST_CASE("search: recovers a planted single-term projection") {
  std::mt19937_64 rng(21);
  const Rotation4 truth = Rotation4::random(rng);
  const OneTermBrdf brdf(truth);
  const SampleSet s = sample_grid(brdf, 10);
  SearchOptions opt;
  opt.terms = 1;
  opt.texture_size = 8;
  opt.restarts = 4;
  opt.fit.smoothing = 1e-5;
  const FitData d(s, opt.fit.eps);
  const SearchResult res = search_factorization(d, opt);
  // The identity projection (a poor guess) for scale.
  const auto id = fit_homomorphic(d, {TermSpec{projection_first_pair(Parameterization::WiWo, 8)}},
                                  opt.fit);
  const double e_id = evaluate_metrics(*id, s, d.transform).rel_mse;
  const double e = evaluate_metrics(*res.factorization, s, d.transform).rel_mse;
  INFO("searched " << e << " vs identity " << e_id << ", " << res.evaluations << " evaluations");
  CHECK(e < 1e-3);
  CHECK(e < 0.05 * e_id);
  REQUIRE(res.terms.size() == 1);
  CHECK(res.terms[0].evaluations > 10);
}

TEST_CASE("search: deterministic for a seed, whatever the thread count") {
  const bf_test::PlantedBrdf brdf;
  const SampleSet s = sample_grid(brdf, 8);
  SearchOptions opt;
  opt.terms = 2;
  opt.texture_size = 6;
  opt.restarts = 3;
  opt.powell.ftol = 1e-2;
  const FitData d(s, opt.fit.eps);
  opt.threads = 1;
  const SearchResult a = search_factorization(d, opt);
  opt.threads = 2;
  const SearchResult b = search_factorization(d, opt);
  REQUIRE(a.rel_mse_after_term.size() == 2);
  CHECK(a.rel_mse_after_term == b.rel_mse_after_term);
  CHECK(a.terms[1].rotation == b.terms[1].rotation);
  CHECK(a.rel_mse_after_term[1] <= a.rel_mse_after_term[0] * (1 + 1e-9));
}

TEST_CASE("search: nlopt optimizers share the objective and improve on their start") {
  std::mt19937_64 rng(23);
  const OneTermBrdf brdf(Rotation4::random(rng));
  const SampleSet s = sample_grid(brdf, 8);
  const FitData d(s, 1e-5);
  for (const char* name : {"praxis", "bobyqa", "neldermead", "sbplx", "direct", "crs"}) {
    SearchOptions opt;
    opt.terms = 1;
    opt.texture_size = 6;
    opt.restarts = 0;
    opt.guesses = {"wi"};
    opt.optimizer = name;
    opt.powell.max_evaluations = 150;
    const SearchResult res = search_factorization(d, opt);
    const TermObjective obj(d, {}, {}, opt, 6);
    INFO(name << ": " << res.terms[0].search_rel_mse << " from " << obj(Rotation4::identity()));
    CHECK(res.terms[0].search_rel_mse <= obj(Rotation4::identity()));
    CHECK(res.terms[0].evaluations <= 160);
  }
}

TEST_CASE("search: options are validated with the field named") {
  SearchOptions opt;
  opt.optimizer = "simplex";
  CHECK_THROWS_WITH(opt.validate(), Catch::Contains("optimizer") && Catch::Contains("simplex"));
  opt = SearchOptions{};
  opt.restarts = 0;
  CHECK_THROWS_WITH(opt.validate(), Catch::Contains("nothing to search from"));
  opt = SearchOptions{};
  opt.guesses = {"h"};
  CHECK_THROWS_WITH(opt.validate(), Catch::Contains("guesses"));
}
