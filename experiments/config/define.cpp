// -D key=value overrides of a parsed config (config.h: apply_define).
#include "experiments/config/config.h"

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

// ------------------------------------------------------------------ -D overrides

namespace {

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

// The value of a -D: TOML if it parses as one, else the text as a string,
// into parsed["v"]. False (an issue reported) for digits TOML cannot hold.
bool parse_define_value(const std::string& text, const std::string& key, const std::string& origin, Ctx& ctx,
                        toml::table& parsed) {
  try {
    // Too deep to parse safely: taken as a string, like any text that is not TOML.
    if (toml_key_depth_problem("v = " + text, origin).empty()) parsed = toml::parse("v = " + text, origin);
    else parsed.insert_or_assign("v", text);
  } catch (const toml::parse_error& e) {
    // Digits TOML cannot hold as an integer (beyond 64 bits) are refused, not read as a string.
    const size_t digits = (!text.empty() && (text[0] == '+' || text[0] == '-')) ? 1 : 0;
    if (text.size() > digits && text[digits] != '0' &&
        text.find_first_not_of("0123456789", digits) == std::string::npos) {
      ctx.issue(origin, key, "expected an integer in 64 bits (or a quoted string), found " + text + " (" +
                                 std::string(e.description()) + ")");
      return false;
    }
    parsed.insert_or_assign("v", text);
  }
  return true;
}

}  // namespace

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
  toml::table parsed;
  if (!parse_define_value(text, key, origin, ctx, parsed)) return;
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

}  // namespace bf
