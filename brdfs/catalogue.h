// The catalogue: a name -> factory table of BRDF models, named presets, and
// loaders for measured files, so any tool can turn a spec string such as
// "cook-torrance:m=0.2", "bluepaint" or "data/cornell/cayman.astm" into a BRDF.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/params.h"

namespace bf {

struct ParamInfo {
  std::string name;
  std::string default_value;  // as printed by `brdf-factor list`
  std::string doc;
};

struct ModelInfo {
  std::string name;         // e.g. "cook-torrance"
  std::string description;  // formula and source, one paragraph
  std::vector<ParamInfo> params;
  // Builds the model from params (reads keys through the dict; unknown keys are
  // reported by the catalogue afterwards). Throws std::invalid_argument on
  // out-of-range values, naming the key, value and rule.
  std::function<BrdfPtr(const ParamDict&)> make;
};

struct PresetInfo {
  std::string name;    // e.g. "bluepaint", "ngan-ward/blue-acrylic"
  std::string model;   // model name
  std::string params;  // "k=v,..." assignments, as parse_assignments reads them
  std::string source;  // where the numbers come from
};

// Loader for a measured file, selected by extension (".astm", ".binary", ...).
using FileLoader = std::function<BrdfPtr(const std::string& path, const ParamDict& options)>;

class Catalogue {
 public:
  // The catalogue with every built-in model, preset and loader registered.
  static const Catalogue& builtin() { return global(); }
  // The same process-wide catalogue, for registering loaders that live in
  // libraries brdfs/ must not depend on (the factorization .json loader of
  // factor/export.h is added by the CLI and tests at start-up).
  static Catalogue& global();

  void add_model(ModelInfo m);
  void add_preset(PresetInfo p);
  void add_loader(const std::string& extension, FileLoader loader);

  // spec: "name", "name:k=v,k=v" (name = model or preset; preset values may be
  // overridden), or a path ending in a registered extension, optionally with
  // ":k=v" loader options. origin names the spec's source in error messages.
  BrdfPtr make(const std::string& spec, const std::string& origin = "--brdf") const;
  // Build a model or preset by name from an already-filled dict (configs).
  BrdfPtr make(const std::string& name, ParamDict& params) const;
  // Loads a file through its extension's loader. A file that names another
  // file (a model fit's spec) is followed at most kMaxFileNesting deep; a
  // chain back to a file being loaded throws std::invalid_argument naming it.
  BrdfPtr load_file(const std::string& path, ParamDict& options) const;
  static constexpr size_t kMaxFileNesting = 8;

  const std::map<std::string, ModelInfo>& models() const { return models_; }
  const std::map<std::string, PresetInfo>& presets() const { return presets_; }
  std::vector<std::string> loader_extensions() const;
  bool is_file_spec(const std::string& spec) const;

 private:
  std::map<std::string, ModelInfo> models_;
  std::map<std::string, PresetInfo> presets_;
  std::map<std::string, FileLoader> loaders_;
};

// Registration hooks, one per source file group, called by Catalogue::builtin().
void register_analytic_models(Catalogue& cat);  // brdfs/models_*.cpp
void register_presets(Catalogue& cat);          // brdfs/presets.cpp
void register_measured_loaders(Catalogue& cat); // brdfs/measured_*.cpp

// Directory holding the data files (params/, cornell/): $BRDF_FACTOR_DATA or
// <source dir>/data.
std::string data_dir();

}  // namespace bf
