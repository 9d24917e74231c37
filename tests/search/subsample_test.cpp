// The search's stratified subsample (search/subsample.h, SearchOptions::
// search_samples): strata keep their weight, the highlight keeps its samples,
// the search runs on the subsample and the answers are refit on every sample.
#include <cmath>
#include <map>

#include "brdfs/sampleset.h"
#include "factor/fit_helpers.h"
#include "search/subsample.h"
#include "search/term_search.h"
#include "solvers/option_error.h"
#include "test_common.h"

using namespace bf;

namespace {

// The planted BRDF of fit_helpers.h on an 8^4 grid: 2,704 samples.
const FitData& planted_data() {
  static const SampleSet s = sample_grid(bf_test::PlantedBrdf(), 8);
  static const FitData d(s, 1e-5);
  return d;
}

SearchOptions small_search(const std::string& strategy) {
  SearchOptions opt;
  opt.strategy = strategy;
  opt.terms = 2;
  opt.texture_size = 6;
  opt.restarts = 1;
  opt.keep = 1;
  opt.beam_width = 2;
  opt.polish_sweeps = 0;
  opt.powell.ftol = 1e-2;
  opt.threads = 2;
  opt.search_samples = 1000;
  return opt;
}

std::map<size_t, double> stratum_weights(const FitData& d, int coarsen) {
  std::map<size_t, double> w;
  for (size_t k = 0; k < d.size(); ++k) w[subsample_stratum(d.x_halfdiff[k], coarsen)] += d.w[k];
  return w;
}

std::vector<TermSpec> specs_of(const HomomorphicFactorization& h) {
  std::vector<TermSpec> sp;
  for (const FactorTerm& t : h.terms()) sp.push_back(TermSpec{t.proj, t.reciprocal, t.rotation});
  return sp;
}

}  // namespace

TEST_CASE("search subsample: n samples, every stratum keeps its weight, sparse strata whole, deterministic per seed") {
  const FitData& d = planted_data();
  REQUIRE(d.size() > 2000);
  SubsampleInfo info;
  const FitData s = stratified_subsample(d, 1000, 7, &info);
  CHECK(s.size() == 1000);
  CHECK(info.samples == 1000);
  CHECK(info.of == d.size());
  CHECK(info.seed == 7);
  CHECK(s.W == Approx(d.W).epsilon(1e-12));
  const auto full = stratum_weights(d, info.coarsen), sub = stratum_weights(s, info.coarsen);
  CHECK(2 * full.size() <= 1000);  // strata coarse enough for two samples each
  CHECK(full.size() == sub.size());  // no stratum lost
  CHECK(info.strata == full.size());
  for (const auto& [k, w] : full) CHECK(sub.at(k) == Approx(w).epsilon(1e-12));
  // A stratum with at most `cap` samples is kept whole, with its own weights.
  std::map<size_t, size_t> count_full, count_sub;
  for (size_t k = 0; k < d.size(); ++k) ++count_full[subsample_stratum(d.x_halfdiff[k], info.coarsen)];
  for (size_t k = 0; k < s.size(); ++k) ++count_sub[subsample_stratum(s.x_halfdiff[k], info.coarsen)];
  size_t whole = 0;
  for (const auto& [k, c] : count_full)
    if (c <= info.cap) {
      CHECK(count_sub.at(k) == c);
      ++whole;
    } else {
      CHECK(count_sub.at(k) >= info.cap);
      CHECK(count_sub.at(k) <= info.cap + 1);
    }
  CHECK(whole > 0);
  // The full data's transform and clamp range (the search sees the same targets).
  CHECK(s.log_range == d.log_range);
  CHECK((s.transform.A == d.transform.A).all());
  // Deterministic for a seed; another seed draws other samples.
  const FitData again = stratified_subsample(d, 1000, 7);
  CHECK(again.w == s.w);
  CHECK(again.g[0] == s.g[0]);
  const FitData other = stratified_subsample(d, 1000, 8);
  CHECK(other.g[0] != s.g[0]);
  CHECK_THROWS_AS(stratified_subsample(d, d.size(), 7), std::invalid_argument);
  CHECK_THROWS_AS(stratified_subsample(d, 0, 7), std::invalid_argument);
}

TEST_CASE("search subsample: above the threshold the search runs on the subsample and the answers fit every sample") {
  const FitData& d = planted_data();
  for (const std::string strategy : {"greedy", "structured"}) {
    INFO(strategy);
    const SearchOptions opt = small_search(strategy);
    const SearchResult r = search_factorization(d, opt);
    CHECK(r.search_samples == 1000);
    CHECK(r.data_samples == d.size());
    CHECK(r.subsample_seed == opt.seed);
    CHECK(r.subsample_strata > 0);
    // The reported errors are those of every sample: the answers refit on all of them.
    REQUIRE(r.rel_mse_after_term.size() == 2);
    const auto& h = dynamic_cast<const HomomorphicFactorization&>(*r.factorization);
    FitOptions fo = opt.fit;
    if (strategy == "structured") fo.solve_last = 2;  // the joint final refit
    std::vector<double> errors;
    fit_homomorphic(d, specs_of(h), fo, "search", &errors);
    CHECK(errors.back() == Approx(r.rel_mse_after_term.back()).epsilon(1e-12));
    // ... and not those of the subsample.
    const FitData sub = stratified_subsample(d, 1000, opt.seed);
    std::vector<double> sub_errors;
    fit_homomorphic(sub, specs_of(h), fo, "search", &sub_errors);
    CHECK(sub_errors.back() != Approx(r.rel_mse_after_term.back()).epsilon(1e-9));
    // Deterministic.
    const SearchResult again = search_factorization(d, opt);
    CHECK(again.rel_mse_after_term == r.rel_mse_after_term);
    CHECK(again.evaluations == r.evaluations);
  }
}

TEST_CASE("search subsample: off and at or below the threshold every sample is searched") {
  const FitData& d = planted_data();
  SearchOptions opt = small_search("greedy");
  opt.terms = 1;
  for (const size_t n : {size_t(0), d.size()}) {
    opt.search_samples = n;
    const SearchResult r = search_factorization(d, opt);
    CHECK(r.search_samples == d.size());
    CHECK(r.data_samples == d.size());
    CHECK(r.subsample_seed == 0);
  }
  opt.search_samples = kMinSearchSamples - 1;
  CHECK_THROWS_WITH(search_factorization(d, opt), Catch::Matchers::Contains("search_samples"));
}

TEST_CASE("search subsample: refit_search_result on the searched samples reproduces the search's answers") {
  // The refit after a subsampled search must fit the answers as the search does.
  const FitData& d = planted_data();
  for (const std::string strategy : {"greedy", "structured"}) {
    INFO(strategy);
    SearchOptions opt = small_search(strategy);
    opt.search_samples = 0;
    const SearchResult r = search_factorization(d, opt);
    SearchResult again = r;
    refit_search_result(d, opt, again);
    REQUIRE(again.rel_mse_after_term.size() == r.rel_mse_after_term.size());
    for (size_t k = 0; k < r.rel_mse_after_term.size(); ++k)
      CHECK(again.rel_mse_after_term[k] == Approx(r.rel_mse_after_term[k]).epsilon(1e-12));
    // Its fits count: one (greedy's schedule) or one per k-term answer.
    CHECK(again.evaluations == r.evaluations + (strategy == "greedy" ? 1 : static_cast<int>(r.answers.size())));
  }
}
