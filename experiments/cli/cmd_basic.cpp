// Subcommands list, eval and sample.
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "brdfs/catalogue.h"
#include "brdfs/sample_csv.h"
#include "brdfs/sampleset.h"
#include "experiments/common/cli_util.h"
#include "experiments/cli/commands.h"
#include "experiments/methods/method_kind.h"

namespace bf {

void add_cmd_list(CLI::App& app) {
  auto* cmd = app.add_subcommand("list", "List the catalogue: models with parameters and "
                                         "defaults, presets, measured-file formats; `list methods`: "
                                         "the method kinds and their keys (markdown)");
  auto what = std::make_shared<std::string>();
  cmd->add_option("what", *what, "methods: the key tables of every method kind")
      ->check(CLI::IsMember({"methods"}));
  cmd->callback([what] {
    if (*what == "methods") {
      std::cout << method_key_tables();
      return;
    }
    const Catalogue& cat = Catalogue::builtin();
    std::cout << "Models:\n";
    for (const auto& [name, m] : cat.models()) {
      std::cout << "  " << name << "\n      " << m.description << "\n";
      for (const auto& p : m.params)
        std::cout << "      " << std::left << std::setw(12) << p.name << " = " << std::setw(10)
                  << p.default_value << "  " << p.doc << "\n";
    }
    std::cout << "Presets:\n";
    for (const auto& [name, p] : cat.presets())
      std::cout << "  " << std::left << std::setw(36) << name << " " << p.model << " ("
                << p.source << ")\n";
    std::cout << "Measured files (--brdf PATH):";
    for (const auto& e : cat.loader_extensions()) std::cout << " " << e;
    std::cout << "\n";
  });
}

void add_cmd_eval(CLI::App& app) {
  auto* cmd = app.add_subcommand("eval", "Print one BRDF value (R G B, 1/sr) for given directions");
  auto spec = std::make_shared<std::string>();
  auto wi = std::make_shared<std::string>();
  auto wo = std::make_shared<std::string>();
  cmd->add_option("--brdf", *spec, "catalogue name[:k=v,...] or measured file")->required();
  cmd->add_option("--wi", *wi, "light direction x,y,z (local frame, normalized)")->required();
  cmd->add_option("--wo", *wo, "view direction x,y,z (local frame, normalized)")->required();
  cmd->callback([=] {
    const BrdfPtr b = Catalogue::builtin().make(*spec);
    const Rgb f = b->eval(parse_direction(*wi, "--wi"), parse_direction(*wo, "--wo"));
    // Parameters validation accepts can still overflow double arithmetic
    // (Cook-Torrance m = 1e-200: m^2 is 0): never print inf or nan.
    if (!f.isFinite().all()) {
      std::ostringstream v;
      v << f[0] << " " << f[1] << " " << f[2];
      throw std::invalid_argument("eval: --brdf " + *spec + " at --wi " + *wi + " --wo " + *wo +
                                  ": expected a finite value, found " + v.str() +
                                  " (the parameters are outside what double precision can evaluate)");
    }
    std::cout << std::setprecision(10) << f[0] << " " << f[1] << " " << f[2] << "\n";
  });
}

void add_cmd_sample(CLI::App& app) {
  auto* cmd = app.add_subcommand("sample", "Write a SampleSet of a BRDF as sample-list CSV");
  auto spec = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto grid = std::make_shared<int>(0);
  auto count = std::make_shared<long long>(0);
  auto seed = std::make_shared<unsigned long long>(1);
  cmd->add_option("--brdf", *spec, "catalogue name[:k=v,...] or measured file")->required();
  cmd->add_option("--out", *out, "output CSV path")->required();
  cmd->add_option("--grid", *grid, "regular res^4 parabolic grid (e.g. 16)");
  cmd->add_option("--stratified", *count, "number of stratified random pairs");
  cmd->add_option("--seed", *seed, "seed for --stratified")
      ->check(non_negative_integer())
      ->capture_default_str();
  cmd->callback([=] {
    if ((*grid > 0) == (*count > 0))
      throw std::invalid_argument("sample: give exactly one of --grid N or --stratified COUNT");
    const BrdfPtr b = Catalogue::builtin().make(*spec);
    const SampleSet s = *grid > 0 ? sample_grid(*b, *grid)
                                  : sample_stratified(*b, static_cast<size_t>(*count), *seed);
    write_sample_csv(s, *out);
    std::cerr << "sample: wrote " << s.summary() << " to " << *out << "\n";
  });
}

}  // namespace bf
