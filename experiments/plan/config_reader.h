// The machinery of the config reader (config.cpp) shared with the method
// catalogue (experiments/methods/): where a value came from (file:line or a
// -D override), the problems found so far, sweep expansion, and a Reader that
// reads one table's keys with their types and ranges and reports each problem
// at its key. Internal to bf::experiments; users read config.h.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <toml++/toml.h>
#include <unordered_map>
#include <vector>

#include "brdfs/directions.h"
#include "experiments/plan/plan.h"

namespace bf {

// The keys of one table (or of one combination of its sweeps) -> their nodes.
using Combo = std::map<std::string, const toml::node*>;

constexpr int64_t kIntMax = std::numeric_limits<int64_t>::max();
constexpr double kInf = std::numeric_limits<double>::infinity();
// The most runs (and sweep combinations of one table) a config may expand to.
constexpr size_t kMaxRuns = 100000;

std::string fmt_num(double v);
// A short rendering of a value for messages ("found ...").
std::string show(const toml::node& n);
std::string type_name(const toml::node& n);
std::string found(const toml::node& n);
bool contains(const std::vector<std::string>& v, const std::string& s);
// " (did you mean 'x'?)" for the accepted name closest to `key` (edit distance < 3), else "".
std::string did_you_mean(const std::string& key, const std::vector<std::string>& accepted);

// One config key: its name, type and accepted range, documented default and
// meaning. The Reader checks a value against it and docs/experiments.md's key
// tables are printed from it (`brdf-factor list methods`), so a range is
// stated once.
struct KeySpec {
  enum class Type { Integer, Number, Boolean, Choice, Text, Other };
  std::string name;
  Type type = Type::Other;
  int64_t int_lo = 0, int_hi = kIntMax;         // Integer: lo..hi
  double lo = 0, hi = kInf;                     // Number: [lo, hi], or (lo, hi] when lo_open
  bool lo_open = false;
  std::vector<std::string> choices;             // Choice
  std::string type_text;                        // Other (and Text): the type column as written
  std::string default_text;                     // the documented default ("" = none / required)
  std::string doc;                              // meaning (markdown)
  // The docs' "type (default)" cell: `integer 1..64 (2)`, `number in (0, 1] (1e-5)`, ...
  std::string type_cell() const;
};
KeySpec int_key(std::string name, int64_t lo, int64_t hi, std::string def, std::string doc);
KeySpec num_key(std::string name, double lo, double hi, bool lo_open, std::string def, std::string doc);
KeySpec bool_key(std::string name, std::string def, std::string doc);
KeySpec choice_key(std::string name, std::vector<std::string> choices, std::string def, std::string doc);
KeySpec other_key(std::string name, std::string type, std::string def, std::string doc);

// The spec named `name` in keys (std::logic_error when absent: a bug).
const KeySpec& find_key(const std::vector<KeySpec>& keys, const std::string& name);

// Where values came from and the problems found so far, each once.
struct Ctx {
  std::string path;  // config path (messages)
  std::string dir;   // folder of the config
  std::unordered_map<const toml::node*, std::string> define_origin;
  std::vector<std::string> issues;
  std::set<std::string> seen;

  void issue(const std::string& where, const std::string& field, const std::string& rule);
  // "file:line" of a node, or "-D key=value" for a value given on the command line.
  std::string where(const toml::node& n) const;
  void mark_define(const toml::node& n, const std::string& origin);
  // Relative paths: the config's folder, then the working directory, then the
  // data folder; "" when none exists (the candidates go to *tried).
  std::string resolve(const std::string& p, std::vector<std::string>* tried) const;
};


// Whether an array value of `key` is one value (true) or a sweep (false).
using ArrayIsValue = std::function<bool(const std::string& key, const toml::array& a)>;
bool never_value(const std::string&, const toml::array&);
bool all_arrays(const toml::array& a);

struct Expansion {
  std::vector<Combo> combos;
  std::set<std::string> swept;  // keys that are sweeps
  bool ok = true;
};
// Expands one table's sweeps: the cartesian product over its swept keys, with
// the groups named by `zip` advanced together. Axes are ordered by position in
// the file (the first is the outermost loop). Keys in no_sweep must be single values.
Expansion expand(const toml::table& t, const std::string& section, const ArrayIsValue& is_value,
                 const std::set<std::string>& no_sweep, Ctx& ctx);

// Combo of a plain (non-sweeping) table.
Combo plain_combo(const toml::table& t);

// Reads the values of one combination, reporting each problem at its key's location.
class Reader {
 public:
  Reader(Ctx& ctx, const Combo& c, std::string section, std::string table_where)
      : ctx_(ctx), c_(c), section_(std::move(section)), where_(std::move(table_where)) {}

  Ctx& ctx() { return ctx_; }
  bool has(const std::string& k) const { return c_.count(k) != 0; }
  // The node of key k (nullptr when absent), marking it read.
  const toml::node* take(const std::string& k);
  std::string where(const std::string& k) const;
  const std::string& table_where() const { return where_; }
  const std::string& section() const { return section_; }
  const Combo& combo() const { return c_; }
  std::string field(const std::string& k) const { return section_ + "." + k; }
  void fail(const std::string& k, const std::string& rule);
  void fail_table(const std::string& rule);
  bool failed() const { return failed_; }
  // Marks the combination invalid when a nested reader already reported why.
  void mark_failed() { failed_ = true; }

  int64_t integer(const std::string& k, int64_t def, int64_t lo, int64_t hi);
  double number(const std::string& k, double def, double lo, double hi, bool lo_open = false);
  bool boolean(const std::string& k, bool def);
  std::string text(const std::string& k, const std::string& def);
  std::string choice(const std::string& k, const std::string& def, const std::vector<std::string>& choices);
  // The same, with the key's name and range from its spec.
  int64_t integer(const KeySpec& k, int64_t def) { return integer(k.name, def, k.int_lo, k.int_hi); }
  double number(const KeySpec& k, double def) { return number(k.name, def, k.lo, k.hi, k.lo_open); }
  bool boolean(const KeySpec& k, bool def) { return boolean(k.name, def); }
  std::string choice(const KeySpec& k, const std::string& def) { return choice(k.name, def, k.choices); }
  // Reports every key not read: unknown keys for `what` (accepted: ...).
  void finish(const std::vector<std::string>& accepted, const std::string& what);

 private:
  Ctx& ctx_;
  const Combo& c_;
  std::string section_, where_;
  std::set<std::string> used_;
  bool failed_ = false;
};

// Reports an options struct's validate() failure: an OptionError whose field
// is one of `keys` at that key (its "field: " prefix dropped), anything else
// at the table (with `prefix` before the message).
// renames: option field -> config key where they differ (refine: blend_weight -> refine_blend).
void report_invalid(Reader& r, const std::exception& e, const std::vector<std::string>& keys,
                    const std::string& prefix = "", const std::map<std::string, std::string>& renames = {});


// Keys shared by several method kinds.
Parameterization read_param(Reader& r, const std::string& key, Parameterization def);
// texture_size: an integer lo..hi, or "auto": the resolution is then chosen by
// the method's tolerance from texture_ladder (default 8, 12, 16, 24, 32;
// ascending integers in lo..hi), filled into m.texture_ladder. Returns the
// fixed size, or the ladder's largest entry for "auto"; sets o's entries.
int read_texture_size(Reader& r, MethodVariant& m, nlohmann::json& o, int def, int lo, int hi);
// The method's `tolerance` table, also recorded in its options `o` (so the run id).
std::optional<Tolerance> read_tolerance(Reader& r, nlohmann::json& o);
// Keys of the tolerance table.
const std::vector<std::string>& tolerance_keys();


}  // namespace bf
