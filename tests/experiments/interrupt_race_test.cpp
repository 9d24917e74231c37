// A run that finishes while the runner is handling SIGINT: the tables and the
// run folders must agree (docs/robustness.md "Interrupt race"). The race is
// made deterministic with the runner's test hook BF_TEST_SIGNAL_AT_RUN_END
// (experiments/run/interrupt.h): the first run to finish raises SIGINT itself
// just before its DONE marker and waits until the runner has taken its list of
// finished runs, so the run ends exactly while the signal is being handled.
#include <catch2/catch.hpp>

#include "experiments/report/outputs.h"
#include "experiments_helpers.h"
#include "process_helpers.h"

using namespace bf_test;
using Catch::Matchers::Contains;

namespace {

const char* const kThreeRuns = R"([experiment]
name = "race"
jobs = 1
plots = false
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "grid"
resolution = 6
[scene]
size = 16
[[method]]
kind = "mccool"
texture_size = [4, 5, 6]
)";

// Runs the CLI with the hook set in the child only.
int run_with_hook(const std::vector<std::string>& args, const std::string& log, std::string* text) {
  ::setenv("BF_TEST_SIGNAL_AT_RUN_END", "1", 1);
  Child c = spawn_cli(args, log);
  ::unsetenv("BF_TEST_SIGNAL_AT_RUN_END");
  const bool ended = wait_child(c, 120);
  if (!ended) kill_child(c);
  *text = read_text(log);
  return ended ? exit_code(c) : -2;
}

}  // namespace

TEST_CASE("interrupt race: a run finishing while SIGINT is handled is listed as its folder says") {
  for (int attempt = 0; attempt < 3; ++attempt) {  // the outcome must not depend on timing
    INFO("attempt " << attempt);
    ScratchDir d;
    const std::string cfg = write_text(d / "race.toml", kThreeRuns);
    const fs::path out = d.path / "out";
    std::string text;
    const int code = run_with_hook({"run", cfg, "--out", out.string(), "--no-plots", "-j", "1"}, d / "run.log", &text);
    INFO(text);
    REQUIRE(code == 130);  // stopped by the signal the hook raised
    CHECK_THAT(text, Contains("interrupted by SIGINT"));
    const auto rows = bf::read_results_csv((out / "results.csv").string());
    REQUIRE(rows.size() == 3);
    size_t ok = 0;
    for (const auto& r : rows) {
      const std::string id = r.at("run_id");
      const bool done = fs::exists(out / "runs" / id / "DONE");
      INFO(id << ": status " << r.at("status") << ", DONE " << (done ? "present" : "absent"));
      CHECK(done == (r.at("status") == "ok"));
      CHECK((r.at("status") == "ok" || r.at("status") == "interrupted"));
      ok += r.at("status") == "ok";
    }
    // The message's counts are the tables' counts.
    CHECK_THAT(text, Contains(std::to_string(ok) + " of 3 runs are finished"));
    // Resume: the runs with DONE are reused, the others done; all agree again.
    std::string again;
    CHECK(run_cli_bounded({"run", cfg, "--out", out.string(), "--no-plots", "-j", "1"}, d / "again.log", 120, &again) ==
          0);
    INFO(again);
    CHECK_THAT(again, Contains(std::to_string(3 - ok) + " run, " + std::to_string(ok) + " cached, 0 failed"));
  }
}
