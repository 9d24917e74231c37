// The config reader's machinery (see config_reader.h).
#include "experiments/plan/config_reader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "experiments/plan/toml_depth.h"

#include "brdfs/catalogue.h"
#include "brdfs/params.h"
#include "experiments/common/cli_util.h"
#include "solvers/option_error.h"

namespace bf {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

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

}  // namespace

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
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

// ------------------------------------------------------------------ where

void Ctx::issue(const std::string& where, const std::string& field, const std::string& rule) {
  std::string m = where + ": " + field + ": " + rule;
  if (seen.insert(m).second) issues.push_back(std::move(m));
}

std::string Ctx::where(const toml::node& n) const {
  auto it = define_origin.find(&n);
  if (it != define_origin.end()) return it->second;
  return path + ":" + std::to_string(n.source().begin.line);
}

void Ctx::mark_define(const toml::node& n, const std::string& origin) {
  define_origin[&n] = origin;
  if (auto a = n.as_array())
    for (const auto& e : *a) mark_define(e, origin);
  if (auto t = n.as_table())
    for (const auto& [k, v] : *t) mark_define(v, origin);
}

std::string Ctx::resolve(const std::string& p, std::vector<std::string>* tried) const {
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

// ------------------------------------------------------------------ sweeps


bool all_arrays(const toml::array& a) {
  if (a.empty()) return false;
  for (const auto& e : a)
    if (!e.is_array()) return false;
  return true;
}

namespace {

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

// The `zip` groups of a table: lists of swept keys advanced together, each
// group at least two keys of equal-length sweeps, each key in one group.
std::vector<std::vector<std::string>> zip_groups(const toml::table& t, const std::string& section,
                                                 const std::map<std::string, std::vector<const toml::node*>>& alts,
                                                 Ctx& ctx, Expansion& ex) {
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
  return groups;
}

}  // namespace

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
  const std::vector<std::vector<std::string>> groups = zip_groups(t, section, alts, ctx, ex);
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

namespace {

std::string range_int(int64_t lo, int64_t hi) {
  if (hi == kIntMax) return ">= " + std::to_string(lo);
  return "in " + std::to_string(lo) + ".." + std::to_string(hi);
}

std::string range_num(double lo, double hi, bool lo_open) {
  if (hi == kInf) return (lo_open ? "> " : ">= ") + fmt_num(lo);
  return std::string("in ") + (lo_open ? "(" : "[") + fmt_num(lo) + ", " + fmt_num(hi) + "]";
}

}  // namespace

const toml::node* Reader::take(const std::string& k) {
  auto it = c_.find(k);
  if (it == c_.end()) return nullptr;
  used_.insert(k);
  return it->second;
}

std::string Reader::where(const std::string& k) const {
  auto it = c_.find(k);
  return it == c_.end() ? where_ : ctx_.where(*it->second);
}

void Reader::fail(const std::string& k, const std::string& rule) {
  ctx_.issue(where(k), field(k), rule);
  failed_ = true;
}

void Reader::fail_table(const std::string& rule) {
  ctx_.issue(where_, section_, rule);
  failed_ = true;
}

int64_t Reader::integer(const std::string& k, int64_t def, int64_t lo, int64_t hi) {
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

double Reader::number(const std::string& k, double def, double lo, double hi, bool lo_open) {
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

bool Reader::boolean(const std::string& k, bool def) {
  const toml::node* n = take(k);
  if (!n) return def;
  auto v = n->as_boolean();
  if (!v) {
    fail(k, "expected true or false, " + found(*n));
    return def;
  }
  return v->get();
}

std::string Reader::text(const std::string& k, const std::string& def) {
  const toml::node* n = take(k);
  if (!n) return def;
  auto v = n->as_string();
  if (!v) {
    fail(k, "expected a string, " + found(*n));
    return def;
  }
  return v->get();
}

std::string Reader::choice(const std::string& k, const std::string& def, const std::vector<std::string>& choices) {
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

void Reader::finish(const std::vector<std::string>& accepted, const std::string& what) {
  for (const auto& [k, n] : c_)
    if (!used_.count(k))
      fail(k, "unknown key for " + what + " (accepted: " + join(accepted, ", ") + ")" + did_you_mean(k, accepted));
}

// ------------------------------------------------------------------ key specs

std::string KeySpec::type_cell() const {
  std::string t;
  switch (type) {
    case Type::Integer:
      t = int_hi == kIntMax ? "integer ≥ " + std::to_string(int_lo)
                            : "integer " + std::to_string(int_lo) + ".." + std::to_string(int_hi);
      break;
    case Type::Number:
      t = hi == kInf ? std::string("number ") + (lo_open ? "> " : "≥ ") + fmt_num(lo)
                     : std::string("number in ") + (lo_open ? "(" : "[") + fmt_num(lo) + ", " + fmt_num(hi) + "]";
      break;
    case Type::Boolean: t = "bool"; break;
    case Type::Choice:
      for (size_t i = 0; i < choices.size(); ++i) t += (i ? " \\| " : "") + ("`\"" + choices[i] + "\"`");
      break;
    case Type::Text:
    case Type::Other: t = type_text; break;
  }
  if (!default_text.empty()) t += " (" + default_text + ")";
  return t;
}

const KeySpec& find_key(const std::vector<KeySpec>& keys, const std::string& name) {
  for (const auto& k : keys)
    if (k.name == name) return k;
  throw std::logic_error("find_key: no key '" + name + "'");
}

KeySpec int_key(std::string name, int64_t lo, int64_t hi, std::string def, std::string doc) {
  KeySpec k;
  k.name = std::move(name);
  k.type = KeySpec::Type::Integer;
  k.int_lo = lo;
  k.int_hi = hi;
  k.default_text = std::move(def);
  k.doc = std::move(doc);
  return k;
}

KeySpec num_key(std::string name, double lo, double hi, bool lo_open, std::string def, std::string doc) {
  KeySpec k;
  k.name = std::move(name);
  k.type = KeySpec::Type::Number;
  k.lo = lo;
  k.hi = hi;
  k.lo_open = lo_open;
  k.default_text = std::move(def);
  k.doc = std::move(doc);
  return k;
}

KeySpec bool_key(std::string name, std::string def, std::string doc) {
  KeySpec k;
  k.name = std::move(name);
  k.type = KeySpec::Type::Boolean;
  k.default_text = std::move(def);
  k.doc = std::move(doc);
  return k;
}

KeySpec choice_key(std::string name, std::vector<std::string> choices, std::string def, std::string doc) {
  KeySpec k;
  k.name = std::move(name);
  k.type = KeySpec::Type::Choice;
  k.choices = std::move(choices);
  k.default_text = "`\"" + def + "\"`";
  k.doc = std::move(doc);
  return k;
}

KeySpec other_key(std::string name, std::string type, std::string def, std::string doc) {
  KeySpec k;
  k.name = std::move(name);
  k.type = KeySpec::Type::Other;
  k.type_text = std::move(type);
  k.default_text = std::move(def);
  k.doc = std::move(doc);
  return k;
}

// Combo of a plain (non-sweeping) table.
Combo plain_combo(const toml::table& t) {
  Combo c;
  for (const auto& [k, v] : t) c[std::string(k.str())] = &v;
  return c;
}

bool never_value(const std::string&, const toml::array&) { return false; }


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

void report_invalid(Reader& r, const std::exception& e, const std::vector<std::string>& keys,
                    const std::string& prefix, const std::map<std::string, std::string>& renames) {
  const auto* oe = dynamic_cast<const OptionError*>(&e);
  const auto renamed = oe ? renames.find(oe->field()) : renames.end();
  const std::string key = !oe ? "" : renamed != renames.end() ? renamed->second : oe->field();
  if (!oe || !contains(keys, key)) {
    r.fail_table(prefix + e.what());
    return;
  }
  std::string msg = e.what();
  const std::string lead = oe->field() + ": ";
  if (const size_t at = msg.find(lead); at != std::string::npos) msg = msg.substr(at + lead.size());
  r.fail(key, msg);
}

const std::vector<std::string>& tolerance_keys() {
  static const std::vector<std::string> keys = {"metric", "value"};
  return keys;
}

std::optional<Tolerance> read_tolerance(Reader& r, json& o) {
  const toml::node* n = r.take("tolerance");
  if (!n) return std::nullopt;
  auto t = n->as_table();
  if (!t) {
    r.fail("tolerance", "expected a table { metric = \"rel_mse\", value = 0.01 }, " + found(*n));
    return std::nullopt;
  }
  const Combo c = plain_combo(*t);
  Reader tr(r.ctx(), c, r.field("tolerance"), r.ctx().where(*n));
  Tolerance tol;
  tol.metric = tr.choice("metric", "rel_mse",
                         {"rel_mse", "rel_mae", "rel_max", "lin_rmse", "lin_mae", "lin_max", "cos_rmse",
                          "shade_rmse", "val_rel_mse", "val_cos_rmse", "val_max_ratio"});
  if (!tr.has("value")) tr.fail_table("needs value = <error target > 0>");
  tol.value = tr.number("value", 1.0, 0.0, kInf, true);
  tr.finish(tolerance_keys(), "tolerance");
  if (tr.failed()) {
    r.mark_failed();
    return std::nullopt;
  }
  o["tolerance"] = {{"metric", tol.metric}, {"value", tol.value}};
  return tol;
}

}  // namespace bf
