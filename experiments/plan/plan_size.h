// Counting a config's runs before expanding them (docs/robustness.md): the
// product brdfs x samplings x methods, each the sum over its tables of the
// product of their sweep lengths, is checked against the run limit while it
// is still a few numbers, so a small config cannot make the planner build
// millions of runs (gigabytes) before refusing.
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <functional>
#include <string>

namespace bf {

// True when an array value of `key` is a value, not a sweep (per section).
using SweepArrayIsValue = std::function<bool(const std::string& key, const toml::array& a)>;

// The combinations one table's sweeps expand to, an upper bound of what the
// planner builds (a zip group counts its longest list), saturating at `cap` + 1.
uint64_t count_table_combinations(const toml::table& t, const SweepArrayIsValue& is_value, uint64_t cap);

// The same summed over a section: a table or an array of tables (other nodes
// count 0, the planner reports them). Saturates at `cap` + 1.
uint64_t count_section_combinations(const toml::node* section, const SweepArrayIsValue& is_value, uint64_t cap);

// a * b saturating at cap + 1.
uint64_t saturating_product(uint64_t a, uint64_t b, uint64_t cap);

}  // namespace bf
