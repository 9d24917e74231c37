// Output-folder checks before an experiment runs (see preflight.h).
#include "experiments/run/preflight.h"

#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <vector>

#include "experiments/plan/plan.h"
#include "experiments/methods/method_kind.h"
#include "experiments/report/viewer.h"

namespace bf {

namespace fs = std::filesystem;

namespace {

std::string human(uint64_t bytes) {
  char buf[64];
  if (bytes >= (uint64_t(1) << 30)) std::snprintf(buf, sizeof buf, "%.1f GiB", bytes / double(uint64_t(1) << 30));
  else std::snprintf(buf, sizeof buf, "%.1f MiB", bytes / double(uint64_t(1) << 20));
  return std::to_string(bytes) + " bytes (" + buf + ")";
}

uint64_t samples_of(const SamplingVariant& s) {
  if (s.kind == "grid") return uint64_t(s.resolution) * s.resolution * s.resolution * s.resolution;
  if (s.kind == "stratified") return s.count;
  if (s.kind == "file") {
    std::error_code ec;
    const auto n = fs::file_size(s.path, ec);
    return ec ? 0 : uint64_t(n) * 4 / 96;
  }
  return 0;  // measured: the file's own (small) sample count
}

}  // namespace

uint64_t estimate_output_bytes(const Plan& plan, const std::vector<bool>& todo) {
  uint64_t bytes = uint64_t(1) << 20;
  std::set<std::string> sample_sets;
  for (size_t i = 0; i < plan.runs.size() && i < todo.size(); ++i) {
    if (!todo[i]) continue;
    const PlannedRun& r = plan.runs[i];
    const MethodVariant& m = plan.methods[r.method];
    const uint64_t t = uint64_t(std::max(m.texture_size, 1));
    bytes += (uint64_t(64) << 10) + uint64_t(std::max(m.terms, 1)) * t * t * 3 * 4 * 2;
    if (sample_sets.insert(r.samples_key).second) bytes += samples_of(plan.samplings[r.sampling]) * 96;
    // The kind's own exports, and the viewer's tabulation of the original (1 MB base64).
    if (plan.experiment.export_factors) {
      bytes += m.impl->export_bytes(m);
      if (plan.experiment.render && m.impl->has_viewer()) {
        bytes += uint64_t(kViewerTableRes) * kViewerTableRes * kViewerTableRes * kViewerTableRes * 3 * 4 * 4 / 3 +
                 (uint64_t(64) << 10);
        if (plan.scene.lighting) bytes += uint64_t(kViewerEnvWidth) * (kViewerEnvWidth / 2) * 3 * 4 * 4 / 3 + (uint64_t(64) << 10);
      }
    }
  }
  return bytes;
}

void check_output_folder(const std::string& dir, uint64_t needed) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir, ec))
    throw std::runtime_error(dir + ": cannot create the output folder: " +
                             (ec ? ec.message() : std::string("exists and is not a folder")));
  // Write access: a real probe (access(2) says yes to root even on a 0555 folder
  // of a read-only mount; creating a file tells the truth).
  const fs::path probe = fs::path(dir) / (".write-probe-" + std::to_string(::getpid()));
  if (FILE* f = std::fopen(probe.c_str(), "wb")) {
    const bool ok = std::fputc('x', f) != EOF;
    const int close_rc = std::fclose(f);
    const int err = errno;
    fs::remove(probe, ec);
    if (!ok || close_rc != 0)
      throw std::runtime_error(dir + ": the output folder is not writable: writing a test file failed: " +
                               std::strerror(err));
  } else {
    throw std::runtime_error(dir + ": the output folder is not writable: cannot create a file in it: " +
                             std::strerror(errno));
  }

  uint64_t free_bytes = 0;
  std::string source = "free";
  if (const char* fake = std::getenv("BF_FAKE_FREE_BYTES"); fake && *fake) {
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(fake, &end, 10);
    if (*end != '\0' || errno != 0 || fake[0] == '-')
      throw std::invalid_argument("BF_FAKE_FREE_BYTES: expected a number of bytes, found '" + std::string(fake) + "'");
    free_bytes = v;
    source = "free (BF_FAKE_FREE_BYTES)";
  } else {
    struct statvfs st {};
    if (::statvfs(dir.c_str(), &st) != 0) return;  // cannot tell: do not block the run
    free_bytes = uint64_t(st.f_bavail) * uint64_t(st.f_frsize);
  }
  if (free_bytes < needed)
    throw std::runtime_error(dir + ": not enough free space for the experiment's outputs: needs about " +
                             human(needed) + ", found " + human(free_bytes) + " " + source +
                             " (estimate: docs/robustness.md, 'Nothing lost')");
}

}  // namespace bf
