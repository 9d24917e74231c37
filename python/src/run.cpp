// Experiment configs from Python: brdf_factor._core.run_experiment wraps
// bf::run_experiment (experiments/run/runner.h) exactly as `brdf-factor run` calls it.
#include <iostream>
#include <sstream>

#include "common.h"
#include "experiments/run/runner.h"

namespace bf::py_module {

void bind_run(py::module_& m) {
  m.def(
      "run_experiment",
      [](const std::string& config, const std::vector<std::string>& defines, const std::string& out, bool dry_run,
         bool force, bool quiet, const std::string& shard, int jobs, bool plots) {
        RunOptions o;
        o.config = config;
        o.defines = defines;
        o.out = out;
        o.dry_run = dry_run;
        o.force = force;
        o.quiet = quiet;
        parse_shard(shard, o.shard, o.shards);
        o.jobs = jobs;
        o.plots = plots;
        // Ctrl-C cancels the runs in progress too (a notebook cannot wait for
        // them); bf::Interrupted then raises KeyboardInterrupt.
        o.cancel_on_signal = true;
        std::ostringstream listing;
        RunSummary s;
        {
          LongCall long_call;
          s = run_experiment(o, listing, std::cerr);
        }
        py::dict files;
        files["results_csv"] = s.files.results_csv;
        files["results_md"] = s.files.results_md;
        files["manifest"] = s.files.manifest;
        files["report"] = s.files.report;
        files["plots"] = s.files.plots;
        files["plots_note"] = s.files.plots_note;
        py::dict d;
        d["out_dir"] = s.out_dir;
        d["planned"] = s.planned;
        d["in_shard"] = s.in_shard;
        d["executed"] = s.executed;
        d["cached"] = s.cached;
        d["redone"] = s.redone;
        d["failed"] = s.failed;
        d["cached_other_build"] = s.cached_other_build;
        d["run_ids"] = s.run_ids;
        d["files"] = files;
        d["output"] = listing.str();
        return d;
      },
      py::arg("config"), py::arg("defines") = std::vector<std::string>{}, py::arg("out") = "",
      py::arg("dry_run") = false, py::arg("force") = false, py::arg("quiet") = true, py::arg("shard") = "1/1",
      py::arg("jobs") = -1, py::arg("plots") = true,
      "bf::run_experiment as `brdf-factor run` calls it; returns the summary as a dict. Use brdf_factor.run().");
}

}  // namespace bf::py_module
