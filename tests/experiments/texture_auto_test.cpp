// texture_size = "auto" with texture_ladder (issue #7): parsed into the
// method's ladder and options (so run ids), and each misuse is one error
// naming the key.
#include <algorithm>

#include "experiments/config.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {
// One [[method]] table after the common head.
std::string with_method(const std::string& method) { return std::string(kConfigHead) + "\n[[method]]\n" + method; }

void require_error(const std::string& method, std::initializer_list<std::string> fragments) {
  require_one_config_error(with_method(method), fragments);
}
}  // namespace

TEST_CASE("config: texture_size = \"auto\" fills the ladder (svd, mccool, fit)") {
  register_loaders();
  const Plan p = parse_plan(with_method(R"(kind = "svd"
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
  CHECK(p.methods[2].svd.res == 12);
}

TEST_CASE("config: texture_size = \"auto\" misuse names the key") {
  require_error("kind = \"svd\"\ntexture_size = \"auto\"\n",
                {"cfg.toml:", "texture_size", "needs a tolerance"});
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
