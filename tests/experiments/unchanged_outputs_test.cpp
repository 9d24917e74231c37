// Pages regenerated from unchanged inputs are not rewritten: a cached re-run
// leaves report.html and results.md (bytes and mtime) as they were; a change
// that shows on the page rewrites them. (The plots skip by hash in
// experiments/report/plot_results.py.)
#include <chrono>

#include "experiments/common/cli_util.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

// Sets the file's mtime an hour back and returns it.
fs::file_time_type age(const std::string& path) {
  const fs::file_time_type t = fs::last_write_time(path) - std::chrono::hours(1);
  fs::last_write_time(path, t);
  return t;
}

}  // namespace

TEST_CASE("outputs: write_file_if_changed keeps a file that holds the same bytes") {
  ScratchDir tmp;
  const std::string p = tmp / "page.html";
  CHECK(write_file_if_changed(p, [](std::ostream& o) { o << "same"; }));
  const fs::file_time_type t = age(p);
  CHECK_FALSE(write_file_if_changed(p, [](std::ostream& o) { o << "same"; }));
  CHECK(fs::last_write_time(p) == t);
  // Different bytes, a longer or shorter text with the same start: written.
  for (const char* text : {"diff", "same and more", "sam"}) {
    INFO(text);
    age(p);
    CHECK(write_file_if_changed(p, [&](std::ostream& o) { o << text; }));
    CHECK(read_text(p) == text);
    CHECK(fs::last_write_time(p) > t);
  }
  // A link is replaced by a file even when its target holds the same bytes.
  const std::string target = write_text(tmp / "target.html", "same");
  const std::string link = tmp / "link.html";
  fs::create_symlink(target, link);
  CHECK(write_file_if_changed(link, [](std::ostream& o) { o << "same"; }));
  CHECK_FALSE(fs::is_symlink(link));
  CHECK(read_text(link) == "same");
}

TEST_CASE("outputs: a cached re-run leaves report.html and results.md untouched, a visible change rewrites them") {
  ScratchDir tmp;
  const std::string body = R"([experiment]
name = "unchanged"
render = false
plots = false

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "mccool"
texture_size = 8
)";
  const std::string cfg = write_text(tmp / "cfg.toml", body);
  REQUIRE(run_quiet(cfg, tmp / "out").executed == 1);
  const std::string report = tmp / "out/report.html", md = tmp / "out/results.md";
  const std::string report_text = read_text(report), md_text = read_text(md);
  const fs::file_time_type t_report = age(report), t_md = age(md);

  const RunSummary again = run_quiet(cfg, tmp / "out");
  CHECK(again.executed == 0);
  CHECK(again.cached == 1);
  CHECK(read_text(report) == report_text);
  CHECK(read_text(md) == md_text);
  CHECK(fs::last_write_time(report) == t_report);
  CHECK(fs::last_write_time(md) == t_md);

  // A description shows on both pages (the runs stay cached): both rewritten.
  write_text(tmp / "cfg.toml", std::string(body).insert(body.find("render"), "description = \"now described\"\n"));
  run_quiet(cfg, tmp / "out");
  CHECK(read_text(report).find("now described") != std::string::npos);
  CHECK(read_text(md).find("now described") != std::string::npos);
  CHECK(fs::last_write_time(report) > t_report);
  CHECK(fs::last_write_time(md) > t_md);
}
