// The brdf-factor subcommands: each add_cmd_* registers one subcommand (its
// options and the callback that runs it) on the CLI11 app. Callbacks throw on
// error; main() turns any exception into a one-line message and exit code 2.
#pragma once

#include <CLI/CLI.hpp>

namespace bf {

// The check of every option held in an unsigned type (the seeds): CLI11 2.1
// converts "-1" to 2^64 - 1 without a word, so anything but decimal digits
// is refused by the option's name before conversion.
inline CLI::Validator non_negative_integer() {
  return CLI::Validator(
      [](std::string& s) {
        return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos
                   ? std::string()
                   : "expected a non-negative integer, found " + s;
      },
      "UINT");
}

void add_cmd_list(CLI::App& app);    // cmd_basic.cpp
void add_cmd_eval(CLI::App& app);    // cmd_basic.cpp
void add_cmd_sample(CLI::App& app);  // cmd_basic.cpp
void add_cmd_export_merl(CLI::App& app);  // cmd_export_merl.cpp
void add_cmd_bench(CLI::App& app);   // cmd_bench.cpp
void add_cmd_run(CLI::App& app);     // cmd_run.cpp
void add_cmd_merge(CLI::App& app);   // cmd_merge.cpp
void add_cmd_stress(CLI::App& app);  // cmd_stress.cpp
void add_cmd_sample_dirs(CLI::App& app);  // cmd_sample_dirs.cpp
void add_cmd_compare(CLI::App& app);  // cmd_compare.cpp

}  // namespace bf
