// The method catalogue's registry and generated key tables (see method_kind.h).
#include <algorithm>
#include <mutex>
#include <sstream>

#include "experiments/common/cli_util.h"
#include "experiments/methods/method_kind.h"
#include "factor/export.h"

namespace bf {

// The registration list: one line per kind, X(id) for the factory
// `std::shared_ptr<const MethodKind> make_<id>_kind()` defined in the kind's
// file. Its order is the order of messages and of the docs.
#define BF_METHOD_KINDS(X) \
  X(mccool)                \
  X(fit)                   \
  X(search)                \
  X(svd)                   \
  X(shk)                   \
  X(shr)                   \
  X(model_fit)

#define BF_DECLARE_KIND(id) std::shared_ptr<const MethodKind> make_##id##_kind();
BF_METHOD_KINDS(BF_DECLARE_KIND)
#undef BF_DECLARE_KIND

namespace {

std::vector<std::shared_ptr<const MethodKind>>& registry() {
#define BF_LIST_KIND(id) make_##id##_kind(),
  static std::vector<std::shared_ptr<const MethodKind>> kinds = {BF_METHOD_KINDS(BF_LIST_KIND)};
#undef BF_LIST_KIND
  return kinds;
}

std::mutex& registry_mutex() {
  static std::mutex mu;
  return mu;
}

}  // namespace

void write_description(const RunContext& c, const MethodOutcome& out) {
  const nlohmann::json d = out.result->describe();
  write_file_atomic((c.run_dir / "factorization.json").string(), [&](std::ostream& o) { o << d.dump(2) << "\n"; });
}

void MethodKind::export_files(const RunContext& c, const MethodOutcome& out) const { write_description(c, out); }

const std::vector<std::shared_ptr<const MethodKind>>& method_kinds() { return registry(); }

const MethodKind* find_method_kind(const std::string& name) {
  for (const auto& k : registry())
    if (k->name() == name) return k.get();
  return nullptr;
}

std::vector<std::string> method_kind_names() {
  std::vector<std::string> names;
  for (const auto& k : registry()) names.push_back(k->name());
  return names;
}

void register_method_kind(std::shared_ptr<const MethodKind> kind) {
  std::lock_guard<std::mutex> lk(registry_mutex());
  if (find_method_kind(kind->name()))
    throw std::invalid_argument("register_method_kind: kind \"" + kind->name() + "\" is already registered");
  registry().push_back(std::move(kind));
}

void unregister_method_kind(const std::string& name) {
  std::lock_guard<std::mutex> lk(registry_mutex());
  auto& kinds = registry();
  kinds.erase(std::remove_if(kinds.begin(), kinds.end(), [&](const auto& k) { return k->name() == name; }),
              kinds.end());
}

std::vector<std::string> refinable_kind_names() {
  std::vector<std::string> names;
  for (const auto& k : registry())
    if (k->refinable()) names.push_back(k->name());
  return names;
}

const std::vector<KeySpec>& common_method_keys() {
  static const std::vector<KeySpec> keys = {
      other_key("kind", "a registered kind (`brdf-factor list methods`)", "required", "the method; not sweepable"),
      other_key("label", "string", "the kind", "the `label` column and the plot legend; not part of the run id"),
      choice_key("refine", {"none", "linear", "cosine", "blend"}, "none",
                 "the nonlinear refinement stage (`factor/refine.h`) after the fit or search; homomorphic kinds "
                 "only, an error elsewhere. See [Refinement](#refinement)"),
      bool_key("sampler", "false",
               "also build the importance sampler of the result (`factor/sampling.h`, default options): columns "
               "`sampler_storage` and `sampler_build_s`; with `export`, `sampling.exr`, `sampling.glsl` and "
               "`sampling.json` in the run folder (docs/design.md, Importance sampling)"),
      choice_key("weight_fit", {"none", "image"}, "none",
                 "`image`: the samples this method fits are weighted by how much the (wi, wo) pairs near them "
                 "contribute to the `[scene]`'s image (rule: design.md §4.2); the row gains `scene_rel_mse`, "
                 "`rel_mse` stays unweighted. `none`: the samples' own weights (the run id is unchanged)"),
      num_key("weight_floor", 0.0, 1.0, false, "0.1",
              "with `weight_fit = \"image\"` only: every sample keeps at least this fraction of the mean weight"),
      other_key("zip", "list of keys", "", "see [Zip](#zip)")};
  return keys;
}

std::vector<std::string> method_keys(const MethodKind& kind) {
  std::vector<std::string> names;
  for (const auto& k : common_method_keys()) names.push_back(k.name);
  for (const auto& k : kind.keys()) names.push_back(k.name);
  return names;
}

MethodCallSpec method_call_spec(const MethodKind& kind) {
  MethodCallSpec c;
  c.kind = kind.name();
  c.function = kind.name();
  std::replace(c.function.begin(), c.function.end(), '-', '_');
  c.input = kind.tabulates() ? "brdf" : "samples";
  std::ostringstream d;
  d << c.function << (kind.tabulates() ? "(brdf, samples=None, **options)" : "(samples, **options)")
    << " -> Factorization\n\n"
    << kind.summary() << "\n\nOptions: the keys of a config's kind = \"" << c.kind
    << "\" (docs/experiments.md), as keywords; None or absent: the default.\n";
  for (const auto& k : kind.keys()) d << "  " << k.name << ": " << k.type_cell() << ". " << k.doc << "\n";
  d << "  metric_eps: the experiment's metric_eps (metrics on the samples).\n";
  if (kind.tabulates()) d << "Metrics are reported when samples are given.\n";
  c.doc = d.str();
  return c;
}

std::vector<MethodCallSpec> method_call_specs() {
  std::vector<MethodCallSpec> out;
  for (const auto& k : registry()) out.push_back(method_call_spec(*k));
  return out;
}

std::string method_key_tables() {
  std::ostringstream o;
  o << "#### Keys of every kind\n\n| key | type (default) | meaning |\n|---|---|---|\n";
  for (const auto& k : common_method_keys()) o << "| `" << k.name << "` | " << k.type_cell() << " | " << k.doc << " |\n";
  o << "\n";
  for (const auto& kind : registry()) {
    o << "#### `kind = \"" << kind->name() << "\"`\n\n" << kind->summary() << "\n\n";
    o << "| key | type (default) | meaning |\n|---|---|---|\n";
    for (const auto& k : kind->keys()) o << "| `" << k.name << "` | " << k.type_cell() << " | " << k.doc << " |\n";
    o << "\n";
  }
  return o.str();
}

}  // namespace bf
