// Nothing lost (issue #8, docs/robustness.md): a `brdf-factor run` killed with
// SIGKILL mid-way leaves every finished run intact, and running it again
// resumes without recomputing them; an output folder that cannot be created or
// written, or a file system without room for the estimated outputs, is an
// error (exit 2, naming the folder) before any run starts.
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <chrono>
#include <map>
#include <regex>
#include <thread>

#include "experiments/config/config.h"
#include "experiments/run/preflight.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

// Twelve small runs, one at a time: long enough to kill between two of them.
const char* kManyRuns = R"(
[experiment]
name = "many"
jobs = 1
plots = false

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 8

[scene]
size = 16

[[method]]
kind = "mccool"
texture_size = [4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]
)";

std::vector<std::string> done_runs(const fs::path& out) {
  std::vector<std::string> ids;
  std::error_code ec;
  if (!fs::exists(out / "runs", ec)) return ids;
  for (const auto& e : fs::directory_iterator(out / "runs", ec))
    if (fs::exists(e.path() / "DONE", ec)) ids.push_back(e.path().filename().string());
  std::sort(ids.begin(), ids.end());
  return ids;
}

size_t count_lines(const std::string& text) { return std::count(text.begin(), text.end(), '\n'); }

uint64_t folder_bytes(const fs::path& dir) {
  uint64_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) n += e.file_size();
  return n;
}

}  // namespace

TEST_CASE("nothing lost: run killed with SIGKILL after its first finished run resumes without recomputing") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "many.toml", kManyRuns);
  const fs::path out = tmp.path / "out";
  const Plan plan = load_plan(cfg);
  REQUIRE(plan.runs.size() == 12);

  // Start the CLI (fork/exec, stdout and stderr to a file) and kill it hard as
  // soon as one run has its DONE marker.
  const std::string log = tmp / "first.log";
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    std::FILE* f = std::freopen(log.c_str(), "w", stderr);
    if (f) ::dup2(::fileno(stderr), 1);
    ::execl(BF_CLI_PATH, BF_CLI_PATH, "run", cfg.c_str(), "--out", out.c_str(), "--no-plots", "-j", "1",
            static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  std::vector<std::string> at_kill;
  int status = 0;
  bool exited = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (std::chrono::steady_clock::now() < deadline) {
    at_kill = done_runs(out);
    if (!at_kill.empty()) break;
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (!exited) {
    ::kill(pid, SIGKILL);
    REQUIRE(::waitpid(pid, &status, 0) == pid);
    CHECK(WIFSIGNALED(status));
  }
  INFO(read_text(log));
  REQUIRE_FALSE(exited);  // killed, not finished on its own
  at_kill = done_runs(out);  // runs that finished before the signal landed
  REQUIRE(!at_kill.empty());
  REQUIRE(at_kill.size() < plan.runs.size());
  CHECK(!fs::exists(out / "results.csv"));  // tables are written at the end

  // Every finished run is whole: its record parses and the files it lists exist.
  std::map<std::string, fs::file_time_type> stamp;
  for (const std::string& id : at_kill) {
    const fs::path dir = out / "runs" / id;
    const nlohmann::json rec = nlohmann::json::parse(read_text((dir / "run.json").string()));
    CHECK(rec.at("run_id") == id);
    stamp[id] = fs::last_write_time(dir / "DONE");
  }

  // Again: the finished runs are reused (the summary line counts them), the rest done.
  std::string text;
  REQUIRE(run_cli("run " + cfg + " --out " + out.string() + " --no-plots -j 1", &text) == 0);
  INFO(text);
  const size_t left = plan.runs.size() - at_kill.size();
  CHECK_THAT(text, Catch::Contains(std::to_string(left) + " run, " + std::to_string(at_kill.size()) + " cached, 0 failed"));
  for (const auto& [id, t] : stamp) {
    INFO(id);
    CHECK(fs::last_write_time(out / "runs" / id / "DONE") == t);  // not recomputed
  }
  CHECK(done_runs(out).size() == plan.runs.size());
  const std::string csv = read_text((out / "results.csv").string());
  CHECK(count_lines(csv) == plan.runs.size() + 1);  // header + every run
  CHECK(csv.find(",failed,") == std::string::npos);
  CHECK_FALSE(std::regex_search(csv, std::regex(R"((^|[^A-Za-z_])(nan|NaN|inf|Infinity)([^A-Za-z_]|$))")));

  // A third time: nothing left to do.
  REQUIRE(run_cli("run " + cfg + " --out " + out.string() + " --no-plots -j 1", &text) == 0);
  CHECK_THAT(text, Catch::Contains("0 run, 12 cached, 0 failed"));

  // The free-space estimate covers what the experiment wrote.
  const uint64_t written = folder_bytes(out);
  const uint64_t estimate = estimate_output_bytes(plan, std::vector<bool>(plan.runs.size(), true));
  INFO("wrote " << written << " bytes, estimate " << estimate);
  CHECK(written <= estimate);
}

TEST_CASE("nothing lost: an output folder that cannot be created or written fails before any run") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "many.toml", kManyRuns);
  std::string text;

  // Under a regular file: ENOTDIR, for root too.
  write_text(tmp / "plain.txt", "not a folder\n");
  const std::string under_file = tmp / "plain.txt/out";
  CHECK(run_cli("run " + cfg + " --out " + under_file + " --no-plots", &text) == 2);
  CHECK_THAT(text, Catch::Contains("brdf-factor: " + under_file + ": cannot create the output folder: ") &&
                       Catch::Contains("Not a directory"));
  CHECK_THAT(text, !Catch::Contains("start 1/"));

  // Read-only folder. chmod 555 blocks an unprivileged user; root (CI runs as
  // root) writes anyway, so as root the CLI runs in a private mount namespace
  // where the folder is bind-mounted read-only (util-linux unshare, needs
  // CAP_SYS_ADMIN): a failure to set that up fails the test, never skips it.
  const fs::path ro = tmp.path / "readonly";
  fs::create_directories(ro);
  ::chmod(ro.c_str(), 0555);
  const bool chmod_blocks = ::access(ro.c_str(), W_OK) != 0;
  auto run_readonly = [&](const std::string& args, std::string* out) {
    if (chmod_blocks) return run_cli(args, out);
    const std::string cmd = "unshare -m sh -c 'mount --bind -o ro " + ro.string() + " " + ro.string() +
                            " && exec " + std::string(BF_CLI_PATH) + " " + args + "' 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    std::string o;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) o.append(buf, n);
    const int st = pclose(p);
    *out = o;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  };
  INFO((chmod_blocks ? "chmod 555" : "read-only bind mount (euid 0)"));
  CHECK(run_readonly("run " + cfg + " --out " + (ro / "out").string() + " --no-plots", &text) == 2);
  CHECK_THAT(text, Catch::Contains((ro / "out").string() + ": cannot create the output folder"));
  CHECK(run_readonly("run " + cfg + " --out " + ro.string() + " --no-plots", &text) == 2);
  CHECK_THAT(text, Catch::Contains(ro.string() + ": the output folder is not writable"));
  CHECK_THAT(text, !Catch::Contains("start 1/"));
  CHECK(fs::is_empty(ro));
  ::chmod(ro.c_str(), 0755);
}

TEST_CASE("nothing lost: too little free space fails before any run, naming folder, need and free") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "many.toml", kManyRuns);
  const std::string out = tmp / "out";
  const uint64_t need = estimate_output_bytes(load_plan(cfg), std::vector<bool>(12, true));
  std::string text;
  // The CLI inherits the variable through popen.
  struct FakeFree {
    explicit FakeFree(const std::string& v) { ::setenv("BF_FAKE_FREE_BYTES", v.c_str(), 1); }
    ~FakeFree() { ::unsetenv("BF_FAKE_FREE_BYTES"); }
  };
  {
    FakeFree f("1000");
    CHECK(run_cli("run " + cfg + " --out " + out + " --no-plots", &text) == 2);
  }
  CHECK_THAT(text, Catch::Contains("brdf-factor: " + out + ": not enough free space") &&
                       Catch::Contains("needs about " + std::to_string(need) + " bytes") &&
                       Catch::Contains("found 1000 bytes (0.0 MiB) free (BF_FAKE_FREE_BYTES)"));
  CHECK_THAT(text, !Catch::Contains("start 1/"));
  CHECK(!fs::exists(fs::path(out) / "runs"));
  CHECK(done_runs(out).empty());

  // Exactly enough for a one-run variant: runs.
  {
    FakeFree f(std::to_string(need));
    CHECK(run_cli("run " + cfg + " --out " + out + " --no-plots -q -D method.texture_size=4", &text) == 0);
  }
  // A malformed override is an error naming the variable.
  {
    FakeFree f("lots");
    CHECK(run_cli("run " + cfg + " --out " + out + " --no-plots", &text) == 2);
  }
  CHECK_THAT(text, Catch::Contains("BF_FAKE_FREE_BYTES: expected a number of bytes, found 'lots'"));
}
