// Tolerance-driven choice of texture resolution together with the SVD rank
// (select_svd_size) or the homomorphic term count (select_homomorphic_size):
// the choice is the brute-force answer, reaches the tolerance, and the next
// smaller resolution (any size up to the cap) and the next smaller rank/term
// count do not.
#include <cmath>
#include <limits>
#include <map>

#include "brdfs/models.h"
#include "brdfs/sampleset.h"
#include "factor/metrics.h"
#include "factor/size_select.h"
#include "factor/svd_baseline.h"
#include "test_common.h"

using namespace bf;

namespace {
// f = 0.2 + a(wi) a(wo) with a narrow bump in a: exactly rank 2 in wiwo, so
// the rank is reached early and the bump needs resolution.
class Bumps final : public Brdf {
 public:
  static double a(const Vec3& w) {
    const Vec3 c = Vec3(0.3, 0.2, 0.9).normalized();
    return 0.5 + 3.0 * std::exp(-(w - c).squaredNorm() / 0.05);
  }
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
    return Rgb(1.0, 0.8, 0.6) * (0.2 + a(wi) * a(wo));
  }
  std::string name() const override { return "bumps-test"; }
  std::string to_string() const override { return "bumps-test"; }
  bool reciprocal() const override { return true; }
  bool isotropic() const override { return false; }
};

// f = p(wi) q(h) p(wo) with a narrow q: McCool's two textures represent it
// exactly in log space (the second term is needed) up to resolution.
class SharpMcCool final : public Brdf {
 public:
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
    const Vec3 h = (wi + wo).normalized();
    const auto p = [](const Vec3& w) { return 0.4 + 0.6 * w.z(); };
    const double q = 0.1 + 4.0 * std::exp(-(1.0 - h.z()) / 0.02);
    return Rgb(0.9, 0.7, 0.5) * (p(wi) * q * p(wo));
  }
  std::string name() const override { return "sharp-mccool-test"; }
  std::string to_string() const override { return "sharp-mccool-test"; }
};

// Brute force: err[(res, k)] for every resolution and size, the first
// resolution reaching tol and the smallest size there.
struct Expect {
  int res = 0, value = 0;
};
Expect first_reaching(const std::vector<int>& ladder, int lo, int hi, const std::map<std::pair<int, int>, double>& err,
                      double tol) {
  for (int res : ladder)
    for (int k = lo; k <= hi; ++k)
      if (err.at({res, k}) <= tol) return {res, k};
  return {};
}
double best_at(const std::map<std::pair<int, int>, double>& err, int res) {
  double b = std::numeric_limits<double>::infinity();
  for (const auto& [key, e] : err)
    if (key.first == res) b = std::min(b, e);
  return b;
}
}  // namespace

TEST_CASE("size selection: svd picks the smallest resolution, then the smallest rank") {
  const Bumps brdf;
  const SampleSet s = sample_stratified(brdf, 3000, 7);
  const LogTransform lt = LogTransform::of(s);
  const std::vector<int> ladder = {4, 6, 8, 12, 16};
  const int cap = 3;
  SvdOptions opt;
  std::map<std::pair<int, int>, double> err;
  for (int res : ladder) {
    SvdOptions o = opt;
    o.res = res;
    o.rank = cap;
    const auto full = fit_svd(brdf, o);
    for (int k = 1; k <= cap; ++k) err[{res, k}] = evaluate_metrics(*full->truncated(k), s, lt).rel_mse;
  }
  // A target the first resolution cannot reach but the last can.
  const double b0 = best_at(err, ladder.front()), b1 = best_at(err, ladder.back());
  INFO("best rel_mse at res " << ladder.front() << ": " << b0 << ", at res " << ladder.back() << ": " << b1);
  REQUIRE(b1 < b0);
  const double tol = std::sqrt(b0 * b1);
  const Expect ex = first_reaching(ladder, 1, cap, err, tol);
  REQUIRE(ex.res > ladder.front());
  const SizeChoice ch = select_svd_size(brdf, s, opt, {"rel_mse", tol}, cap, ladder);
  CHECK(ch.reached);
  CHECK(ch.texture_size == ex.res);
  CHECK(ch.value == ex.value);
  CHECK(ch.error <= tol);
  CHECK(ch.error == Approx(err.at({ex.res, ex.value})).epsilon(1e-9));
  REQUIRE(ch.result);
  const auto* f = dynamic_cast<const SvdFactorization*>(ch.result.get());
  REQUIRE(f);
  CHECK(f->options().res == ex.res);
  CHECK(f->rank() == ex.value);
  // The selector's own choice, checked against the brute-force table: the
  // next smaller resolution reaches with no rank up to the cap, the next
  // smaller rank at the chosen resolution does not either, and every
  // (resolution, rank) it scored has the brute-force error.
  const size_t i = std::find(ladder.begin(), ladder.end(), ch.texture_size) - ladder.begin();
  REQUIRE(i > 0);
  REQUIRE(i < ladder.size());
  CHECK(best_at(err, ladder[i - 1]) > tol);
  if (ch.value > 1) CHECK(err.at({ch.texture_size, ch.value - 1}) > tol);
  for (const auto& t : ch.tried) {
    INFO("tried res " << t.texture_size << " rank " << t.value);
    CHECK(t.error == Approx(err.at({t.texture_size, t.value})).epsilon(1e-9));
  }
  // The choice above is rank 1 (measured); a tolerance that no rank-1 fit
  // reaches at any resolution makes the rank matter: the choice has rank >= 2,
  // rank - 1 at its resolution does not reach, nor does any smaller resolution.
  double best1 = std::numeric_limits<double>::infinity();
  for (int res : ladder) best1 = std::min(best1, err.at({res, 1}));
  REQUIRE(err.at({ladder.back(), 2}) < best1);
  const double tol2 = std::sqrt(best1 * err.at({ladder.back(), 2}));
  const SizeChoice ch2 = select_svd_size(brdf, s, opt, {"rel_mse", tol2}, cap, ladder);
  CHECK(ch2.reached);
  REQUIRE(ch2.value >= 2);
  CHECK(err.at({ch2.texture_size, ch2.value - 1}) > tol2);
  CHECK(ch2.error == Approx(err.at({ch2.texture_size, ch2.value})).epsilon(1e-9));
  for (int res : ladder)
    if (res < ch2.texture_size) CHECK(best_at(err, res) > tol2);
  // tried lists every (resolution, rank) scored, in order, up to the choice.
  REQUIRE(!ch.tried.empty());
  CHECK(ch.tried.front().texture_size == ladder.front());
  CHECK(ch.tried.back().texture_size == ex.res);
  CHECK(ch.tried.back().value == ex.value);
  CHECK(ch.tried.size() == i * size_t(cap) + size_t(ex.value));
  CHECK(ch.seconds > 0.0);
  // Unreachable: the lowest error over everything tried, reached = false.
  const SizeChoice none = select_svd_size(brdf, s, opt, {"rel_mse", 1e-12}, 2, {4, 6});
  CHECK_FALSE(none.reached);
  CHECK(none.tried.size() == 4);
  double lowest = 1e300;
  for (const auto& t : none.tried) lowest = std::min(lowest, t.error);
  CHECK(none.error == lowest);
  // Bad ladders name the field and the rule.
  REQUIRE_THROWS_WITH(select_svd_size(brdf, s, opt, {"rel_mse", 0.1}, 2, {8, 6}),
                      Catch::Contains("texture_ladder: expected strictly ascending resolutions, found 6 after 8"));
  REQUIRE_THROWS_WITH(select_svd_size(brdf, s, opt, {"rel_mse", 0.1}, 2, {}),
                      Catch::Contains("texture_ladder: expected a non-empty list"));
  REQUIRE_THROWS_WITH(select_svd_size(brdf, s, opt, {"rel_mse", 0.1}, 2, {1, 4}),
                      Catch::Contains("expected resolutions in 2..256, found 1"));
}

TEST_CASE("size selection: homomorphic terms and resolution (McCool's projections)") {
  const SharpMcCool brdf;
  const SampleSet s = sample_stratified(brdf, 3000, 11);
  const LogTransform lt = LogTransform::of(s);
  FitOptions fo;
  const FitData data(s, fo.eps);
  const std::vector<int> ladder = {3, 4, 8, 16};
  // terms 1..2 of McCool's pair: p(wi) p(wo), then q(h).
  std::map<std::pair<int, int>, double> err;
  for (int res : ladder)
    for (int j = 1; j <= 2; ++j) {
      const auto terms = mccool_terms(res);
      err[{res, j}] = metric_value(
          evaluate_metrics(*fit_homomorphic(data, std::vector<TermSpec>(terms.begin(), terms.begin() + j), fo), s, lt),
          "rel_mse");
    }
  const double b0 = best_at(err, ladder.front()), b1 = best_at(err, ladder.back());
  INFO("best rel_mse at res " << ladder.front() << ": " << b0 << ", at res " << ladder.back() << ": " << b1);
  REQUIRE(b1 < b0);
  const double tol = std::sqrt(b0 * b1);
  const Expect ex = first_reaching(ladder, 1, 2, err, tol);
  REQUIRE(ex.res > ladder.front());
  const SizeChoice ch =
      select_homomorphic_size(data, s, lt, mccool_terms, 1, 2, fo, "mccool", {"rel_mse", tol}, ladder);
  CHECK(ch.reached);
  CHECK(ch.knob == "terms");
  CHECK(ch.texture_size == ex.res);
  CHECK(ch.value == ex.value);
  CHECK(ch.error == Approx(err.at({ex.res, ex.value})).epsilon(1e-9));
  // The selector's own choice against the brute-force table (as above).
  const size_t i = std::find(ladder.begin(), ladder.end(), ch.texture_size) - ladder.begin();
  REQUIRE(i > 0);
  REQUIRE(i < ladder.size());
  CHECK(best_at(err, ladder[i - 1]) > tol);
  REQUIRE(ch.value == 2);  // measured: the second term (q(h)) is needed
  CHECK(err.at({ch.texture_size, 1}) > tol);
  for (const auto& t : ch.tried) {
    INFO("tried res " << t.texture_size << " terms " << t.value);
    CHECK(t.error == Approx(err.at({t.texture_size, t.value})).epsilon(1e-9));
  }
  const auto* h = dynamic_cast<const HomomorphicFactorization*>(ch.result.get());
  REQUIRE(h);
  CHECK(int(h->terms().size()) == ex.value);
  CHECK(h->terms().front().proj.res == ex.res);
  CHECK(ch.errors_after_term.size() == size_t(ex.value));
  // Fixed two terms (kind = "mccool"): only the resolution moves.
  const SizeChoice two =
      select_homomorphic_size(data, s, lt, mccool_terms, 2, 2, fo, "mccool", {"rel_mse", tol}, ladder);
  CHECK(two.value == 2);
  for (const auto& t : two.tried) CHECK(t.value == 2);
  REQUIRE_THROWS_WITH(select_homomorphic_size(data, s, lt, mccool_terms, 1, 3, fo, "mccool", {"rel_mse", tol}, ladder),
                      Catch::Contains("3 terms asked for, only 2 projections given"));
}
