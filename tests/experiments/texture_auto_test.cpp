// Sizes from a tolerance (issue #7): texture_size = "auto" with texture_ladder
// parsed into the method's ladder and options (so run ids), each misuse one
// error naming the key; and the search's tolerance, which stops the greedy
// search at the first term that reaches the target.
#include <algorithm>

#include "experiments/config/config.h"
#include "experiments/methods/homomorphic.h"
#include "factor/svd_baseline.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {
// One [[method]] table after the common head.
std::string texture_config(const std::string& method) { return std::string(kConfigHead) + "\n[[method]]\n" + method; }

void require_error(const std::string& method, std::initializer_list<std::string> fragments) {
  require_one_config_error(texture_config(method), fragments);
}
}  // namespace

TEST_CASE("config: texture_size = \"auto\" fills the ladder (svd, mccool, fit)") {
  register_loaders();
  const Plan p = parse_plan(texture_config(R"(kind = "svd"
texture_size = "auto"
terms = 6
tolerance = { metric = "rel_mse", value = 0.05 }

[[method]]
kind = "mccool"
texture_size = "auto"
texture_ladder = [4, 8]
tolerance = { metric = "cos_rmse", value = 0.1 }

[[method]]
kind = "svd"
texture_size = 12
)"), "cfg.toml");
  REQUIRE(p.methods.size() == 3);
  const MethodVariant& svd = p.methods[0];
  CHECK(svd.texture_ladder == std::vector<int>{8, 12, 16, 24, 32});
  CHECK(svd.options["texture_size"] == "auto");
  CHECK(svd.options["texture_ladder"] == nlohmann::json({8, 12, 16, 24, 32}));
  CHECK(svd.cap == 6);
  const MethodVariant& mc = p.methods[1];
  CHECK(mc.texture_ladder == std::vector<int>{4, 8});
  CHECK(mc.tolerance.has_value());
  CHECK(p.methods[2].texture_ladder.empty());
  CHECK(p.methods[2].options["texture_size"] == 12);
  CHECK(kind_options<SvdOptions>(p.methods[2]).res == 12);
}

TEST_CASE("config: texture_size = \"auto\" misuse names the key") {
  require_error("kind = \"svd\"\ntexture_size = \"auto\"\n",
                {"cfg.toml:", "texture_size", "needs a tolerance"});
  require_error("kind = \"mccool\"\ntexture_size = \"auto\"\n", {"texture_size", "needs a tolerance"});
  require_error("kind = \"fit\"\ntexture_size = \"auto\"\nprojections = [{ name = \"wi\" }]\n",
                {"texture_size", "needs a tolerance"});
  require_error("kind = \"svd\"\ntexture_size = \"big\"\n",
                {"texture_size", "expected an integer in 2..256 or \"auto\"", "big"});
  require_error("kind = \"svd\"\ntexture_size = 16\ntexture_ladder = [8, 16]\n"
                "tolerance = { metric = \"rel_mse\", value = 0.1 }\n",
                {"texture_ladder", "applies only with texture_size = \"auto\""});
  require_error("kind = \"svd\"\ntexture_size = \"auto\"\ntexture_ladder = [8, 16, 12]\n"
                "tolerance = { metric = \"rel_mse\", value = 0.1 }\n",
                {"texture_ladder", "strictly ascending", "found 12 after 16"});
  require_error("kind = \"svd\"\ntexture_size = \"auto\"\ntexture_ladder = [8, 300]\n"
                "tolerance = { metric = \"rel_mse\", value = 0.1 }\n",
                {"texture_ladder", "in 2..256", "300"});
  require_error("kind = \"mccool\"\ntolerance = { metric = \"rel_mse\", value = 0.1 }\n",
                {"tolerance", "only choose the resolution", "texture_size = \"auto\""});
  require_error("kind = \"search\"\ntexture_size = \"auto\"\n", {"texture_size"});
}

TEST_CASE("config: a search tolerance caps terms (default 8) and refuses beam > 1") {
  register_loaders();
  const Plan p = parse_plan(texture_config(R"(kind = "search"
tolerance = { metric = "rel_mse", value = 0.05 }

[[method]]
kind = "search"
terms = 3
tolerance = { metric = "cos_rmse", value = 0.01 }
)"), "cfg.toml");
  REQUIRE(p.methods.size() == 2);
  CHECK(p.methods[0].cap == 8);
  CHECK(homomorphic_options(p.methods[0]).search.terms == 8);
  CHECK(p.methods[0].options["tolerance"]["metric"] == "rel_mse");
  CHECK(p.methods[1].cap == 3);
  require_error("kind = \"search\"\nbeam = 2\ntolerance = { metric = \"rel_mse\", value = 0.05 }\n",
                {"cfg.toml:", "tolerance", "beam = 1", "found beam = 2"});
}

TEST_CASE("runner: a search with a tolerance stops at the first term that reaches it") {
  ScratchDir tmp;
  const std::string search = R"(
[[method]]
kind = "search"
strategy = "greedy"
texture_size = 6
restarts = 1
)";
  // The same search with 3 fixed terms gives the error after each term (the
  // greedy search: a tolerance runs it alone, also under strategy = "best").
  run_quiet(write_text(tmp / "fixed.toml", std::string(kConfigHead) + search + "terms = 3\n"), tmp / "fixed");
  const auto fixed = read_results_csv(tmp / "fixed/results.csv");
  REQUIRE(fixed.size() == 1);
  std::vector<double> errs;
  std::stringstream ss(fixed[0].at("errors_after_term"));
  for (std::string t; std::getline(ss, t, ';');) errs.push_back(std::stod(t));
  REQUIRE(errs.size() == 3);
  REQUIRE(errs[1] < errs[0]);
  // A target between the errors after terms 1 and 2 stops a search capped at 4 after term 2.
  const std::string target = std::to_string(0.5 * (errs[0] + errs[1]));
  run_quiet(write_text(tmp / "tol.toml", std::string(kConfigHead) + search +
                                             "terms = 4\ntolerance = { metric = \"rel_mse\", value = " + target + " }\n"),
            tmp / "out");
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 1);
  INFO(rows[0].at("notes"));
  CHECK(rows[0].at("terms") == "2");
  CHECK(rows[0].at("tolerance_reached") == "true");
  CHECK(std::stod(rows[0].at("rel_mse")) == Approx(errs[1]).epsilon(1e-6));
  const auto rec = nlohmann::json::parse(read_text(tmp / ("out/runs/" + rows[0].at("run_id") + "/run.json")));
  REQUIRE(rec["size_choice"]["tried"].size() == 2);
  CHECK(rec["size_choice"]["value"] == 2);
  CHECK(rec["size_choice"]["reached"] == true);
}
