// The output folder under hostile and concurrent use (docs/robustness.md):
// nothing outside --out is written or deleted (merge manifests naming ../,
// planted links at temporary names), one writer per output folder (two real
// processes), and SIGINT/SIGTERM stop a run cleanly (real signals). Every
// wait on a child process is bounded.
#include <signal.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "brdfs/temp_file.h"
#include "experiments/config/config.h"
#include "experiments/run/outdir_lock.h"
#include "experiments_helpers.h"
#include "process_helpers.h"

using namespace bf_test;
using Catch::Matchers::Contains;

namespace {

// Small runs one at a time: a run of them lasts long enough to interrupt.
std::string many_runs_config(int runs, int resolution = 10) {
  std::string sizes;
  for (int i = 0; i < runs; ++i) sizes += (i ? ", " : "") + std::to_string(4 + i);
  return "[experiment]\nname = \"many\"\njobs = 1\nplots = false\n[[brdf]]\npreset = \"bluepaint\"\n"
         "[sampling]\nkind = \"grid\"\nresolution = " + std::to_string(resolution) + "\n[scene]\nsize = 16\n[[method]]\nkind = \"mccool\"\n"
         "texture_size = [" + sizes + "]\n";
}

std::vector<std::string> done_run_ids(const fs::path& out) {
  std::vector<std::string> ids;
  std::error_code ec;
  if (!fs::exists(out / "runs", ec)) return ids;
  for (const auto& e : fs::directory_iterator(out / "runs", ec))
    if (fs::exists(e.path() / "DONE", ec)) ids.push_back(e.path().filename().string());
  return ids;
}

// Waits (bounded) until `pred` holds or the child ends; true if pred held.
template <class Pred>
bool wait_until(Child& c, double seconds, Pred pred) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (pred()) return true;
    if (wait_child(c, 0)) return pred();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

size_t count_found(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("outdir: merge refuses a shard manifest whose run_id leaves the output folder") {
  ScratchDir d;
  const std::string cfg = write_text(d / "tiny.toml", kTinyConfig);
  run_quiet(cfg, d / "s1", {}, false, false, 1, 2);
  run_quiet(cfg, d / "s2", {}, false, false, 2, 2);
  // A victim folder next to the merge target that a "../victim" run id would reach.
  write_text(d / "victim/keep.txt", "keep");
  fs::create_directories(d.path / "merged" / "runs");
  const std::vector<std::string> bad_ids = {"../../victim", "../victim", "..", "a/b", "/tmp", "x\ny"};
  for (const std::string& bad : bad_ids) {
    INFO(bad);
    nlohmann::json m = nlohmann::json::parse(read_text(d / "s1/manifest.json"));
    const std::string old = m["runs"][0]["run_id"];
    m["runs"][0]["run_id"] = bad;
    for (auto& p : m["plan"])
      if (p["run_id"] == old) p["run_id"] = bad;
    fs::create_directories(d.path / "h1");
    fs::copy(d.path / "s1", d.path / "h1", fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    write_text(d / "h1/manifest.json", m.dump(1));
    std::string text;
    CHECK(run_cli("merge " + (d / "h1") + " " + (d / "s2") + " --out " + (d / "merged") + " --no-plots", &text) == 2);
    INFO(text);
    CHECK_THAT(text, Contains("h1/manifest.json: plan[") && Contains("].run_id: expected a plain name"));
    CHECK(read_text(d / "victim/keep.txt") == "keep");
    fs::remove_all(d.path / "h1");
  }
  // A listed file that climbs out is refused too.
  nlohmann::json m = nlohmann::json::parse(read_text(d / "s1/manifest.json"));
  m["runs"][0]["files"] = {"../../victim/keep.txt"};
  fs::copy(d.path / "s1", d.path / "h2", fs::copy_options::recursive);
  write_text(d / "h2/manifest.json", m.dump(1));
  std::string text;
  CHECK(run_cli("merge " + (d / "h2") + " " + (d / "s2") + " --out " + (d / "merged") + " --no-plots", &text) == 2);
  CHECK_THAT(text, Contains("h2/manifest.json: runs[0].files: expected a file name inside the experiment folder"));
  // The honest shards still merge.
  CHECK(run_cli("merge " + (d / "s1") + " " + (d / "s2") + " --out " + (d / "merged") + " --no-plots", &text) == 0);
  CHECK(read_text(d / "victim/keep.txt") == "keep");
}

TEST_CASE("outdir: a second run on the same output folder refuses, naming the holder") {
  ScratchDir d;
  // 16^4 grid: each run lasts long enough (about a second) for the second process to start meanwhile.
  const std::string cfg = write_text(d / "many.toml", many_runs_config(10, 16));
  const fs::path out = d.path / "out";
  Child first = spawn_cli({"run", cfg, "--out", out.string(), "--no-plots", "-j", "1"}, d / "first.log");
  // Wait until the first holds the lock and is inside its runs.
  REQUIRE(wait_until(first, 120, [&] { return fs::exists(out / "runs") && !read_text((out / bf::OutdirLock::kFileName).string()).empty(); }));
  REQUIRE(!wait_child(first, 0));
  REQUIRE(done_run_ids(out).size() < 10);
  std::string second;
  const int rc = run_cli_bounded({"run", cfg, "--out", out.string(), "--no-plots", "-j", "1"}, d / "second.log", 60,
                                 &second);
  const bool first_still_running = !wait_child(first, 0);
  INFO(second);
  if (first_still_running || rc != 0) {
    CHECK(rc == 2);
    CHECK_THAT(second, Contains("another brdf-factor process is writing to this output folder") &&
                           Contains("pid " + std::to_string(first.pid)) && Contains("choose another --out"));
  } else {
    // The first finished all its runs before the second got going (a very
    // loaded machine): the second then legitimately found every run cached.
    WARN("the first run ended before the second started: the refusal was not exercised");
    CHECK_THAT(second, Contains("0 run, 10 cached"));
  }
  // The first one was not disturbed: it finishes every run, exit 0.
  const bool ended = wait_child(first, 300);
  if (!ended) kill_child(first);
  REQUIRE(ended);
  INFO(read_text(d / "first.log"));
  CHECK(exit_code(first) == 0);
  CHECK(done_run_ids(out).size() == 10);
  CHECK(count_found(read_text((out / "results.csv").string()), "\n") == 11);
  // Once the holder is gone the folder is free again (a kernel lock: nothing stale).
  std::string again;
  CHECK(run_cli_bounded({"run", cfg, "--out", out.string(), "--no-plots", "-j", "1"}, d / "third.log", 120, &again) ==
        0);
  CHECK_THAT(again, Contains("0 run, 10 cached"));
  // In-process: two locks in one process on one folder also exclude each other.
  {
    const bf::OutdirLock a((d.path / "x").string(), "test");
    REQUIRE(a.held());
    CHECK_THROWS_WITH(bf::OutdirLock((d.path / "x").string(), "test"), Contains("pid " + std::to_string(::getpid())));
  }
  CHECK(bf::OutdirLock((d.path / "x").string(), "test").held());
}

TEST_CASE("outdir: links planted at temporary names are not written through") {
  ScratchDir d;
  const std::string cfg = write_text(d / "tiny.toml", kTinyConfig);
  const fs::path out = d.path / "out";
  const auto plan = bf::load_plan(cfg);
  write_text(d / "victim.txt", "victim");
  fs::create_directories(out / "runs" / plan.runs[0].run_id);
  // Every fixed temporary name the writers used before.
  for (const fs::path& p : {out / "results.csv.tmp", out / "results.md.tmp", out / "manifest.json.tmp",
                            out / "report.html.tmp", out / "config.toml.tmp", out / ".results.csv.tmp",
                            out / "runs" / plan.runs[0].run_id / "run.json.tmp",
                            out / "runs" / plan.runs[0].run_id / "DONE.tmp"})
    fs::create_symlink(d.path / "victim.txt", p);
  run_quiet(cfg, out.string());
  CHECK(read_text(d / "victim.txt") == "victim");
  CHECK(fs::exists(out / "results.csv"));
  // No temporary is left behind.
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    INFO(e.path().string());
    CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
  }
  // Unique names, created exclusively: two temporaries for one target differ.
  const std::string a = bf::create_unique_temp((out / "x.csv").string());
  const std::string b = bf::create_unique_temp((out / "x.csv").string());
  CHECK(a != b);
  CHECK(fs::is_regular_file(a));
  CHECK(fs::is_regular_file(b));
}

TEST_CASE("outdir: SIGINT and SIGTERM stop a run cleanly, keep the finished runs and say how to resume") {
  for (const int sig : {SIGINT, SIGTERM}) {
    const std::string name = sig == SIGINT ? "SIGINT" : "SIGTERM";
    INFO(name);
    ScratchDir d;
    const std::string cfg = write_text(d / "many.toml", many_runs_config(12));
    const fs::path out = d.path / "out";
    Child c = spawn_cli({"run", cfg, "--out", out.string(), "--no-plots", "-j", "1"}, d / "run.log");
    REQUIRE(wait_until(c, 120, [&] { return !done_run_ids(out).empty(); }));
    REQUIRE(!wait_child(c, 0));  // still running
    ::kill(c.pid, sig);
    const bool ended = wait_child(c, 60);  // bounded: a run in flight may finish first
    if (!ended) kill_child(c);
    REQUIRE(ended);
    const std::string log = read_text(d / "run.log");
    INFO(log);
    REQUIRE(WIFEXITED(c.status));  // not killed by the signal: it stopped itself
    CHECK(WEXITSTATUS(c.status) == 128 + sig);
    CHECK_THAT(log, Contains("interrupted by " + name) && Contains("run the same command again to resume"));
    const auto finished = done_run_ids(out);
    REQUIRE(!finished.empty());
    REQUIRE(finished.size() < 12);
    // The tables hold every run: finished ones ok, the rest marked interrupted.
    const std::string csv = read_text((out / "results.csv").string());
    CHECK(count_found(csv, "\n") == 13);
    CHECK(count_found(csv, ",interrupted,") + finished.size() >= 12);
    for (const auto& id : finished) CHECK_THAT(csv, Contains(id));
    const std::string md = read_text((out / "results.md").string());
    CHECK_THAT(md, Contains("interrupted"));
    // Resume: the finished runs are reused.
    std::string again;
    CHECK(run_cli_bounded({"run", cfg, "--out", out.string(), "--no-plots", "-j", "1"}, d / "again.log", 300, &again) ==
          0);
    CHECK_THAT(again, Contains(std::to_string(12 - finished.size()) + " run, " + std::to_string(finished.size()) +
                               " cached, 0 failed"));
  }
}
