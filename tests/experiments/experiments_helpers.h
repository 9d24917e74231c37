// Helpers shared by the experiments tests: scratch folders, config files,
// quiet runs, CLI invocation, report.html in headless Chromium.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "brdfs/catalogue.h"
#include "experiments/config/config.h"
#include "experiments/run/runner.h"
#include "factor/export.h"
#include "test_common.h"

namespace bf_test {

namespace fs = std::filesystem;

// A fresh folder under the system temp dir, removed when the object dies.
struct ScratchDir {
  fs::path path;
  ScratchDir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("bf-exp-test-" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string operator/(const std::string& rel) const { return (path / rel).string(); }
};

inline std::string write_text(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << text;
  return path;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void register_loaders() {
  static bool done = [] {
    bf::register_export_loader(bf::Catalogue::global());
    return true;
  }();
  (void)done;
}

// Debian's Chromium on the PATH ("" when not installed).
inline std::string chromium_browser() {
  for (const char* c : {"chromium", "chromium-browser"})
    if (std::system(("command -v " + std::string(c) + " > /dev/null 2>&1").c_str()) == 0) return c;
  return "";
}

// The headless Chromium command line for report.html's viewer: software
// WebGL2 (SwiftShader), no sandbox (test containers), then `args`.
inline std::string chromium_command(const std::string& browser, const std::string& args) {
  return browser + " --headless --no-sandbox --use-gl=swiftshader --enable-unsafe-swiftshader --disable-gpu-sandbox " +
         args;
}

// Opens `page` (report.html) at "#viewer-test" (query `query`, "" for none;
// extra Chromium flags `flags`), dumps the DOM after load into `dir` and
// returns the text of the page's <pre id="viewer-test"> (the viewer's test
// numbers, one JSON object a line). "" when Chromium failed or the element is
// missing; the caller REQUIREs it non-empty.
inline std::string viewer_test_output(const std::string& browser, const std::string& page, const std::string& dir,
                                      const std::string& query = "", const std::string& flags = "") {
  const std::string dom = dir + "/dom.html";
  const std::string cmd = chromium_command(browser, flags + " --dump-dom 'file://" + page + query + "#viewer-test' > " +
                                                        dom + " 2> " + dir + "/chromium.log");
  if (std::system(cmd.c_str()) != 0) return "";
  const std::string text = read_text(dom);
  // (std::regex recurses per character: too deep for a megabyte page.)
  const size_t at = text.find("<pre id=\"viewer-test\"");
  if (at == std::string::npos) return "";
  const size_t open = text.find('>', at) + 1, close = text.find("</pre>", open);
  return close == std::string::npos ? "" : text.substr(open, close - open);
}

// Runs an experiment quietly (no plots unless asked); returns the summary.
inline bf::RunSummary run_quiet(const std::string& config, const std::string& out,
                                std::vector<std::string> defines = {}, bool plots = false,
                                bool force = false, int shard = 1, int shards = 1) {
  register_loaders();
  bf::RunOptions o;
  o.config = config;
  o.out = out;
  o.defines = std::move(defines);
  o.quiet = true;
  o.plots = plots;
  o.force = force;
  o.shard = shard;
  o.shards = shards;
  std::ostringstream sout, serr;
  return bf::run_experiment(o, sout, serr);
}

// The CLI's exit code and its stderr/stdout (merged into *output).
inline int run_cli(const std::string& args, std::string* output) {
  const std::string cmd = std::string(BF_CLI_PATH) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  if (output) *output = out;
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

inline std::string source_path(const std::string& rel) {
  return std::string(BRDF_FACTOR_SOURCE_DIR) + "/" + rel;
}

// A small, fast experiment: bluepaint on a 6^4 grid, three cheap methods.
inline const char* kTinyConfig = R"(
[experiment]
name = "tiny"
seed = 5

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[scene]
size = 24

[[method]]
kind = "mccool"
texture_size = [4, 6]

[[method]]
kind = "fit"
projections = [{ name = "wi" }, { name = "h" }]
terms = [1, 2]
texture_size = 6

[[method]]
kind = "svd"
terms = 1
texture_size = 6
)";

// The head of the config-validation tests: one BRDF (bluepaint) on a 6^4 grid;
// append [[method]] tables.
inline const char* const kConfigHead = R"([experiment]
name = "t"

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6
)";

// The messages of the ConfigError that parse_plan throws for `text` read as
// "cfg.toml" (empty if it validates).
inline std::vector<std::string> config_errors(const std::string& text,
                                              const std::vector<std::string>& defines = {}) {
  register_loaders();
  try {
    bf::parse_plan(text, "cfg.toml", defines);
  } catch (const bf::ConfigError& e) {
    return e.messages();
  }
  return {};
}

// Exactly one config error for `text`, containing every fragment.
inline void require_one_config_error(const std::string& text, std::initializer_list<std::string> fragments,
                                     const std::vector<std::string>& defines = {}) {
  const auto errs = config_errors(text, defines);
  std::string all;
  for (const auto& m : errs) all += m + "\n";
  INFO(all);
  REQUIRE(errs.size() == 1);
  for (const auto& f : fragments) CHECK(errs[0].find(f) != std::string::npos);
}

}  // namespace bf_test
