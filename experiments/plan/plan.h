// Experiment configs (docs/design.md §5, docs/experiments.md): TOML parsing, `-D`
// overrides, validation that names file:line, field and rule for every problem
// before any work starts, and sweep expansion into a plan of runs, each with a
// content-hash run id.
#pragma once

#include <any>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/symmetry.h"
#include "factor/size_choice.h"

namespace bf {

class MethodKind;  // experiments/methods/method_kind.h
struct ShLighting;  // factor/lighting.h

// Every problem found in a config, one line each, formatted
// "<file>:<line>: <field>: <rule, expected, found>" (or "-D key=value: <field>: ..."
// for a value given on the command line). what() joins them so that main()'s
// "brdf-factor: " prefix starts every line.
class ConfigError : public std::invalid_argument {
 public:
  explicit ConfigError(std::vector<std::string> messages);
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  std::vector<std::string> messages_;
};

// [experiment]
struct ExperimentSettings {
  std::string name;         // default: the config file's stem
  uint64_t seed = 1;        // default seed of stratified sampling and of searches
  std::string out;          // output folder; default "results/<name>" (relative to the working dir)
  std::string description;  // free text shown in results.md and report.html
  int jobs = 0;             // runs executed at once; 0 = hardware threads (see runner.h)
  bool plots = true;        // call experiments/report/plot_results.py after the runs
  bool render = true;       // per run: sphere picture (original | approximation | error)
  bool export_factors = true;  // per run: factor textures, sidecar, GLSL (config key `export`)
  double metric_eps = 1e-5; // eps of the log transform every method is scored with (docs/design.md §4)
  // Validation (docs/design.md §4 "validation"): stratified pairs over the
  // whole hemisphere pair scored against the BRDF (0 = none; kValidationAuto,
  // the default: blocks of kValidationBlockPairs, from kValidationMinBlocks
  // doubled until the standard error of val_rel_mse is at most
  // kValidationTargetSe of it or kValidationMaxBlocks are scored;
  // experiments/report/validation.h), and the fraction of measured/file
  // samples held out of the fit.
  int validation_pairs = kValidationAuto;
  static constexpr int kValidationAuto = -1;
  static constexpr int kValidationBlockPairs = 4096;
  static constexpr int kValidationMinBlocks = 8;
  static constexpr int kValidationMaxBlocks = 64;
  static constexpr double kValidationTargetSe = 0.015;
  double holdout = 0.1;
  // k-fold hold-out instead of the single fraction (experiments/run/folds.h):
  // 0 = off; k >= 2 fits each method k times without one fold each, and the
  // run's own fit on every sample; kFoldsAuto (the default when neither
  // `folds` nor `holdout` is set): kAutoFolds folds on raw samples of at most
  // kAutoFoldsMaxSamples valid samples, else the single fraction
  // (folds_for, experiments/report/validation.h).
  int folds = kFoldsAuto;
  static constexpr int kFoldsAuto = -1;
  static constexpr int kAutoFolds = 5;
  static constexpr size_t kAutoFoldsMaxSamples = 20000;
};

// The seed of the validation set and of the held-out choice, derived from
// experiment.seed (independent of every sampling and method seed).
uint64_t validation_seed(uint64_t experiment_seed);
// The seed of the whole-domain fill's pairs (symmetry_prep.h): unrelated to
// the validation set's, so the fill never samples the validation pairs.
uint64_t fill_seed(uint64_t experiment_seed);

// [scene]: the picture of every run and the shade_rmse column (docs/design.md
// §4), with the defaults below when the config has no [scene] (the default
// scene); `shade_rmse = false` drops the column. A unit sphere at the origin seen by an
// orthographic camera on +z, lit by one point light, or by band-limited SH
// lighting (factor/lighting.h) when `environment` or `lighting_order` is set;
// the SH lighting's order then caps the orders of sh-k and sh-r.
struct SceneSettings {
  bool named = false;             // the config has a [scene] table
  bool shade = true;              // key shade_rmse: the shade_rmse column (default scene when no [scene])
  Vec3 light = Vec3(2.0, 2.0, 4.0);  // light position (world; sphere radius 1)
  double intensity = 20.0;        // radiance = intensity * f * cos(theta_i) / distance^2
  int size = 128;                 // pixels per panel edge
  std::string environment;        // lat-long map (resolved path); "" = none
  double environment_eps = 1e-3;  // band limit: smallest L capturing 1 - eps of the map's energy
  int lighting_order = -1;        // explicit band limit (-1: measured, or point light without a map)
  int lighting_nodes = 0;         // shading quadrature: theta nodes (0 = auto), phi = 2x
  std::shared_ptr<const ShLighting> lighting;  // set when the scene is SH-lit
  nlohmann::json identity() const;
};

struct BrdfVariant {
  std::string label;        // the results' `brdf` column: `name`, else "preset[:k=v,...]" or the file
  std::string where;        // "file:line" of its [[brdf]] table
  BrdfPtr brdf;
  bool measured = false;    // has raw measured samples (sampling.kind = "measured")
  nlohmann::json identity;  // everything that determines it (hashed into run ids)
};

// The orbit a run's fit uses when its samples stand for their symmetries
// (experiments/run/symmetry_prep.h, docs/design.md §4.3): at most 2 staggered
// rotations per sample (with swap and mirror, 8 copies of a Cornell sample), a
// 2,000,000-sample budget. The stagger spreads the set over every azimuth
// already; more rotations cost time and memory without lowering the errors.
inline constexpr OrbitOptions kRunOrbit{2, 2'000'000};
// The share of each measured sample's weight that stays on the sample itself;
// its orbit copies share the rest. Without it the fit spends its capacity off
// the measured slice and the held-out error rises (docs/design.md §4.3).
inline constexpr double kRawShare = 0.5;
// The whole-domain fill of raw samples (experiments/run/symmetry_prep.h,
// docs/design.md §4.5): kFillPairs stratified pairs of the training samples'
// interpolant carrying kFillShare of the fit's weight ("auto").
inline constexpr size_t kFillPairs = 8192;
inline constexpr double kFillShare = 0.3;
// Both, as they enter a sampling's identity (run ids) when an orbit may be used.
inline nlohmann::json orbit_identity() {
  return {{"max_rotations", kRunOrbit.max_rotations}, {"budget", kRunOrbit.budget}, {"raw_share", kRawShare}};
}

struct SamplingVariant {
  std::string kind;         // "grid" | "stratified" | "file" | "measured"
  // Raw samples (measured, file): held out, fitted with their symmetries.
  bool raw() const { return kind == "measured" || kind == "file"; }
  int resolution = 16;      // grid: res^4 parabolic grid
  uint64_t count = 0;       // stratified: pairs
  uint64_t seed = 1;        // stratified
  std::string path;         // file: sample-list CSV (resolved path)
  std::string symmetries = "auto";  // "auto" | "off" | names joined by '+' (experiments/run/symmetry_prep.h)
  // measured: "auto" (= "measure" for a MERL table, "none" otherwise) | "measure"
  // (each table cell weighted by the hemisphere-pair measure it stands for) | "none".
  std::string weights = "auto";
  // measured: the whole-domain fill (experiments/run/symmetry_prep.h, docs/design.md
  // §4.5): -1 = "auto" (kFillShare when the training BRDF holds over the whole domain
  // and the fit uses its symmetries), 0 = "off", else the fill's share of the fit's weight.
  double fill = -1.0;
  std::string label;        // "grid 16^4", "stratified 20000 seed 1", "file x.csv", "measured"
  std::string where;
  nlohmann::json identity;  // kind + parameters (+ file digest)
};

// One [[method]] variant. Its kind (experiments/methods/) reads and runs it;
// only the kind looks at its typed options, which it keeps in `typed` (its own
// struct, e.g. HomomorphicOptions of methods/homomorphic.h, read through
// kind_options<T>). The fields here are the ones every part of a run reads.
struct MethodVariant {
  std::string kind;         // a registered kind's name (`brdf-factor list methods`)
  const MethodKind* impl = nullptr;  // that kind

  std::string label;        // `label` key, default the kind
  std::string where;        // "file:line" of its [[method]] table
  nlohmann::json options;   // every effective option with its default filled in (hashed)
  nlohmann::json execution; // options that do not change results (threads): recorded, not hashed
  // Size: terms and texels per texture edge, for the kinds that have them
  // (the preflight's disk estimate reads them too).
  int texture_size = 16;
  int terms = 2;
  std::optional<Tolerance> tolerance;  // fit, svd, sh-k, sh-r, mccool
  int cap = 0;              // with a tolerance: the largest terms / order tried
  // texture_size = "auto" (mccool, fit, svd; needs a tolerance): the
  // resolutions tried, ascending (key texture_ladder); empty = fixed texture_size.
  std::vector<int> texture_ladder;
  // Common keys (methods/catalogue.cpp): the refinement stage after a
  // homomorphic fit, "none" | "linear" | "cosine" | "blend" (factor/refine.h;
  // its options are the kind's), and whether to build and export the
  // importance sampler (experiments/run/sampling_run.h).
  std::string refine = "none";
  bool sampler = false;
  uint64_t seed = 0;        // the kind's seed (0 when the kind has none)
  int cores = 1;            // cores the method keeps busy by itself (scheduling, runner.h)
  std::any typed;           // the kind's own options (kind_options<T>)
  // A key chosen at run time by held-out error (`smoothing = "cv"` of mccool
  // and fit, docs/design.md §4.1 "cv"): its candidates in order and how one
  // is set on a copy of the variant. Unset: nothing is chosen.
  struct HeldOutChoice {
    std::string key;
    std::vector<double> ladder;
    std::function<void(MethodVariant&, double)> apply;
  };
  std::optional<HeldOutChoice> cv;
};

// The kind's typed options of m. The mutable form creates a T{} the first
// time (a kind's reader); both throw std::logic_error, naming the method, when
// m holds options of another type (a kind reading another kind's variant).
template <class T>
T& kind_options(MethodVariant& m) {
  if (!m.typed.has_value()) m.typed = T{};
  if (T* t = std::any_cast<T>(&m.typed)) return *t;
  throw std::logic_error("method \"" + m.label + "\" (kind " + m.kind + "): options of another type than asked");
}
template <class T>
const T& kind_options(const MethodVariant& m) {
  if (const T* t = std::any_cast<T>(&m.typed)) return *t;
  throw std::logic_error("method \"" + m.label + "\" (kind " + m.kind + "): " +
                         (m.typed.has_value() ? "options of another type than asked" : "no typed options were read"));
}

struct PlannedRun {
  std::string run_id;       // 12 hex digits of the identity's hash
  size_t brdf = 0, sampling = 0, method = 0;  // indices into Plan's vectors
  std::string samples_key;  // hash of (brdf, sampling) identities: the sample cache key
  nlohmann::json identity;  // everything that determines the run's outputs
};

struct Plan {
  std::string config_path;  // as given
  std::string config_text;  // the file as read
  std::vector<std::string> defines;  // -D key=value, in order
  ExperimentSettings experiment;
  SceneSettings scene;
  std::vector<BrdfVariant> brdfs;
  std::vector<SamplingVariant> samplings;
  std::vector<MethodVariant> methods;
  // Product brdfs x samplings x methods, in that nesting order; combinations
  // with an identical identity are kept once (counted in `duplicates`).
  std::vector<PlannedRun> runs;
  size_t duplicates = 0;
  std::string plan_hash;    // hash of every run id in order (shards of one plan share it)
};

// 64-bit FNV-1a of bytes as 16 hex digits.
std::string content_hash(const std::string& bytes);
// FNV-1a of a file's bytes (16 hex digits); throws std::invalid_argument if unreadable.
std::string file_hash(const std::string& path);
// 12 hex digits of content_hash(j.dump()) (nlohmann orders object keys, so equal values hash equally).
std::string short_hash(const nlohmann::json& j);

}  // namespace bf
