// The method catalogue's registry and generated key tables (see method_kind.h).
#include <algorithm>
#include <mutex>
#include <sstream>

#include "experiments/common/cli_util.h"
#include "experiments/methods/method_kind.h"
#include "factor/export.h"

namespace bf {

// One factory per kind, defined in its file of experiments/methods/.
std::shared_ptr<const MethodKind> make_mccool_kind();
std::shared_ptr<const MethodKind> make_fit_kind();
std::shared_ptr<const MethodKind> make_search_kind();
std::shared_ptr<const MethodKind> make_svd_kind();
std::shared_ptr<const MethodKind> make_shk_kind();
std::shared_ptr<const MethodKind> make_shr_kind();
std::shared_ptr<const MethodKind> make_model_fit_kind();

namespace {

std::vector<std::shared_ptr<const MethodKind>>& registry() {
  // The registration list: the order of messages and of the docs.
  static std::vector<std::shared_ptr<const MethodKind>> kinds = {
      make_mccool_kind(), make_fit_kind(), make_search_kind(), make_svd_kind(),
      make_shk_kind(),    make_shr_kind(), make_model_fit_kind(),
  };
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
