// The sample cache (see sample_cache.h).
#include "experiments/sample_cache.h"

#include <cstring>
#include <fstream>

#include "brdfs/sample_csv.h"
#include "experiments/cli_util.h"
#if __has_include("brdfs/measured.h")
#include "brdfs/measured.h"
#define BF_HAVE_MEASURED 1
#endif

namespace bf {

namespace fs = std::filesystem;

namespace {

// Binary sample cache: magic, count, flags, then the arrays. Any mismatch on
// reading (size, magic, counts) makes the cache entry unusable (resampled).
constexpr char kSampleMagic[8] = {'B', 'F', 'S', 'A', 'M', 'P', '0', '1'};

}  // namespace

void write_samples_bin(const SampleSet& s, const std::string& path) {
  write_file_atomic(path, [&](std::ostream& o) {
    auto put64 = [&](uint64_t v) { o.write(reinterpret_cast<const char*>(&v), sizeof v); };
    o.write(kSampleMagic, 8);
    const uint64_t n = s.size();
    put64(n);
    put64(s.weight.empty() ? 0 : 1);
    put64(s.invalid_value);
    put64(s.invalid_horizon);
    put64(s.invalid_weight);
    put64(s.description.size());
    o.write(s.description.data(), static_cast<std::streamsize>(s.description.size()));
    for (const auto* arr : {&s.wi, &s.wo})
      for (const Vec3& v : *arr) o.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(double));
    for (const Rgb& v : s.value) o.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(double));
    if (!s.weight.empty()) o.write(reinterpret_cast<const char*>(s.weight.data()), n * sizeof(double));
    o.write(reinterpret_cast<const char*>(s.valid.data()), static_cast<std::streamsize>(n));
  });
}

bool read_samples_bin(const std::string& path, SampleSet& s) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::error_code ec;
  const uint64_t file_size = fs::file_size(path, ec);
  if (ec) return false;
  char magic[8];
  if (!in.read(magic, 8) || std::memcmp(magic, kSampleMagic, 8) != 0) return false;
  uint64_t h[6];
  if (!in.read(reinterpret_cast<char*>(h), sizeof h)) return false;
  const uint64_t n = h[0], has_w = h[1], dlen = h[5];
  if (n > 200'000'000 || has_w > 1 || dlen > 1'000'000) return false;
  const uint64_t expect = 8 + sizeof h + dlen + n * (9 * sizeof(double) + (has_w ? sizeof(double) : 0) + 1);
  if (expect != file_size) return false;
  s = SampleSet{};
  s.description.resize(dlen);
  in.read(s.description.data(), static_cast<std::streamsize>(dlen));
  s.wi.resize(n);
  s.wo.resize(n);
  s.value.resize(n);
  for (auto* arr : {&s.wi, &s.wo})
    for (Vec3& v : *arr) in.read(reinterpret_cast<char*>(v.data()), 3 * sizeof(double));
  for (Rgb& v : s.value) in.read(reinterpret_cast<char*>(v.data()), 3 * sizeof(double));
  if (has_w) {
    s.weight.resize(n);
    in.read(reinterpret_cast<char*>(s.weight.data()), n * sizeof(double));
  }
  s.valid.resize(n);
  in.read(reinterpret_cast<char*>(s.valid.data()), static_cast<std::streamsize>(n));
  if (!in) return false;
  s.invalid_value = h[2];
  s.invalid_horizon = h[3];
  s.invalid_weight = h[4];
  return true;
}

std::shared_ptr<const SampleSet> make_samples(const Plan& plan, const PlannedRun& r, const fs::path& cache_dir,
                                              bool force, bool* from_cache) {
  const BrdfVariant& b = plan.brdfs[r.brdf];
  const SamplingVariant& s = plan.samplings[r.sampling];
  *from_cache = false;
  auto out = std::make_shared<SampleSet>();
  if (s.kind == "file") {
    *out = read_sample_csv(s.path);
    return out;
  }
  if (s.kind == "measured") {
#ifdef BF_HAVE_MEASURED
    *out = measured_samples(*b.brdf);
    return out;
#else
    throw std::invalid_argument("sampling: measured samples are not available in this build");
#endif
  }
  const fs::path path = cache_dir / (r.samples_key + ".bin");
  if (!force && read_samples_bin(path.string(), *out)) {
    *from_cache = true;
    return out;
  }
  if (s.kind == "grid") *out = sample_grid(*b.brdf, s.resolution);
  else *out = sample_stratified(*b.brdf, s.count, s.seed);
  write_samples_bin(*out, path.string());
  return out;
}

}  // namespace bf
