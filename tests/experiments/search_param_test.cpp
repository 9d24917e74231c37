// The search's parameterization: an explicit `parameterization` (or a sweep
// over it) is every term's, whatever the strategy; without it the structured
// search chooses per term. results.csv, results.md and report.html say what was
// asked (`parameterization`), what each term read (`term_parameterizations`)
// and which strategy made the row (`search_strategy`).
#include <map>
#include <set>

#include "experiments/methods/homomorphic.h"
#include "experiments/report/outputs.h"
#include "experiments_helpers.h"
#include "factor/export.h"
#include "search/structured_search.h"

using namespace bf;
using namespace bf_test;

namespace {

// Runs `body` (Python, with plot_results imported as p) and expects it to
// print "ok": a probe of the plots' series naming.
void check_plot_probe(const std::string& body) {
  const std::string py = find_python(nullptr);
  INFO("no python3 with matplotlib (scripts/install-deps.sh installs python3-matplotlib)");
  REQUIRE(!py.empty());
  ScratchDir tmp;
  const std::string probe = "import sys; sys.path.insert(0, '" +
                            fs::path(plot_script_path()).parent_path().string() +
                            "'); import plot_results as p\n" + body + "print('ok')\n";
  write_text(tmp / "probe.py", probe);
  CHECK(std::system((py + " " + (tmp / "probe.py") + " > " + (tmp / "probe.txt") + " 2>&1").c_str()) == 0);
  INFO(read_text(tmp / "probe.txt"));
  CHECK(read_text(tmp / "probe.txt") == "ok\n");
}

// Small and fast, and of McCool's form p(wi) q(h) p(wo): the structured search
// mixes wiwo and halfdiff terms on it when allowed to (the control below
// checks that it does).
const char* const kSweepConfig = R"([experiment]
name = "param"
seed = 1
render = false

[[brdf]]
model = "mccool-form"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "search"
label = "asked"
parameterization = ["wiwo", "halfdiff"]
terms = 2
texture_size = 6
restarts = 1
threads = 1

[[method]]
kind = "search"
label = "free"
terms = 2
texture_size = 6
restarts = 1
threads = 1
)";

std::vector<std::string> split_plus(const std::string& s) {
  std::vector<std::string> out;
  size_t a = 0;
  while (true) {
    const size_t b = s.find('+', a);
    out.push_back(s.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) return out;
    a = b + 1;
  }
}

// Each term's parameterization as exported (the factorization itself, not a column).
std::vector<std::string> exported_params(const fs::path& out, const std::string& run_id) {
  const auto f = load_factorization((out / "runs" / run_id / "factors.json").string());
  const auto* h = dynamic_cast<const HomomorphicFactorization*>(f.get());
  REQUIRE(h);
  std::vector<std::string> p;
  for (const FactorTerm& t : h->terms()) p.push_back(to_string(t.proj.param));
  return p;
}

}  // namespace

TEST_CASE("search parameterization: a sweep over wiwo and halfdiff gives rows whose every term reads the asked one") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "param.toml", kSweepConfig);
  const fs::path out = tmp.path / "out";
  const RunSummary sum = run_quiet(cfg, out.string());
  REQUIRE(sum.failed == 0);
  const auto rows = read_results_csv((out / "results.csv").string());
  REQUIRE(rows.size() == 3);
  std::map<std::string, int> asked;
  bool free_mixed = false;
  for (const auto& r : rows) {
    INFO(r.at("label") << " " << r.at("sweep") << ": parameterization " << r.at("parameterization")
                       << ", terms " << r.at("term_parameterizations") << ", strategy " << r.at("search_strategy"));
    const std::vector<std::string> terms = split_plus(r.at("term_parameterizations"));
    CHECK(terms.size() == 2);
    CHECK(terms == exported_params(out, r.at("run_id")));  // the column is the factorization's truth
    CHECK((r.at("search_strategy") == "greedy" || r.at("search_strategy") == "structured"));
    if (r.at("label") == "asked") {
      const std::string p = r.at("parameterization");
      CHECK(r.at("sweep") == "parameterization=" + p);
      ++asked[p];
      for (const std::string& t : terms) CHECK(t == p);
    } else {
      // No key: the search may choose per term, and the column says so.
      CHECK(r.at("parameterization") == "either");
      for (const std::string& t : terms) CHECK((t == "wiwo" || t == "halfdiff"));
      free_mixed = std::set<std::string>(terms.begin(), terms.end()).size() == 2;
    }
  }
  CHECK(asked == std::map<std::string, int>{{"wiwo", 1}, {"halfdiff", 1}});
  // The control: on this case the free search does mix, so "every term reads
  // the asked one" above is not true by accident.
  CHECK(free_mixed);
  // The columns reach results.md and report.html.
  const std::string md = read_text((out / "results.md").string());
  const std::string html = read_text((out / "report.html").string());
  for (const char* col : {"search_strategy", "term_parameterizations"}) {
    CHECK(md.find(col) != std::string::npos);
    CHECK(html.find("<th>" + std::string(col) + "</th>") != std::string::npos);
  }
  CHECK(html.find(">halfdiff+halfdiff<") != std::string::npos);
}

TEST_CASE("search parameterization: the options say fixed exactly when the key is given") {
  register_loaders();
  const Plan plan = parse_plan(std::string(kConfigHead) +
                                   "[[method]]\nkind = \"search\"\nparameterization = [\"wiwo\", \"halfdiff\"]\n"
                                   "[[method]]\nkind = \"search\"\n"
                                   "[[method]]\nkind = \"search\"\nterm_param = \"fixed\"\n"
                                   "[[method]]\nkind = \"search\"\nstrategy = \"structured\"\n"
                                   "parameterization = \"halfdiff\"\nterm_param = \"fixed\"\n",
                               "cfg.toml");
  REQUIRE(plan.methods.size() == 5);
  CHECK(homomorphic_options(plan.methods[0]).search.term_param == "fixed");
  CHECK(homomorphic_options(plan.methods[0]).search.param == Parameterization::WiWo);
  CHECK(homomorphic_options(plan.methods[1]).search.term_param == "fixed");
  CHECK(homomorphic_options(plan.methods[1]).search.param == Parameterization::HalfDiff);
  CHECK(homomorphic_options(plan.methods[2]).search.term_param == "either");  // no key: the search chooses
  CHECK(homomorphic_options(plan.methods[3]).search.term_param == "fixed");
  CHECK(homomorphic_options(plan.methods[3]).search.param == Parameterization::WiWo);
  CHECK(homomorphic_options(plan.methods[4]).search.term_param == "fixed");
  CHECK(homomorphic_options(plan.methods[4]).search.param == Parameterization::HalfDiff);
  // The run id tells a fixed search from a free one.
  CHECK(plan.methods[0].options.dump() != plan.methods[2].options.dump());
}

TEST_CASE("search options: beam_width and polish_sweeps default by the search size and a set value is kept") {
  register_loaders();
  const Plan plan = parse_plan(std::string(kConfigHead) +
                                   "[[method]]\nkind = \"search\"\nterms = 5\n"
                                   "[[method]]\nkind = \"search\"\nterms = 5\nbeam_width = 8\npolish_sweeps = 2\n"
                                   "[[method]]\nkind = \"search\"\nterms = 3\n",
                               "cfg.toml");
  REQUIRE(plan.methods.size() == 3);
  const SearchOptions& a = homomorphic_options(plan.methods[0]).search;
  const SearchOptions& b = homomorphic_options(plan.methods[1]).search;
  const SearchOptions& c = homomorphic_options(plan.methods[2]).search;
  CHECK(effective_beam_width(a) == 4);
  CHECK(effective_polish_sweeps(a) == 0);
  CHECK(b.beam_width == 8);
  CHECK(b.polish_sweeps == 2);
  CHECK(effective_beam_width(c) == 8);
  CHECK(effective_polish_sweeps(c) == 2);
  // The run id holds the values the search runs with.
  CHECK(plan.methods[0].options["beam_width"] == 4);
  CHECK(plan.methods[0].options["polish_sweeps"] == 0);
  CHECK(plan.methods[1].options["beam_width"] == 8);
  CHECK(plan.methods[2].options["polish_sweeps"] == 2);
  CHECK(plan.methods[0].options.dump() != plan.methods[1].options.dump());
}

TEST_CASE("search options: a non-greedy search's run id holds the structured search's revision") {
  // A change that moves the structured search's answers raises the revision,
  // so a run cached by an older search is recomputed (runner: a cached run is
  // found by its id). Greedy runs keep their ids: the thesis's search has not
  // changed.
  register_loaders();
  const Plan plan = parse_plan(std::string(kConfigHead) +
                                   "[[method]]\nkind = \"search\"\nterms = 2\n"
                                   "[[method]]\nkind = \"search\"\nterms = 2\nstrategy = \"best\"\n"
                                   "[[method]]\nkind = \"search\"\nterms = 2\nstrategy = \"greedy\"\n",
                               "cfg.toml");
  REQUIRE(plan.methods.size() == 3);
  CHECK(plan.methods[0].options.value("structured_revision", -1) == kStructuredSearchRevision);
  CHECK(plan.methods[1].options.value("structured_revision", -1) == kStructuredSearchRevision);
  CHECK_FALSE(plan.methods[2].options.contains("structured_revision"));
  REQUIRE(plan.runs.size() == 3);
  CHECK(plan.runs[0].identity.at("method").value("structured_revision", -1) == kStructuredSearchRevision);
}

TEST_CASE("search parameterization: term_param either with an explicit parameterization is refused, naming both keys") {
  for (const std::string strategy : {"", "strategy = \"structured\"\n", "strategy = \"greedy\"\n"}) {
    INFO(strategy);
    require_one_config_error(std::string(kConfigHead) + "[[method]]\nkind = \"search\"\n" + strategy +
                                 "parameterization = \"halfdiff\"\nterm_param = \"either\"\n",
                             {"cfg.toml:", "method[0].term_param", "parameterization = \"halfdiff\"",
                              "term_param = \"either\"", "expected"});
  }
  // A sweep: each combination with the key is refused the same way.
  const auto errs = config_errors(std::string(kConfigHead) + "[[method]]\nkind = \"search\"\n"
                                                              "parameterization = [\"wiwo\", \"halfdiff\"]\n"
                                                              "term_param = \"either\"\n");
  REQUIRE(!errs.empty());
  for (const auto& e : errs) CHECK(e.find("term_param") != std::string::npos);
}

TEST_CASE("search parameterization: the plots group a parameterization sweep by the asked value") {
  // Rows of one sweep whose terms read other points than asked (a results.csv
  // of a version that let the search choose, or a column of the terms' own):
  // still one series per asked value, never one per chosen set.
  check_plot_probe(
      "rows = [\n"
      "  {'label': 's', 'parameterization': 'wiwo+halfdiff', 'term_parameterizations': 'wiwo+halfdiff',\n"
      "   'sweep': 'parameterization=wiwo terms=2'},\n"
      "  {'label': 's', 'parameterization': 'wiwo', 'term_parameterizations': 'wiwo+wiwo',\n"
      "   'sweep': 'parameterization=wiwo terms=3'},\n"
      "  {'label': 's', 'parameterization': 'halfdiff', 'term_parameterizations': 'halfdiff+halfdiff',\n"
      "   'sweep': 'parameterization=halfdiff terms=2'},\n"
      "  {'label': 's', 'parameterization': 'wiwo+halfdiff', 'term_parameterizations': 'halfdiff+wiwo',\n"
      "   'sweep': 'parameterization=halfdiff terms=3'},\n"
      "  {'label': 'f', 'parameterization': 'either', 'term_parameterizations': 'halfdiff+wiwo', 'sweep': 'terms=2'},\n"
      "  {'label': 'f', 'parameterization': 'either', 'term_parameterizations': 'wiwo+wiwo', 'sweep': 'terms=3'},\n"
      "]\n"
      "names = [p.series_name(r, {'terms'}) for r in rows]\n"
      "assert names[0] == names[1] and names[2] == names[3] and names[0] != names[2], names\n"
      "assert 'wiwo' in names[0] and 'halfdiff' in names[2], names\n"
      "assert names[4] == names[5] and len(set(names)) == 3, names\n");
}

TEST_CASE("search parameterization: the plots split a reciprocity sweep by the asked value") {
  // thesis-bluepaint's sweep: reciprocity = [false, true]; the false run's
  // answers were refit with reciprocal terms (final_reciprocity), so its
  // column reads true too. Two series, not one drawn over the other.
  check_plot_probe(
      "rows = [\n"
      "  {'label': 's', 'parameterization': 'wiwo', 'reciprocity': 'true',\n"
      "   'sweep': 'parameterization=wiwo reciprocity=false'},\n"
      "  {'label': 's', 'parameterization': 'wiwo', 'reciprocity': 'true',\n"
      "   'sweep': 'parameterization=wiwo reciprocity=true'},\n"
      "  {'label': 's', 'parameterization': 'wiwo', 'reciprocity': 'false',\n"
      "   'sweep': 'parameterization=wiwo reciprocity=false'},\n"
      "  {'label': 'm', 'parameterization': 'wiwo', 'reciprocity': 'true', 'sweep': ''},\n"
      "  {'label': 'm', 'parameterization': 'wiwo', 'reciprocity': 'false', 'sweep': ''},\n"
      "]\n"
      "names = [p.series_name(r, {'terms'}) for r in rows]\n"
      "assert len(set(names)) == 5, names\n"
      "assert names[1].endswith(' recip') and names[0].endswith('recip answers'), names\n"
      "assert 'recip' not in names[2] and 'recip' not in names[4] and names[3].endswith(' recip'), names\n");
}

TEST_CASE("search parameterization: bench search follows the config's rule") {
  std::string out;
  CHECK(run_cli("bench search --parameterization halfdiff --term-param either", &out) == 2);
  CHECK(out.find("--term-param: either") != std::string::npos);
  CHECK(out.find("--parameterization halfdiff") != std::string::npos);
  // --parameterization alone fixes every term (McCool's form: the free search mixes).
  REQUIRE(run_cli("bench search --brdf mccool-form --grid 6 --texture 6 --terms 2 --restarts 1 --threads 1 "
                  "--parameterization wiwo",
                  &out) == 0);
  const auto line = out.find("{\"");
  REQUIRE(line != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(out.substr(line, out.find('\n', line) - line));
  CHECK(j.at("term_param") == "fixed");
  CHECK(j.at("term_parameterizations") == nlohmann::json::array({"wiwo", "wiwo"}));
}

TEST_CASE("search parameterization: bench planted prints a dash for the search it did not run and never nan") {
  for (const char* strategy : {"structured", "greedy"}) {
    INFO(strategy);
    std::string out;
    REQUIRE(run_cli(std::string("bench planted --count 1 --terms 2 --grid 6 --texture 6 --restarts 1 --threads 1 "
                                "--strategy ") + strategy,
                    &out) == 0);
    INFO(out);
    CHECK(out.find("nan") == std::string::npos);
    const auto row = out.find("| planted-rotation(0, 2 terms, wiwo) |");
    REQUIRE(row != std::string::npos);
    const std::string line = out.substr(row, out.find('\n', row) - row);
    // greedy, structured, the two ratios, fits and seconds: three cells of the
    // search not run are "-", and the run one's are numbers.
    size_t dashes = 0;
    for (size_t at = line.find("| - |"); at != std::string::npos; at = line.find("| - |", at + 3)) ++dashes;
    CHECK(dashes == 4);
  }
}

TEST_CASE("search parameterization: bench planted --family mixed runs only the term count and parameterization given") {
  std::string out;
  REQUIRE(run_cli("bench planted --family mixed --count 1 --terms 3 --parameterization halfdiff --grid 6 --texture 6 "
                  "--restarts 1 --threads 1 --strategy greedy",
                  &out) == 0);
  INFO(out);
  // One member row (of the family's six variants), the one asked for.
  std::vector<std::string> rows;
  for (size_t at = out.find("| planted"); at != std::string::npos; at = out.find("| planted", at + 1))
    rows.push_back(out.substr(at, out.find('\n', at) - at));
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].find("3 terms") != std::string::npos);
  CHECK(rows[0].find("halfdiff") != std::string::npos);
  // The 2-term member is a pair across parameterizations, the given one first.
  REQUIRE(run_cli("bench planted --family mixed --count 1 --terms 2 --parameterization halfdiff --grid 6 --texture 6 "
                  "--restarts 1 --threads 1 --strategy greedy",
                  &out) == 0);
  CHECK(out.find("| planted-mixed-pair(0, halfdiff + wiwo) |") != std::string::npos);
  // The family has 2-, 3- and 4-term members only.
  CHECK(run_cli("bench planted --family mixed --count 1 --terms 5 --grid 6 --texture 6", &out) == 2);
  CHECK(out.find("--terms: the mixed family has members of 2, 3 and 4 terms; found 5") != std::string::npos);
}

TEST_CASE("search_samples: 0 and off disable the subsample and bad values are refused naming the key") {
  const std::string head = std::string(kConfigHead) + "[[method]]\nkind = \"search\"\nterms = 1\nsearch_samples = ";
  for (const char* bad : {"10", "-1", "999", "\"auto\"", "1.5", "true"}) {
    INFO(bad);
    require_one_config_error(head + bad + "\n", {"search_samples", "expected 0 or \"off\"", ">= 1000"});
  }
  for (const char* ok : {"0", "\"off\"", "1000", "250000"}) {
    INFO(ok);
    CHECK(config_errors(head + ok + "\n").empty());
  }
  // The key enters the run id (a cached search on every sample is not a subsampled one).
  const Plan a = parse_plan(head + "0\n", "cfg.toml", {}), b = parse_plan(head + "\"off\"\n", "cfg.toml", {}),
             c = parse_plan(head + "5000\n", "cfg.toml", {});
  CHECK(a.runs.at(0).run_id == b.runs.at(0).run_id);
  CHECK(a.runs.at(0).run_id != c.runs.at(0).run_id);
}

TEST_CASE("final_reciprocity: auto follows the BRDF's declared reciprocity, a set value is kept, bad values refused") {
  // Two BRDFs on a small grid: bluepaint (Lafortune, reciprocal) and
  // separable (a(wi) b(wo) c(h), not reciprocal); the default 2-term search,
  // and the same with final_reciprocity = false, and with sampling.symmetries
  // leaving reciprocity out.
  ScratchDir tmp;
  // separable only where "auto" is asked (the other cases turn it off for any BRDF).
  const auto config = [&](const std::string& name, const std::string& sym, const std::string& key) {
    return write_text(tmp / (name + ".toml"),
                      "[experiment]\nname = \"fr\"\nseed = 1\nrender = false\n"
                      "[[brdf]]\npreset = \"bluepaint\"\n" +
                          std::string(name == std::string("auto") ? "[[brdf]]\nmodel = \"separable\"\n" : "") +
                      "[sampling]\nkind = \"grid\"\nresolution = 6\n" + sym +
                          "[[method]]\nkind = \"search\"\nterms = 2\ntexture_size = 6\nrestarts = 1\nthreads = 1\n" +
                          key);
  };
  struct Case {
    const char* name;
    std::string sym, key;
    bool on_bluepaint;
  };
  const std::vector<Case> cases = {{"auto", "", "", true},
                                   {"off", "", "final_reciprocity = false\n", false},
                                   {"iso", "symmetries = \"isotropic\"\n", "", false},
                                   // reciprocal during the search: nothing left to refit
                                   {"recip", "", "reciprocity = true\n", false}};
  std::map<std::string, std::string> ids;
  for (const Case& k : cases) {
    const fs::path out = tmp.path / k.name;
    REQUIRE(run_quiet(config(k.name, k.sym, k.key), out.string()).failed == 0);
    const auto rows = read_results_csv((out / "results.csv").string());
    CHECK(rows.size() == (std::string(k.name) == "auto" ? 2u : 1u));
    for (const auto& row : rows) {
      const bool blue = row.at("brdf") == "bluepaint";
      INFO(k.name << " " << row.at("brdf") << ": reciprocity " << row.at("reciprocity"));
      const nlohmann::json rec =
          nlohmann::json::parse(read_text((out / "runs" / row.at("run_id") / "run.json").string()));
      const nlohmann::json& fr = rec.at("final_reciprocity");
      const bool on = blue && k.on_bluepaint;
      CHECK(fr.at("on") == on);
      CHECK(fr.at("reciprocal_answers").size() == (on ? 2u : 0u));
      // On the reciprocal paint the refit is lower and kept: the row's terms are reciprocal.
      const bool recip = on || k.key.find("reciprocity = true") != std::string::npos;
      CHECK(row.at("reciprocity") == (recip ? "true" : "false"));
      const auto f = load_factorization((out / "runs" / row.at("run_id") / "factors.json").string());
      const auto* h = dynamic_cast<const HomomorphicFactorization*>(f.get());
      REQUIRE(h);
      for (const FactorTerm& t : h->terms()) CHECK(t.reciprocal == recip);
      if (blue) ids[k.name] = row.at("run_id");
    }
  }
  // The setting enters the run id unless it is off (the search of before the key).
  CHECK(ids.at("auto") != ids.at("off"));
  const std::string one = std::string(kConfigHead) + "[[method]]\nkind = \"search\"\nterms = 1\n";
  const Plan pa = parse_plan(one, "cfg.toml", {}), pf = parse_plan(one + "final_reciprocity = false\n", "cfg.toml", {}),
             pt = parse_plan(one + "final_reciprocity = true\n", "cfg.toml", {});
  CHECK_FALSE(pf.runs.at(0).identity.at("method").contains("final_reciprocity"));
  CHECK(pa.runs.at(0).identity.at("method").at("final_reciprocity") == "auto");
  CHECK(pa.runs.at(0).run_id != pf.runs.at(0).run_id);
  CHECK(pt.runs.at(0).run_id != pf.runs.at(0).run_id);
  // true is kept even for a BRDF that does not declare reciprocity.
  const std::string head = std::string(kConfigHead) + "[[method]]\nkind = \"search\"\nterms = 1\nfinal_reciprocity = ";
  for (const char* ok : {"true", "false", "\"auto\""}) {
    INFO(ok);
    CHECK(config_errors(head + ok + "\n").empty());
  }
  for (const char* bad : {"\"yes\"", "1", "\"on\""}) {
    INFO(bad);
    require_one_config_error(head + bad + "\n", {"final_reciprocity", "expected \"auto\", true or false", "found"});
  }
}
