// libFuzzer target: a shard's manifest.json as `merge` reads it
// (experiments/report/outputs.h read_experiment_manifest, then merge_experiments
// into a fresh folder). Oracle beyond crashes: every run id the reader
// accepts is a plain name, and the merge writes nothing outside its folders
// (a marker file next to them must survive).
#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "brdfs/safe_path.h"
#include "experiments/report/outputs.h"
#include "experiments/run/runner.h"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const fs::path root = fs::temp_directory_path() / ("bf_fuzz_merge_" + std::to_string(::getpid()));
  static const fs::path shard = root / "a" / "b" / "shard";
  static const fs::path out = root / "a" / "b" / "out";
  static const fs::path marker = root / "a" / "marker";
  static bool init = [] {
    fs::create_directories(shard);
    std::ofstream(marker) << "marker";
    return true;
  }();
  (void)init;
  std::error_code ec;
  fs::remove_all(out, ec);
  {
    std::ofstream f(shard / "manifest.json", std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const bf::ExperimentOutput e = bf::read_experiment_manifest(shard.string());
    for (const auto& r : e.runs)
      if (!bf::is_plain_name(r.run_id)) std::abort();
  } catch (const std::exception&) {
  }
  try {
    std::ostringstream o, err;
    bf::merge_experiments({shard.string()}, out.string(), true, false, o, err);
  } catch (const std::exception&) {
  }
  if (!fs::exists(marker)) std::abort();  // something outside the folders was deleted
  return 0;
}
