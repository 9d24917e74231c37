// The sample cache (see sample_cache.h).
#include "experiments/run/sample_cache.h"

#include <cmath>
#include <cstring>
#include <fstream>

#include "brdfs/sample_csv.h"
#include "experiments/common/cli_util.h"
#include "experiments/run/file_integrity.h"
#if __has_include("brdfs/measured.h")
#include "brdfs/measured.h"
#define BF_HAVE_MEASURED 1
#endif

namespace bf {

namespace fs = std::filesystem;

namespace {

// Binary sample cache (docs/design.md §5.4): magic, six counts, the
// description, the arrays, then the 64-bit FNV-1a of every byte before it.
constexpr char kSampleMagic[8] = {'B', 'F', 'S', 'A', 'M', 'P', '0', '2'};
constexpr char kOldSampleMagic[8] = {'B', 'F', 'S', 'A', 'M', 'P', '0', '1'};
constexpr uint64_t kHeaderBytes = 8 + 6 * sizeof(uint64_t);

// Well-formed UTF-8 without control characters (the description goes into
// run.json and the tables).
bool printable_utf8(const std::string& s) {
  for (size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7f) return false;
      ++i;
      continue;
    }
    const int len = c >= 0xf0 && c <= 0xf4 ? 4 : c >= 0xe0 ? 3 : c >= 0xc2 && c < 0xe0 ? 2 : 0;
    if (!len || i + len > s.size()) return false;
    for (int k = 1; k < len; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xc0) != 0x80) return false;
    i += len;
  }
  return true;
}

// What is wrong with a decoded sample set, or "" when nothing is: every
// direction finite and of unit length, the flags and masked counts exactly
// what SampleSet::validate() derives from the data (so a valid sample has
// directions above the horizon, finite non-negative values and weights).
std::string check_decoded(const SampleSet& s) {
  for (size_t k = 0; k < s.size(); ++k)
    for (const Vec3* w : {&s.wi[k], &s.wo[k]})
      if (!w->allFinite() || !(std::abs(w->norm() - 1.0) <= 1e-9))
        return "sample " + std::to_string(k) + ": expected unit directions, found (" + std::to_string(w->x()) + ", " +
               std::to_string(w->y()) + ", " + std::to_string(w->z()) + ")";
  SampleSet check;
  check.wi = s.wi;
  check.wo = s.wo;
  check.value = s.value;
  check.weight = s.weight;
  check.validate();
  for (size_t k = 0; k < s.size(); ++k)
    if (check.valid[k] != s.valid[k])
      return "sample " + std::to_string(k) + ": valid flag " + std::to_string(int(s.valid[k])) +
             " disagrees with its data (expected " + std::to_string(int(check.valid[k])) + ")";
  if (check.invalid_value != s.invalid_value || check.invalid_horizon != s.invalid_horizon ||
      check.invalid_weight != s.invalid_weight)
    return "the masked counts disagree with the data";
  if (!printable_utf8(s.description)) return "the description is not printable text";
  return "";
}

}  // namespace

void write_samples_bin(const SampleSet& s, const std::string& path) {
  write_file_atomic(path, [&](std::ostream& o) {
    Fnv1a64 h;
    auto put = [&](const void* p, size_t n) {
      h.update(p, n);
      o.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
    };
    auto put64 = [&](uint64_t v) { put(&v, sizeof v); };
    put(kSampleMagic, 8);
    const uint64_t n = s.size();
    put64(n);
    put64(s.weight.empty() ? 0 : 1);
    put64(s.invalid_value);
    put64(s.invalid_horizon);
    put64(s.invalid_weight);
    put64(s.description.size());
    put(s.description.data(), s.description.size());
    for (const auto* arr : {&s.wi, &s.wo})
      for (const Vec3& v : *arr) put(v.data(), 3 * sizeof(double));
    for (const Rgb& v : s.value) put(v.data(), 3 * sizeof(double));
    if (!s.weight.empty()) put(s.weight.data(), n * sizeof(double));
    put(s.valid.data(), n);
    const uint64_t digest = h.value();
    o.write(reinterpret_cast<const char*>(&digest), sizeof digest);
  });
}

SampleCacheRead read_samples_bin(const std::string& path, SampleSet& s) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  if (st.type() == fs::file_type::not_found) return {false, ""};
  if (st.type() != fs::file_type::regular) return {false, "expected a regular file, found " + describe_file_type(path)};
  const uint64_t file_size = fs::file_size(path, ec);
  if (ec) return {false, "cannot read its size: " + ec.message()};
  std::ifstream in(path, std::ios::binary);
  if (!in) return {false, "cannot open"};
  Fnv1a64 h;
  auto get = [&](void* p, size_t n) {
    if (!in.read(static_cast<char*>(p), static_cast<std::streamsize>(n))) return false;
    h.update(p, n);
    return true;
  };
  char magic[8];
  if (file_size < kHeaderBytes + sizeof(uint64_t) || !get(magic, 8))
    return {false, std::to_string(file_size) + " bytes, too short for a sample cache (truncated)"};
  if (std::memcmp(magic, kOldSampleMagic, 8) == 0)
    return {false, "an older format without a content hash"};
  if (std::memcmp(magic, kSampleMagic, 8) != 0) return {false, "not a sample cache (its first bytes are not BFSAMP02)"};
  uint64_t hd[6];
  if (!get(hd, sizeof hd)) return {false, "truncated header"};
  const uint64_t n = hd[0], has_w = hd[1], dlen = hd[5];
  if (n > 200'000'000 || has_w > 1 || dlen > 1'000'000)
    return {false, "implausible counts (" + std::to_string(n) + " samples, weights " + std::to_string(has_w) +
                       ", description of " + std::to_string(dlen) + " bytes)"};
  const uint64_t expect =
      kHeaderBytes + dlen + n * (9 * sizeof(double) + (has_w ? sizeof(double) : 0) + 1) + sizeof(uint64_t);
  if (expect != file_size)
    return {false, std::to_string(file_size) + " bytes where its counts call for " + std::to_string(expect) +
                       (file_size < expect ? " (truncated)" : "")};
  SampleSet r;
  r.description.resize(dlen);
  r.wi.resize(n);
  r.wo.resize(n);
  r.value.resize(n);
  bool ok = get(r.description.data(), dlen);
  for (auto* arr : {&r.wi, &r.wo})
    for (Vec3& v : *arr) ok = ok && get(v.data(), 3 * sizeof(double));
  for (Rgb& v : r.value) ok = ok && get(v.data(), 3 * sizeof(double));
  if (has_w) {
    r.weight.resize(n);
    ok = ok && get(r.weight.data(), n * sizeof(double));
  }
  r.valid.resize(n);
  ok = ok && get(r.valid.data(), n);
  uint64_t stored = 0;
  if (!ok || !in.read(reinterpret_cast<char*>(&stored), sizeof stored)) return {false, "cannot read (truncated)"};
  if (stored != h.value())
    return {false, "content hash mismatch (recorded " + hex64(stored) + ", computed " + h.hex() + ")"};
  r.invalid_value = hd[2];
  r.invalid_horizon = hd[3];
  r.invalid_weight = hd[4];
  if (std::string why = check_decoded(r); !why.empty()) return {false, "decoded content refused: " + why};
  s = std::move(r);
  return {true, ""};
}

std::shared_ptr<const SampleSet> make_samples(const Plan& plan, const PlannedRun& r, const fs::path& cache_dir,
                                              bool force, bool* from_cache, std::string* problem) {
  const BrdfVariant& b = plan.brdfs[r.brdf];
  const SamplingVariant& s = plan.samplings[r.sampling];
  *from_cache = false;
  if (problem) problem->clear();
  auto out = std::make_shared<SampleSet>();
  if (s.kind == "file") {
    *out = read_sample_csv(s.path);
    return out;
  }
  if (s.kind == "measured") {
#ifdef BF_HAVE_MEASURED
    // weights (config): "auto" = a MERL table's cells by their measure.
    const bool measure = s.weights == "measure" || (s.weights == "auto" && has_cell_measure(*b.brdf));
    try {
      *out = measured_samples(*b.brdf, measure);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(s.where + ": sampling.weights: " + e.what());
    }
    return out;
#else
    throw std::invalid_argument("sampling: measured samples are not available in this build");
#endif
  }
  const fs::path path = cache_dir / (r.samples_key + ".bin");
  if (!force) {
    SampleCacheRead got = read_samples_bin(path.string(), *out);
    if (got.ok) {
      // The count the sampling makes (a cache of another size is not this one).
      const uint64_t want = s.kind == "grid" ? [&] {
        const size_t d = grid_directions(s.resolution).size();
        return uint64_t(d) * d;
      }() : s.count;
      if (out->size() == want) {
        // The declaration is the BRDF's, not the file's (as sample_grid sets it).
        out->symmetries = symmetries_of(*b.brdf);
        *from_cache = true;
        return out;
      }
      got.problem = "holds " + std::to_string(out->size()) + " samples, the sampling makes " + std::to_string(want);
    }
    if (!got.problem.empty() && problem) *problem = path.string() + ": " + got.problem;
  }
  if (s.kind == "grid") *out = sample_grid(*b.brdf, s.resolution);
  else *out = sample_stratified(*b.brdf, s.count, s.seed);
  write_samples_bin(*out, path.string());
  return out;
}

}  // namespace bf
