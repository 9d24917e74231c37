// Reading an experiment config file into a Plan (the types are in
// experiments/plan/plan.h). The reader asks the method catalogue
// (experiments/methods/) for each kind's keys, so it sits above it.
#pragma once

#include <string>
#include <vector>

#include "experiments/plan/config_reader.h"
#include "experiments/plan/plan.h"

namespace bf {

// Reads, overrides, validates and expands a config file. defines: "key=value"
// (see apply_define). Throws ConfigError listing every problem found (each
// once), or std::invalid_argument for an unreadable file.
Plan load_plan(const std::string& path, const std::vector<std::string>& defines = {});
// Same from text; `path` names the file in messages and anchors relative paths.
Plan parse_plan(const std::string& text, const std::string& path,
                const std::vector<std::string>& defines = {});

// Keys of docs/experiments.md, per section ("experiment", "sampling", "scene",
// "brdf" (reserved keys only), "projection", "tolerance") and per method kind
// ("method:search", ...: the common keys, then the kind's, from the catalogue).
std::vector<std::string> config_keys(const std::string& section);

// Applies one -D key=value to the parsed config; problems go to ctx.
void apply_define(toml::table& root, const std::string& def, Ctx& ctx);

// One [[method]] table of kind `kind` (one combination of its sweeps), read as
// the config reader reads each: other kinds' keys refused, the common keys,
// the kind's own (experiments/methods/), unknown keys. Problems go to r. The
// Python module reads a method's keyword arguments through it.
void read_method_table(Reader& r, const MethodKind& kind, uint64_t base_seed, MethodVariant& m);
// The [experiment] table as the config reader reads it (problems go to ctx;
// path names the config: the default name and out).
ExperimentSettings read_experiment_table(const toml::table& t, Ctx& ctx, const std::string& path);

// Reads the [scene] table (nullptr: the default scene), problems to ctx
// (experiments/config/scene_config.cpp).
SceneSettings read_scene(const toml::table* t, Ctx& ctx);

}  // namespace bf
