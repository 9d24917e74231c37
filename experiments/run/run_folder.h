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

#include "experiments/plan/plan.h"
#include "experiments/methods/method_kind.h"
#include "experiments/report/outputs.h"
#include "factor/metrics.h"

namespace bf {

// run.json's opening: what the run is (its outcome is added as it goes).
nlohmann::json run_record(const Plan& plan, const PlannedRun& pr, const SampleSet& samples);

// The columns every kind fills: metrics, storage, time, seed, the size choice
// (and its record in rec["size_choice"]); problems go to notes.
void fill_common_columns(const RunContext& c, const MethodOutcome& out, const Metrics& mt, double seconds,
                         Row& row, std::vector<std::string>& notes, nlohmann::json& rec);

// Writes run.json (rec with the row and the folder's file list); returns the
// files listed (relative to exp_dir, sorted). The run is finished only once
// its DONE marker is written (done_marker, write_done_marker).
std::vector<std::string> write_run_record(const std::filesystem::path& exp_dir,
                                          const std::filesystem::path& run_dir, const std::string& run_id,
                                          const Row& row, nlohmann::json& rec);

// The DONE marker of a run whose files are written: JSON with the run id and
// the content hash (64-bit FNV-1a, 16 hex digits) of every listed file
// (relative to exp_dir), run.json included. Throws naming a file it cannot hash.
std::string done_marker(const std::filesystem::path& exp_dir, const std::string& run_id,
                        const std::vector<std::string>& files);
// Writes the marker (atomically) as run_dir/DONE: from then on the run is finished.
void write_done_marker(const std::filesystem::path& run_dir, const std::string& marker);

// The files of a finished run as its DONE marker lists them: path relative
// to exp_dir -> content hash.
using RunFileHashes = std::vector<std::pair<std::string, std::string>>;

// A finished run's entry, or nothing. Nothing with *problem = "" when the
// folder has no DONE marker (not finished); nothing with *problem naming the
// file and what is wrong when the run cannot be trusted: a DONE marker that is
// not this format (an older one without hashes included), a listed file that
// is missing, a link or not a regular file, a content hash that does not
// match, a run.json that does not parse or disagrees with the marker. When
// hashes is given it receives the verified list.
std::optional<RunEntry> load_done_run(const std::filesystem::path& exp_dir, const std::string& run_id,
                                      std::string* problem = nullptr, RunFileHashes* hashes = nullptr);
// Whether runs/<run_id>/ exists (finished or not).
bool incomplete_folder(const std::filesystem::path& exp_dir, const std::string& run_id);

// What each run.json records of the build that made it (key "build"):
// brdf_factor version, and git_commit / git_dirty of the source tree when it
// is a git checkout (software_versions()).
nlohmann::json build_identity(const nlohmann::json& versions);
// A run record's build.git_commit; "" when it has none (older runs, no git).
std::string cached_run_commit(const nlohmann::json& record);

}  // namespace bf
