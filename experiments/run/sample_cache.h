// The sample cache of an experiment folder (cache/samples/<key>.bin): the
// samples of a (BRDF, sampling) pair, computed once and shared by its runs.
#pragma once

#include <filesystem>
#include <memory>

#include "brdfs/sampleset.h"
#include "experiments/plan/plan.h"

namespace bf {

// Writes s in the cache's binary format (atomically), its content hash last.
void write_samples_bin(const SampleSet& s, const std::string& path);

// How reading a cache entry went: ok, or not with `problem` saying why when
// the file exists ("" when it is missing).
struct SampleCacheRead {
  bool ok = false;
  std::string problem;
};
// Reads a cache entry into s (left unchanged unless ok). Refused: a link or
// other non-regular file, a size or magic that is not the format's, a content
// hash that does not match, and decoded content that SampleSet::validate()
// would not have produced (directions not finite and unit, valid flags or
// masked counts that disagree with the data, a description that is not text).
SampleCacheRead read_samples_bin(const std::string& path, SampleSet& s);

// The samples of run r: read from a file or the measured BRDF, or from the
// cache (*from_cache = true), else sampled and cached. force: resample. When
// a cache entry exists but is refused (read_samples_bin, or a sample count
// that is not the sampling's), it is rebuilt and *problem says why, naming
// its path; otherwise *problem is "".
std::shared_ptr<const SampleSet> make_samples(const Plan& plan, const PlannedRun& r,
                                              const std::filesystem::path& cache_dir, bool force, bool* from_cache,
                                              std::string* problem = nullptr);

}  // namespace bf
