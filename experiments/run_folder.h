// A run's folder runs/<run_id>/ (docs/experiments.md "The experiment
// folder"): run.json's record and the columns every kind fills, the files it
// lists, the DONE marker written last, and reading a finished run back (the
// run cache). The runner (runner.h) decides what to run; this file is what a
// run leaves behind.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "experiments/config.h"
#include "experiments/methods/method_kind.h"
#include "experiments/outputs.h"
#include "factor/metrics.h"

namespace bf {

// run.json's opening: what the run is (its outcome is added as it goes).
nlohmann::json run_record(const Plan& plan, const PlannedRun& pr, const SampleSet& samples);

// The columns every kind fills: metrics, storage, time, seed, the size choice
// (and its record in rec["size_choice"]); problems go to notes.
void fill_common_columns(const RunContext& c, const MethodOutcome& out, const Metrics& mt, double seconds,
                         Row& row, std::vector<std::string>& notes, nlohmann::json& rec);

// Writes run.json (rec with the row and the folder's file list) and then the
// DONE marker; returns the files listed (relative to exp_dir, sorted).
std::vector<std::string> finish_run_folder(const std::filesystem::path& exp_dir,
                                           const std::filesystem::path& run_dir, const std::string& run_id,
                                           const Row& row, nlohmann::json& rec);

// A finished run's entry, or nothing when the folder is incomplete (no DONE,
// unreadable run.json, a listed file missing).
std::optional<RunEntry> load_done_run(const std::filesystem::path& exp_dir, const std::string& run_id);
// Whether runs/<run_id>/ exists (finished or not).
bool incomplete_folder(const std::filesystem::path& exp_dir, const std::string& run_id);

// What each run.json records of the build that made it (key "build"):
// brdf_factor version, and git_commit / git_dirty of the source tree when it
// is a git checkout (software_versions()).
nlohmann::json build_identity(const nlohmann::json& versions);
// A run record's build.git_commit; "" when it has none (older runs, no git).
std::string cached_run_commit(const nlohmann::json& record);

}  // namespace bf
