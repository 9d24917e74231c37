// Subcommand export-merl: tabulate any catalogue BRDF or measured file as a
// MERL .binary table (brdfs/merl.h), written atomically.
#include <iostream>
#include <memory>

#include "brdfs/catalogue.h"
#include "brdfs/merl.h"
#include "experiments/cli/commands.h"

namespace bf {

void add_cmd_export_merl(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export-merl",
      "Tabulate a BRDF as a MERL .binary file (90x90x180 half/diff bins, float64 RGB)");
  auto spec = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  cmd->add_option("--brdf", *spec,
                  "catalogue name[:k=v,...] or measured file (.astm, .brdf, .csv, .binary)")
      ->required();
  cmd->add_option("--out", *out, "output file (34,992,012 bytes; written via a unique temporary + rename)")
      ->required();
  cmd->callback([=] {
    // Everything that can fail on the input happens before anything is written.
    const BrdfPtr b = Catalogue::builtin().make(*spec);
    MerlTabulateStats st;
    const MerlTable table = merl_tabulate(*b, &st);
    write_merl(table, *out);
    std::cerr << "export-merl: wrote " << *out << " (" << st.cells << " cells, " << st.below_horizon
              << " below the horizon and " << st.invalid
              << " with invalid values stored as missing) from " << b->to_string() << "\n";
  });
}

}  // namespace bf
