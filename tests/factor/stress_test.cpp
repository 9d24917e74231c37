// Tests of the stress matrix (factor/stress.h): every case meets its written
// expectation for every method at a small size, and the pieces behave.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

#include "brdfs/catalogue.h"
#include "factor/stress.h"
#include "test_common.h"

using namespace bf;

namespace {
// Small sizes: the whole matrix runs in a few seconds.
StressOptions small_options() {
  StressOptions o;
  o.res = 12;
  o.samples = 1500;
  o.svd_res = 12;
  return o;
}
}  // namespace

TEST_CASE("stress: every case meets its expectation for every method") {
  const StressOptions o = small_options();
  for (const StressCase& c : stress_cases()) {
    const StressInput in = c.make(o);
    for (const std::string& m : stress_methods()) {
      const StressResult r = run_stress(c, in, m, o);
      INFO(stress_csv_row(r));
      CHECK(r.pass);
      // Never NaN in a result that claims to be finite.
      if (!r.threw) {
        CHECK(std::isfinite(r.rel_mse));
        CHECK(std::isfinite(r.cos_rmse));
      } else {
        CHECK_FALSE(r.message.empty());
      }
    }
  }
}

TEST_CASE("stress: case names are unique and every case has a description") {
  std::vector<std::string> names;
  for (const StressCase& c : stress_cases()) {
    CHECK_FALSE(c.description.empty());
    names.push_back(c.name);
  }
  std::sort(names.begin(), names.end());
  CHECK(std::adjacent_find(names.begin(), names.end()) == names.end());
  CHECK(names.size() >= 14);
}

TEST_CASE("stress: expectations round-trip through their text form") {
  for (const std::string s : {"finite", "finite|error", "rel_mse<=0.25", "error~'mean'"})
    CHECK(StressExpectation::parse(s).to_string() == s);
  REQUIRE_THROWS_WITH(StressExpectation::parse("rel_mse<=abc"), Catch::Contains("rel_mse<=X"));
  REQUIRE_THROWS_WITH(StressExpectation::parse("fine"), Catch::Contains("found 'fine'"));
}

TEST_CASE("stress: an expectation that does not hold fails the result") {
  const StressOptions o = small_options();
  std::vector<StressCase> cases = stress_cases();
  StressCase c = *std::find_if(cases.begin(), cases.end(), [](const StressCase& x) { return x.name == "all-zero"; });
  c.expect = StressExpectation::parse("finite");
  const StressResult r = run_stress(c, c.make(o), "mccool", o);
  CHECK(r.threw);
  CHECK_FALSE(r.pass);
  REQUIRE_THROWS_WITH(run_stress(c, c.make(o), "nope", o), Catch::Contains("unknown method 'nope'"));
}

TEST_CASE("stress: condition estimate of a well-posed fit is finite and >= 1") {
  const BrdfPtr b = Catalogue::builtin().make("cook-torrance:m=0.3");
  const SampleSet s = sample_stratified(*b, 3000, 3);
  const FitData d(s, 1e-5);
  size_t n = 0;
  const double k = normal_matrix_condition(d, mccool_terms(8), FitOptions{}, 1000, &n);
  CHECK(n > 0);
  CHECK(std::isfinite(k));
  CHECK(k >= 1.0);
  // Over the limit: not computed, but the unknowns are still counted.
  size_t n2 = 0;
  CHECK(std::isnan(normal_matrix_condition(d, mccool_terms(8), FitOptions{}, 10, &n2)));
  CHECK(n2 == n);
}

TEST_CASE("stress: options are validated with the field named") {
  StressOptions o;
  o.res = 1;
  REQUIRE_THROWS_WITH(o.validate(), Catch::Contains("res: expected"));
  o = StressOptions{};
  o.samples = 3;
  REQUIRE_THROWS_WITH(o.validate(), Catch::Contains("samples: expected"));
}

TEST_CASE("stress: the CLI table prints '-' for values it did not compute, never nan") {
  // all-zero: every method refuses (no rel_mse, no cos_rmse); --cond-max 1: no
  // condition estimate anywhere.
  bf_test::TempDir d("stress_cli");
  const std::string out = d.file("stdout.txt"), csv = d.file("stress.csv");
  std::string cmd = BF_CLI_PATH;
  cmd.append(" stress --case all-zero --samples 300 --res 8 --svd-res 8 --cond-max 1 --out ")
      .append(csv)
      .append(" > ")
      .append(out);
  const int status = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  const std::string text = bf_test::slurp(out);
  INFO(text);
  CHECK(text.find("all-zero") != std::string::npos);
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return std::tolower(ch); });
  CHECK(lower.find("nan") == std::string::npos);
  CHECK(lower.find(" inf") == std::string::npos);
  CHECK(text.find(" - ") != std::string::npos);
  const std::string table = bf_test::slurp(csv);
  CHECK(table.find("all-zero") != std::string::npos);
  CHECK(table.find("nan") == std::string::npos);
}
