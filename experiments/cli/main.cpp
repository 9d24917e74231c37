// brdf-factor: the command-line entry point. Subcommands are registered from
// commands.h; every error becomes one line on stderr and exit code 2.
#include <CLI/CLI.hpp>
#include <exception>
#include <new>
#include <iostream>

#include "brdfs/catalogue.h"
#include "experiments/cli/commands.h"
#include "experiments/run/interrupt.h"
#include "factor/export.h"

namespace bf {
void add_cmd_mc_variance(CLI::App& app);  // cmd_mc_variance.cpp
}

int main(int argc, char** argv) {
  CLI::App app{"brdf-factor: BRDF factorization toolkit (homomorphic fits, projection search, "
               "SVD and SH baselines)"};
  app.require_subcommand(1);
  app.get_formatter()->column_width(36);
  bf::add_cmd_list(app);
  bf::add_cmd_eval(app);
  bf::add_cmd_sample(app);
  bf::add_cmd_export_merl(app);
  bf::add_cmd_bench(app);
  bf::add_cmd_run(app);
  bf::add_cmd_merge(app);
  bf::add_cmd_stress(app);
  bf::add_cmd_sample_dirs(app);
  bf::add_cmd_mc_variance(app);
  bf::add_cmd_compare(app);
  try {
    bf::register_export_loader(bf::Catalogue::global());
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "brdf-factor: " << e.what() << " (see brdf-factor --help)\n";
    return 2;
  } catch (const bf::Interrupted& e) {
    std::cerr << "brdf-factor: " << e.what() << "\n";
    return 128 + e.signal();
  } catch (const std::bad_alloc&) {
    std::cerr << "brdf-factor: out of memory: the input asks for more memory than this machine has "
                 "(the bounds are in docs/robustness.md)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "brdf-factor: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
