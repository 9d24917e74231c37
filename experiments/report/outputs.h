// An experiment folder's tables and records (docs/design.md §5): results.csv,
// results.md, manifest.json, the config copy, the plots (through
// experiments/report/plot_results.py) and report.html, all written atomically. Used
// by `run` (one folder per experiment or shard) and by `merge`.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

namespace bf {

// Version of the folder layout (manifest.json "format_version").
inline constexpr int kExperimentFormatVersion = 1;
inline constexpr const char* kExperimentFormat = "brdf-factor-experiment";
inline constexpr const char* kBrdfFactorVersion = "0.1.0";

// results.csv columns: docs/design.md §5's, exactly and in that order...
const std::vector<std::string>& required_columns();
// ...then the extras: label, sampling, sweep, seed, status, errors_after_term,
// negative_texels, order, view_order, tolerance, tolerance_reached,
// shade_rmse, val_rel_mse, val_cos_rmse, val_max_ratio, holdout_rel_mse,
// holdout_cos_rmse, validation, flag (experiments/report/validation.h), isotropic,
// refine, refine_seconds, <metric>_before (the 7 metrics of the
// fit before refinement), model, sampler_storage, sampler_build_s
// (experiments/run/sampling_run.h), notes (docs/experiments.md says what each holds).
const std::vector<std::string>& result_columns();

// One results row: column -> cell text; a missing column is an empty cell.
using Row = std::map<std::string, std::string>;

struct RunEntry;
// Columns of the tables for people (results.md, report.html): the required
// ones with `label` after `method`, then those extras that some row fills
// (order, view_order, tolerance, tolerance_reached, shade_rmse, refine,
// refine_seconds, rel_mse_before, lin_rmse_before, cos_rmse_before, seed,
// sampling, sweep, model, notes).
std::vector<std::string> display_columns(const std::vector<RunEntry>& runs);

// Numbers as cells: %.9g; "" for NaN or infinity (never written as text).
std::string format_number(double v);
// Short form for people (results.md): 4 significant digits.
std::string format_short(const std::string& cell);

struct RunEntry {
  std::string run_id;
  std::string status;              // "ok" | "failed"
  int shard = 1;                   // which shard of the plan ran it
  Row row;
  std::vector<std::string> files;  // relative to the experiment folder, e.g. "runs/<id>/sphere.png"
  nlohmann::json record;           // the run's run.json (options, seeds, per-term details)
};

struct ExperimentOutput {
  std::string dir;                   // the experiment folder
  nlohmann::json experiment;         // name, seed, description, out
  std::string config_path, config_text;
  std::vector<std::string> defines;  // -D overrides, in order
  std::string plan_hash;
  int shard = 1, shards = 1;
  nlohmann::json plan = nlohmann::json::array();  // every run of the experiment: {run_id, shard, brdf, method, label}
  std::vector<RunEntry> runs;        // this folder's runs, in plan order
  std::vector<std::string> merged_from;  // merge: the shard folders
  bool plots = true;                 // call the plot script
};

struct OutputFiles {
  std::string results_csv, results_md, manifest, report;  // paths
  std::vector<std::string> plots;    // relative to the folder
  std::string plots_note;            // why there are no plots, if there are none
};

// Writes config.toml, results.csv, plots/, results.md, manifest.json and
// report.html into e.dir (each file atomically; report last). Progress and
// the plot note go to `log` when not null.
OutputFiles write_experiment_outputs(const ExperimentOutput& e, std::ostream* log);

// Reads a folder's manifest.json back (merge). Throws std::invalid_argument
// naming the file and field when it is missing or malformed.
ExperimentOutput read_experiment_manifest(const std::string& dir);

void write_results_csv(const std::string& path, const std::vector<Row>& rows);
// Parses a results.csv (quoted cells allowed); throws std::invalid_argument
// naming path:line when a row's cell count differs from the header's.
std::vector<Row> read_results_csv(const std::string& path);

// Versions of brdf-factor (+ git commit when the source tree is a git checkout)
// and of the libraries it was built with.
nlohmann::json software_versions();

// A python3 that can import matplotlib ($BRDF_FACTOR_PYTHON, python3 on PATH,
// /usr/bin/python3, in that order), or "" with the reason in *why.
std::string find_python(std::string* why);
// experiments/report/plot_results.py ($BRDF_FACTOR_PLOT_SCRIPT overrides).
std::string plot_script_path();

}  // namespace bf
