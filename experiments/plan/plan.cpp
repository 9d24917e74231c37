// The plan's types (plan.h): content hashes, the validation seed and the
// scene's identity.
#include "experiments/plan/plan.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "brdfs/file_check.h"
#include "factor/lighting.h"

namespace bf {

using nlohmann::json;

ConfigError::ConfigError(std::vector<std::string> messages)
    : std::invalid_argument([&] {
        std::string s;
        for (size_t i = 0; i < messages.size(); ++i) s += (i ? "\nbrdf-factor: " : "") + messages[i];
        return s;
      }()),
      messages_(std::move(messages)) {}

std::string content_hash(const std::string& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string file_hash(const std::string& path) {
  check_regular_file(path, kMaxImageFileBytes, "");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot read");
  std::ostringstream ss;
  ss << in.rdbuf();
  return content_hash(ss.str());
}

std::string short_hash(const json& j) { return content_hash(j.dump()).substr(0, 12); }

uint64_t validation_seed(uint64_t experiment_seed) {
  // FNV-1a of a fixed tag and the seed: unrelated to the sampling and method
  // seeds (which are experiment.seed itself by default).
  return std::stoull(content_hash("validation:" + std::to_string(experiment_seed)).substr(0, 12), nullptr, 16);
}

uint64_t fill_seed(uint64_t experiment_seed) {
  return std::stoull(content_hash("fill:" + std::to_string(experiment_seed)).substr(0, 12), nullptr, 16);
}


// ------------------------------------------------------------------ keys

nlohmann::json SceneSettings::identity() const {
  nlohmann::json j = {{"light", {light.x(), light.y(), light.z()}}, {"intensity", intensity}, {"size", size},
                      {"shade_rmse", shade}};
  // Only SH-lit scenes carry the lighting (point-lit run ids are unchanged).
  if (lighting) {
    j["lighting"] = {{"source", environment.empty() ? "directional" : "env"},
                     {"digest", environment.empty() ? "" : file_hash(environment)},
                     {"environment_eps", environment_eps},
                     {"lighting_order", lighting_order},
                     {"order", lighting->order},
                     {"nodes", lighting_nodes}};
  }
  return j;
}

}  // namespace bf
