// Runs an experiment plan (config.h): the sample cache, the run cache
// (runs/<run_id>/ with a DONE marker written last), sharding, parallel
// execution, progress on stderr, and the folder outputs (outputs.h).
//
// Parallelism. A run whose method keeps several cores busy by itself (a
// search with more than one start and threads = 0, svd, sh-k and sh-r, whose
// tabulation is a parallel loop) runs alone, using them; runs that are serial
// (mccool, fit, a single-start search) run `jobs` at a time. Each run holds
// min(jobs, its cores) tokens of `jobs`, in plan order, so the machine is
// never oversubscribed and a sweep of cheap runs fills every core.
// docs/experiments.md gives the measurements behind this choice.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "experiments/plan/plan.h"
#include "experiments/report/outputs.h"
#include "experiments/run/run_folder.h"

namespace bf {

struct RunOptions {
  std::string config;                // path of the TOML config
  std::vector<std::string> defines;  // -D key=value
  std::string out;                   // overrides experiment.out when non-empty
  bool dry_run = false;              // list what would run and be skipped; write nothing
  bool force = false;                // redo runs even when cached
  bool quiet = false;                // no progress on stderr
  int shard = 1, shards = 1;         // execute run i (0-based, plan order) iff i % shards == shard - 1
  int jobs = -1;                     // runs at once; -1 = experiment.jobs; 0 = hardware threads
  bool plots = true;                 // false: skip plot_results.py (--no-plots)
  // The first SIGINT/SIGTERM also cancels the runs in progress (solvers/cancel.h)
  // instead of letting them finish; they are marked interrupted like the runs
  // not started. For callers that cannot wait (the Python module's Ctrl-C).
  bool cancel_on_signal = false;
};

struct RunSummary {
  std::string out_dir;
  size_t planned = 0;      // runs in the whole plan
  size_t in_shard = 0;     // runs of this shard
  size_t executed = 0;     // computed now (including redone ones)
  size_t cached = 0;       // reused from runs/<id>/
  size_t redone = 0;       // incomplete folders (no DONE) computed again
  size_t failed = 0;
  size_t cached_other_build = 0;  // cached runs made by another git commit (or none recorded), warned about
  std::vector<std::string> run_ids;  // this shard's runs, plan order
  OutputFiles files;       // empty for a dry run
};

// Prints the "results: ..." and "report: ..." lines of a written folder.
void print_output_paths(std::ostream& out, const OutputFiles& f);

// Parses "K/N" with 1 <= K <= N; throws std::invalid_argument naming --shard.
void parse_shard(const std::string& text, int& k, int& n);

// Loads the config, applies overrides, validates (ConfigError before any
// work), runs, writes the folder. `out` receives the dry-run listing and the
// final "results: ..." lines, `err` the progress. Throws std::runtime_error
// after writing the outputs when a run failed (the failed rows are marked).
RunSummary run_experiment(const RunOptions& opt, std::ostream& out, std::ostream& err);

// Collates shard folders into one experiment folder (`merge`): every shard of
// one plan (same plan hash and shard count), each shard once, every planned
// run present and done exactly once. Throws std::invalid_argument naming the
// missing or duplicated runs and shards before writing anything.
RunSummary merge_experiments(const std::vector<std::string>& dirs, const std::string& out_dir,
                             bool quiet, bool plots, std::ostream& out, std::ostream& err);

}  // namespace bf
