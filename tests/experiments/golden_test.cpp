// Run ids are the cache keys of every experiment folder: a refactoring of the
// config reader or the method catalogue must not change them. The golden file
// tests/data/golden/run_ids.txt holds the --dry-run listing (run ids and
// descriptions) of every run config under experiments/; regenerate it with
// tests/data/golden/make-run-ids.sh only for a change meant to change run ids.
#include <set>

#include "experiments/run/runner.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

// name -> its listing, from the golden file ("== name" starts a section).
std::map<std::string, std::string> golden_sections() {
  std::istringstream in(read_text(std::string(BF_TEST_DATA_DIR) + "/golden/run_ids.txt"));
  std::map<std::string, std::string> out;
  std::string line, name;
  while (std::getline(in, line)) {
    if (line.rfind("== ", 0) == 0) name = line.substr(3);
    else out[name] += line + "\n";
  }
  return out;
}

}  // namespace

TEST_CASE("golden: every run config under experiments/ keeps its run ids and descriptions") {
  register_loaders();
  const auto golden = golden_sections();
  std::set<std::string> configs;
  for (const auto& e : fs::directory_iterator(source_path("experiments")))
    if (e.path().extension() == ".toml" && e.path().stem() != "stress") configs.insert(e.path().stem().string());
  std::set<std::string> in_golden;
  for (const auto& [k, v] : golden) in_golden.insert(k);
  CHECK(configs == in_golden);  // a new example config needs its golden section
  REQUIRE(golden.size() >= 18);
  for (const auto& [name, listing] : golden) {
    INFO(name);
    RunOptions o;
    o.config = source_path("experiments/" + name + ".toml");
    o.out = "/nonexistent/golden";
    o.dry_run = true;
    o.quiet = true;
    std::ostringstream out, err;
    run_experiment(o, out, err);
    CHECK(out.str() == listing);
  }
}
