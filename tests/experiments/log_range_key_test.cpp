// The homomorphic kinds' clamp_log_range key (docs/design.md §3.2): on by
// default, its range in the exported sidecar and in run.json's reconstruction;
// false exports an unclamped factorization and gives another run id.
#include <fstream>

#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

TEST_CASE("log range: the clamp_log_range key reaches the export and the run id") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "cfg.toml", R"([experiment]
name = "t"
plots = false

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "mccool"
texture_size = 8

[[method]]
kind = "mccool"
texture_size = 8
clamp_log_range = false
)");
  const RunSummary s = run_quiet(cfg, tmp / "out");
  REQUIRE(s.failed == 0);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("run_id") != rows[1].at("run_id"));
  size_t clamped = 0;
  for (const Row& row : rows) {
    const fs::path run = fs::path(tmp / "out/runs") / row.at("run_id");
    std::ifstream sj(run / "factors.json"), rj(run / "run.json");
    const nlohmann::json side = nlohmann::json::parse(sj), rec = nlohmann::json::parse(rj);
    const bool has = side.contains("log_range");
    INFO(rec.dump().substr(0, 2000));
    clamped += has;
    CHECK((rec.dump().find("exp(clamp(s, log_range)") != std::string::npos) == has);
    CHECK((rec.dump().find("\"clamp_log_range\":false") != std::string::npos) == !has);
    if (has) {
      for (int c = 0; c < 3; ++c) CHECK(side["log_range"][c][0].get<double>() <= side["log_range"][c][1].get<double>());
    }
  }
  CHECK(clamped == 1);
}
