// Subcommand `merge`: collate shard folders of one experiment (runner.h).
#include <iostream>
#include <memory>

#include "experiments/cli/commands.h"
#include "experiments/run/runner.h"

namespace bf {

void add_cmd_merge(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "merge", "Collate the shard folders of `run --shard K/N` into one experiment folder, checking that "
               "every run is present exactly once");
  auto dirs = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  auto no_plots = std::make_shared<bool>(false);
  cmd->add_option("dirs", *dirs, "shard folders (each written by run --shard K/N)")->required();
  cmd->add_option("--out", *out, "merged experiment folder (new, or a previous merge)")->required();
  cmd->add_flag("-q,--quiet", *quiet, "no progress on stderr");
  cmd->add_flag("--no-plots", *no_plots, "do not call experiments/report/plot_results.py");
  cmd->callback([=] { merge_experiments(*dirs, *out, *quiet, !*no_plots, std::cout, std::cerr); });
}

}  // namespace bf
