// Subcommand `run`: one experiment from a TOML config (runner.h, docs/experiments.md).
#include <iostream>
#include <memory>

#include "experiments/cli/commands.h"
#include "experiments/run/runner.h"

namespace bf {

void add_cmd_run(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "run", "Run an experiment: every BRDF x sampling x method (sweeps expanded) of a TOML config; "
             "writes results.csv, results.md, manifest.json, report.html and runs/<run_id>/");
  auto o = std::make_shared<RunOptions>();
  auto shard = std::make_shared<std::string>("1/1");
  auto no_plots = std::make_shared<bool>(false);
  cmd->add_option("config", o->config, "experiment config (TOML; keys in docs/experiments.md)")->required();
  cmd->add_option("--out", o->out, "output folder (default: experiment.out; with --shard, "
                                   "experiment.out/shard-K-of-N)");
  cmd->add_option("-D,--define", o->defines,
                  "override a config value: section.key=value, method.key=value (every method that "
                  "accepts key), method[N].key=value (N from 0); value in TOML syntax, else a string")
      ->take_all()
      ->expected(1)
      ->allow_extra_args(false);
  cmd->add_flag("--dry-run", o->dry_run, "list the runs that would execute and those skipped; write nothing");
  cmd->add_flag("--force", o->force, "redo runs (and sampling) even when cached");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress on stderr");
  cmd->add_option("--shard", *shard, "execute the deterministic K-th of N parts of the runs (K/N)")
      ->capture_default_str();
  cmd->add_option("-j,--jobs", o->jobs, "runs at once (0 = hardware threads; default: experiment.jobs)");
  cmd->add_flag("--no-plots", *no_plots, "do not call experiments/report/plot_results.py");
  cmd->callback([o, shard, no_plots] {
    RunOptions opt = *o;
    parse_shard(*shard, opt.shard, opt.shards);
    opt.plots = !*no_plots;
    run_experiment(opt, std::cout, std::cerr);
  });
}

}  // namespace bf
