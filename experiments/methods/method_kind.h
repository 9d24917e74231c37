// The method catalogue: every factorization method an experiment can run
// (`[[method]] kind = "..."`), the counterpart of brdfs/catalogue.h for
// methods. Each kind lives in one file of experiments/methods/ and holds its
// keys (with types, ranges, defaults and docs), how it reads and validates
// them, how it runs (one fit, or a tolerance-driven selection), the results
// columns it fills, what it adds to run.json, and its extra output files. The
// config reader (config.cpp), the runner (runner.cpp) and the outputs never
// name a kind: they ask the catalogue.
//
// A kind is a class deriving from MethodKind (a virtual interface: one object
// per kind, no state). Adding a kind: the algorithm in factor/ or search/
// (with its own Factorization subclass if no existing one fits: it carries its
// export, GLSL and viewer data, factor/factorization.h), one file here
// defining the class and its factory make_<id>_kind(), one line X(id) in the
// list of methods/catalogue.cpp, a test. Python gets `bf.<name>` and
// `bf.factor(name)` from the registry (method_call_specs below). A test may
// add a kind of its own at run time with register_method_kind(). See
// docs/design.md "How a method kind plugs in".
#pragma once

#include <any>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "brdfs/sampleset.h"
#include "experiments/plan/plan.h"
#include "experiments/plan/config_reader.h"
#include "experiments/report/outputs.h"
#include "experiments/report/render.h"
#include "factor/isotropy.h"
#include "factor/metrics.h"
#include "factor/size_choice.h"

namespace bf {

// What a run hands its method.
struct RunContext {
  const Plan& plan;
  const PlannedRun& run;
  const BrdfVariant& brdf;
  const MethodVariant& method;
  const SampleSet& samples;
  const LogTransform& lt;             // of the samples, with experiment.metric_eps
  const IsotropyResult& isotropy;     // the BRDF's azimuthal-invariance test
  std::filesystem::path run_dir;      // runs/<run_id>/ (exists, empty)
  // The render of the original BRDF under the scene (shared by the runs of a BRDF).
  std::function<std::shared_ptr<const SphereRender>()> original;
};

// What a method's run returns to the runner.
struct MethodOutcome {
  FactorizationPtr result;                // the approximation scored, rendered and exported
  std::optional<SizeChoice> choice;       // with a tolerance: what was chosen and tried
  int evaluations = 0;                    // objective evaluations (the `evaluations` column)
  nlohmann::json record = nlohmann::json::object();  // entries added to run.json
  std::vector<std::string> notes;         // the `notes` column, in order
  std::any state;                         // the kind's own data, from run() to its row and files
};

class MethodKind {
 public:
  virtual ~MethodKind() = default;
  // The `kind` value, e.g. "search".
  virtual std::string name() const = 0;
  // One paragraph for `brdf-factor list methods` and the docs.
  virtual std::string summary() const = 0;
  // The kind's own keys, in the order documented (the common keys kind,
  // label, refine and zip are the catalogue's; see method_keys()).
  virtual std::vector<KeySpec> keys() const = 0;
  // Whether refine = "linear" | "cosine" | "blend" applies (a homomorphic fit).
  virtual bool refinable() const { return false; }
  // Whether the kind has a seed (the `seed` column and run.json seeds.method = m.seed).
  virtual bool seeded() const { return false; }
  // Options shown in the run's one-line description (in this order).
  virtual std::vector<std::string> described() const = 0;
  // The value shown for one of them (m.options[key] unless the kind says
  // better, e.g. a search whose terms each choose their parameterization).
  virtual nlohmann::json described_value(const MethodVariant& m, const std::string& key) const {
    return m.options.at(key);
  }
  // Results columns beyond the common ones that a successful run of this
  // kind fills (checked by the generic catalogue test).
  virtual std::vector<std::string> columns() const = 0;
  // A small, fast [[method]] body of this kind (TOML lines after `kind = ...`)
  // that runs on a 6^4 grid in well under a second: the catalogue test runs
  // every kind through it.
  virtual std::string example() const = 0;
  // Arrays that are one value of a key rather than a sweep (e.g. guesses).
  virtual bool array_is_value(const std::string& key, const toml::array& a) const {
    (void)key, (void)a;
    return false;
  }

  // Reads and validates the kind's keys from r into m (typed options, cores,
  // seed) and o (every effective option, hashed into the run id). Problems go
  // to r, each at its key. base_seed: experiment.seed.
  virtual void read(Reader& r, MethodVariant& m, nlohmann::json& o, uint64_t base_seed) const = 0;
  // Rules about the method and the rest of the plan (scene lighting, BRDFs),
  // after every section is read; may adjust m (and its options).
  virtual void check_plan(const Plan& plan, MethodVariant& m, Ctx& ctx) const {
    (void)plan, (void)m, (void)ctx;
  }

  // Runs the method on the samples (timed by the runner as `seconds`).
  virtual MethodOutcome run(const RunContext& c) const = 0;
  // Fills the kind's columns of the row (and notes) from the outcome.
  virtual void fill_row(const RunContext& c, MethodOutcome& out, Row& row) const = 0;
  // Writes the exported factors (when experiment.export is on).
  virtual void export_files(const RunContext& c, const MethodOutcome& out) const;
  // Outputs after the picture (e.g. the SHRM): files in c.run_dir, entries in
  // out.record, notes, and cells of row.
  virtual void extra_outputs(const RunContext& c, MethodOutcome& out, Row& row) const {
    (void)c, (void)out, (void)row;
  }
  // Bytes export_files writes beyond the common estimate (textures of
  // texture_size per term, factorization.json): the preflight's disk estimate
  // (experiments/run/preflight.h).
  virtual uint64_t export_bytes(const MethodVariant& m) const {
    (void)m;
    return 0;
  }
  // Whether report.html's viewer shows runs of this kind (a tabulation of the
  // original is then written beside the run, counted by the preflight).
  virtual bool has_viewer() const { return true; }

  // Whether the kind tabulates the BRDF itself (svd, sh-k, sh-r) rather than
  // fitting the samples: Python's bf.<kind>(brdf, samples=None, **options)
  // instead of bf.<kind>(samples, **options).
  virtual bool tabulates() const { return false; }
  // What a direct call (Python's Factorization) reports beyond out.record:
  // rel_mse on the samples after each term, and entries of its `info`.
  // samples_given: false when a tabulating kind was called without samples.
  virtual void report_call(const RunContext& c, const MethodOutcome& out, bool samples_given,
                           std::vector<double>& errors_after_term, nlohmann::json& info) const {
    (void)c, (void)out, (void)samples_given, (void)errors_after_term, (void)info;
  }
};

// The registered kinds, in registration order (the order of messages and docs).
// Writes runs/<id>/factorization.json, the result's describe() (the default
// export_files).
void write_description(const RunContext& c, const MethodOutcome& out);

const std::vector<std::shared_ptr<const MethodKind>>& method_kinds();
// The kind named `name`, or nullptr.
const MethodKind* find_method_kind(const std::string& name);
std::vector<std::string> method_kind_names();
// Adds a kind (tests); throws std::invalid_argument for a name already taken.
void register_method_kind(std::shared_ptr<const MethodKind> kind);
// Removes a kind added by register_method_kind (tests; plans using it must be gone).
void unregister_method_kind(const std::string& name);

// Registers a kind for the lifetime of the object (a test's one registration
// line), then removes it.
class ScopedMethodKind {
 public:
  explicit ScopedMethodKind(std::shared_ptr<const MethodKind> kind) : name_(kind->name()) {
    register_method_kind(std::move(kind));
  }
  ~ScopedMethodKind() { unregister_method_kind(name_); }
  ScopedMethodKind(const ScopedMethodKind&) = delete;
  ScopedMethodKind& operator=(const ScopedMethodKind&) = delete;

 private:
  std::string name_;
};

// Keys of every [[method]] table, whatever its kind: kind, label, refine, zip.
const std::vector<KeySpec>& common_method_keys();
// Every key a kind accepts (common keys, then its own), by name.
std::vector<std::string> method_keys(const MethodKind& kind);
// The names of the kinds with refinable() (for messages).
std::vector<std::string> refinable_kind_names();

// How Python calls a kind (python/src/methods.cpp binds one function per
// registered kind from this table, python/brdf_factor/__init__.py lists them).
struct MethodCallSpec {
  std::string kind;      // the `kind` value, e.g. "sh-k"
  std::string function;  // the Python name: kind with '-' as '_', e.g. "sh_k"
  std::string input;     // "samples" (fits them) or "brdf" (tabulates it; MethodKind::tabulates)
  std::string doc;       // the docstring: signature, summary, the keys with their types, defaults and docs
};
MethodCallSpec method_call_spec(const MethodKind& kind);
std::vector<MethodCallSpec> method_call_specs();  // of every registered kind, in order

// The markdown key tables of every kind, as docs/experiments.md holds them
// between its "generated" markers and `brdf-factor list methods` prints them.
std::string method_key_tables();

}  // namespace bf
