// The sample cache of an experiment folder (cache/samples/<key>.bin): the
// samples of a (BRDF, sampling) pair, computed once and shared by its runs.
#pragma once

#include <filesystem>
#include <memory>

#include "brdfs/sampleset.h"
#include "experiments/config.h"

namespace bf {

// Writes s in the cache's binary format (atomically).
void write_samples_bin(const SampleSet& s, const std::string& path);
// Reads a cache entry; false when it is missing or unusable (size, magic, counts).
bool read_samples_bin(const std::string& path, SampleSet& s);
// The samples of run r: read from a file or the measured BRDF, or from the
// cache (*from_cache = true), else sampled and cached. force: resample.
std::shared_ptr<const SampleSet> make_samples(const Plan& plan, const PlannedRun& r,
                                              const std::filesystem::path& cache_dir, bool force, bool* from_cache);

}  // namespace bf
