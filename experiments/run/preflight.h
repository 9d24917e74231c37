// Checks made before an experiment starts any run (docs/robustness.md, "Nothing
// lost"): the output folder can be created and written, and its file system
// has room for an estimate of what the runs will write. Each failure throws
// std::runtime_error naming the folder, so no compute is spent on results that
// could not be saved.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bf {

struct Plan;

// Bytes an experiment is expected to write for the runs it will do:
//   1 MiB (results.csv/md, manifest, report.html, plots)
// + per run to do: 64 KiB (run.json, sidecar, sphere renders)
//                  + terms x texture_size^2 x 3 channels x 4 bytes x 2 (EXR textures, slack)
// + per sample set to build: samples x 96 bytes (binary cache; grid: res^4 pairs,
//   stratified: count, file: 4 x the CSV's size).
// `todo[i]` says whether plan.runs[i] will be executed.
uint64_t estimate_output_bytes(const Plan& plan, const std::vector<bool>& todo);

// Creates `dir` if needed, checks a file can be created in it, and that its file
// system has at least `needed` bytes available (statvfs f_bavail x f_frsize).
// The environment variable BF_FAKE_FREE_BYTES, when set to a number, replaces
// the measured free space (tests of the disk-full path).
void check_output_folder(const std::string& dir, uint64_t needed);

}  // namespace bf
