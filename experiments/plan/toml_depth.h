// A bound on TOML key nesting, checked on the text before the TOML parser
// sees it (docs/robustness.md). toml++ limits nested arrays and inline tables
// (TOML_MAX_NESTED_VALUES = 256) but not dotted keys or table headers: a
// 70 KB line `a.a.a...a = 1` or `[a.a...a]` nests tens of thousands of tables
// and overflows the stack inside the parser.
#pragma once

#include <cstddef>
#include <string>

namespace bf {

inline constexpr size_t kMaxTomlKeyDepth = 256;

// The first place where a key (a dotted key or a table header, plus the
// arrays and inline tables it sits in) nests deeper than max_depth, as
// "ORIGIN:LINE: TOML: a key nests N tables deep at column C (limit M)", or ""
// when there is none. A light lexer: strings (all four kinds), comments,
// arrays, inline tables and headers; malformed TOML is left to the parser.
std::string toml_key_depth_problem(const std::string& text, const std::string& origin,
                                   size_t max_depth = kMaxTomlKeyDepth);

}  // namespace bf
