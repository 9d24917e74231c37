// kind = "search": Cole's automatic factorization (search/term_search.h):
// greedy over terms, an optimizer over 4D rotations per term, seeded random
// restarts in parallel; with a tolerance, the search stops at the first term
// whose refit reaches the target. Keys the search gains go here.
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include "brdfs/symmetry.h"
#include "experiments/methods/homomorphic.h"
#include "factor/size_select.h"
#include "search/rotation4.h"
#include "search/structured_search.h"
#include "search/term_search.h"
#include "solvers/parallel.h"

namespace bf {

using nlohmann::json;

// A search with a key chosen by held-out error (docs/design.md §4.1 "cv"):
// the search runs once per fit set at `base` (the configured options; a "cv"
// key at its default: smoothing 1e-3, texture_size 16), and every candidate
// refits the projections it found. Keyed by the fit set's content, so the
// candidates of one fold (or of the held-out fraction) share one search, and
// the run's own fit on the same training samples reuses it.
struct SearchCvCache {
  SearchOptions base;
  std::mutex mu;
  std::map<uint64_t, std::shared_ptr<const SearchResult>> searched;
};

namespace {

// 64-bit FNV-1a of a sample set's directions, values, weights and mask.
uint64_t fingerprint(const SampleSet& s) {
  uint64_t h = 1469598103934665603ULL;
  const auto feed = [&h](const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  };
  const size_t n = s.size();
  feed(&n, sizeof n);
  feed(s.wi.data(), s.wi.size() * sizeof(Vec3));
  feed(s.wo.data(), s.wo.size() * sizeof(Vec3));
  feed(s.value.data(), s.value.size() * sizeof(Rgb));
  feed(s.weight.data(), s.weight.size() * sizeof(double));
  feed(s.valid.data(), s.valid.size());
  return h;
}

// r's answers (greedy: its factorization, the schedule) refit on `data` at
// resolution res with fo, as the search refits them (the structured search
// solves all terms jointly with final_joint).
void refit_at(const FitData& data, const FitOptions& fo, bool final_joint, int res, SearchResult& r) {
  const bool joint = r.strategy == "structured" && final_joint;
  const auto refit = [&](const HomomorphicFactorization& f, std::vector<double>* errors) {
    std::vector<TermSpec> sp;
    for (const FactorTerm& t : f.terms()) sp.push_back(TermSpec{t.proj, t.reciprocal, t.rotation});
    FitOptions o = fo;
    if (joint) o.solve_last = std::max(o.solve_last, static_cast<int>(sp.size()));
    return fit_homomorphic(data, terms_at_resolution(sp, res), o, "search", errors);
  };
  std::vector<double> errors;
  if (r.answers.empty()) {
    r.factorization = refit(*r.factorization, &errors);
    r.rel_mse_after_term = errors;
    return;
  }
  for (size_t k = 0; k < r.answers.size(); ++k) {
    if (!r.answers[k]) continue;
    r.answers[k] = refit(*r.answers[k], &errors);
    r.rel_mse_after_term[k] = errors.back();
  }
  r.factorization = r.answers.back();
}

KeySpec with_default(KeySpec k, std::string default_text) {
  k.default_text = std::move(default_text);
  return k;
}

const std::vector<KeySpec>& search_keys() {
  static const std::vector<KeySpec> keys = [] {
    std::vector<KeySpec> k = fit_keys(other_key("texture_size", "integer 2..1024 or `\"cv\"`", "16",
                                                "final resolution; `\"cv\"` (raw samples): chosen by held-out error "
                                                "from 8, 12, 16, 24, 32, the search run once at 16 and its "
                                                "projections refit at each (docs/design.md §4.1 \"cv\")"));
    const auto r = refine_keys();
    k.insert(k.end(), r.begin(), r.end());
    const std::vector<KeySpec> own = {
        with_default(choice_key("parameterization", {"wiwo", "halfdiff"}, "",
                   "given (or swept): every term of every strategy reads it (`term_param = \"fixed\"`; "
                   "`term_param = \"either\"` with it is an error). Not given: the greedy search reads wiwo and "
                   "the structured search chooses wiwo or halfdiff per term; column `parameterization` then says "
                   "`either` (greedy alone: `wiwo`). Column `term_parameterizations` lists each term's"),
                     "none: the search's choice"),
        int_key("terms", 1, 64, "2; 8 with a tolerance", "textures to build; with a tolerance, the cap"),
        other_key("search_texture_size", "0 or 2..1024", "0", "resolution during the search; 0 = texture_size"),
        int_key("restarts", 0, 100000, "6", "seeded random starts per term"),
        other_key("guesses", "list of `\"wi\"`, `\"wo\"`, `\"wi+wo\"`", "[]", "extra starts"),
        bool_key("reciprocity", "false", "every term read through its conjugate too"),
        other_key("final_reciprocity", "`\"auto\"`, true or false", "`\"auto\"`",
                  "structured, without `reciprocity`: every k-term answer is also refit with its terms read "
                  "through their conjugates too (the same planes) and kept when its rel_mse on the fit samples is "
                  "lower. `\"auto\"`: when the BRDF declares reciprocity (an analytic model's formula, a "
                  "Cornell, pbrt or MERL file, a CSV's declaration) and `sampling.symmetries` does not leave it "
                  "out. Column `reciprocity` (`true` / `mixed` / `false`), run.json `final_reciprocity`. "
                  "docs/search.md \"Reciprocal answers\""),
        choice_key("optimizer", {"powell", "praxis", "bobyqa", "neldermead", "sbplx", "direct", "crs"}, "powell", ""),
        num_key("ftol", 0.0, 1.0, true, "1e-3",
                "relative improvement per sweep below which Powell stops (also nlopt's ftol)"),
        num_key("line_tol", 0.0, 10.0, true, "0.02", "golden-section bracket width (radians of t)"),
        choice_key("line_search", {"golden", "brent"}, "golden",
                   "refinement of a bracketed line minimum: golden section, or Brent's parabolic steps "
                   "(about 35% fewer fits; on W1 the per-term errors differ by up to 0.4%, docs/speed.md)"),
        num_key("initial_step", 0.0, 6.28, true, "0.3", "first bracketing step (below 2π)"),
        int_key("max_sweeps", 1, 100000, "30", "Powell sweeps per minimization"),
        int_key("max_evaluations", 10, 100000000, "5000", "objective evaluations per minimization"),
        int_key("threads", 0, 1024, "0",
                "restarts in parallel; 0 = hardware threads. Not part of the run id (results do not depend on it)"),
        int_key("seed", 0, kIntMax, "`experiment.seed`", "seed of the random restarts (column `seed`)"),
        int_key("beam", 1, 100000, "1",
                "non-greedy: the `beam` best first-term candidates (from different starts) are each continued to "
                "the last term; the branch with the lowest final `rel_mse` (at `texture_size`) wins. Branch 1 is "
                "the greedy search, so never worse than greedy; costs about `beam` times the searches of terms "
                "2..J. At most restarts + guesses. run.json holds `beam_rel_mse` per branch"),
        int_key("backfit_sweeps", 0, 1000, "0",
                "non-greedy: after each added term j ≥ 2, terms 1..j are re-searched in turn with the other "
                "projections held (cyclic; stops early when a sweep moves nothing), from their current rotation; "
                "the objective is the whole fit schedule's error with that one projection changed, so each "
                "accepted move lowers it. Per-term `backfit_evaluations` and `backfit_moves` in run.json"),
        int_key("backfit_restarts", 0, 100000, "0",
                "extra seeded random starts per re-search (besides the current rotation)"),
        other_key("tolerance", "table", "",
                  "stop after the first term that reaches the target; `terms` is then the cap (default 8); "
                  "needs `beam = 1`"),
        choice_key("strategy", {"best", "greedy", "structured"}, "structured",
                   "`greedy`: Cole's search, term by term (the keys above). `structured` (search/structured_search.h): "
                   "starts from planes read off the data's Hessians, Cole's guesses in both parameterizations and "
                   "seeded random rotations, a beam of partial configurations, a joint polish of every term and a "
                   "joint final refit; refuses `beam`, `backfit_*` and the nlopt optimizers. `best`: both, keeping "
                   "the factorization with the lower rel_mse (run.json `search_strategy` says which; with a "
                   "tolerance the greedy search alone); refuses what `structured` refuses. Default `structured`, or `greedy` when "
                   "`beam`, `backfit_sweeps`, `backfit_restarts` or `optimizer` is given. Measured in docs/search.md"),
        with_default(choice_key("term_param", {"either", "fixed"}, "",
                                "structured: each term reads the wiwo or the halfdiff point as the search chooses "
                                "(`either`), or every term reads `parameterization` (`fixed`)"),
                     "`\"fixed\"` when `parameterization` is given, else `\"either\"`"),
        int_key("keep", 1, 1000, "3", "structured: starts refined by Powell per term (the best by one fit each)"),
        with_default(int_key("polish_sweeps", 0, 1000, "",
                             "structured: final sweeps re-searching each term with the others held"),
                     by_search_size(kSmallSearchPolishSweeps, kLargeSearchPolishSweeps)),
        with_default(int_key("beam_width", 1, 1000, "", "structured: partial configurations kept per term"),
                     by_search_size(kSmallSearchBeamWidth, kLargeSearchBeamWidth)),
        bool_key("final_joint", "true", "structured: the final refit solves all terms jointly"),
        bool_key("reseed", "true",
                 "structured, 2-4 terms, `term_param = \"either\"`: re-read every term (3-4 terms: and pair of terms; 2 "
                 "terms: and 8 random starts of a wiwo and a halfdiff term together, 8 more in the answer's mix when "
                 "its terms share one) under the joint fit after the polish (finds planes of different "
                 "parameterizations; up to ~5x the fits on planted mixtures, about 4x on W1's 2-term search)"),
        int_key("joint_polish_terms", 0, 64, "3",
                "structured: searches of up to this many terms pick their last term and polish under the joint fit"),
        other_key("search_samples", "0, `\"off\"` or an integer >= 1000", "100000",
                  "above this many fit samples the search evaluates its candidates (screening, Powell, polish) on a "
                  "stratified subsample of this many (strata over θh, φh, θd, φd, a cap per stratum, each stratum's "
                  "weight kept; seeded by `seed`), and refits its answers at `texture_size` on every sample; every "
                  "metric uses every sample. 0 or `\"off\"`: every sample. Column `search_samples`, run.json "
                  "`search_subsample`. docs/search.md \"Search on a subsample\"")};
    k.insert(k.end(), own.begin(), own.end());
    return k;
  }();
  return keys;
}

const KeySpec& key(const std::string& name) { return find_key(search_keys(), name); }

// search_samples: 0 or "off" (every sample) or a count >= kMinSearchSamples.
void read_search_samples(Reader& r, SearchOptions& s) {
  const toml::node* n = r.take("search_samples");
  if (!n) return;
  const std::string rule = "expected 0 or \"off\" (search on every sample) or an integer >= " +
                           std::to_string(kMinSearchSamples) + " (the subsample's size), ";
  if (auto str = n->as_string()) {
    if (str->get() == "off") s.search_samples = 0;
    else r.fail("search_samples", rule + "found \"" + str->get() + "\"");
    return;
  }
  auto v = n->as_integer();
  if (!v) {
    r.fail("search_samples", rule + found(*n));
    return;
  }
  if (v->get() != 0 && v->get() < static_cast<int64_t>(kMinSearchSamples)) {
    r.fail("search_samples", rule + "found " + std::to_string(v->get()));
    return;
  }
  s.search_samples = static_cast<size_t>(v->get());
}

// final_reciprocity: "auto", true or false (stored as "auto", "true", "false").
void read_final_reciprocity(Reader& r, HomomorphicOptions& h) {
  const toml::node* n = r.take("final_reciprocity");
  if (!n) return;
  if (auto b = n->as_boolean()) {
    h.final_reciprocity = b->get() ? "true" : "false";
    return;
  }
  auto str = n->as_string();
  if (str && str->get() == "auto") return;
  r.fail("final_reciprocity", "expected \"auto\", true or false, " +
                                  (str ? "found \"" + str->get() + "\"" : found(*n)));
}

// Whether a run's search refits its answers with reciprocal terms: the
// setting, or with "auto" the BRDF's declared reciprocity (a Python call
// without a BRDF: its samples' declaration) unless the run's
// sampling.symmetries leaves it out ("off", "none" or a list without it).
bool final_reciprocity_of(const RunContext& c) {
  const HomomorphicOptions& h = homomorphic_options(c.method);
  if (h.search.strategy == "greedy") return false;  // its answers are one schedule's prefixes
  if (h.reciprocity) return false;                   // its terms are reciprocal already
  const std::string& setting = h.final_reciprocity;
  if (setting != "auto") return setting == "true";
  // A call from Python has no plan: its samples and BRDF say it.
  const std::string sym =
      c.run.sampling < c.plan.samplings.size() ? c.plan.samplings[c.run.sampling].symmetries : "auto";
  if (sym == "off" || sym == "none") return false;
  if (sym != "auto" && !parse_symmetries(sym, "sampling.symmetries").reciprocal) return false;
  return c.brdf.brdf ? c.brdf.brdf->reciprocal() : c.samples.symmetries.reciprocal;
}

void read_guesses(Reader& r, SearchOptions& s) {
  const toml::node* g = r.take("guesses");
  if (!g) return;
  auto a = g->as_array();
  if (!a) {
    r.fail("guesses", "expected a list of \"wi\", \"wo\", \"wi+wo\", " + found(*g));
    return;
  }
  for (const auto& e : *a) {
    auto str = e.as_string();
    if (!str) {
      r.fail("guesses", "expected a list of \"wi\", \"wo\", \"wi+wo\", found an element " + show(e));
      continue;
    }
    try {
      guess_rotation(str->get());
      s.guesses.push_back(str->get());
    } catch (const std::exception&) {
      r.fail("guesses", "expected \"wi\", \"wo\" or \"wi+wo\", found \"" + str->get() + "\"");
    }
  }
}

// The search's effective options, hashed into the run id.
void record_options(const MethodVariant& m, json& o) {
  const HomomorphicOptions& h = homomorphic_options(m);
  const SearchOptions& s = h.search;
  o["parameterization"] = to_string(h.param);
  o["terms"] = m.terms;
  if (o.value("texture_size", json()) != json("cv")) o["texture_size"] = m.texture_size;
  o["search_texture_size"] = s.search_texture_size;
  o["restarts"] = s.restarts;
  o["guesses"] = s.guesses;
  o["reciprocity"] = h.reciprocity;
  // In the run id unless "false": a structured search with it off is the search of
  // before the key (structured revision 3), whose cached runs stay valid.
  if (s.strategy != "greedy" && h.final_reciprocity != "false") o["final_reciprocity"] = h.final_reciprocity;
  o["optimizer"] = s.optimizer;
  o["ftol"] = s.powell.ftol;
  o["line_tol"] = s.powell.line_tol;
  // In the run id only when not the default, so existing runs keep their cache.
  if (s.powell.line_search != PowellOptions::LineSearch::Golden) o["line_search"] = to_string(s.powell.line_search);
  o["initial_step"] = s.powell.initial_step;
  o["max_sweeps"] = s.powell.max_sweeps;
  o["max_evaluations"] = s.powell.max_evaluations;
  o["seed"] = m.seed;
  // Every strategy: above it the search runs on a subsample (0 = off).
  o["search_samples"] = s.search_samples;
  // Non-greedy options enter the run id only when set, so greedy runs keep their cache.
  if (s.strategy != "greedy") {
    o["strategy"] = s.strategy;
    o["term_param"] = s.term_param;
    o["keep"] = s.keep;
    o["polish_sweeps"] = effective_polish_sweeps(s);
    o["beam_width"] = effective_beam_width(s);
    o["final_joint"] = s.final_joint;
    o["joint_polish_terms"] = s.joint_polish_terms;
    o["reseed"] = s.reseed;
    o["structured_revision"] = kStructuredSearchRevision;
  }
  if (s.beam != 1) o["beam"] = s.beam;
  if (s.backfit_sweeps != 0) o["backfit_sweeps"] = s.backfit_sweeps;
  if (s.backfit_sweeps != 0 && s.backfit_restarts != 0) o["backfit_restarts"] = s.backfit_restarts;
}

// The `parameterization` column of a search: what its options ask of every
// term. "either": the structured search (alone or in "best") may choose wiwo
// or halfdiff per term (no parameterization given); otherwise the one every
// term reads. Column `term_parameterizations` says what each term read.
std::string asked_parameterization(const SearchOptions& s) {
  return s.strategy != "greedy" && s.term_param == "either" ? "either" : to_string(s.param);
}

json term_records(const SearchResult& sr) {
  json terms = json::array();
  for (const auto& t : sr.terms)
    terms.push_back({{"rotation", t.rotation},
                     {"search_rel_mse", std::isfinite(t.search_rel_mse) ? json(t.search_rel_mse) : json()},
                     {"evaluations", t.evaluations},
                     {"seconds", t.seconds},
                     {"best_start", t.best_start},
                     {"backfit_evaluations", t.backfit_evaluations},
                     {"backfit_moves", t.backfit_moves}});
  return terms;
}

class SearchKind final : public HomomorphicKind {
 public:
  std::string name() const override { return "search"; }
  std::string summary() const override {
    return "Cole's automatic factorization: greedy over terms, Powell (or an nlopt optimizer) over 4D rotations "
           "per term, seeded random restarts in parallel, search at `search_texture_size` and refit at "
           "`texture_size`. `beam` and `backfit_*` enter the run id only when not at their defaults, so greedy "
           "runs keep their cache.";
  }
  std::vector<KeySpec> keys() const override { return search_keys(); }
  bool seeded() const override { return true; }
  std::string example() const override { return "terms = 1\ntexture_size = 6\nrestarts = 1\nthreads = 1\n"; }
  std::vector<std::string> described() const override {
    return {"parameterization", "terms", "texture_size", "reciprocity", "restarts", "optimizer", "beam",
            "backfit_sweeps", "seed"};
  }
  // `parameterization` as the results column has it: "either" for a search
  // whose terms each choose (the option then holds only greedy's default).
  json described_value(const MethodVariant& m, const std::string& key) const override {
    if (key == "parameterization") return asked_parameterization(homomorphic_options(m).search);
    return m.options.at(key);
  }
  bool array_is_value(const std::string& key, const toml::array& a) const override {
    return key == "guesses" && !all_arrays(a);
  }
  std::vector<std::string> columns() const override {
    std::vector<std::string> c = homomorphic_columns();
    c.push_back("search_strategy");
    c.push_back("search_samples");
    return c;
  }
  void fill_row(const RunContext& c, MethodOutcome& out, Row& row) const override {
    fill_homomorphic_row(c, out, row);
    row["parameterization"] = asked_parameterization(homomorphic_options(c.method).search);
    row["search_strategy"] = out.record.value("search_strategy", "");
    // The samples the search evaluated its candidates on (= samples unless subsampled).
    const json& sub = out.record.value("search_subsample", json::object());
    row["search_samples"] = sub.contains("samples") ? std::to_string(sub["samples"].get<size_t>()) : "";
  }

  void read(Reader& r, MethodVariant& m, json& o, uint64_t base_seed) const override {
    read_refine_options(r, m, o);
    HomomorphicOptions& h = homomorphic_options(m);
    SearchOptions& s = h.search;
    // Configs default to the structured search (over seeds 1-3 its mean is at or
    // below greedy's at every term count on W1, Cook-Torrance and the five
    // paints; docs/search.md "Config default"); "greedy" reproduces earlier
    // results, "best" runs both. A greedy-only key (beam, backfit_*, optimizer)
    // without a strategy means greedy.
    const bool greedy_keys =
        r.has("beam") || r.has("backfit_sweeps") || r.has("backfit_restarts") || r.has("optimizer");
    s.strategy = r.choice(key("strategy"), greedy_keys ? "greedy" : "structured");
    // An explicit parameterization (or a sweep over it) is every term's: the
    // structured search then reads no other point. Without it the structured
    // search chooses per term (the documented default).
    const bool param_given = r.has("parameterization");
    s.term_param = r.choice(key("term_param"), param_given ? "fixed" : "either");
    s.keep = static_cast<int>(r.integer(key("keep"), s.keep));
    s.polish_sweeps = static_cast<int>(r.integer(key("polish_sweeps"), s.polish_sweeps));
    s.beam_width = static_cast<int>(r.integer(key("beam_width"), s.beam_width));
    s.final_joint = r.boolean(key("final_joint"), s.final_joint);
    s.joint_polish_terms = static_cast<int>(r.integer(key("joint_polish_terms"), s.joint_polish_terms));
    s.reseed = r.boolean(key("reseed"), s.reseed);
    h.param = read_param(r, "parameterization", s.param);
    if (param_given && r.has("term_param") && s.term_param == "either")
      r.fail("term_param", "term_param = \"either\" lets the search choose each term's parameterization, which "
                           "contradicts the explicit parameterization = \"" + to_string(h.param) +
                           "\"; expected term_param = \"fixed\" or no term_param (with parameterization every "
                           "term reads it), or no parameterization (the search chooses per term)");
    m.tolerance = read_tolerance(r, o);
    // With a tolerance, `terms` is the cap (default 8): the greedy search stops
    // at the first term whose refit reaches the target.
    m.terms = static_cast<int>(r.integer(key("terms"), m.tolerance ? 8 : s.terms));
    if (m.tolerance) m.cap = m.terms;
    // texture_size = "cv": the search runs at the default 16 (SearchCvCache).
    m.texture_size = take_texture_cv(r, o, false) ? s.texture_size
                                           : static_cast<int>(r.integer("texture_size", s.texture_size, 2, 1024));
    s.search_texture_size = static_cast<int>(r.integer("search_texture_size", 0, 0, 1024));
    if (s.search_texture_size == 1) r.fail("search_texture_size", "expected 0 (same as texture_size) or 2..1024, found 1");
    s.restarts = static_cast<int>(r.integer(key("restarts"), s.restarts));
    read_guesses(r, s);
    read_search_samples(r, s);
    h.reciprocity = r.boolean(key("reciprocity"), false);
    read_final_reciprocity(r, h);
    s.optimizer = r.choice(key("optimizer"), s.optimizer);
    s.powell.ftol = r.number(key("ftol"), s.powell.ftol);
    s.powell.line_tol = r.number(key("line_tol"), s.powell.line_tol);
    s.powell.line_search = parse_line_search(r.choice(key("line_search"), to_string(s.powell.line_search)));
    s.powell.initial_step = r.number(key("initial_step"), s.powell.initial_step);
    s.powell.max_sweeps = static_cast<int>(r.integer(key("max_sweeps"), s.powell.max_sweeps));
    s.powell.max_evaluations = static_cast<int>(r.integer(key("max_evaluations"), s.powell.max_evaluations));
    s.threads = static_cast<int>(r.integer(key("threads"), 0));
    s.beam = static_cast<int>(r.integer(key("beam"), s.beam));
    s.backfit_sweeps = static_cast<int>(r.integer(key("backfit_sweeps"), s.backfit_sweeps));
    s.backfit_restarts = static_cast<int>(r.integer(key("backfit_restarts"), s.backfit_restarts));
    m.seed = static_cast<uint64_t>(r.integer(key("seed"), static_cast<int64_t>(base_seed)));
    read_fit_options(r, h.fit, o);
    if (s.strategy != "structured" && s.restarts == 0 && s.guesses.empty() && !r.failed())
      r.fail("restarts", "restarts = 0 and no guesses leave nothing to search from (give restarts >= 1 or guesses)");
    s.terms = m.terms;
    s.param = h.param;
    s.texture_size = m.texture_size;
    s.reciprocity = h.reciprocity;
    s.fit = h.fit;
    s.seed = m.seed;
    record_options(m, o);
    if (m.tolerance && s.beam != 1)
      r.fail("tolerance", "a tolerance stops the greedy search after a term, which needs beam = 1; found beam = " +
                              std::to_string(s.beam));
    m.execution["threads"] = s.threads;
    const int starts = s.restarts + static_cast<int>(s.guesses.size());
    m.cores = std::max(1, std::min(hardware_threads(s.threads), starts));
    if (!r.failed()) {
      try {
        s.validate();
      } catch (const std::exception& e) {
        report_invalid(r, e, method_keys(*this));
      }
    }
    finish_refine_options(r, m, o);
    if (m.cv) {
      h.search_cv = std::make_shared<SearchCvCache>();
      h.search_cv->base = s;
    }
  }

  MethodOutcome run(const RunContext& c) const override {
    const MethodVariant& m = c.method;
    const HomomorphicOptions& h = homomorphic_options(m);
    const FitData data(c.samples, h.fit.eps);
    if (h.search_cv) return run_cv(c, data);
    SearchOptions so = h.search;
    so.final_reciprocity = final_reciprocity_of(c);
    SizeChoice choice;  // with a tolerance: the terms tried, filled as the search goes
    if (m.tolerance) {
      // The greedy search stops at the first term whose refit reaches the
      // target (search/term_search.h, stop_after_term); later terms are never searched.
      choice.method = "search";
      choice.knob = "terms";
      choice.metric = m.tolerance->metric;
      so.stop_after_term = [&](const HomomorphicFactorization& hf) {
        const double v = m.tolerance->error_of(hf, c.samples, c.lt);
        choice.tried.push_back({static_cast<int>(hf.terms().size()), -1, v});
        choice.value = static_cast<int>(hf.terms().size());
        choice.error = v;
        choice.reached = v <= m.tolerance->value;
        return choice.reached;
      };
    }
    SearchResult sr = search_factorization(data, so);
    std::optional<SizeChoice> chosen;
    if (m.tolerance) {
      choice.seconds = sr.seconds;
      choice.result = sr.factorization;
      choice.errors_after_term = sr.rel_mse_after_term;
      chosen = choice;
    }
    return outcome_of(c, std::move(sr), std::move(chosen));
  }

 private:
  // A run under a "cv" key: the search at the base options (once per fit
  // set, SearchCvCache), its projections refit at this candidate's smoothing
  // and texture size. run.json `search_cv` says which, and whether this call
  // ran the search or reused it.
  MethodOutcome run_cv(const RunContext& c, const FitData& data) const {
    const MethodVariant& m = c.method;
    const HomomorphicOptions& h = homomorphic_options(m);
    SearchCvCache& cache = *h.search_cv;
    const uint64_t key = fingerprint(c.samples);
    std::shared_ptr<const SearchResult> base;
    {
      std::lock_guard<std::mutex> lk(cache.mu);
      if (const auto it = cache.searched.find(key); it != cache.searched.end()) base = it->second;
    }
    const bool reused = base != nullptr;
    if (!base) {
      SearchOptions so = cache.base;
      so.final_reciprocity = final_reciprocity_of(c);
      base = std::make_shared<const SearchResult>(search_factorization(data, so));
      std::lock_guard<std::mutex> lk(cache.mu);
      cache.searched.emplace(key, base);
    }
    SearchResult sr = *base;
    refit_at(data, h.fit, cache.base.final_joint, m.texture_size, sr);
    MethodOutcome out = outcome_of(c, std::move(sr), std::nullopt);
    out.record["search_cv"] = {{"base_smoothing", cache.base.fit.smoothing},
                               {"base_texture_size", cache.base.texture_size},
                               {"search", reused ? "reused" : "ran"},
                               {"search_seconds", base->seconds},
                               {"smoothing", h.fit.smoothing},
                               {"texture_size", m.texture_size}};
    return out;
  }

  // The outcome of a search result: the refinement, the row's state and run.json's search entries.
  MethodOutcome outcome_of(const RunContext& c, SearchResult sr, std::optional<SizeChoice> chosen) const {
    HomomorphicRun run;
    run.h = sr.factorization;
    run.errors_after_term = sr.rel_mse_after_term;
    MethodOutcome out = finish_homomorphic(c, std::move(run), std::move(chosen), sr.evaluations);
    out.record["terms"] = term_records(sr);
    out.record["search_strategy"] = sr.strategy;
    // Which k-term answers were refit with reciprocal terms (empty: not asked or greedy).
    out.record["final_reciprocity"] = {{"setting", homomorphic_options(c.method).final_reciprocity},
                                       {"on", final_reciprocity_of(c)},
                                       {"reciprocal_answers", sr.reciprocal_answers}};
    // What the search's candidates were evaluated on (the final fit and the
    // metrics use every sample): a stratified subsample above search_samples.
    out.record["search_subsample"] = {{"threshold", homomorphic_options(c.method).search.search_samples},
                                      {"samples", sr.search_samples},
                                      {"of", sr.data_samples},
                                      {"subsampled", sr.search_samples < sr.data_samples},
                                      {"seed", sr.subsample_seed},
                                      {"strata", sr.subsample_strata}};
    json term_params = json::array();
    for (const FactorTerm& t : sr.factorization->terms()) term_params.push_back(to_string(t.proj.param));
    out.record["term_parameterizations"] = term_params;
    // The structured search's k-term answers (errors_after_term[k-1] is the
    // error of answers[k-1], which need not be a prefix of the row's factorization).
    if (!sr.answers.empty()) {
      json answers = json::array();
      for (size_t k = 0; k < sr.answers.size(); ++k) {
        json params = json::array(), rotations = json::array();
        for (const FactorTerm& t : sr.answers[k]->terms()) {
          params.push_back(to_string(t.proj.param));
          rotations.push_back(t.rotation ? json(*t.rotation) : json());
        }
        answers.push_back({{"terms", k + 1},
                           {"rel_mse", sr.rel_mse_after_term[k]},
                           {"parameterizations", params},
                           {"rotations", rotations}});
      }
      out.record["answers"] = answers;
    }
    if (sr.beam_rel_mse.size() > 1) {
      out.record["beam_rel_mse"] = sr.beam_rel_mse;
      out.record["best_branch"] = sr.best_branch;
    }
    return out;
  }
};

}  // namespace

std::shared_ptr<const MethodKind> make_search_kind() { return std::make_shared<SearchKind>(); }

}  // namespace bf
