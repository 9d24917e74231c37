// `brdf-factor compare`: a BRDF scored against a reference on the validation
// design, with the reference's log transform.
#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "experiments_helpers.h"

namespace {

nlohmann::json compare(const std::string& args) {
  std::string out;
  REQUIRE(bf_test::run_cli("compare " + args, &out) == 0);
  return nlohmann::json::parse(out);
}

}  // namespace

TEST_CASE("compare cli: a BRDF scores zero against itself and ln of a scale against its scaled twin") {
  const nlohmann::json self = compare("--brdf cook-torrance:m=0.2 --reference cook-torrance:m=0.2 --pairs 512");
  CHECK(self["rel_mse"].get<double>() == 0.0);
  CHECK(self["lin_rmse"].get<double>() == 0.0);
  CHECK(self["max_ratio"].get<double>() == Approx(1.0));
  CHECK(self["valid"].get<int>() > 0);
  // f = 2 f_ref with a constant f_ref = A: every channel's log error is
  // ln((2 + eps) / (1 + eps)), so rel_mse is its square.
  const double eps = 1e-3;
  const nlohmann::json twice = compare("--brdf lambert:kd=0.6 --reference lambert:kd=0.3 --pairs 256 --eps 0.001");
  const double d = std::log((2 + eps) / (1 + eps));
  CHECK(twice["rel_mse"].get<double>() == Approx(d * d).epsilon(1e-9));
  CHECK(twice["max_ratio"].get<double>() == Approx(2.0));
  // The set is the run's validation design at this seed and size.
  CHECK(twice["pairs"].get<int>() == 256);
  CHECK(twice["set"].get<std::string>().find("validation") != std::string::npos);
}

TEST_CASE("compare cli: bad pairs eps and unknown BRDFs are refused naming the option") {
  std::string out;
  CHECK(bf_test::run_cli("compare --brdf lambert --reference lambert --pairs 3", &out) == 2);
  CHECK_THAT(out, Catch::Contains("--pairs") && Catch::Contains("found 3"));
  CHECK(bf_test::run_cli("compare --brdf lambert --reference lambert --eps 0", &out) == 2);
  CHECK_THAT(out, Catch::Contains("--eps") && Catch::Contains("(0, 1]"));
  CHECK(bf_test::run_cli("compare --brdf lambert --reference no-such-model", &out) == 2);
  CHECK_THAT(out, Catch::Contains("--reference") && Catch::Contains("no-such-model"));
}
