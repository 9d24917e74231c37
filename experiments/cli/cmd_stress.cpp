// Subcommand `stress`: runs the stress matrix of factor/stress.h (hard cases x
// methods), prints one line per result and optionally a CSV; exit code 1 when
// an expectation fails.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <toml++/toml.h>

#include "experiments/common/cli_util.h"
#include "experiments/cli/commands.h"
#include "factor/stress.h"

namespace bf {

namespace {

// A table cell: the value with `digits` significant digits, "-" when it was not
// computed (NaN; no output ever shows "nan").
std::string cell(double v, int digits) {
  if (std::isnan(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

struct StressArgs {
  StressOptions opt;
  std::string out;
  std::string config;
  std::vector<std::string> only;  // case names; empty = all
  bool list = false;
};

// Reads the optional case list: [[case]] tables with `name` (required) and
// optional `expect` (all methods) and `expect_<method>` strings.
void apply_config(const std::string& path, std::vector<StressCase>& cases) {
  toml::table t;
  try {
    t = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw std::runtime_error(path + ": " + std::string(e.description()));
  }
  const toml::array* arr = t["case"].as_array();
  if (!arr) throw std::runtime_error(path + ": expected an array of [[case]] tables");
  std::map<std::string, const StressCase*> by_name;
  for (const StressCase& c : cases) by_name[c.name] = &c;
  std::vector<StressCase> selected;
  for (const toml::node& n : *arr) {
    const toml::table* ct = n.as_table();
    if (!ct) throw std::runtime_error(path + ": expected every [[case]] entry to be a table");
    const std::optional<std::string> name = (*ct)["name"].value<std::string>();
    if (!name) throw std::runtime_error(path + ": a [[case]] has no string 'name'");
    auto it = by_name.find(*name);
    if (it == by_name.end()) throw std::runtime_error(path + ": unknown stress case '" + *name + "'");
    StressCase c = *it->second;
    for (const auto& [key, val] : *ct) {
      const std::string k(key.str());
      if (k == "name") continue;
      const std::optional<std::string> s = val.value<std::string>();
      if (!s) throw std::runtime_error(path + ": case '" + *name + "': key '" + k + "' must be a string");
      if (k == "expect") {
        c.expect = StressExpectation::parse(*s);
        c.overrides.clear();
      } else if (k.rfind("expect_", 0) == 0) {
        const std::string m = k.substr(7);
        const auto ms = stress_methods();
        if (std::find(ms.begin(), ms.end(), m) == ms.end())
          throw std::runtime_error(path + ": case '" + *name + "': unknown method in key '" + k + "'");
        c.overrides.insert(c.overrides.begin(), {m, StressExpectation::parse(*s)});
      } else {
        throw std::runtime_error(path + ": case '" + *name + "': unknown key '" + k + "'");
      }
    }
    selected.push_back(std::move(c));
  }
  cases = std::move(selected);
}

int run(const StressArgs& a) {
  a.opt.validate();
  std::vector<StressCase> cases = stress_cases();
  if (!a.config.empty()) apply_config(a.config, cases);
  if (!a.only.empty()) {
    std::vector<StressCase> kept;
    for (const std::string& n : a.only) {
      auto it = std::find_if(cases.begin(), cases.end(), [&](const StressCase& c) { return c.name == n; });
      if (it == cases.end()) throw std::invalid_argument("--case: unknown stress case '" + n + "'");
      kept.push_back(*it);
    }
    cases = std::move(kept);
  }
  if (a.list) {
    for (const StressCase& c : cases) std::cout << c.name << "  " << c.description << "\n";
    return 0;
  }
  std::vector<StressResult> results;
  bool all_pass = true;
  std::printf("%-18s %-8s %-6s %11s %11s %10s %7s %-16s %s\n", "case", "method", "finite", "rel_mse",
              "cos_rmse", "cond", "seconds", "expectation", "result");
  for (const StressCase& c : cases) {
    StressInput in;
    try {
      in = c.make(a.opt);
    } catch (const std::exception& e) {
      throw std::runtime_error("stress case '" + c.name + "': building the input failed: " + e.what());
    }
    for (const std::string& m : stress_methods()) {
      StressResult r = run_stress(c, in, m, a.opt);
      all_pass = all_pass && r.pass;
      std::printf("%-18s %-8s %-6s %11s %11s %10s %7.2f %-16s %s%s\n", r.case_name.c_str(),
                  r.method.c_str(), r.threw ? "error" : r.finite ? "yes" : "NO", cell(r.rel_mse, 4).c_str(),
                  cell(r.cos_rmse, 4).c_str(), cell(r.condition, 3).c_str(), r.seconds,
                  r.expectation.c_str(), r.pass ? "pass" : "FAIL",
                  r.threw ? ("  (" + r.message + ")").c_str() : "");
      std::fflush(stdout);
      results.push_back(std::move(r));
    }
  }
  if (!a.out.empty())
    write_file_atomic(a.out, [&](std::ostream& o) {
      o << stress_csv_header() << "\n";
      for (const StressResult& r : results) o << stress_csv_row(r) << "\n";
    });
  return all_pass ? 0 : 1;
}

}  // namespace

void add_cmd_stress(CLI::App& app) {
  auto a = std::make_shared<StressArgs>();
  CLI::App* c = app.add_subcommand(
      "stress", "Run the stress matrix (hard cases x methods, docs/design.md §7); exit 1 if an expectation fails");
  c->add_option("--out", a->out, "CSV with one row per case and method");
  c->add_option("--config", a->config,
                "TOML case list ([[case]] name, expect, expect_<method>); default: every built-in case");
  c->add_option("--case", a->only, "Run only these cases (repeatable)");
  c->add_option("--res", a->opt.res, "Texture resolution of the homomorphic terms")->capture_default_str();
  c->add_option("--samples", a->opt.samples, "Stratified samples per case")->capture_default_str();
  c->add_option("--svd-res", a->opt.svd_res, "SVD texel grid resolution")->capture_default_str();
  c->add_option("--seed", a->opt.seed, "Seed of samples and random projections")
      ->check(non_negative_integer())
      ->capture_default_str();
  c->add_option("--cond-max", a->opt.cond_max_unknowns,
                "Largest number of unknowns for the dense condition estimate")->capture_default_str();
  c->add_flag("--list", a->list, "List the cases and exit");
  c->callback([a]() {
    // Failed expectations are a result, not an error: exit 1 directly (main
    // maps exceptions to 2).
    if (run(*a) != 0) {
      std::cout.flush();
      std::fflush(stdout);
      std::exit(1);
    }
  });
}

}  // namespace bf
