// The runner: outputs, caching, resume after a kill, sharding and merge,
// report links, failures.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <regex>

#include "experiments/report/outputs.h"
#include "experiments/report/report.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

// Rows without the timing column, which differs between executions.
std::vector<Row> rows_without_time(const std::string& csv) {
  std::vector<Row> rows = read_results_csv(csv);
  for (auto& r : rows) r.erase("seconds");
  return rows;
}

std::string row_text(const Row& r) {
  std::string s;
  for (const auto& [k, v] : r) s += k + "=" + v + " ";
  return s;
}

void require_no_nan(const std::string& path) {
  const std::string text = read_text(path);
  static const std::regex bad(R"((^|[^A-Za-z_])(nan|NaN|inf|Infinity)([^A-Za-z_]|$))");
  INFO(path);
  CHECK(!std::regex_search(text, bad));
}

}  // namespace

TEST_CASE("runner: dry run lists every run with its action and writes nothing") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  register_loaders();
  RunOptions o;
  o.config = cfg;
  o.out = tmp / "out";
  o.dry_run = true;
  std::ostringstream out, err;
  const RunSummary s = run_experiment(o, out, err);
  CHECK(s.planned == 5);
  const std::string text = out.str();
  INFO(text);
  CHECK(text.find("5 runs (1 brdf x 1 sampling x 5 method variants)") != std::string::npos);
  CHECK(text.find("would run 5, skip 0 cached") != std::string::npos);
  for (const auto& id : s.run_ids) CHECK(text.find(id + "  run") != std::string::npos);
  CHECK(!fs::exists(tmp / "out"));

  // After a run, the dry run says what would be skipped, and which shards skip what.
  run_quiet(cfg, tmp / "out");
  std::ostringstream out2;
  o.shard = 1;
  o.shards = 2;
  o.out = tmp / "out";
  run_experiment(o, out2, err);
  INFO(out2.str());
  CHECK(out2.str().find("would run 0, skip 3 cached (--force redoes them) and 2 of other shards") !=
        std::string::npos);
  CHECK(out2.str().find("other-shard") != std::string::npos);
}

TEST_CASE("runner: outputs, then a re-run reuses every run, --force redoes them") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  const std::string out = tmp / "out";
  const RunSummary a = run_quiet(cfg, out);
  CHECK(a.executed == 5);
  CHECK(a.cached == 0);

  // results.csv: docs/design.md §5's columns first, in order.
  const std::string header = read_text(out + "/results.csv").substr(0, read_text(out + "/results.csv").find('\n'));
  std::string expected;
  for (const auto& c : required_columns()) expected += (expected.empty() ? "" : ",") + c;
  CHECK(header.rfind(expected + ",", 0) == 0);
  const auto rows = read_results_csv(out + "/results.csv");
  REQUIRE(rows.size() == 5);
  for (const auto& r : rows) {
    INFO(row_text(r));
    CHECK(r.at("status") == "ok");
    CHECK(!r.at("rel_mse").empty());
    CHECK(r.at("brdf") == "bluepaint");
    CHECK(fs::exists(fs::path(out) / "runs" / r.at("run_id") / "DONE"));
    CHECK(fs::exists(fs::path(out) / "runs" / r.at("run_id") / "sphere.png"));
    CHECK(!r.at("shade_rmse").empty());  // [scene] given
  }
  CHECK(rows[0].at("method") == "mccool");
  CHECK(rows[0].at("reciprocity") == "true");
  CHECK(rows[0].at("errors_after_term").find(';') != std::string::npos);
  CHECK(fs::exists(fs::path(out) / "runs" / rows[0].at("run_id") / "factors.json"));
  CHECK(fs::exists(fs::path(out) / "runs" / rows[0].at("run_id") / "factors_term0.exr"));
  CHECK(fs::exists(fs::path(out) / "runs" / rows[0].at("run_id") / "factors.glsl"));
  CHECK(rows[2].at("terms") == "1");
  CHECK(rows[3].at("terms") == "2");
  CHECK(rows[4].at("method") == "svd");
  CHECK(rows[4].at("reciprocity").empty());
  CHECK(fs::exists(fs::path(out) / "runs" / rows[4].at("run_id") / "factorization.json"));
  for (const char* f : {"results.csv", "results.md", "manifest.json", "report.html", "config.toml"})
    CHECK(fs::exists(fs::path(out) / f));
  for (const char* f : {"results.csv", "results.md", "manifest.json", "report.html"}) require_no_nan(out + "/" + f);

  // manifest: config, versions, seeds, per-run files.
  nlohmann::json m;
  std::ifstream(out + "/manifest.json") >> m;
  CHECK(m["config"]["text"] == kTinyConfig);
  CHECK(m["versions"]["brdf_factor"] == kBrdfFactorVersion);
  CHECK(m["experiment"]["seed"] == 5);
  REQUIRE(m["runs"].size() == 5);
  CHECK(m["runs"][0]["seeds"]["experiment"] == 5);
  for (const auto& r : m["runs"])
    for (const auto& f : r["files"]) CHECK(fs::exists(fs::path(out) / f.get<std::string>()));

  const std::string csv_before = read_text(out + "/results.csv");
  const RunSummary b = run_quiet(cfg, out);
  CHECK(b.executed == 0);
  CHECK(b.cached == 5);
  CHECK(read_text(out + "/results.csv") == csv_before);  // cached rows are the stored ones

  const RunSummary c = run_quiet(cfg, out, {}, false, /*force=*/true);
  CHECK(c.executed == 5);
  CHECK(c.cached == 0);

  // A changed option redoes only the runs it determines.
  const RunSummary d = run_quiet(cfg, out, {"method[2].texture_size=4"});
  CHECK(d.executed == 1);
  CHECK(d.cached == 4);
}

TEST_CASE("runner: a run folder without its done-marker is redone, never reported as done") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  const std::string out = tmp / "out";
  const RunSummary a = run_quiet(cfg, out);
  REQUIRE(a.run_ids.size() == 5);
  // Simulate a kill during run 2: its folder exists, half-written, no DONE.
  const fs::path killed = fs::path(out) / "runs" / a.run_ids[2];
  fs::remove(killed / "DONE");
  fs::remove(killed / "run.json");
  write_text((killed / "factors.json").string(), "{ half");
  // And a run whose listed file vanished.
  fs::remove(fs::path(out) / "runs" / a.run_ids[4] / "sphere.png");

  register_loaders();
  RunOptions o;
  o.config = cfg;
  o.out = out;
  o.dry_run = true;
  std::ostringstream dry, err;
  run_experiment(o, dry, err);
  CHECK(dry.str().find(a.run_ids[2] + "  redo") != std::string::npos);

  const RunSummary b = run_quiet(cfg, out);
  CHECK(b.executed == 2);
  CHECK(b.redone == 2);
  CHECK(b.cached == 3);
  CHECK(fs::exists(killed / "DONE"));
  CHECK(read_text((killed / "factors.json").string()).find("{ half") == std::string::npos);
}

TEST_CASE("runner: shards 1..N together equal the unsharded rows, and merge collates them") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  run_quiet(cfg, tmp / "all");
  const auto all_rows = rows_without_time(tmp / "all/results.csv");
  REQUIRE(all_rows.size() == 5);

  std::vector<Row> union_rows;
  std::vector<std::string> dirs;
  for (int k = 1; k <= 3; ++k) {
    const std::string d = tmp / ("shard" + std::to_string(k));
    const RunSummary s = run_quiet(cfg, d, {}, false, false, k, 3);
    CHECK(s.in_shard == (k == 1 || k == 2 ? 2u : 1u));
    for (auto& r : rows_without_time(d + "/results.csv")) union_rows.push_back(r);
    dirs.push_back(d);
  }
  REQUIRE(union_rows.size() == all_rows.size());
  for (const auto& r : all_rows) {
    INFO(row_text(r));
    CHECK(std::count(union_rows.begin(), union_rows.end(), r) == 1);
  }

  std::ostringstream out, err;
  const RunSummary m = merge_experiments({dirs[2], dirs[0], dirs[1]}, tmp / "merged", true, false, out, err);
  CHECK(m.in_shard == 5);
  CHECK(rows_without_time(tmp / "merged/results.csv") == all_rows);  // plan order restored
  for (const auto& r : all_rows) CHECK(fs::exists(fs::path(tmp / "merged") / "runs" / r.at("run_id") / "DONE"));

  // The CLI's default shard folder is experiment.out/shard-K-of-N.
  std::string text;
  CHECK(run_cli("run " + cfg + " -q --no-plots --shard 2/3 -D experiment.out=" + (tmp / "cli"), &text) == 0);
  CHECK(fs::exists(fs::path(tmp / "cli") / "shard-2-of-3" / "results.csv"));
  CHECK(run_cli("run " + cfg + " --shard 4/3", &text) == 2);
  CHECK(text.find("--shard") != std::string::npos);
}

TEST_CASE("runner: merge detects missing and duplicated runs") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  const std::string s1 = tmp / "s1", s2 = tmp / "s2";
  run_quiet(cfg, s1, {}, false, false, 1, 2);
  run_quiet(cfg, s2, {}, false, false, 2, 2);
  std::ostringstream out, err;
  auto merge_error = [&](const std::vector<std::string>& dirs) -> std::string {
    try {
      merge_experiments(dirs, tmp / "m", true, false, out, err);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  SECTION("a missing shard") {
    const std::string e = merge_error({s1});
    INFO(e);
    CHECK(e.find("2 of 5 runs missing") != std::string::npos);
    CHECK(e.find("no folder given") != std::string::npos);
    CHECK(!fs::exists(tmp / "m"));
  }
  SECTION("a shard given twice") {
    const std::string e = merge_error({s1, s2, s1});
    CHECK(e.find("shard 1/2 given twice") != std::string::npos);
  }
  SECTION("a run present in two folders") {
    // A copy of shard 1 that claims to be shard 2: its runs duplicate shard 1's.
    const std::string fake = tmp / "fake";
    fs::copy(s1, fake, fs::copy_options::recursive);
    nlohmann::json m;
    std::ifstream(fake + "/manifest.json") >> m;
    m["shard"]["k"] = 2;
    std::ofstream(fake + "/manifest.json") << m.dump();
    const std::string e = merge_error({s1, fake});
    INFO(e);
    CHECK(e.find("3 duplicated") != std::string::npos);
    CHECK(e.find("runs missing") != std::string::npos);
  }
  SECTION("a run that is not done") {
    nlohmann::json m;
    std::ifstream(s2 + "/manifest.json") >> m;
    fs::remove(fs::path(s2) / "runs" / m["runs"][0]["run_id"].get<std::string>() / "DONE");
    const std::string e = merge_error({s1, s2});
    CHECK(e.find("has no DONE marker") != std::string::npos);
  }
  SECTION("shards of different plans") {
    run_quiet(cfg, tmp / "other", {"sampling.resolution=5"}, false, false, 2, 2);
    const std::string e = merge_error({s1, tmp / "other"});
    CHECK(e.find("plan") != std::string::npos);
  }
  SECTION("the CLI exits 2 with one line") {
    std::string text;
    CHECK(run_cli("merge " + s1 + " --out " + (tmp / "m"), &text) == 2);
    CHECK(text.rfind("brdf-factor: merge: 2 of 5 runs missing", 0) == 0);
  }
}

TEST_CASE("runner: every link and image of report.html resolves") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  const std::string out = tmp / "out";
  const RunSummary s = run_quiet(cfg, out, {}, /*plots=*/true);
  const std::string html = read_text(out + "/report.html");
  const auto links = html_links(html);
  CHECK(links.size() > 20);
  size_t images = 0;
  for (const auto& l : links) {
    INFO(l);
    CHECK(l.find("://") == std::string::npos);  // self-contained: no network resources
    if (l.rfind("#", 0) == 0) {
      CHECK(html.find("id=\"" + l.substr(1) + "\"") != std::string::npos);
      continue;
    }
    CHECK(fs::exists(fs::path(out) / l));
    images += l.size() > 4 && l.substr(l.size() - 4) == ".png";
  }
  CHECK(images >= 5);
  // Every run file is linked.
  for (const auto& id : s.run_ids)
    for (const auto& e : fs::directory_iterator(fs::path(out) / "runs" / id)) {
      const std::string name = e.path().filename().string();
      if (name == "DONE") continue;
      CHECK(std::find(links.begin(), links.end(), "runs/" + id + "/" + name) != links.end());
    }
  {
    // python3-matplotlib is installed by scripts/install-deps.sh: missing, the test fails.
    std::string why;
    const bool have_python = !find_python(&why).empty();
    INFO("no python3 with matplotlib (" << why << "; " << s.files.plots_note
                                        << "): scripts/install-deps.sh installs python3-matplotlib");
    REQUIRE(have_python);
    // error_vs_terms, error_vs_seconds, error_vs_storage, by_brdf_rel_mse, by_brdf_cos_rmse
    CHECK(s.files.plots.size() >= 5);  // plus error_vs_<key> per swept numeric option
    const auto has_plot = [&](const std::string& stem) {
      return std::any_of(s.files.plots.begin(), s.files.plots.end(),
                         [&](const std::string& p) { return p.find(stem) != std::string::npos; });
    };
    CHECK(has_plot("error_vs_storage"));
    CHECK(has_plot("by_brdf_rel_mse"));
    CHECK(has_plot("by_brdf_cos_rmse"));
    for (const auto& p : s.files.plots) CHECK(std::find(links.begin(), links.end(), p) != links.end());
  }
}

TEST_CASE("runner: a failing run is marked failed, is not done, and makes the command fail") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "zero.toml", R"(
[[brdf]]
model = "lambert"
kd = 0
[[brdf]]
preset = "bluepaint"
[sampling]
resolution = 5
[[method]]
kind = "mccool"
texture_size = 4
)");
  const std::string out = tmp / "out";
  CHECK_THROWS_WITH(run_quiet(cfg, out), Catch::Contains("1 of 2 runs failed") && Catch::Contains("mean"));
  const auto rows = read_results_csv(out + "/results.csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("status") == "failed");
  CHECK(rows[0].at("rel_mse").empty());
  CHECK(rows[0].at("notes").rfind("failed: ", 0) == 0);
  CHECK(!fs::exists(fs::path(out) / "runs" / rows[0].at("run_id") / "DONE"));
  CHECK(rows[1].at("status") == "ok");
  require_no_nan(out + "/results.csv");
  std::string text;
  CHECK(run_cli("run " + cfg + " -q --no-plots --out " + out, &text) == 2);
  CHECK(text.find("brdf-factor: 1 of 2 runs failed") != std::string::npos);
}

TEST_CASE("runner: progress on stderr, silenced by --quiet") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  register_loaders();
  RunOptions o;
  o.config = cfg;
  o.out = tmp / "out";
  o.plots = false;
  o.defines = {"method[0].texture_size=4"};
  std::ostringstream out, err;
  run_experiment(o, out, err);
  INFO(err.str());
  CHECK(err.str().find("[4/4] done") != std::string::npos);
  CHECK(err.str().find("eta") != std::string::npos);
  CHECK(out.str().find("results: " + (tmp / "out") + "/results.md") != std::string::npos);
  CHECK(out.str().find("report:  " + (tmp / "out") + "/report.html") != std::string::npos);
  std::string text;
  CHECK(run_cli("run " + cfg + " -q --no-plots --out " + (tmp / "q"), &text) == 0);
  CHECK(text.find("done") == std::string::npos);
  CHECK(text.find("results: ") != std::string::npos);
}

TEST_CASE("runner: the Slurm template's tasks merge into the whole experiment") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "tiny.toml", kTinyConfig);
  const std::string script = source_path("experiments/slurm-array.sh");
  for (int k = 1; k <= 2; ++k) {
    const int code = std::system(("CONFIG=" + cfg + " OUT=" + (tmp / "out") + " N=2 SLURM_ARRAY_TASK_ID=" +
                                  std::to_string(k) + " BRDF_FACTOR=" + BF_CLI_PATH + " DEFINES='-q' bash " + script +
                                  " >/dev/null 2>&1")
                                     .c_str());
    CHECK(code == 0);
  }
  std::string text;
  CHECK(run_cli("merge " + (tmp / "out/shard-1-of-2") + " " + (tmp / "out/shard-2-of-2") + " -q --no-plots --out " +
                    (tmp / "merged"),
                &text) == 0);
  INFO(text);
  CHECK(read_results_csv(tmp / "merged/results.csv").size() == 5);
}

TEST_CASE("runner: tabulating methods on measured data say how it was resampled") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "measured.toml", R"(
[[brdf]]
model = "krylon-blue"
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "stratified"
count = 600
[[method]]
kind = "svd"
texture_size = 4
terms = 1
[[method]]
kind = "mccool"
texture_size = 4
)");
  const std::string out = tmp / "out";
  run_quiet(cfg, out);
  const auto rows = read_results_csv(out + "/results.csv");
  REQUIRE(rows.size() == 4);
  for (const auto& r : rows) {
    INFO(r.at("brdf") << " " << r.at("method") << ": " << r.at("notes"));
    const bool resampled = r.at("notes").find("resampled: tabulated from the modified Shepard interpolant") !=
                           std::string::npos;
    // Only the SVD of the measured paint reads an interpolant; McCool fits the
    // samples themselves and bluepaint is analytic.
    CHECK(resampled == (r.at("brdf") == "krylon-blue" && r.at("method") == "svd"));
  }
}

TEST_CASE("runner: cached runs made by another build are counted and warned about") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "two.toml", R"(
[[brdf]]
preset = "bluepaint"
[sampling]
resolution = 5
[[method]]
kind = "mccool"
texture_size = [4, 5]
)");
  const std::string out = tmp / "out";
  const RunSummary first = run_quiet(cfg, out);
  REQUIRE(first.executed == 2);
  const nlohmann::json build = build_identity(software_versions());
  CHECK(build.contains("brdf_factor"));
  if (bf_test::skip_unless_ci(build.contains("git_commit"),
                              "the source tree is not a git checkout (or git is missing): "
                              "nothing to compare builds by"))
    return;
  // Every run records the build that made it.
  const std::string run_json = out + "/runs/" + first.run_ids[0] + "/run.json";
  nlohmann::json rec = nlohmann::json::parse(read_text(run_json));
  CHECK(cached_run_commit(rec) == build["git_commit"].get<std::string>());
  // Same build: reused silently.
  RunOptions o;
  o.config = cfg;
  o.out = out;
  o.quiet = true;
  std::ostringstream sout, serr;
  RunSummary again = run_experiment(o, sout, serr);
  CHECK(again.cached == 2);
  CHECK(again.cached_other_build == 0);
  CHECK(serr.str().find("another build") == std::string::npos);
  // One run from another commit, one with no record at all (an older version).
  rec["build"]["git_commit"] = "0123456789ab";
  write_text(run_json, rec.dump(2));
  const std::string run_json2 = out + "/runs/" + first.run_ids[1] + "/run.json";
  nlohmann::json rec2 = nlohmann::json::parse(read_text(run_json2));
  rec2.erase("build");
  write_text(run_json2, rec2.dump(2));
  // As those builds would have left them: each DONE marker hashes its run's files as written.
  for (const auto& id : first.run_ids) {
    const fs::path dir = fs::path(out) / "runs" / id;
    const auto files = nlohmann::json::parse(read_text((dir / "run.json").string()))["files"];
    write_done_marker(dir, done_marker(out, id, files.get<std::vector<std::string>>()));
  }
  std::ostringstream sout2, serr2;
  again = run_experiment(o, sout2, serr2);
  CHECK(again.cached == 2);
  CHECK(again.cached_other_build == 2);
  INFO(serr2.str());
  CHECK(serr2.str().find("warning: 2 of 2 cached runs were made by another build (0123456789ab, unrecorded; "
                         "this build " + build["git_commit"].get<std::string>()) != std::string::npos);
  CHECK(serr2.str().find("--force redoes them") != std::string::npos);
}
