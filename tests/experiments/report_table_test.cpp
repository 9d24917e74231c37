// Tests of the tables for people and the plot script: key columns first, best
// value per BRDF marked, plot_results.py ticks, series and redraw-on-change.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "experiments/report/outputs.h"
#include "experiments/report/report.h"
#include "test_common.h"

using namespace bf;
using bf_test::TempDir;

namespace {
RunEntry run(const std::string& brdf, const std::string& rel_mse, const std::string& storage,
             const std::string& status = "ok") {
  RunEntry r;
  r.status = status;
  r.row["brdf"] = brdf;
  r.row["method"] = "svd";
  r.row["rel_mse"] = rel_mse;
  r.row["storage_floats"] = storage;
  r.row["seconds"] = "1";
  return r;
}
}  // namespace

TEST_CASE("report table: key columns first, the rest in order") {
  const std::vector<std::string> cols = {"run_id", "brdf", "method", "label", "parameterization", "terms",
                                         "rel_mse", "rel_mae", "cos_rmse", "storage_floats", "seconds",
                                         "evaluations", "notes"};
  const auto out = key_columns_first(cols);
  const std::vector<std::string> expected = {"brdf", "method", "label", "rel_mse", "cos_rmse", "storage_floats",
                                             "seconds", "evaluations", "run_id", "parameterization", "terms",
                                             "rel_mae", "notes"};
  CHECK(out == expected);
  std::vector<RunEntry> runs;
  CHECK(display_columns(runs).front() == "brdf");
}

TEST_CASE("report table: the best value per BRDF and column is marked, failed runs and lone runs are not") {
  std::vector<RunEntry> runs = {run("a", "0.5", "100"), run("a", "0.2", "300"), run("a", "0.2", "200"),
                                run("a", "0.01", "10", "failed"), run("b", "0.9", "50"), run("c", "", "7"),
                                run("c", "0.3", "8")};
  const auto best = best_cells(runs, {"brdf", "rel_mse", "storage_floats", "seconds"});
  CHECK(best.count({1, "rel_mse"}) == 1);  // tie: both marked
  CHECK(best.count({2, "rel_mse"}) == 1);
  CHECK(best.count({0, "rel_mse"}) == 0);
  CHECK(best.count({3, "rel_mse"}) == 0);         // failed
  CHECK(best.count({0, "storage_floats"}) == 1);  // 100 < 200 < 300
  CHECK(best.count({4, "rel_mse"}) == 0);         // only run of b
  CHECK(best.count({6, "rel_mse"}) == 0);         // the other c run has no value
  CHECK(best.count({5, "storage_floats"}) == 1);
  CHECK(best.count({0, "brdf"}) == 0);
  // seconds: all equal within a BRDF -> all marked.
  CHECK(best.count({0, "seconds"}) == 1);
  CHECK(best.count({4, "seconds"}) == 0);
}

TEST_CASE("plot script: ticks, a plot per swept option, redrawn only when results.csv changes") {
  const std::string py = find_python(nullptr);
  // matplotlib is installed by scripts/install-deps.sh: missing, the test fails.
  INFO("no python3 with matplotlib (scripts/install-deps.sh installs python3-matplotlib)");
  REQUIRE(!py.empty());
  TempDir dir("plots");
  const std::string script = plot_script_path();
  // Tick choice: 3..8 labelled ticks for a range of spans, inside the range.
  {
    const std::string probe =
        "import sys; sys.path.insert(0, '" + std::filesystem::path(script).parent_path().string() +
        "'); import plot_results as p\n"
        "for lo, hi in [(0.3, 0.5), (0.042, 0.047), (0.03, 0.6), (1e-4, 0.5), (1e-9, 1.0), (100, 2e4), (1e-12, 1e3)]:\n"
        "    t = p.log_ticks(lo, hi)\n"
        "    assert 3 <= len(t) <= 8, (lo, hi, t)\n"
        "    assert all(lo * (1 - 1e-9) <= x <= hi * (1 + 1e-9) for x in t), (lo, hi, t)\n"
        "    assert len(set(p.compact(x) for x in t)) == len(t), (lo, hi, t)\n"
        "print('ok')\n";
    std::ofstream(dir.file("probe.py")) << probe;
    CHECK(std::system((py + " " + dir.file("probe.py") + " > " + dir.file("probe.txt") + " 2>&1").c_str()) == 0);
    INFO(bf_test::slurp(dir.file("probe.txt")));
    CHECK(bf_test::slurp(dir.file("probe.txt")) == "ok\n");
  }
  // A sweep over terms and texture_size for two parameterizations.
  const std::string csv = dir.file("results.csv");
  auto write_csv = [&](double scale) {
    std::ofstream o(csv);
    o << "run_id,brdf,method,parameterization,reciprocity,terms,texture_size,rel_mse,cos_rmse,storage_floats,"
         "seconds,label,sampling,sweep,status\n";
    int id = 0;
    for (const char* param : {"wiwo", "halfdiff"})
      for (int terms : {1, 2, 4})
        for (int res : {8, 16})
          o << id++ << ",b," << "svd," << param << ",," << terms << "," << res << ","
            << scale * 0.5 / (terms * res) << "," << 0.1 / terms << "," << terms * res * res << ","
            << 0.01 * terms << ",svd,grid 8^4,parameterization=" << param << " terms=" << terms
            << " texture_size=" << res << ",ok\n";
  };
  write_csv(1.0);
  const std::string out = dir.file("plots");
  const std::string cmd = py + " " + script + " " + csv + " --out " + out + " > " + dir.file("log.txt") + " 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string log1 = bf_test::slurp(dir.file("log.txt"));
  INFO(log1);
  for (const char* stem : {"error_vs_terms", "error_vs_storage", "error_vs_seconds", "error_vs_texture_size",
                           "by_brdf_rel_mse", "by_brdf_cos_rmse"})
    CHECK(std::filesystem::exists(out + "/" + stem + ".png"));
  CHECK(!std::filesystem::exists(out + "/error_vs_parameterization.png"));  // not numeric
  const auto t1 = std::filesystem::last_write_time(out + "/error_vs_storage.png");
  // Unchanged inputs: nothing redrawn, the same files reported.
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string log2 = bf_test::slurp(dir.file("log.txt"));
  CHECK(log2.find("not redrawn") != std::string::npos);
  CHECK(log2.find("wrote " + out + "/error_vs_storage.png") != std::string::npos);
  CHECK(std::filesystem::last_write_time(out + "/error_vs_storage.png") == t1);
  // Changed results: redrawn.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  write_csv(2.0);
  REQUIRE(std::system(cmd.c_str()) == 0);
  CHECK(bf_test::slurp(dir.file("log.txt")).find("not redrawn") == std::string::npos);
  CHECK(std::filesystem::last_write_time(out + "/error_vs_storage.png") != t1);
}
