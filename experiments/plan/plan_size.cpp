// Run counting before expansion (see plan_size.h).
#include "experiments/plan/plan_size.h"

#include <algorithm>
#include <map>
#include <set>
#include <vector>

namespace bf {

uint64_t saturating_product(uint64_t a, uint64_t b, uint64_t cap) {
  if (a == 0 || b == 0) return 0;
  if (a > cap || b > cap || a > (cap + 1) / b) return cap + 1;
  return std::min(a * b, cap + 1);
}

uint64_t count_table_combinations(const toml::table& t, const SweepArrayIsValue& is_value, uint64_t cap) {
  std::map<std::string, uint64_t> len;  // swept keys only
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (key == "zip") continue;
    if (auto s = v.as_table(); s && s->size() == 1 && s->contains("sweep")) {
      if (auto a = s->get("sweep")->as_array(); a && !a->empty()) len[key] = a->size();
    } else if (auto a = v.as_array(); a && !a->empty() && !is_value(key, *a)) {
      len[key] = a->size();
    }
  }
  // zip groups: one axis each, as long as its longest list.
  std::vector<std::vector<std::string>> groups;
  if (const toml::node* z = t.get("zip"); z && z->as_array()) {
    const toml::array& za = *z->as_array();
    std::vector<std::string> flat;
    for (const auto& g : za) {
      if (auto ga = g.as_array()) {
        std::vector<std::string> keys;
        for (const auto& e : *ga)
          if (auto s = e.as_string()) keys.push_back(s->get());
        groups.push_back(keys);
      } else if (auto s = g.as_string()) {
        flat.push_back(s->get());
      }
    }
    if (!flat.empty()) groups.push_back(flat);
  }
  uint64_t total = 1;
  std::set<std::string> grouped;
  for (const auto& g : groups) {
    uint64_t longest = 0;
    for (const auto& k : g) {
      auto it = len.find(k);
      if (it == len.end() || grouped.count(k)) continue;
      longest = std::max(longest, it->second);
      grouped.insert(k);
    }
    if (longest > 0) total = saturating_product(total, longest, cap);
  }
  for (const auto& [k, n] : len)
    if (!grouped.count(k)) total = saturating_product(total, n, cap);
  return total;
}

uint64_t count_section_combinations(const toml::node* section, const SweepArrayIsValue& is_value, uint64_t cap) {
  if (!section) return 0;
  if (auto t = section->as_table()) return count_table_combinations(*t, is_value, cap);
  uint64_t sum = 0;
  if (auto a = section->as_array())
    for (const auto& e : *a)
      if (auto t = e.as_table()) {
        sum += count_table_combinations(*t, is_value, cap);
        if (sum > cap) return cap + 1;
      }
  return sum;
}

}  // namespace bf
