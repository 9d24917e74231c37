// See sampling_run.h.
#include "experiments/run/sampling_run.h"

#include <chrono>

#include "experiments/common/cli_util.h"
#include "factor/sampling.h"
#include "factor/sampling_export.h"

namespace bf {

void run_sampling(const Brdf& result, bool fitted_isotropic, bool export_files, const std::filesystem::path& run_dir,
                  Row& row, nlohmann::json& record) {
  SamplerOptions o;
  o.method = "tabulated";
  if (fitted_isotropic) o.view_phi_bins = 1;
  const auto t0 = std::chrono::steady_clock::now();
  const auto s = make_sampler(result, o);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row["sampler_storage"] = std::to_string(s->storage_floats());
  row["sampler_build_s"] = format_number(seconds);
  const SamplerTable& t = *sampler_table(*s);
  nlohmann::json entry = sampling_entry(t, "sampling.exr", "sampling.glsl");
  entry.erase("file"), entry.erase("glsl");  // nothing written without export
  if (export_files) {
    entry = write_sampling_export(*s, run_dir.string());
    write_file_atomic((run_dir / "sampling.json").string(),
                      [&](std::ostream& out) { out << entry.dump(2) << "\n"; });
  }
  entry["build_seconds"] = seconds;
  record["sampling"] = entry;
}

}  // namespace bf
