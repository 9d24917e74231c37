// Experiment configs (see config.h and docs/experiments.md).
#include "experiments/config.h"

#include "brdfs/file_check.h"
#include "brdfs/safe_path.h"
#include "experiments/plan_size.h"
#include "experiments/toml_depth.h"

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
#include "brdfs/params.h"
#include "factor/metrics.h"
#include "search/rotation4.h"
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
constexpr int kRunFormatVersion = 1;
constexpr size_t kMaxRuns = 100000;

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

nlohmann::json SceneSettings::identity() const {
  nlohmann::json j = {{"light", {light.x(), light.y(), light.z()}}, {"intensity", intensity}, {"size", size},
                      {"shade_rmse", named}};
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

// ------------------------------------------------------------------ keys

namespace {

const std::vector<std::string> kCommonMethodKeys = {"kind", "label", "refine", "zip"};
const std::vector<std::string> kFitKeys = {"texture_size", "smoothing", "eps", "subtract_eps",
                                           "solve_last", "solver"};
// Keys of the refinement stage (factor/refine.h) of the homomorphic kinds.
const std::vector<std::string> kRefineKeys = {"refine_blend", "refine_iterations", "refine_smoothing"};

std::vector<std::string> join_keys(std::initializer_list<std::vector<std::string>> parts) {
  std::vector<std::string> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

const std::map<std::string, std::vector<std::string>>& key_table() {
  static const std::map<std::string, std::vector<std::string>> t = {
      {"top", {"experiment", "brdf", "sampling", "method", "scene"}},
      {"experiment", {"name", "seed", "out", "description", "jobs", "plots", "render", "export",
                      "metric_eps"}},
      {"sampling", {"kind", "resolution", "count", "seed", "path", "zip"}},
      {"scene", {"light", "intensity", "size", "environment", "environment_eps", "lighting_order",
                 "lighting_nodes"}},
      {"brdf", {"preset", "model", "file", "name", "zip"}},
      {"projection", {"parameterization", "matrix", "name", "reciprocal"}},
      {"tolerance", {"metric", "value"}},
      {"method:mccool", join_keys({kCommonMethodKeys, kFitKeys, kRefineKeys, {"terms", "tolerance", "texture_ladder"}})},
      {"method:fit", join_keys({kCommonMethodKeys, kFitKeys, kRefineKeys,
                                {"projections", "terms", "parameterization", "reciprocity",
                                 "tolerance", "texture_ladder"}})},
      {"method:search",
       join_keys({kCommonMethodKeys, kFitKeys, kRefineKeys,
                  {"parameterization", "terms", "search_texture_size", "restarts", "guesses",
                   "reciprocity", "optimizer", "ftol", "line_tol", "initial_step", "max_sweeps",
                   "max_evaluations", "threads", "seed", "beam", "backfit_sweeps",
                   "backfit_restarts", "tolerance"}})},
      {"method:svd", join_keys({kCommonMethodKeys,
                                {"texture_size", "terms", "parameterization", "log", "eps",
                                 "subtract_eps", "rim_inset", "extend_below_horizon",
                                 "float_textures", "tolerance", "texture_ladder"}})},
      {"method:sh-k", join_keys({kCommonMethodKeys,
                                 {"order", "texture_size", "theta_nodes", "phi_nodes", "rim_inset",
                                  "min_cos", "float_textures", "tolerance", "reduce_isotropic"}})},
      {"method:sh-r", join_keys({kCommonMethodKeys,
                                 {"order", "view_order", "max_order", "max_view_order",
                                  "energy_eps", "theta_i_nodes", "theta_o_nodes", "phi_nodes",
                                  "min_cos", "tolerance", "shrm"}})},
      {"method:model-fit", join_keys({kCommonMethodKeys,
                                      {"model", "metric", "cube_root", "anisotropic", "lobes", "eps",
                                       "starts", "seed", "max_iterations", "threads"}})},
  };
  return t;
}

const std::vector<std::string> kMethodKinds = {"mccool", "fit", "search", "svd", "sh-k", "sh-r", "model-fit"};
const std::vector<std::string> kSamplingKinds = {"grid", "stratified", "file", "measured"};

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

std::string join(const std::vector<std::string>& v, const std::string& sep = ", ") {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> d(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) d[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t prev = d[0];
    d[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t cur = d[j];
      d[j] = std::min({d[j] + 1, d[j - 1] + 1, prev + (a[i - 1] == b[j - 1] ? 0 : 1)});
      prev = cur;
    }
  }
  return d[b.size()];
}

std::string did_you_mean(const std::string& key, const std::vector<std::string>& accepted) {
  std::string best;
  size_t bd = 3;
  for (const auto& a : accepted) {
    const size_t d = edit_distance(key, a);
    if (d < bd) bd = d, best = a;
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

}  // namespace

const std::vector<std::string>& config_keys(const std::string& section) {
  static const std::vector<std::string> none;
  auto it = key_table().find(section);
  return it == key_table().end() ? none : it->second;
}

// ------------------------------------------------------------------ context

namespace {

using Combo = std::map<std::string, const toml::node*>;

std::string fmt_num(double v) {
  std::ostringstream ss;
  ss.precision(12);
  ss << v;
  return ss.str();
}

// A short rendering of a value for messages ("found ...").
std::string show(const toml::node& n) {
  if (auto v = n.as_integer()) return std::to_string(v->get());
  if (auto v = n.as_floating_point()) return fmt_num(v->get());
  if (auto v = n.as_boolean()) return v->get() ? "true" : "false";
  if (auto v = n.as_string()) return "\"" + v->get() + "\"";
  if (n.is_array()) return "an array";
  if (n.is_table()) return "a table";
  return "a date/time";
}

std::string type_name(const toml::node& n) {
  if (n.is_integer()) return "an integer";
  if (n.is_floating_point()) return "a float";
  if (n.is_boolean()) return "a boolean";
  if (n.is_string()) return "a string";
  if (n.is_array()) return "an array";
  if (n.is_table()) return "a table";
  return "a date/time";
}

std::string found(const toml::node& n) {
  if (n.is_array() || n.is_table()) return "found " + show(n);
  return "found " + show(n) + " (" + type_name(n) + ")";
}

struct Ctx {
  std::string path;  // config path (messages)
  std::string dir;   // folder of the config
  std::unordered_map<const toml::node*, std::string> define_origin;
  std::vector<std::string> issues;
  std::set<std::string> seen;

  void issue(const std::string& where, const std::string& field, const std::string& rule) {
    std::string m = where + ": " + field + ": " + rule;
    if (seen.insert(m).second) issues.push_back(std::move(m));
  }
  std::string where(const toml::node& n) const {
    auto it = define_origin.find(&n);
    if (it != define_origin.end()) return it->second;
    return path + ":" + std::to_string(n.source().begin.line);
  }
  void mark_define(const toml::node& n, const std::string& origin) {
    define_origin[&n] = origin;
    if (auto a = n.as_array())
      for (const auto& e : *a) mark_define(e, origin);
    if (auto t = n.as_table())
      for (const auto& [k, v] : *t) mark_define(v, origin);
  }
  // Relative paths: the config's folder, then the working directory, then the data folder.
  std::string resolve(const std::string& p, std::vector<std::string>* tried) const {
    if (p.empty()) return p;
    fs::path fp(p);
    if (fp.is_absolute()) {
      if (tried) tried->push_back(p);
      return fs::exists(fp) ? p : "";
    }
    for (const fs::path& base : {fs::path(dir), fs::current_path(), fs::path(data_dir())}) {
      const fs::path c = base.empty() ? fp : base / fp;
      if (tried) tried->push_back(c.string());
      std::error_code ec;
      if (fs::exists(c, ec)) return c.lexically_normal().string();
    }
    return "";
  }
};

// ------------------------------------------------------------------ -D overrides

struct PathSeg {
  std::string name;
  int index = -1;
};

bool parse_path(const std::string& key, std::vector<PathSeg>& segs) {
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) {
    PathSeg s;
    const auto lb = part.find('[');
    if (lb != std::string::npos) {
      if (part.back() != ']') return false;
      const std::string num = part.substr(lb + 1, part.size() - lb - 2);
      if (num.empty() || num.size() > 6 || num.find_first_not_of("0123456789") != std::string::npos) return false;
      s.index = std::stoi(num);
      part = part.substr(0, lb);
    }
    if (part.empty()) return false;
    s.name = part;
    segs.push_back(s);
    if (segs.size() > 16) return false;  // a define path is section.key or section.key.subkey
  }
  return !segs.empty();
}

// Sets `key` in `t` to a copy of `value`, remembering the -D origin of the new node.
void set_value(toml::table& t, const std::string& key, const toml::node& value, Ctx& ctx,
               const std::string& origin) {
  value.visit([&](const auto& v) { t.insert_or_assign(key, v); });
  if (const toml::node* n = t.get(key)) ctx.mark_define(*n, origin);
}

std::string kind_of(const toml::table& t) {
  if (auto k = t["kind"].value<std::string>()) return *k;
  return "";
}

void apply_define(toml::table& root, const std::string& def, Ctx& ctx) {
  const std::string origin = "-D " + def;
  const auto eq = def.find('=');
  if (eq == std::string::npos || eq == 0) {
    ctx.issue(origin, "-D", "expected key=value (e.g. -D sampling.resolution=8), found '" + def + "'");
    return;
  }
  const std::string key = def.substr(0, eq), text = def.substr(eq + 1);
  std::vector<PathSeg> segs;
  if (!parse_path(key, segs) || segs.size() < 2) {
    ctx.issue(origin, key,
              "expected section.key, section[N].key or section.key.subkey (sections: " +
                  join(config_keys("top")) + ")");
    return;
  }
  // The value: TOML if it parses as one, else the text as a string.
  toml::table parsed;
  try {
    // Too deep to parse safely: taken as a string, like any text that is not TOML.
    if (toml_key_depth_problem("v = " + text, origin).empty()) parsed = toml::parse("v = " + text, origin);
    else parsed.insert_or_assign("v", text);
  } catch (const toml::parse_error&) {
    parsed.insert_or_assign("v", text);
  }
  const toml::node& value = *parsed.get("v");

  const PathSeg& top = segs[0];
  if (!contains(config_keys("top"), top.name)) {
    ctx.issue(origin, key, "unknown section '" + top.name + "' (accepted: " +
                               join(config_keys("top")) + ")" +
                               did_you_mean(top.name, config_keys("top")));
    return;
  }
  // Collect the target tables of the first segment.
  std::vector<toml::table*> targets;
  toml::node* sect = root.get(top.name);
  if (!sect) {
    if (top.name == "brdf" || top.name == "method") {
      ctx.issue(origin, key, "the config has no [[" + top.name + "]] table to override");
      return;
    }
    root.insert_or_assign(top.name, toml::table{});
    sect = root.get(top.name);
    ctx.mark_define(*sect, origin);
  }
  if (auto arr = sect->as_array()) {
    if (top.index >= 0) {
      if (static_cast<size_t>(top.index) >= arr->size() || !arr->get(top.index)->is_table()) {
        ctx.issue(origin, key, "index " + std::to_string(top.index) + " out of range (the config has " +
                                   std::to_string(arr->size()) + " " + top.name +
                                   " tables, numbered from 0)");
        return;
      }
      targets.push_back(arr->get(top.index)->as_table());
    } else {
      for (auto& e : *arr)
        if (auto t = e.as_table()) targets.push_back(t);
    }
  } else if (auto t = sect->as_table()) {
    if (top.index > 0) {
      ctx.issue(origin, key, "index " + std::to_string(top.index) + " out of range (one " + top.name +
                                 " table, numbered 0)");
      return;
    }
    targets.push_back(t);
  } else {
    ctx.issue(origin, key, "'" + top.name + "' in the config is not a table");
    return;
  }
  // method.KEY without an index: only the methods whose kind accepts KEY.
  if (top.name == "method" && top.index < 0) {
    std::vector<toml::table*> keep;
    std::set<std::string> kinds;
    for (auto* t : targets) {
      kinds.insert(kind_of(*t));
      if (contains(config_keys("method:" + kind_of(*t)), segs[1].name)) keep.push_back(t);
    }
    if (keep.empty()) {
      ctx.issue(origin, key, "no [[method]] of this config accepts '" + segs[1].name +
                                 "' (kinds present: " +
                                 join(std::vector<std::string>(kinds.begin(), kinds.end())) + ")");
      return;
    }
    targets = keep;
  }
  for (toml::table* t : targets) {
    toml::table* cur = t;
    bool ok = true;
    for (size_t i = 1; i + 1 < segs.size() && ok; ++i) {
      toml::node* n = cur->get(segs[i].name);
      if (!n) {
        cur->insert_or_assign(segs[i].name, toml::table{});
        n = cur->get(segs[i].name);
        ctx.mark_define(*n, origin);
      }
      if (segs[i].index >= 0) {
        auto a = n->as_array();
        if (!a || static_cast<size_t>(segs[i].index) >= a->size() || !a->get(segs[i].index)->is_table()) {
          ctx.issue(origin, key, "'" + segs[i].name + "[" + std::to_string(segs[i].index) +
                                     "]' is not a table of the config");
          ok = false;
          break;
        }
        n = a->get(segs[i].index);
      }
      cur = n->as_table();
      if (!cur) {
        ctx.issue(origin, key, "'" + segs[i].name + "' is " + type_name(*n) + ", not a table");
        ok = false;
      }
    }
    if (ok) set_value(*cur, segs.back().name, value, ctx, origin);
  }
}

// ------------------------------------------------------------------ sweeps

using ArrayIsValue = std::function<bool(const std::string& key, const toml::array& a)>;

bool all_arrays(const toml::array& a) {
  if (a.empty()) return false;
  for (const auto& e : a)
    if (!e.is_array()) return false;
  return true;
}

std::pair<int, int> position(const Ctx& ctx, const toml::node& n) {
  if (ctx.define_origin.count(&n)) return {std::numeric_limits<int>::max(), 0};
  return {static_cast<int>(n.source().begin.line), static_cast<int>(n.source().begin.column)};
}

// The alternatives of one option: the elements of a sweep, or the value itself.
// Returns false (after an issue) for an empty sweep.
bool alternatives(const std::string& key, const toml::node& n, const std::string& field,
                  const ArrayIsValue& is_value, Ctx& ctx, std::vector<const toml::node*>& out,
                  bool& swept) {
  swept = false;
  out.clear();
  if (auto t = n.as_table(); t && t->size() == 1 && t->contains("sweep")) {
    const toml::node* s = t->get("sweep");
    auto a = s->as_array();
    if (!a || a->empty()) {
      ctx.issue(ctx.where(*s), field + ".sweep", "expected a non-empty array of values, " + found(*s));
      return false;
    }
    for (const auto& e : *a) out.push_back(&e);
    swept = true;
    return true;
  }
  if (auto a = n.as_array(); a && !is_value(key, *a)) {
    if (a->empty()) {
      ctx.issue(ctx.where(n), field,
                "expected a value or a non-empty list of values (a sweep), found an empty array");
      return false;
    }
    for (const auto& e : *a) out.push_back(&e);
    swept = true;
    return true;
  }
  out.push_back(&n);
  return true;
}

struct Expansion {
  std::vector<Combo> combos;
  std::set<std::string> swept;  // keys that are sweeps
  bool ok = true;
};

// Expands one table's sweeps: the cartesian product over its swept keys, with
// the groups named by `zip` advanced together. Axes are ordered by position in
// the file (the first is the outermost loop).
Expansion expand(const toml::table& t, const std::string& section, const ArrayIsValue& is_value,
                 const std::set<std::string>& no_sweep, Ctx& ctx) {
  Expansion ex;
  struct Axis {
    std::vector<std::string> keys;
    std::vector<std::vector<const toml::node*>> values;  // per key
    std::pair<int, int> pos;
    size_t size() const { return values.empty() ? 1 : values[0].size(); }
  };
  std::map<std::string, std::vector<const toml::node*>> alts;
  std::map<std::string, std::pair<int, int>> pos;
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (key == "zip") continue;
    std::vector<const toml::node*> a;
    bool swept = false;
    if (!alternatives(key, v, section + "." + key, is_value, ctx, a, swept)) {
      ex.ok = false;
      continue;
    }
    if (swept && no_sweep.count(key)) {
      ctx.issue(ctx.where(v), section + "." + key,
                "cannot be a sweep (expected a single value, found a list of " +
                    std::to_string(a.size()) + ")");
      ex.ok = false;
      continue;
    }
    if (swept) ex.swept.insert(key);
    alts[key] = a;
    pos[key] = position(ctx, v);
  }
  // zip groups
  std::vector<std::vector<std::string>> groups;
  if (const toml::node* z = t.get("zip")) {
    const std::string field = section + ".zip";
    auto za = z->as_array();
    bool good = za && !za->empty();
    if (good) {
      if (all_arrays(*za)) {
        for (const auto& g : *za) {
          std::vector<std::string> keys;
          for (const auto& e : *g.as_array()) {
            if (!e.is_string()) good = false;
            else keys.push_back(e.as_string()->get());
          }
          groups.push_back(keys);
        }
      } else {
        std::vector<std::string> keys;
        for (const auto& e : *za) {
          if (!e.is_string()) good = false;
          else keys.push_back(e.as_string()->get());
        }
        groups.push_back(keys);
      }
    }
    if (!good) {
      ctx.issue(ctx.where(*z), field,
                "expected a list of key names (or a list of such lists), " + found(*z));
      ex.ok = false;
      groups.clear();
    }
    std::set<std::string> used;
    for (const auto& g : groups) {
      if (g.size() < 2) {
        ctx.issue(ctx.where(*z), field, "each zip group needs at least two keys, found [" + join(g) + "]");
        ex.ok = false;
      }
      size_t len = 0;
      for (const auto& k : g) {
        if (!used.insert(k).second) {
          ctx.issue(ctx.where(*z), field, "key '" + k + "' appears in more than one zip group");
          ex.ok = false;
        }
        auto it = alts.find(k);
        if (it == alts.end() || !ex.swept.count(k)) {
          ctx.issue(ctx.where(*z), field,
                    "'" + k + "' is not a sweep of this table (zip pairs up lists of equal length)");
          ex.ok = false;
          continue;
        }
        if (len == 0) len = it->second.size();
        else if (it->second.size() != len) {
          ctx.issue(ctx.where(*z), field,
                    "zipped lists must have equal lengths, found " + std::to_string(len) + " for '" +
                        g[0] + "' and " + std::to_string(it->second.size()) + " for '" + k + "'");
          ex.ok = false;
        }
      }
    }
  }
  if (!ex.ok) return ex;
  std::vector<Axis> axes;
  std::set<std::string> in_group;
  for (const auto& g : groups) {
    Axis ax;
    ax.pos = {std::numeric_limits<int>::max(), 0};
    for (const auto& k : g) {
      ax.keys.push_back(k);
      ax.values.push_back(alts[k]);
      ax.pos = std::min(ax.pos, pos[k]);
      in_group.insert(k);
    }
    axes.push_back(ax);
  }
  for (const auto& [k, a] : alts) {
    if (in_group.count(k)) continue;
    Axis ax;
    ax.keys = {k};
    ax.values = {a};
    ax.pos = pos[k];
    axes.push_back(ax);
  }
  std::stable_sort(axes.begin(), axes.end(), [](const Axis& a, const Axis& b) { return a.pos < b.pos; });
  size_t total = 1;
  for (const auto& ax : axes) {
    total *= ax.size();
    if (total > kMaxRuns) {
      ctx.issue(ctx.where(t), section,
                "the sweeps expand to more than " + std::to_string(kMaxRuns) + " combinations");
      ex.ok = false;
      return ex;
    }
  }
  std::vector<size_t> idx(axes.size(), 0);
  for (size_t n = 0; n < total; ++n) {
    Combo c;
    for (size_t a = 0; a < axes.size(); ++a)
      for (size_t k = 0; k < axes[a].keys.size(); ++k) c[axes[a].keys[k]] = axes[a].values[k][idx[a]];
    ex.combos.push_back(std::move(c));
    for (size_t a = axes.size(); a-- > 0;) {
      if (++idx[a] < axes[a].size()) break;
      idx[a] = 0;
    }
  }
  return ex;
}

// ------------------------------------------------------------------ typed reading

// Reads the values of one combination, reporting each problem at its key's location.
class Reader {
 public:
  Reader(Ctx& ctx, const Combo& c, std::string section, std::string table_where)
      : ctx_(ctx), c_(c), section_(std::move(section)), where_(std::move(table_where)) {}

  bool has(const std::string& k) const { return c_.count(k) != 0; }
  const toml::node* take(const std::string& k) {
    auto it = c_.find(k);
    if (it == c_.end()) return nullptr;
    used_.insert(k);
    return it->second;
  }
  std::string where(const std::string& k) const {
    auto it = c_.find(k);
    return it == c_.end() ? where_ : ctx_.where(*it->second);
  }
  const std::string& table_where() const { return where_; }
  const std::string& section() const { return section_; }
  std::string field(const std::string& k) const { return section_ + "." + k; }
  void fail(const std::string& k, const std::string& rule) {
    ctx_.issue(where(k), field(k), rule);
    failed_ = true;
  }
  void fail_table(const std::string& rule) {
    ctx_.issue(where_, section_, rule);
    failed_ = true;
  }
  bool failed() const { return failed_; }
  // Marks the combination invalid when a nested reader already reported why.
  void mark_failed() { failed_ = true; }

  int64_t integer(const std::string& k, int64_t def, int64_t lo, int64_t hi) {
    const toml::node* n = take(k);
    if (!n) return def;
    auto v = n->as_integer();
    if (!v) {
      fail(k, "expected an integer " + range_int(lo, hi) + ", " + found(*n));
      return def;
    }
    if (v->get() < lo || v->get() > hi) {
      fail(k, "expected an integer " + range_int(lo, hi) + ", found " + std::to_string(v->get()));
      return def;
    }
    return v->get();
  }
  double number(const std::string& k, double def, double lo, double hi, bool lo_open = false) {
    const toml::node* n = take(k);
    if (!n) return def;
    double x;
    if (auto i = n->as_integer()) x = static_cast<double>(i->get());
    else if (auto f = n->as_floating_point()) x = f->get();
    else {
      fail(k, "expected a number " + range_num(lo, hi, lo_open) + ", " + found(*n));
      return def;
    }
    if (!std::isfinite(x) || (lo_open ? x <= lo : x < lo) || x > hi) {
      fail(k, "expected a number " + range_num(lo, hi, lo_open) + ", found " + fmt_num(x));
      return def;
    }
    return x;
  }
  bool boolean(const std::string& k, bool def) {
    const toml::node* n = take(k);
    if (!n) return def;
    auto v = n->as_boolean();
    if (!v) {
      fail(k, "expected true or false, " + found(*n));
      return def;
    }
    return v->get();
  }
  std::string text(const std::string& k, const std::string& def) {
    const toml::node* n = take(k);
    if (!n) return def;
    auto v = n->as_string();
    if (!v) {
      fail(k, "expected a string, " + found(*n));
      return def;
    }
    return v->get();
  }
  std::string choice(const std::string& k, const std::string& def, const std::vector<std::string>& choices) {
    const toml::node* n = take(k);
    if (!n) return def;
    auto v = n->as_string();
    std::string list;
    for (size_t i = 0; i < choices.size(); ++i) list += (i ? ", " : "") + ("\"" + choices[i] + "\"");
    if (!v) {
      fail(k, "expected one of " + list + ", " + found(*n));
      return def;
    }
    if (!contains(choices, v->get())) {
      fail(k, "expected one of " + list + ", found \"" + v->get() + "\"" + did_you_mean(v->get(), choices));
      return def;
    }
    return v->get();
  }
  // Reports every key not read: unknown keys, and keys of other kinds.
  void finish(const std::vector<std::string>& accepted, const std::string& what,
              const std::map<std::string, std::vector<std::string>>* other_kinds = nullptr) {
    for (const auto& [k, n] : c_) {
      if (used_.count(k)) continue;
      std::vector<std::string> owners;
      if (other_kinds)
        for (const auto& [kind, keys] : *other_kinds)
          if (contains(keys, k)) owners.push_back(kind);
      if (!owners.empty())
        fail(k, "does not apply to " + what + " (it is a key of kind " + join(owners, ", ") + ")");
      else
        fail(k, "unknown key for " + what + " (accepted: " + join(accepted) + ")" + did_you_mean(k, accepted));
    }
  }

 private:
  static std::string range_int(int64_t lo, int64_t hi) {
    if (hi == std::numeric_limits<int64_t>::max()) return ">= " + std::to_string(lo);
    return "in " + std::to_string(lo) + ".." + std::to_string(hi);
  }
  static std::string range_num(double lo, double hi, bool lo_open) {
    if (hi == std::numeric_limits<double>::infinity()) return (lo_open ? "> " : ">= ") + fmt_num(lo);
    return std::string("in ") + (lo_open ? "(" : "[") + fmt_num(lo) + ", " + fmt_num(hi) + "]";
  }
  Ctx& ctx_;
  const Combo& c_;
  std::string section_, where_;
  std::set<std::string> used_;
  bool failed_ = false;
};

constexpr int64_t kIntMax = std::numeric_limits<int64_t>::max();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Combo of a plain (non-sweeping) table.
Combo plain_combo(const toml::table& t) {
  Combo c;
  for (const auto& [k, v] : t) c[std::string(k.str())] = &v;
  return c;
}

bool never_value(const std::string&, const toml::array&) { return false; }

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
  r.finish(config_keys("experiment"), "[experiment]");
  return e;
}

SceneSettings read_scene(const toml::table* t, Ctx& ctx) {
  SceneSettings s;
  if (!t) return s;
  s.named = true;
  const Combo c = plain_combo(*t);
  Reader r(ctx, c, "scene", ctx.where(*t));
  if (const toml::node* n = r.take("light")) {
    auto a = n->as_array();
    bool ok = a && a->size() == 3;
    Vec3 p = Vec3::Zero();
    for (size_t i = 0; ok && i < 3; ++i) {
      const auto& e = *a->get(i);
      if (auto x = e.as_integer()) p[i] = static_cast<double>(x->get());
      else if (auto f = e.as_floating_point()) p[i] = f->get();
      else ok = false;
      if (!std::isfinite(p[i])) ok = false;
    }
    if (!ok) r.fail("light", "expected a position [x, y, z] of three finite numbers, " + found(*n));
    else if (p.norm() <= 1.0) r.fail("light", "expected a position outside the unit sphere (|p| > 1), found |p| = " + fmt_num(p.norm()));
    else s.light = p;
  }
  s.intensity = r.number("intensity", s.intensity, 0.0, kInf, true);
  s.size = static_cast<int>(r.integer("size", s.size, 16, 1024));
  // SH lighting (factor/lighting.h): an environment map with a measured band
  // limit, or an explicit order (alone: the point light band-limited to it).
  const bool has_env = r.has("environment"), has_order = r.has("lighting_order");
  const std::string env = r.text("environment", "");
  s.environment_eps = r.number("environment_eps", s.environment_eps, 0.0, 1.0, true);
  s.lighting_order = static_cast<int>(r.integer("lighting_order", -1, 0, 60));
  s.lighting_nodes = static_cast<int>(r.integer("lighting_nodes", 0, 0, 512));
  if (r.has("environment_eps") && (!has_env || has_order))
    r.fail("environment_eps", has_env ? "environment_eps measures the band limit, but lighting_order fixes it: remove one"
                                      : "environment_eps needs environment = \"<lat-long map>\"");
  if (has_env && (r.has("light") || r.has("intensity")))
    r.fail(r.has("light") ? "light" : "intensity",
           "light and intensity describe the point light; with environment the map's radiance lights the sphere");
  if (has_env && !r.failed()) {
    std::vector<std::string> tried;
    s.environment = ctx.resolve(env, &tried);
    if (s.environment.empty()) {
      r.fail("environment", "file not found (looked for " + join(tried, ", ") + ")");
    } else {
      try {
        const LatLongMap map = read_latlong(s.environment);
        const int cap = std::min(60, (map.height - 1) / 2);
        if (has_order) {
          if (s.lighting_order > cap)
            throw std::invalid_argument(s.environment + ": lighting_order " + std::to_string(s.lighting_order) +
                                        " exceeds the order a " + std::to_string(map.width) + "x" +
                                        std::to_string(map.height) + " map resolves exactly (" + std::to_string(cap) + ")");
          ShLighting l = project_latlong(map, s.lighting_order);
          l.band_limit = s.lighting_order;
          s.lighting = std::make_shared<const ShLighting>(std::move(l));
        } else {
          s.lighting = std::make_shared<const ShLighting>(environment_lighting(map, s.environment_eps, cap));
        }
      } catch (const std::exception& e) {
        r.fail("environment", e.what());
      }
    }
  } else if (has_order && !r.failed()) {
    const double d2 = s.light.squaredNorm();
    s.lighting = std::make_shared<const ShLighting>(
        directional_lighting(s.light, Rgb::Constant(s.intensity / d2), s.lighting_order));
  }
  r.finish(config_keys("scene"), "[scene]");
  return s;
}

// The scene's SH lighting band limit L caps SH orders (notes §2.2: F_B =
// min(F_L, F_rho); BRDF bands above L do not change the shading). Recorded in
// the options (so in run ids) as lighting_cap.
void apply_lighting_cap(Plan& plan, Ctx& ctx) {
  for (auto& m : plan.methods) {
    if (m.kind == "sh-r" && m.shrm && !plan.scene.lighting)
      ctx.issue(m.where, "method.shrm",
                "shrm = true needs SH lighting: set [scene] environment = \"<lat-long map>\" or lighting_order");
    if (!plan.scene.lighting || (m.kind != "sh-k" && m.kind != "sh-r")) continue;
    const int L = plan.scene.lighting->order;
    json& o = m.options;
    o["lighting_cap"] = L;
    if (m.kind == "sh-k") {
      if (m.tolerance) m.cap = std::min(m.cap, L);
      m.shk.order = std::min(m.shk.order, L);
      o["order"] = m.shk.order;
    } else {
      m.shr.max_order = std::min(m.shr.max_order, L);
      if (m.shr.order > L) m.shr.order = L;
      if (m.tolerance) m.cap = std::min(m.cap, L);
      o["max_order"] = m.shr.max_order;
      o["order"] = m.shr.order;
    }
  }
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
      ParamDict params(r.table_where() + ": " + section);
      json pj = json::object();
      std::vector<std::string> label_parts;
      std::map<std::string, std::string> param_where;
      for (const auto& [k, n] : c) {
        if (k == "preset" || k == "model" || k == "file" || k == "name") continue;
        r.take(k);
        param_where[k] = ctx.where(*n);
        if (auto v = n->as_integer()) {
          params.set_numbers(k, {static_cast<double>(v->get())});
          pj[k] = v->get();
          label_parts.push_back(k + "=" + std::to_string(v->get()));
        } else if (auto f = n->as_floating_point()) {
          if (!std::isfinite(f->get())) {
            r.fail(k, "expected a finite number, found " + fmt_num(f->get()));
            continue;
          }
          params.set_numbers(k, {f->get()});
          pj[k] = f->get();
          label_parts.push_back(k + "=" + fmt_num(f->get()));
        } else if (auto s = n->as_string()) {
          params.set_string(k, s->get());
          pj[k] = s->get();
          label_parts.push_back(k + "=" + s->get());
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
          params.set_numbers(k, xs);
          pj[k] = xs;
          label_parts.push_back(k + "=" + txt);
        } else {
          r.fail(k, "expected a number, three numbers or a word (a BRDF parameter), " + found(*n));
        }
      }
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
          b.brdf = Catalogue::global().load_file(resolved, params);
          b.identity = {{"file", fs::path(src).filename().string()},
                        {"digest", file_hash(resolved)},
                        {"options", pj}};
          b.label = name.empty() ? src : name;
        } else {
          b.brdf = Catalogue::global().make(src, params);
          b.identity = {{src_key, src}, {"params", pj}, {"eval", b.brdf->to_string()}};
          b.label = name.empty() ? src : name;
        }
      } catch (const std::exception& e) {
        // Point at the parameter the message names, when it names one.
        std::string msg = e.what();
        const std::string prefix = r.table_where() + ": " + section;
        std::string where = r.table_where(), field = section;
        for (const auto& [k, w] : param_where)
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
      if (name.empty() && !label_parts.empty()) b.label += ":" + join(label_parts, ",");
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
        s.resolution = static_cast<int>(r.integer("resolution", 16, 2, 256));
        if (s.resolution > kMaxSampleGridResolution)  // brdfs/sampleset.h: bounded memory
          r.fail("resolution", "expected at most " + std::to_string(kMaxSampleGridResolution) +
                                   " (a res^4 grid: 64 gives about 1e7 pairs), found " +
                                   std::to_string(s.resolution));
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

bool method_array_is_value(const std::string& key, const toml::array& a) {
  if (key == "guesses" || key == "projections" || key == "texture_ladder") return !all_arrays(a);
  return false;
}

FitOptions::Solver parse_solver(const std::string& s) {
  if (s == "dense") return FitOptions::Solver::Dense;
  if (s == "sparse") return FitOptions::Solver::Sparse;
  if (s == "qr") return FitOptions::Solver::ReferenceQR;
  return FitOptions::Solver::Auto;
}

void read_fit_options(Reader& r, FitOptions& f, json& o) {
  f.eps = r.number("eps", f.eps, 0.0, 1.0, true);
  f.smoothing = r.number("smoothing", f.smoothing, 0.0, kInf);
  f.subtract_eps = r.boolean("subtract_eps", f.subtract_eps);
  f.solve_last = static_cast<int>(r.integer("solve_last", f.solve_last, 1, 64));
  const std::string solver = r.choice("solver", "auto", {"auto", "dense", "sparse", "qr"});
  f.solver = parse_solver(solver);
  o["eps"] = f.eps;
  o["smoothing"] = f.smoothing;
  o["subtract_eps"] = f.subtract_eps;
  o["solve_last"] = f.solve_last;
  o["solver"] = solver;
}

Parameterization read_param(Reader& r, const std::string& key, Parameterization def) {
  const std::string s = r.choice(key, to_string(def), {"wiwo", "halfdiff"});
  return parse_parameterization(s);
}

// texture_size: an integer lo..hi, or "auto": the resolution is then chosen by
// the method's tolerance from texture_ladder (default 8, 12, 16, 24, 32;
// ascending integers in lo..hi), filled into m.texture_ladder. Returns the
// fixed size, or the ladder's largest entry for "auto"; sets o's entries.
int read_texture_size(Reader& r, MethodVariant& m, json& o, int def, int lo, int hi) {
  const std::string range = "in " + std::to_string(lo) + ".." + std::to_string(hi);
  int size = def;
  bool is_auto = false;
  if (const toml::node* n = r.take("texture_size")) {
    auto str = n->as_string();
    auto v = n->as_integer();
    if (str && str->get() == "auto") is_auto = true;
    else if (v && v->get() >= lo && v->get() <= hi) size = static_cast<int>(v->get());
    else r.fail("texture_size", "expected an integer " + range + " or \"auto\", " + found(*n));
  }
  std::vector<int> ladder = default_texture_ladder();
  if (const toml::node* l = r.take("texture_ladder")) {
    if (!is_auto) r.fail("texture_ladder", "texture_ladder applies only with texture_size = \"auto\"");
    const auto* a = l->as_array();
    if (!a || a->empty()) {
      r.fail("texture_ladder", "expected a non-empty list of integers " + range + ", e.g. [8, 12, 16, 24, 32], " + found(*l));
    } else {
      ladder.clear();
      for (const auto& e : *a) {
        auto i = e.as_integer();
        if (!i || i->get() < lo || i->get() > hi) {
          r.fail("texture_ladder", "expected integers " + range + ", found an element " + show(e));
          break;
        }
        if (!ladder.empty() && i->get() <= ladder.back()) {
          r.fail("texture_ladder", "expected strictly ascending resolutions, found " + std::to_string(i->get()) +
                                       " after " + std::to_string(ladder.back()));
          break;
        }
        ladder.push_back(static_cast<int>(i->get()));
      }
    }
  }
  if (is_auto) {
    if (!ladder.empty()) size = ladder.back();
    m.texture_ladder = ladder;
    o["texture_size"] = "auto";
    o["texture_ladder"] = ladder;
  } else {
    o["texture_size"] = size;
  }
  return size;
}

// The method's `tolerance` table, also recorded in its options `o` (so the run id).
std::optional<Tolerance> read_tolerance(Reader& r, Ctx& ctx, json& o) {
  const toml::node* n = r.take("tolerance");
  if (!n) return std::nullopt;
  auto t = n->as_table();
  if (!t) {
    r.fail("tolerance", "expected a table { metric = \"rel_mse\", value = 0.01 }, " + found(*n));
    return std::nullopt;
  }
  const Combo c = plain_combo(*t);
  Reader tr(ctx, c, r.field("tolerance"), ctx.where(*n));
  Tolerance tol;
  tol.metric = tr.choice("metric", "rel_mse",
                         {"rel_mse", "rel_mae", "rel_max", "lin_rmse", "lin_mae", "lin_max", "cos_rmse"});
  if (!tr.has("value")) tr.fail_table("needs value = <error target > 0>");
  tol.value = tr.number("value", 1.0, 0.0, kInf, true);
  tr.finish(config_keys("tolerance"), "tolerance");
  if (tr.failed()) {
    r.mark_failed();
    return std::nullopt;
  }
  o["tolerance"] = {{"metric", tol.metric}, {"value", tol.value}};
  return tol;
}

void read_projections(Reader& r, Ctx& ctx, MethodVariant& m, json& o) {
  const toml::node* n = r.take("projections");
  if (!n) {
    r.fail_table("kind = \"fit\" needs projections = [{ name = \"wi\" }, { matrix = [[...], [...]] }, ...]");
    return;
  }
  auto a = n->as_array();
  if (!a || a->empty()) {
    r.fail("projections", "expected a non-empty list of tables "
                          "{ parameterization, matrix = [[4 numbers], [4 numbers]] or name, reciprocal }, " +
                              found(*n));
    return;
  }
  json list = json::array();
  for (size_t j = 0; j < a->size(); ++j) {
    const toml::node& e = *a->get(j);
    const std::string field = r.field("projections[" + std::to_string(j) + "]");
    auto t = e.as_table();
    if (!t) {
      ctx.issue(ctx.where(e), field, "expected a table { parameterization, matrix or name, reciprocal }, " + found(e));
      r.mark_failed();
      continue;
    }
    const Combo c = plain_combo(*t);
    Reader pr(ctx, c, field, ctx.where(e));
    const bool has_param = pr.has("parameterization");
    Parameterization param = read_param(pr, "parameterization", m.param);
    const bool recip = pr.boolean("reciprocal", m.reciprocity);
    Mat24 P = Mat24::Zero();
    std::string name;
    if (pr.has("matrix") == pr.has("name")) {
      if (pr.has("matrix"))
        pr.fail("name", "matrix and name are alternatives: give one of them, found both");
      else
        pr.fail_table("expected matrix = [[4 numbers], [4 numbers]] or name = \"wi\" | \"wo\" | \"h\" | \"d\"");
    } else if (pr.has("name")) {
      name = pr.choice("name", "wi", {"wi", "wo", "h", "d"});
      const Parameterization implied = (name == "wi" || name == "wo") ? Parameterization::WiWo
                                                                       : Parameterization::HalfDiff;
      if (has_param && param != implied)
        pr.fail("name", "name = \"" + name + "\" is a " + to_string(implied) +
                            " projection, but parameterization = \"" + to_string(param) + "\"");
      param = implied;
      const bool first = name == "wi" || name == "h";
      P = first ? projection_first_pair(param, m.texture_size).P : projection_second_pair(param, m.texture_size).P;
    } else {
      const toml::node* mn = pr.take("matrix");
      auto rows = mn->as_array();
      bool ok = rows && rows->size() == 2;
      for (size_t rr = 0; ok && rr < 2; ++rr) {
        auto row = rows->get(rr)->as_array();
        ok = row && row->size() == 4;
        for (size_t cc = 0; ok && cc < 4; ++cc) {
          const auto v = row->get(cc)->value<double>();
          ok = v.has_value() && std::isfinite(*v);
          if (ok) P(rr, cc) = *v;
        }
      }
      if (!ok) pr.fail("matrix", "expected [[4 numbers], [4 numbers]] (a 2x4 matrix), " + found(*mn));
    }
    pr.finish(config_keys("projection"), "a projection");
    if (pr.failed()) {
      r.mark_failed();
      continue;
    }
    Projection proj{param, P, m.texture_size};
    try {
      proj.validate();
    } catch (const std::exception& ex) {
      ctx.issue(pr.where(name.empty() ? "matrix" : "name"), field + (name.empty() ? ".matrix" : ".name"),
                std::string(ex.what()) + " (rows must be orthonormal)");
      r.mark_failed();
      continue;
    }
    m.projections.push_back({proj, recip, std::nullopt});
    json pj = {{"parameterization", to_string(param)}, {"reciprocal", recip}};
    if (!name.empty()) pj["name"] = name;
    pj["matrix"] = {{P(0, 0), P(0, 1), P(0, 2), P(0, 3)}, {P(1, 0), P(1, 1), P(1, 2), P(1, 3)}};
    list.push_back(pj);
  }
  o["projections"] = list;
}

std::map<std::string, std::vector<std::string>> other_kind_keys(const std::string& kind) {
  std::map<std::string, std::vector<std::string>> m;
  for (const auto& k : kMethodKinds)
    if (k != kind) m[k] = config_keys("method:" + k);
  return m;
}

int hardware_cores() { return std::max(1u, std::thread::hardware_concurrency()); }

void read_method(Reader& r, Ctx& ctx, const std::string& kind, uint64_t base_seed, MethodVariant& m) {
  json o = {{"kind", kind}};
  m.kind = kind;
  m.label = r.text("label", kind);
  const std::string refine = r.choice("refine", "none", {"none", "linear", "cosine", "blend"});
  const bool homomorphic = kind == "mccool" || kind == "fit" || kind == "search";
  if (refine != "none" && !homomorphic)
    r.fail("refine", "refine = \"" + refine + "\" applies to the homomorphic kinds (mccool, fit, search) only; kind = \"" +
                         kind + "\" needs refine = \"none\"");
  m.refine = refine;
  o["refine"] = refine;
  if (homomorphic) {
    // Read whatever refine is (so that a sweep over refine may carry them), but
    // hashed only when a refinement runs: refine = "none" runs stay identical.
    RefineOptions& ro = m.refine_options;
    ro.objective = refine == "none" ? ro.objective : refine;
    ro.blend_weight = r.number("refine_blend", ro.blend_weight, 0.0, kInf);
    ro.max_iterations = static_cast<int>(r.integer("refine_iterations", ro.max_iterations, 1, 100000));
    const bool own_smoothing = r.has("refine_smoothing");
    ro.smoothing = r.number("refine_smoothing", ro.smoothing, 0.0, kInf);
    if (refine != "none") {
      if (refine == "blend") o["refine_blend"] = ro.blend_weight;
      o["refine_iterations"] = ro.max_iterations;
      // Default: the fit's own smoothing (filled in below, once it is read).
      o["refine_smoothing"] = own_smoothing ? json(ro.smoothing) : json();
    }
    if (!own_smoothing) ro.smoothing = -1;  // = the fit's smoothing
  }
  const auto cap_terms = [&](int def_cap) {
    if (m.tolerance) {
      m.cap = m.terms;
      if (!r.has("terms")) m.cap = def_cap;
      o["max_terms"] = m.cap;
    }
  };

  if (kind == "mccool") {
    m.texture_size = read_texture_size(r, m, o, 16, 2, 1024);
    m.tolerance = read_tolerance(r, ctx, o);
    if (m.tolerance && m.texture_ladder.empty())
      r.fail("tolerance", "kind = \"mccool\" has exactly 2 textures: a tolerance can only choose the resolution "
                          "(set texture_size = \"auto\")");
    if (const toml::node* tn = r.take("terms"); tn && !(tn->is_integer() && tn->as_integer()->get() == 2))
      r.fail("terms", "kind = \"mccool\" has exactly 2 textures (p(wi)/p(wo) shared, and p(h)), found " +
                          show(*tn));
    m.terms = 2;
    read_fit_options(r, m.fit, o);
    m.param = Parameterization::WiWo;
    o["terms"] = 2;
  } else if (kind == "fit") {
    m.texture_size = read_texture_size(r, m, o, 16, 2, 1024);
    m.param = read_param(r, "parameterization", Parameterization::WiWo);
    m.reciprocity = r.boolean("reciprocity", false);
    read_fit_options(r, m.fit, o);
    m.tolerance = read_tolerance(r, ctx, o);
    o["parameterization"] = to_string(m.param);
    o["reciprocity"] = m.reciprocity;
    read_projections(r, ctx, m, o);
    const int n = static_cast<int>(m.projections.size());
    m.terms = static_cast<int>(r.integer("terms", std::max(n, 1), 1, 1024));
    if (n > 0 && m.terms > n)
      r.fail("terms", "terms = " + std::to_string(m.terms) + " but only " + std::to_string(n) +
                          " projections are given (terms uses the first `terms` of them)");
    o["terms"] = m.terms;
    cap_terms(n);
  } else if (kind == "search") {
    SearchOptions& s = m.search;
    m.param = read_param(r, "parameterization", s.param);
    m.tolerance = read_tolerance(r, ctx, o);
    // With a tolerance, `terms` is the cap (default 8): the greedy search stops
    // at the first term whose refit reaches the target.
    m.terms = static_cast<int>(r.integer("terms", m.tolerance ? 8 : s.terms, 1, 64));
    if (m.tolerance) m.cap = m.terms;
    m.texture_size = static_cast<int>(r.integer("texture_size", s.texture_size, 2, 1024));
    s.search_texture_size = static_cast<int>(r.integer("search_texture_size", 0, 0, 1024));
    if (s.search_texture_size == 1) r.fail("search_texture_size", "expected 0 (same as texture_size) or 2..1024, found 1");
    s.restarts = static_cast<int>(r.integer("restarts", s.restarts, 0, 100000));
    if (const toml::node* g = r.take("guesses")) {
      auto a = g->as_array();
      if (!a) r.fail("guesses", "expected a list of \"wi\", \"wo\", \"wi+wo\", " + found(*g));
      else
        for (const auto& e : *a) {
          auto str = e.as_string();
          if (!str) {
            r.fail("guesses", "expected a list of \"wi\", \"wo\", \"wi+wo\", found an element " + show(e));
            continue;
          }
          try {
            guess_rotation(str->get());
            s.guesses.push_back(str->get());
          } catch (const std::exception&) {
            r.fail("guesses", "expected \"wi\", \"wo\" or \"wi+wo\", found \"" + str->get() + "\"");
          }
        }
    }
    m.reciprocity = r.boolean("reciprocity", false);
    s.optimizer = r.choice("optimizer", s.optimizer,
                           {"powell", "praxis", "bobyqa", "neldermead", "sbplx", "direct", "crs"});
    s.powell.ftol = r.number("ftol", s.powell.ftol, 0.0, 1.0, true);
    s.powell.line_tol = r.number("line_tol", s.powell.line_tol, 0.0, 10.0, true);
    s.powell.initial_step = r.number("initial_step", s.powell.initial_step, 0.0, 10.0, true);
    s.powell.max_sweeps = static_cast<int>(r.integer("max_sweeps", s.powell.max_sweeps, 1, 100000));
    s.powell.max_evaluations = static_cast<int>(r.integer("max_evaluations", s.powell.max_evaluations, 10, 100000000));
    s.threads = static_cast<int>(r.integer("threads", 0, 0, 1024));
    s.beam = static_cast<int>(r.integer("beam", s.beam, 1, 100000));
    s.backfit_sweeps = static_cast<int>(r.integer("backfit_sweeps", s.backfit_sweeps, 0, 1000));
    s.backfit_restarts = static_cast<int>(r.integer("backfit_restarts", s.backfit_restarts, 0, 100000));
    m.seed = static_cast<uint64_t>(r.integer("seed", static_cast<int64_t>(base_seed), 0, kIntMax));
    read_fit_options(r, m.fit, o);
    if (s.restarts == 0 && s.guesses.empty() && !r.failed())
      r.fail("restarts", "restarts = 0 and no guesses leave nothing to search from (give restarts >= 1 or guesses)");
    s.terms = m.terms;
    s.param = m.param;
    s.texture_size = m.texture_size;
    s.reciprocity = m.reciprocity;
    s.fit = m.fit;
    s.seed = m.seed;
    o["parameterization"] = to_string(m.param);
    o["terms"] = m.terms;
    o["texture_size"] = m.texture_size;
    o["search_texture_size"] = s.search_texture_size;
    o["restarts"] = s.restarts;
    o["guesses"] = s.guesses;
    o["reciprocity"] = m.reciprocity;
    o["optimizer"] = s.optimizer;
    o["ftol"] = s.powell.ftol;
    o["line_tol"] = s.powell.line_tol;
    o["initial_step"] = s.powell.initial_step;
    o["max_sweeps"] = s.powell.max_sweeps;
    o["max_evaluations"] = s.powell.max_evaluations;
    o["seed"] = m.seed;
    // Non-greedy options enter the run id only when set, so greedy runs keep their cache.
    if (s.beam != 1) o["beam"] = s.beam;
    if (s.backfit_sweeps != 0) o["backfit_sweeps"] = s.backfit_sweeps;
    if (s.backfit_sweeps != 0 && s.backfit_restarts != 0) o["backfit_restarts"] = s.backfit_restarts;
    if (m.tolerance && s.beam != 1)
      r.fail("tolerance", "a tolerance stops the greedy search after a term, which needs beam = 1; found beam = " +
                              std::to_string(s.beam));
    m.execution["threads"] = s.threads;
    const int starts = s.restarts + static_cast<int>(s.guesses.size());
    m.cores = std::max(1, std::min(s.threads == 0 ? hardware_cores() : s.threads, starts));
    if (!r.failed()) {
      try {
        s.validate();
      } catch (const std::exception& e) {
        r.fail_table(e.what());
      }
    }
  } else if (kind == "svd") {
    SvdOptions& v = m.svd;
    m.texture_size = read_texture_size(r, m, o, v.res, 2, 256);
    m.tolerance = read_tolerance(r, ctx, o);
    m.terms = static_cast<int>(r.integer("terms", m.tolerance ? 16 : v.rank, 1, 100000));
    m.param = read_param(r, "parameterization", v.param);
    v.log = r.boolean("log", v.log);
    if (!v.log)
      for (const char* k : {"eps", "subtract_eps"})
        if (r.has(k)) {
          r.fail(k, std::string(k) + " applies only to the log-space SVD: set log = true or remove " + k);
          r.take(k);
        }
    v.eps = r.number("eps", v.eps, 0.0, 1.0, true);
    v.subtract_eps = r.boolean("subtract_eps", v.subtract_eps);
    v.rim_inset = r.number("rim_inset", v.rim_inset, 0.0, 0.5);  // 0: half a texel (SvdOptions)
    v.extend_below_horizon = r.boolean("extend_below_horizon", v.extend_below_horizon);
    v.float_textures = r.boolean("float_textures", v.float_textures);
    v.res = m.texture_size;
    v.rank = m.terms;
    v.param = m.param;
    o["terms"] = v.rank;
    o["parameterization"] = to_string(v.param);
    o["log"] = v.log;
    o["eps"] = v.eps;
    o["subtract_eps"] = v.subtract_eps;
    o["rim_inset"] = v.rim_inset;
    o["extend_below_horizon"] = v.extend_below_horizon;
    o["float_textures"] = v.float_textures;
    if (m.tolerance) m.cap = m.terms;
    m.cores = hardware_cores();
    if (!r.failed()) {
      try {
        v.validate();
      } catch (const std::exception& e) {
        r.fail_table(e.what());
      }
    }
  } else if (kind == "sh-k") {
    ShkOptions& k = m.shk;
    m.tolerance = read_tolerance(r, ctx, o);
    k.order = static_cast<int>(r.integer("order", m.tolerance ? 30 : k.order, 0, 200));
    m.texture_size = static_cast<int>(r.integer("texture_size", k.view_res, 2, 512));
    k.view_res = m.texture_size;
    k.theta_nodes = static_cast<int>(r.integer("theta_nodes", 0, 0, 100000));
    k.phi_nodes = static_cast<int>(r.integer("phi_nodes", 0, 0, 100000));
    k.rim_inset = r.number("rim_inset", k.rim_inset, 0.0, 0.1, true);
    k.min_cos = r.number("min_cos", k.min_cos, 0.0, 1.0, true);
    k.float_textures = r.boolean("float_textures", k.float_textures);
    // Isotropic BRDFs (azimuthal-invariance test at run time) stored along phi_v = 0 only.
    o["reduce_isotropic"] = r.boolean("reduce_isotropic", true);
    o["order"] = k.order;
    o["texture_size"] = k.view_res;
    o["theta_nodes"] = k.theta_nodes;
    o["phi_nodes"] = k.phi_nodes;
    o["rim_inset"] = k.rim_inset;
    o["min_cos"] = k.min_cos;
    o["float_textures"] = k.float_textures;
    if (m.tolerance) m.cap = k.order;
    m.cores = hardware_cores();
    if (!r.failed()) {
      try {
        k.validate();
      } catch (const std::exception& e) {
        r.fail_table(e.what());
      }
    }
  } else if (kind == "model-fit") {
    ModelFitOptions& f = m.model_fit;
    f.model = r.text("model", f.model);
    f.metric = r.choice("metric", f.metric, {"cosine", "log"});
    f.cube_root = r.boolean("cube_root", f.cube_root);
    if (f.cube_root && f.metric != "cosine")
      r.fail("cube_root", "cube_root = true applies to metric = \"cosine\" only, found metric = \"" + f.metric + "\"");
    f.anisotropic = r.boolean("anisotropic", f.anisotropic);
    f.lobes = static_cast<int>(r.integer("lobes", f.lobes, 1, 3));
    f.eps = r.number("eps", f.eps, 0.0, 1.0, true);
    f.starts = static_cast<int>(r.integer("starts", f.starts, 1, 1000));
    m.seed = static_cast<uint64_t>(r.integer("seed", static_cast<int64_t>(base_seed), 0, kIntMax));
    f.seed = m.seed;
    f.max_iterations = static_cast<int>(r.integer("max_iterations", f.max_iterations, 1, 100000));
    f.threads = static_cast<int>(r.integer("threads", 0, 0, 1024));
    o["model"] = f.model;
    o["metric"] = f.metric;
    o["cube_root"] = f.cube_root;
    o["anisotropic"] = f.anisotropic;
    o["lobes"] = f.lobes;
    o["eps"] = f.eps;
    o["starts"] = f.starts;
    o["seed"] = f.seed;
    o["max_iterations"] = f.max_iterations;
    m.execution["threads"] = f.threads;
    m.cores = std::max(1, f.threads == 0 ? hardware_cores() : f.threads);
    if (!r.failed()) {
      try {
        m.terms = static_cast<int>(check_model_fit(f));
      } catch (const std::exception& e) {
        const std::string msg = e.what();
        // Messages start with the option's name ("model: ...", "lobes: ...").
        const size_t colon = msg.find(':');
        const std::string key = colon == std::string::npos ? "model" : msg.substr(0, colon);
        if (contains(config_keys("method:model-fit"), key)) r.fail(key, msg.substr(colon + 2));
        else r.fail("model", msg);
      }
    }
  } else if (kind == "sh-r") {
    ShrOptions& s = m.shr;
    m.tolerance = read_tolerance(r, ctx, o);
    const bool has_order = r.has("order"), has_view = r.has("view_order");
    s.max_order = static_cast<int>(r.integer("max_order", s.max_order, 0, 400));
    s.max_view_order = static_cast<int>(r.integer("max_view_order", s.max_view_order, 0, 100));
    s.order = static_cast<int>(r.integer("order", -1, 0, 400));
    s.view_order = static_cast<int>(r.integer("view_order", -1, 0, 100));
    if (has_order != has_view)
      r.fail(has_order ? "order" : "view_order",
             "fixed orders need both order and view_order (or neither: orders chosen by energy_eps or tolerance)");
    if ((has_order || has_view) && m.tolerance)
      r.fail("tolerance", "tolerance chooses the orders: remove order/view_order (the caps are max_order, max_view_order)");
    if (has_order && s.order > s.max_order)
      r.fail("order", "order " + std::to_string(s.order) + " exceeds max_order " + std::to_string(s.max_order));
    if (has_view && s.view_order > s.max_view_order)
      r.fail("view_order", "view_order " + std::to_string(s.view_order) + " exceeds max_view_order " +
                               std::to_string(s.max_view_order));
    if (r.has("energy_eps") && (has_order || m.tolerance))
      r.fail("energy_eps", "energy_eps chooses the orders; it contradicts fixed orders or a tolerance");
    s.energy_eps = r.number("energy_eps", s.energy_eps, 0.0, 1.0, true);
    s.theta_i_nodes = static_cast<int>(r.integer("theta_i_nodes", 0, 0, 100000));
    s.theta_o_nodes = static_cast<int>(r.integer("theta_o_nodes", 0, 0, 100000));
    s.phi_nodes = static_cast<int>(r.integer("phi_nodes", 0, 0, 100000));
    s.min_cos = r.number("min_cos", s.min_cos, 0.0, 1.0, true);
    m.shrm = r.boolean("shrm", false);
    if (m.shrm) o["shrm"] = true;  // absent when false: existing run ids unchanged
    o["max_order"] = s.max_order;
    o["max_view_order"] = s.max_view_order;
    o["order"] = s.order;
    o["view_order"] = s.view_order;
    o["energy_eps"] = s.energy_eps;
    o["theta_i_nodes"] = s.theta_i_nodes;
    o["theta_o_nodes"] = s.theta_o_nodes;
    o["phi_nodes"] = s.phi_nodes;
    o["min_cos"] = s.min_cos;
    if (m.tolerance) m.cap = s.max_order;
    m.cores = hardware_cores();
    if (!r.failed()) {
      try {
        s.validate();
      } catch (const std::exception& e) {
        r.fail_table(e.what());
      }
    }
  }
  // One rule for every kind that reads texture_size = "auto" (mccool, fit, svd).
  if (!m.texture_ladder.empty() && !m.tolerance)
    r.fail("texture_size", "texture_size = \"auto\" needs a tolerance (the error target that picks the size)");
  if (!r.failed() && (kind == "mccool" || kind == "fit")) {
    try {
      m.fit.validate();
    } catch (const std::exception& e) {
      r.fail_table(e.what());
    }
  }
  if (homomorphic) {
    RefineOptions& ro = m.refine_options;
    if (ro.smoothing < 0) ro.smoothing = m.fit.smoothing;
    if (refine != "none") o["refine_smoothing"] = ro.smoothing;
    ro.threads = 1;
    if (!r.failed()) {
      try {
        ro.validate();
      } catch (const std::exception& e) {
        r.fail_table(std::string("refinement: ") + e.what());
      }
    }
  }
  r.finish(config_keys("method:" + kind), "kind = \"" + kind + "\"", nullptr);
  m.options = o;
}

void read_methods(const toml::node* node, Ctx& ctx, uint64_t base_seed, std::vector<MethodVariant>& out) {
  if (!node) {
    ctx.issue(ctx.path, "method", "missing: the config needs at least one [[method]] table (kind = \"" +
                                      join(kMethodKinds, "\" | \"") + "\")");
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
        r.fail_table("missing kind (expected one of \"" + join(kMethodKinds, "\", \"") + "\")");
        continue;
      }
      const std::string kind = r.choice("kind", "", kMethodKinds);
      if (r.failed()) continue;
      // Keys of other kinds get a message naming the kinds they belong to.
      for (const auto& [k, n] : c)
        if (!contains(config_keys("method:" + kind), k)) {
          std::vector<std::string> owners;
          for (const auto& [ok, keys] : other_kind_keys(kind))
            if (contains(keys, k)) owners.push_back(ok);
          if (!owners.empty()) {
            r.fail(k, "does not apply to kind = \"" + kind + "\" (it is a key of kind " + join(owners) + ")");
            r.take(k);
          }
        }
      MethodVariant m;
      m.where = r.table_where();
      read_method(r, ctx, kind, base_seed, m);
      if (r.failed()) continue;
      out.push_back(std::move(m));
    }
  }
}

}  // namespace

// ------------------------------------------------------------------ plan

// Counts the runs (experiments/plan_size.h) before anything is expanded.
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
  apply_lighting_cap(plan, ctx);

  // Combinations that need a measured BRDF.
  for (const auto& s : plan.samplings) {
    if (s.kind != "measured") continue;
    for (const auto& b : plan.brdfs)
      if (!b.measured)
        ctx.issue(s.where, "sampling.kind",
                  "kind = \"" + s.kind + "\" without path uses a measured BRDF's own samples, but brdf '" +
                      b.label + "' (" + b.where + ") is not measured: use kind = \"grid\" or \"stratified\"");
  }
  for (const auto& m : plan.methods)
    if (m.kind == "sh-r")
      for (const auto& b : plan.brdfs)
        if (!b.brdf->isotropic())
          ctx.issue(m.where, "method.kind", "sh-r needs an isotropic BRDF, but brdf '" + b.label +
                                                "' is anisotropic (use sh-k)");
  if (!ctx.issues.empty()) throw ConfigError(ctx.issues);

  const json common = {{"v", kRunFormatVersion},
                       {"metric_eps", plan.experiment.metric_eps},
                       {"render", plan.experiment.render},
                       {"export", plan.experiment.export_factors},
                       {"scene", plan.scene.identity()}};
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

}  // namespace bf
