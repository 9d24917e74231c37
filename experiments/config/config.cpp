// Experiment configs (see config.h and docs/experiments.md).
#include "experiments/config/config.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <thread>
#include <toml++/toml.h>
#include <unordered_map>

#include "brdfs/catalogue.h"
#include "brdfs/file_check.h"
#include "brdfs/params.h"
#include "brdfs/safe_path.h"
#include "brdfs/sampleset.h"
#include "brdfs/spectral.h"
#include "experiments/plan/plan_size.h"
#include "experiments/plan/toml_depth.h"
#include "experiments/common/cli_util.h"
#include "experiments/plan/config_reader.h"
#include "experiments/methods/method_kind.h"
#if __has_include("brdfs/measured.h")
#include "brdfs/measured.h"
#define BF_HAVE_MEASURED 1
#endif
#if __has_include("brdfs/merl.h")
#include "brdfs/merl.h"
#define BF_HAVE_MERL 1
#endif

namespace bf {

namespace fs = std::filesystem;
using nlohmann::json;

// Bump when the meaning of a run's outputs changes, so old caches are not reused.
// 2: every run is scored on a validation set and by the default scene, and
// runs on measured/file samples are trained without their held-out samples.
constexpr int kRunFormatVersion = 2;

namespace {

const std::map<std::string, std::vector<std::string>>& key_table() {
  static const std::map<std::string, std::vector<std::string>> t = {
      {"top", {"experiment", "brdf", "sampling", "method", "scene"}},
      {"experiment", {"name", "seed", "out", "description", "jobs", "plots", "render", "export",
                      "metric_eps", "validation_pairs", "holdout", "folds"}},
      {"sampling", {"kind", "resolution", "count", "seed", "path", "zip", "symmetries", "weights", "fill"}},
      {"scene", {"shade_rmse", "light", "intensity", "size", "environment", "environment_eps", "lighting_order",
                 "lighting_nodes"}},
      {"brdf", {"preset", "model", "file", "name", "zip"}},
      {"projection", {"parameterization", "matrix", "name", "reciprocal"}},
      {"tolerance", tolerance_keys()},
  };
  return t;
}

const std::vector<std::string> kSamplingKinds = {"grid", "stratified", "file", "measured"};

}  // namespace

std::vector<std::string> config_keys(const std::string& section) {
  if (section.rfind("method:", 0) == 0) {
    const MethodKind* kind = find_method_kind(section.substr(7));
    return kind ? method_keys(*kind) : std::vector<std::string>{};
  }
  auto it = key_table().find(section);
  return it == key_table().end() ? std::vector<std::string>{} : it->second;
}

namespace {

// ------------------------------------------------------------------ sections

ExperimentSettings read_experiment(const toml::table* t, Ctx& ctx, const std::string& path) {
  ExperimentSettings e;
  e.name = fs::path(path).stem().string();
  if (!t) {
    e.out = "results/" + e.name;
    return e;
  }
  const Combo c = plain_combo(*t);
  Reader r(ctx, c, "experiment", ctx.where(*t));
  e.name = r.text("name", e.name);
  if (!is_plain_name(e.name))
    r.fail("name", "expected a non-empty name of letters, digits, '.', '_' and '-', not '.' or '..', found " +
                       quote_for_message(e.name));
  e.seed = static_cast<uint64_t>(r.integer("seed", 1, 0, kIntMax));
  e.out = r.text("out", "results/" + e.name);
  if (e.out.empty()) r.fail("out", "expected a folder path, found \"\"");
  e.description = r.text("description", "");
  e.jobs = static_cast<int>(r.integer("jobs", 0, 0, 1024));
  e.plots = r.boolean("plots", true);
  e.render = r.boolean("render", true);
  e.export_factors = r.boolean("export", true);
  e.metric_eps = r.number("metric_eps", 1e-5, 0.0, 1.0, true);
  // Default "auto": blocks scored until the val_rel_mse is precise
  // (experiments/report/validation.h); a number: one set of that many pairs.
  if (r.has("validation_pairs") && r.combo().at("validation_pairs")->is_string()) {
    r.choice("validation_pairs", "auto", {"auto"});
    e.validation_pairs = ExperimentSettings::kValidationAuto;
  } else {
    e.validation_pairs = static_cast<int>(r.integer("validation_pairs", e.validation_pairs, 0, 1000000));
  }
  e.holdout = r.number("holdout", e.holdout, 0.0, 0.5, false);
  // Default: auto (5 folds on small raw sample sets), unless the single
  // fraction is chosen by setting `holdout`.
  if (r.has("folds") && r.combo().at("folds")->is_string()) {
    r.choice("folds", "auto", {"auto"});
    if (r.has("holdout"))
      r.fail("folds", "folds = \"auto\" chooses between folds and the single fraction, but holdout = " +
                          format_number(e.holdout) + " is set too: expected one of them");
    e.folds = ExperimentSettings::kFoldsAuto;
  } else {
    e.folds = static_cast<int>(r.integer("folds", r.has("holdout") ? 0 : ExperimentSettings::kFoldsAuto, 0, 1000000));
  }
  if (e.folds == 1)
    r.fail("folds", "expected 0 (off: the single `holdout` fraction) or a number of folds >= 2, found 1");
  else if (e.folds >= 2 && r.has("holdout"))
    r.fail("folds", "folds = " + std::to_string(e.folds) +
                        " holds every sample out once and replaces the single `holdout` fraction, but holdout = " +
                        format_number(e.holdout) + " is set too: expected one of them");
  r.finish(config_keys("experiment"), "[experiment]");
  return e;
}


// Values of [[brdf]] parameters go to the catalogue's ParamDict.
bool brdf_array_is_value(const std::string& key, const toml::array& a) {
  if (key == "preset" || key == "model" || key == "file" || key == "name") return false;
  if (a.empty()) return false;
  for (const auto& e : a)
    if (!e.is_number()) return false;
  return true;
}

bool is_measured(const Brdf& b) {
#ifdef BF_HAVE_MEASURED
  if (dynamic_cast<const MeasuredBrdf*>(&b)) return true;
#endif
#ifdef BF_HAVE_MERL
  if (dynamic_cast<const MerlBrdf*>(&b)) return true;
#endif
  (void)b;
  return false;
}

// A [[brdf]] table's parameters: every key but preset, model, file and name.
struct BrdfParams {
  ParamDict params;
  json values = json::object();               // hashed into the BRDF's identity
  std::vector<std::string> label_parts;       // "k=v" for the label
  std::map<std::string, std::string> where;   // key -> file:line
};

void read_brdf_params(Reader& r, const Combo& c, BrdfParams& bp) {
  for (const auto& [k, n] : c) {
    if (k == "preset" || k == "model" || k == "file" || k == "name") continue;
    r.take(k);
    bp.where[k] = r.ctx().where(*n);
    if (auto v = n->as_integer()) {
      bp.params.set_numbers(k, {static_cast<double>(v->get())});
      bp.values[k] = v->get();
      bp.label_parts.push_back(k + "=" + std::to_string(v->get()));
    } else if (auto f = n->as_floating_point()) {
      if (!std::isfinite(f->get())) {
        r.fail(k, "expected a finite number, found " + fmt_num(f->get()));
        continue;
      }
      bp.params.set_numbers(k, {f->get()});
      bp.values[k] = f->get();
      bp.label_parts.push_back(k + "=" + fmt_num(f->get()));
    } else if (auto s = n->as_string()) {
      bp.params.set_string(k, s->get());
      bp.values[k] = s->get();
      bp.label_parts.push_back(k + "=" + s->get());
    } else if (auto a = n->as_array(); a && brdf_array_is_value(k, *a)) {
      std::vector<double> xs;
      std::string txt;
      for (const auto& e : *a) {
        xs.push_back(e.value<double>().value_or(0.0));
        txt += (txt.empty() ? "" : "/") + fmt_num(xs.back());
      }
      if (xs.size() != 1 && xs.size() != 3) {
        r.fail(k, "expected one number or three (r, g, b), found " + std::to_string(xs.size()) +
                      " (to sweep a parameter write " + k + " = { sweep = [...] })");
        continue;
      }
      bp.params.set_numbers(k, xs);
      bp.values[k] = xs;
      bp.label_parts.push_back(k + "=" + txt);
    } else {
      r.fail(k, "expected a number, three numbers or a word (a BRDF parameter), " + found(*n));
    }
  }
}

void read_brdfs(const toml::node* node, Ctx& ctx, std::vector<BrdfVariant>& out) {
  if (!node) {
    ctx.issue(ctx.path, "brdf", "missing: the config needs at least one [[brdf]] table "
                                "(preset = \"...\", model = \"...\" or file = \"...\")");
    return;
  }
  std::vector<const toml::table*> tables;
  if (auto t = node->as_table()) tables.push_back(t);
  else if (auto a = node->as_array()) {
    for (const auto& e : *a) {
      if (auto t = e.as_table()) tables.push_back(t);
      else ctx.issue(ctx.where(e), "brdf", "expected [[brdf]] tables, " + found(e));
    }
  } else {
    ctx.issue(ctx.where(*node), "brdf", "expected [[brdf]] tables, " + found(*node));
    return;
  }
  if (tables.empty() && node->is_array())
    ctx.issue(ctx.where(*node), "brdf", "expected at least one [[brdf]] table, found an empty array");
  std::set<std::string> seen_ids;
  for (size_t i = 0; i < tables.size(); ++i) {
    const std::string section = "brdf[" + std::to_string(i) + "]";
    const Expansion ex = expand(*tables[i], section, brdf_array_is_value, {}, ctx);
    if (!ex.ok) continue;
    for (const Combo& c : ex.combos) {
      Reader r(ctx, c, section, ctx.where(*tables[i]));
      const int sources = int(r.has("preset")) + int(r.has("model")) + int(r.has("file"));
      if (sources != 1) {
        if (sources == 0)
          r.fail_table("expected one of preset = \"...\", model = \"...\" or file = \"...\", found none");
        else
          r.fail(r.has("file") ? "file" : "model",
                 "preset, model and file are alternatives: give exactly one, found " +
                     std::to_string(sources));
        continue;
      }
      const std::string src_key = r.has("preset") ? "preset" : r.has("model") ? "model" : "file";
      const std::string src = r.text(src_key, "");
      const std::string name = r.text("name", "");
      if (r.failed()) continue;
      if (src_key == "preset" && Catalogue::global().models().count(src)) {
        r.fail("preset", "\"" + src + "\" is a model, not a preset: write model = \"" + src + "\"");
        continue;
      }
      if (src_key == "model" && Catalogue::global().presets().count(src)) {
        r.fail("model", "\"" + src + "\" is a preset, not a model: write preset = \"" + src + "\"");
        continue;
      }
      if (src_key == "preset" && !Catalogue::global().presets().count(src)) {
        r.fail("preset", "unknown preset \"" + src + "\" (see `brdf-factor list`)" + [&] {
          std::vector<std::string> names;
          for (const auto& [k, v] : Catalogue::global().presets()) names.push_back(k);
          return did_you_mean(src, names);
        }());
        continue;
      }
      if (src_key == "model" && !Catalogue::global().models().count(src)) {
        std::vector<std::string> names;
        for (const auto& [k, v] : Catalogue::global().models()) names.push_back(k);
        r.fail("model", "unknown model \"" + src + "\" (models: " + join(names) + ")" + did_you_mean(src, names));
        continue;
      }
      // Parameters: every other key.
      BrdfParams bp{ParamDict(r.table_where() + ": " + section)};
      read_brdf_params(r, c, bp);
      if (r.failed()) continue;
      BrdfVariant b;
      b.where = r.table_where();
      try {
        if (src_key == "file") {
          std::vector<std::string> tried;
          const std::string resolved = ctx.resolve(src, &tried);
          if (resolved.empty()) {
            r.fail("file", "file not found (looked for " + join(tried, ", ") + ")");
            continue;
          }
          if (!Catalogue::global().is_file_spec(resolved)) {
            r.fail("file", "unknown measured-file extension (accepted: " +
                               join(Catalogue::global().loader_extensions()) + ")");
            continue;
          }
          b.brdf = Catalogue::global().load_file(resolved, bp.params);
          b.identity = {{"file", fs::path(src).filename().string()},
                        {"digest", file_hash(resolved)},
                        {"options", bp.values}};
          // Spectral files: the gamut mapping's floor shapes the samples (brdfs/spectral.h).
          const std::string ext = fs::path(resolved).extension().string();
          if (ext == ".astm" || ext == ".brdf") b.identity["gamut_floor"] = kGamutFloor;
          // MERL rules that change results (symmetry_prep.h scored_set, runner.cpp
          // prepare_fit's fill): runs cached before them differ.
          if (ext == ".binary") b.identity["merl_rules"] = "cells scored over their orbit; fill of the training cells";
          b.label = name.empty() ? src : name;
        } else {
          b.brdf = Catalogue::global().make(src, bp.params);
          b.identity = {{src_key, src}, {"params", bp.values}, {"eval", b.brdf->to_string()}};
          b.label = name.empty() ? src : name;
        }
      } catch (const std::exception& e) {
        // Point at the parameter the message names, when it names one.
        std::string msg = e.what();
        const std::string prefix = r.table_where() + ": " + section;
        std::string where = r.table_where(), field = section;
        for (const auto& [k, w] : bp.where)
          if (msg.find("'" + k + "'") != std::string::npos) {
            where = w;
            field = section + "." + k;
            break;
          }
        if (msg.rfind(prefix + ": ", 0) == 0) msg = msg.substr(prefix.size() + 2);
        else if (msg.rfind(prefix, 0) == 0) msg = msg.substr(prefix.size());
        ctx.issue(where, field, msg);
        continue;
      }
      if (name.empty() && !bp.label_parts.empty()) b.label += ":" + join(bp.label_parts, ",");
      b.measured = is_measured(*b.brdf);
      if (!seen_ids.insert(short_hash(b.identity)).second) continue;  // same BRDF twice
      out.push_back(std::move(b));
    }
  }
}

std::vector<std::string> sampling_keys_of(const std::string& kind) {
  if (kind == "grid") return {"resolution"};
  if (kind == "stratified") return {"count", "seed"};
  if (kind == "file") return {"path"};
  return {};
}

// sampling.fill of kind "measured": "auto" (-1), "off" (0) or a share in
// (0, 0.9]; in the identity (results depend on it), in the label when set.
void read_fill(Reader& r, SamplingVariant& s) {
  if (r.has("fill") && r.combo().at("fill")->is_string())
    s.fill = r.choice("fill", "auto", {"auto", "off"}) == "off" ? 0.0 : -1.0;
  else if (r.has("fill"))
    s.fill = r.number("fill", -1.0, 0.0, 0.9);
  if (s.fill < 0) {
    s.identity["fill"] = "auto";
  } else {
    s.identity["fill"] = s.fill;
    s.label += s.fill == 0 ? std::string(" fill off") : " fill " + fmt_num(s.fill);
  }
  if (s.fill != 0) s.identity["fill_pairs"] = kFillPairs;
  if (s.fill < 0) s.identity["fill_share"] = kFillShare;
}

// The keys of measured samplings: `weights` (brdfs/measured.h) and `fill`
// (experiments/run/symmetry_prep.h); refused for other kinds, naming the key.
void read_measured_keys(Reader& r, SamplingVariant& s) {
  // Sample weights of measured data (brdfs/measured.h): "auto" weights a MERL
  // table's cells by their measure, leaves scattered samples unweighted. In
  // the identity of every measured set (its results depend on it).
  if (r.has("weights") && s.kind != "measured") {
    r.fail("weights", "applies to kind = \"measured\" only (a table's cell weights), found kind = \"" +
                          s.kind + "\"");
    r.take("weights");
  } else if (s.kind == "measured") {
    s.weights = r.choice("weights", "auto", {"auto", "measure", "none"});
    s.identity["weights"] = s.weights;
    if (s.weights != "auto") s.label += " weights " + s.weights;
  }
  // The whole-domain fill of raw samples (experiments/run/symmetry_prep.h):
  // "auto", "off" or a share of the fit's weight in (0, 0.9].
  if (r.has("fill") && s.kind != "measured") {
    r.fail("fill", "applies to kind = \"measured\" only (a measured BRDF's interpolant fills the domain), "
                   "found kind = \"" + s.kind + "\"");
    r.take("fill");
  } else if (s.kind == "measured") {
    read_fill(r, s);
  }
}

void read_samplings(const toml::node* node, Ctx& ctx, uint64_t base_seed,
                    std::vector<SamplingVariant>& out) {
  std::vector<const toml::table*> tables;
  if (!node) {
    SamplingVariant s;
    s.kind = "grid";
    s.resolution = 16;
    s.label = "grid 16^4";
    s.where = ctx.path;
    s.identity = {{"kind", "grid"}, {"resolution", 16}};
    out.push_back(s);
    return;
  }
  if (auto t = node->as_table()) tables.push_back(t);
  else if (auto a = node->as_array()) {
    for (const auto& e : *a)
      if (auto t = e.as_table()) tables.push_back(t);
      else ctx.issue(ctx.where(e), "sampling", "expected a [sampling] table, " + found(e));
  } else {
    ctx.issue(ctx.where(*node), "sampling", "expected a [sampling] table, " + found(*node));
    return;
  }
  std::set<std::string> seen;
  for (size_t i = 0; i < tables.size(); ++i) {
    const std::string section = tables.size() == 1 && node->is_table() ? "sampling"
                                                                          : "sampling[" + std::to_string(i) + "]";
    const Expansion ex = expand(*tables[i], section, never_value, {}, ctx);
    if (!ex.ok) continue;
    const bool kind_swept = ex.swept.count("kind") != 0;
    // Keys of any kind present in the sweep are dropped where they do not apply.
    std::set<std::string> sweep_keys;
    if (kind_swept)
      for (const Combo& c : ex.combos)
        if (auto k = c.at("kind")->as_string())
          for (const auto& key : sampling_keys_of(k->get())) sweep_keys.insert(key);
    for (const Combo& c : ex.combos) {
      Reader r(ctx, c, section, ctx.where(*tables[i]));
      SamplingVariant s;
      s.where = r.table_where();
      s.kind = r.choice("kind", "grid", kSamplingKinds);
      if (r.failed()) continue;
      if (s.kind == "grid") {
        // brdfs/sampleset.h: a res^4 grid, bounded memory (64 gives about 1e7 pairs).
        s.resolution = static_cast<int>(r.integer("resolution", 16, 2, kMaxSampleGridResolution));
        s.label = "grid " + std::to_string(s.resolution) + "^4";
        s.identity = {{"kind", "grid"}, {"resolution", s.resolution}};
      } else if (s.kind == "stratified") {
        if (!r.has("count")) r.fail_table("kind = \"stratified\" needs count = <number of pairs>");
        s.count = static_cast<uint64_t>(r.integer("count", 1, 1, static_cast<long long>(kMaxStratifiedCount)));
        s.seed = static_cast<uint64_t>(r.integer("seed", static_cast<int64_t>(base_seed), 0, kIntMax));
        s.label = "stratified " + std::to_string(s.count) + " seed " + std::to_string(s.seed);
        s.identity = {{"kind", "stratified"}, {"count", s.count}, {"seed", s.seed}};
      } else if (s.kind == "file" && r.has("path")) {
        const std::string p = r.text("path", "");
        std::vector<std::string> tried;
        s.path = ctx.resolve(p, &tried);
        if (!r.failed() && s.path.empty()) r.fail("path", "file not found (looked for " + join(tried, ", ") + ")");
        else if (!r.failed()) {
          s.label = "file " + fs::path(p).filename().string();
          s.identity = {{"kind", "file"}, {"file", fs::path(p).filename().string()}, {"digest", file_hash(s.path)}};
        }
      } else {
        // "measured", or "file" without a path: the measured BRDF's own samples.
        s.kind = "measured";
        s.label = "measured";
        s.identity = {{"kind", "measured"}};
      }
      // Symmetries the fit's raw samples stand for (experiments/run/symmetry_prep.h).
      // Raw samples record the key in their identity (their results depend on it);
      // grid and stratified sets only when it is set to something other than "auto".
      s.symmetries = r.text("symmetries", "auto");
      if (!r.failed() && s.symmetries != "auto" && s.symmetries != "off") {
        try {
          parse_symmetries(s.symmetries, "symmetries");
        } catch (const std::invalid_argument&) {
          r.fail("symmetries", "expected \"auto\", \"off\", \"none\" or names joined by '+' (isotropic, "
                               "reciprocal, bilateral), found \"" + s.symmetries + "\"");
        }
      }
      if (s.raw() || s.symmetries != "auto") {
        s.identity["symmetries"] = s.symmetries;
        // The orbit's settings are code constants: in the identity, so that
        // changing them never reuses a run cached under the old ones.
        if (s.symmetries != "off" && s.symmetries != "none") s.identity["orbit"] = orbit_identity();
      }
      if (s.symmetries != "auto") s.label += " symmetries " + s.symmetries;
      read_measured_keys(r, s);
      for (const auto& key : {"resolution", "count", "seed", "path"}) {
        if (!r.has(key) || contains(sampling_keys_of(s.kind), key)) continue;
        if (kind_swept && sweep_keys.count(key)) {
          r.take(key);
          continue;
        }
        r.fail(key, std::string("does not apply to kind = \"") + s.kind + "\" (keys of kind " + s.kind +
                        ": " + (sampling_keys_of(s.kind).empty() ? "none" : join(sampling_keys_of(s.kind))) + ")");
        r.take(key);
      }
      r.finish(config_keys("sampling"), "[sampling]");
      if (r.failed()) continue;
      if (!seen.insert(short_hash(s.identity)).second) continue;
      out.push_back(std::move(s));
    }
  }
}

// ------------------------------------------------------------------ methods

// An array value of a method key is one value (not a sweep) when a kind says so.
bool method_array_is_value(const std::string& key, const toml::array& a) {
  for (const auto& k : method_kinds())
    if (k->array_is_value(key, a)) return true;
  return false;
}

// Keys of other kinds than `kind` get a message naming the kinds they belong to.
void reject_other_kinds_keys(Reader& r, const MethodKind& kind) {
  const std::vector<std::string> own = method_keys(kind);
  for (const auto& [k, n] : r.combo()) {
    if (contains(own, k)) continue;
    std::vector<std::string> owners;
    for (const auto& other : method_kinds())
      if (other.get() != &kind && contains(method_keys(*other), k)) owners.push_back(other->name());
    if (owners.empty()) continue;
    r.fail(k, "does not apply to kind = \"" + kind.name() + "\" (it is a key of kind " + join(owners) + ")");
    r.take(k);
  }
}

// The keys every kind shares (label, refine), then the kind's own (methods/).
void read_method(Reader& r, const MethodKind& kind, uint64_t base_seed, MethodVariant& m) {
  json o = {{"kind", kind.name()}};
  m.kind = kind.name();
  m.impl = &kind;
  m.label = r.text("label", m.kind);
  m.refine = r.choice(find_key(common_method_keys(), "refine"), "none");
  if (m.refine != "none" && !kind.refinable())
    r.fail("refine", "refine = \"" + m.refine + "\" applies to the homomorphic kinds (" +
                         join(refinable_kind_names()) + ") only; kind = \"" + m.kind + "\" needs refine = \"none\"");
  o["refine"] = m.refine;
  m.sampler = r.boolean(find_key(common_method_keys(), "sampler"), false);
  if (m.sampler) o["sampler"] = true;  // (absent when false: run ids of configs without it unchanged)
  // Scene-weighted fits (experiments/report/scene_weights.h): in the options,
  // hence the run id, only when asked for.
  const std::string weight_fit = r.choice(find_key(common_method_keys(), "weight_fit"), "none");
  const bool has_floor = r.has("weight_floor");
  const double weight_floor = r.number(find_key(common_method_keys(), "weight_floor"), 0.1);
  if (weight_fit != "none") o["weight_fit"] = {{"rule", weight_fit}, {"floor", weight_floor}};
  else if (has_floor)
    r.fail("weight_floor", "weight_floor is the floor of the image weights, but weight_fit is \"none\": set "
                           "weight_fit = \"image\" or remove weight_floor");
  kind.read(r, m, o, base_seed);
  // One rule for every kind that reads texture_size = "auto".
  if (!m.texture_ladder.empty() && !m.tolerance)
    r.fail("texture_size", "texture_size = \"auto\" needs a tolerance (the error target that picks the size)");
  r.finish(method_keys(kind), "kind = \"" + m.kind + "\"");
  m.options = o;
}

void read_methods(const toml::node* node, Ctx& ctx, uint64_t base_seed, std::vector<MethodVariant>& out) {
  const std::vector<std::string> kinds = method_kind_names();
  if (!node) {
    ctx.issue(ctx.path, "method", "missing: the config needs at least one [[method]] table (kind = \"" +
                                      join(kinds, "\" | \"") + "\")");
    return;
  }
  std::vector<const toml::table*> tables;
  if (auto t = node->as_table()) tables.push_back(t);
  else if (auto a = node->as_array()) {
    for (const auto& e : *a)
      if (auto t = e.as_table()) tables.push_back(t);
      else ctx.issue(ctx.where(e), "method", "expected [[method]] tables, " + found(e));
  } else {
    ctx.issue(ctx.where(*node), "method", "expected [[method]] tables, " + found(*node));
    return;
  }
  for (size_t i = 0; i < tables.size(); ++i) {
    const std::string section = "method[" + std::to_string(i) + "]";
    const Expansion ex = expand(*tables[i], section, method_array_is_value, {"kind", "label"}, ctx);
    if (!ex.ok) continue;
    for (const Combo& c : ex.combos) {
      Reader r(ctx, c, section, ctx.where(*tables[i]));
      if (!r.has("kind")) {
        r.fail_table("missing kind (expected one of \"" + join(kinds, "\", \"") + "\")");
        continue;
      }
      const MethodKind* kind = find_method_kind(r.choice("kind", "", kinds));
      if (r.failed() || !kind) continue;
      MethodVariant m;
      read_method_table(r, *kind, base_seed, m);
      if (r.failed()) continue;
      out.push_back(std::move(m));
    }
  }
}

}  // namespace

// ------------------------------------------------------------------ plan

// Counts the runs (experiments/plan/plan_size.h) before anything is expanded.
static void check_plan_size_before_expanding(const toml::table& root, const std::string& path) {
  const uint64_t cap = kMaxRuns;
  const uint64_t b = count_section_combinations(root.get("brdf"), brdf_array_is_value, cap);
  const uint64_t s = count_section_combinations(root.get("sampling"), never_value, cap);
  const uint64_t m = count_section_combinations(root.get("method"), method_array_is_value, cap);
  if (saturating_product(saturating_product(b, s, cap), m, cap) <= cap) return;
  auto n = [&](uint64_t x) { return x > cap ? "more than " + std::to_string(cap) : std::to_string(x); };
  throw ConfigError({path + ": experiment: the config expands to more than " + std::to_string(cap) +
                     " runs (limit " + std::to_string(cap) + "): " + n(b) + " brdf x " + n(s) + " sampling x " +
                     n(m) + " method combinations; nothing was expanded"});
}

// What every run of a plan shares in its identity: the format version and
// the experiment settings its results depend on.
static json identity_common(const Plan& plan) {
  json common = {{"v", kRunFormatVersion},
                 {"metric_eps", plan.experiment.metric_eps},
                 {"render", plan.experiment.render},
                 {"export", plan.experiment.export_factors},
                 {"scene", plan.scene.identity()},
                 {"validation", {{"pairs", plan.experiment.validation_pairs == ExperimentSettings::kValidationAuto
                                               ? json("auto")
                                               : json(plan.experiment.validation_pairs)},
                                 {"holdout", plan.experiment.holdout},
                                 {"seed", validation_seed(plan.experiment.seed)}}}};
  // Only when on: runs without folds keep their ids. "auto" enters only the
  // ids of runs on raw samples (parse_plan), the only ones it can change.
  if (plan.experiment.folds > 0) common["validation"]["folds"] = plan.experiment.folds;
  return common;
}

Plan parse_plan(const std::string& text, const std::string& path, const std::vector<std::string>& defines) {
  Ctx ctx;
  ctx.path = path;
  ctx.dir = fs::path(path).parent_path().string();
  if (std::string p = toml_key_depth_problem(text, path); !p.empty()) throw ConfigError({p});
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw ConfigError({path + ":" + std::to_string(e.source().begin.line) + ": TOML: " +
                       std::string(e.description())});
  }
  for (const auto& d : defines) apply_define(root, d, ctx);
  check_plan_size_before_expanding(root, path);

  Plan plan;
  plan.config_path = path;
  plan.config_text = text;
  plan.defines = defines;
  for (const auto& [k, v] : root)
    if (!contains(config_keys("top"), std::string(k.str())))
      ctx.issue(ctx.where(v), std::string(k.str()),
                "unknown section (accepted: " + join(config_keys("top")) + ")" +
                    did_you_mean(std::string(k.str()), config_keys("top")));
  auto table_of = [&](const char* name) -> const toml::table* {
    const toml::node* n = root.get(name);
    if (!n) return nullptr;
    if (!n->is_table()) {
      ctx.issue(ctx.where(*n), name, std::string("expected a [") + name + "] table, " + found(*n));
      return nullptr;
    }
    return n->as_table();
  };
  plan.experiment = read_experiment(table_of("experiment"), ctx, path);
  plan.scene = read_scene(table_of("scene"), ctx);
  read_brdfs(root.get("brdf"), ctx, plan.brdfs);
  read_samplings(root.get("sampling"), ctx, plan.experiment.seed, plan.samplings);
  read_methods(root.get("method"), ctx, plan.experiment.seed, plan.methods);
  // Rules of each method about the rest of the plan (methods/: scene lighting, BRDFs).
  for (auto& m : plan.methods) m.impl->check_plan(plan, m, ctx);

  // Tolerances on metrics scored outside the fit's samples need their source.
  for (const auto& m : plan.methods) {
    if (!m.tolerance) continue;
    if (m.tolerance->metric == "shade_rmse" && !plan.scene.shade)
      ctx.issue(m.where, "tolerance.metric",
                "metric = \"shade_rmse\" needs the scene's shade_rmse, but [scene] shade_rmse = false");
    if (m.tolerance->metric.rfind("val_", 0) == 0 && plan.experiment.validation_pairs == 0)
      ctx.issue(m.where, "tolerance.metric",
                "metric = \"" + m.tolerance->metric +
                    "\" is scored on the validation set, but [experiment] validation_pairs = 0 (no set)");
  }

  // A key chosen by held-out error needs held-out samples: raw samples with
  // a held-out fraction or folds.
  for (const auto& m : plan.methods) {
    if (!m.cv) continue;
    const std::string rule = m.cv->key + " = \"cv\" chooses it by held-out error, ";
    for (const auto& s : plan.samplings)
      if (s.kind != "measured" && s.kind != "file")
        ctx.issue(m.where, "method." + m.cv->key,
                  rule + "which only raw samples have (sampling kind \"measured\" or \"file\"), found kind \"" +
                      s.kind + "\" (" + s.where + "): give a number");
    if (plan.experiment.folds < 2 && !(plan.experiment.holdout > 0))
      ctx.issue(m.where, "method." + m.cv->key, rule + "but [experiment] holdout = 0 and folds = 0 hold nothing out: set one");
  }

  // Combinations that need a measured BRDF.
  for (const auto& s : plan.samplings) {
    if (s.kind != "measured") continue;
    for (const auto& b : plan.brdfs)
      if (!b.measured)
        ctx.issue(s.where, "sampling.kind",
                  "kind = \"" + s.kind + "\" without path uses a measured BRDF's own samples, but brdf '" +
                      b.label + "' (" + b.where + ") is not measured: use kind = \"grid\" or \"stratified\"");
  }
  if (!ctx.issues.empty()) throw ConfigError(ctx.issues);

  const json common = identity_common(plan);
  std::set<std::string> ids;
  json all = json::array();
  for (size_t b = 0; b < plan.brdfs.size(); ++b)
    for (size_t s = 0; s < plan.samplings.size(); ++s) {
      const std::string samples_key = short_hash({{"brdf", plan.brdfs[b].identity},
                                                  {"sampling", plan.samplings[s].identity}});
      for (size_t m = 0; m < plan.methods.size(); ++m) {
        PlannedRun r;
        r.brdf = b;
        r.sampling = s;
        r.method = m;
        r.samples_key = samples_key;
        r.identity = common;
        r.identity["brdf"] = plan.brdfs[b].identity;
        r.identity["sampling"] = plan.samplings[s].identity;
        if (plan.experiment.folds == ExperimentSettings::kFoldsAuto && plan.samplings[s].raw())
          r.identity["validation"]["folds"] = "auto";
        r.identity["method"] = plan.methods[m].options;
        r.run_id = short_hash(r.identity);
        if (!ids.insert(r.run_id).second) {
          ++plan.duplicates;
          continue;
        }
        all.push_back(r.run_id);
        plan.runs.push_back(std::move(r));
      }
    }
  if (plan.runs.size() > kMaxRuns)
    throw ConfigError({path + ": experiment: the config expands to " + std::to_string(plan.runs.size()) +
                       " runs (limit " + std::to_string(kMaxRuns) + ")"});
  plan.plan_hash = short_hash(all);
  return plan;
}

Plan load_plan(const std::string& path, const std::vector<std::string>& defines) {
  return parse_plan(read_regular_file(path, kMaxTextFileBytes, "config"), path, defines);
}

// ------------------------------------------------------------------ one table, for other readers

void read_method_table(Reader& r, const MethodKind& kind, uint64_t base_seed, MethodVariant& m) {
  reject_other_kinds_keys(r, kind);
  m.where = r.table_where();
  read_method(r, kind, base_seed, m);
}

ExperimentSettings read_experiment_table(const toml::table& t, Ctx& ctx, const std::string& path) {
  return read_experiment(&t, ctx, path);
}

}  // namespace bf
