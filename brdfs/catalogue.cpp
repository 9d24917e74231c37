// Catalogue implementation (see catalogue.h).
#include "brdfs/catalogue.h"

#include "brdfs/file_check.h"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace bf {

Catalogue& Catalogue::global() {
  static Catalogue cat = [] {
    Catalogue c;
    register_analytic_models(c);
    register_presets(c);
    register_measured_loaders(c);
    return c;
  }();
  return cat;
}

void Catalogue::add_model(ModelInfo m) {
  const std::string n = m.name;
  models_[n] = std::move(m);
}
void Catalogue::add_preset(PresetInfo p) {
  const std::string n = p.name;
  presets_[n] = std::move(p);
}
void Catalogue::add_loader(const std::string& ext, FileLoader l) { loaders_[ext] = std::move(l); }

std::vector<std::string> Catalogue::loader_extensions() const {
  std::vector<std::string> e;
  for (const auto& [k, v] : loaders_) e.push_back(k);
  return e;
}

namespace {
std::string extension_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return path.substr(dot);
}
}  // namespace

bool Catalogue::is_file_spec(const std::string& spec) const {
  const std::string path = spec.substr(0, spec.find(':'));
  return loaders_.count(extension_of(path)) != 0;
}

BrdfPtr Catalogue::load_file(const std::string& path, ParamDict& options) const {
  const std::string ext = extension_of(path);
  auto it = loaders_.find(ext);
  if (it == loaders_.end()) {
    std::string acc;
    for (const auto& e : loader_extensions()) acc += (acc.empty() ? "" : ", ") + e;
    throw std::invalid_argument(path + ": unknown measured-file extension '" + ext +
                                "' (accepted: " + acc + ")");
  }
  check_regular_file(path, kMaxDataFileBytes, "");
  // A file may name another file (a model fit's spec); a chain that comes
  // back to a file being loaded, or is deeper than kMaxFileNesting, is an
  // error instead of unbounded recursion.
  thread_local std::vector<std::string> loading;
  std::error_code ec;
  std::string key = std::filesystem::weakly_canonical(path, ec).string();
  if (ec) key = path;
  std::string chain;
  for (const auto& p : loading) chain += p + " -> ";
  for (const auto& p : loading)
    if (p == key)
      throw std::invalid_argument(path + ": refers back to a file being loaded (" + chain + key + ")");
  if (loading.size() >= kMaxFileNesting)
    throw std::invalid_argument(path + ": files name each other more than " + std::to_string(kMaxFileNesting) +
                                " deep (" + chain + key + ")");
  loading.push_back(key);
  struct Pop {
    std::vector<std::string>& v;
    ~Pop() { v.pop_back(); }
  } pop{loading};
  return it->second(path, options);
}

BrdfPtr Catalogue::make(const std::string& spec, const std::string& origin) const {
  if (spec.empty()) throw std::invalid_argument(origin + ": empty BRDF name");
  const auto colon = spec.find(':');
  const std::string name = spec.substr(0, colon);
  ParamDict params(origin);
  if (colon != std::string::npos) params.parse_assignments(spec.substr(colon + 1));
  if (is_file_spec(spec)) return load_file(name, params);
  return make(name, params);
}

BrdfPtr Catalogue::make(const std::string& name, ParamDict& params) const {
  std::string model_name = name;
  auto pit = presets_.find(name);
  if (pit != presets_.end()) {
    // Preset values fill in whatever the caller did not set explicitly.
    ParamDict preset(params.origin());
    preset.parse_assignments(pit->second.params);
    params.merge_defaults_from(preset);
    model_name = pit->second.model;
  }
  auto mit = models_.find(model_name);
  if (mit == models_.end()) {
    std::string acc;
    for (const auto& [k, v] : models_) acc += (acc.empty() ? "" : ", ") + k;
    throw std::invalid_argument(params.origin() + ": unknown BRDF '" + name +
                                "' (models: " + acc +
                                "; presets: see `brdf-factor list`; or a file ending in " +
                                [&] {
                                  std::string e;
                                  for (const auto& x : loader_extensions())
                                    e += (e.empty() ? "" : ", ") + x;
                                  return e;
                                }() +
                                ")");
  }
  BrdfPtr b = mit->second.make(params);
  std::vector<std::string> accepted;
  for (const auto& p : mit->second.params) accepted.push_back(p.name);
  params.check_unused(model_name, accepted);
  return b;
}

std::string data_dir() {
  if (const char* env = std::getenv("BRDF_FACTOR_DATA")) return env;
  return std::string(BRDF_FACTOR_SOURCE_DIR) + "/data";
}

}  // namespace bf
