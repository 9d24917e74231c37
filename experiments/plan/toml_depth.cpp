// Key-depth pre-scan of TOML text (see toml_depth.h).
#include "experiments/plan/toml_depth.h"

#include <vector>

namespace bf {

namespace {

// The index of the last character of the string (basic or literal, single or
// multi-line) opening at text[i]; counts the lines it spans.
size_t skip_string(const std::string& text, size_t i, size_t& line, size_t& line_start) {
  const size_t n = text.size();
  const char c = text[i];
  const bool multi = i + 2 < n && text[i + 1] == c && text[i + 2] == c;
  i += multi ? 3 : 1;
  for (; i < n; ++i) {
    if (c == '"' && text[i] == '\\') {
      ++i;
      if (i < n && text[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
      continue;
    }
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
      if (!multi) break;  // malformed: the parser reports it
      continue;
    }
    if (text[i] == c && (!multi || (i + 2 < n && text[i + 1] == c && text[i + 2] == c))) {
      if (multi) i += 2;
      break;
    }
  }
  return i;
}

}  // namespace

std::string toml_key_depth_problem(const std::string& text, const std::string& origin, size_t max_depth) {
  // Open arrays ('[') and inline tables ('{'), each with the table depth of
  // what sits directly inside it: the keys of an inline table start at the
  // depth of the key that holds it; array elements share the array's depth
  // (toml++ bounds nested arrays itself).
  struct Open {
    char bracket;
    size_t depth;
  };
  std::vector<Open> stack;
  size_t header_depth = 0;  // keys after [a.b] start at depth 2
  size_t value_depth = 0;   // depth of the value being read (after '=')
  bool key_context = true;  // at a line start (top level), after '{' or after ',' in an inline table
  bool in_header = false;   // inside [a.b] or [[a.b]]
  bool part_open = false;   // a key component has started since the last '.'
  size_t parts = 0;         // components of the current key or header
  size_t line = 1, line_start = 0;
  const size_t n = text.size();
  auto base = [&] { return stack.empty() ? (in_header ? 0 : header_depth) : stack.back().depth; };
  auto problem = [&](size_t at, size_t depth) {
    return origin + ":" + std::to_string(line) + ": TOML: a key nests " + std::to_string(depth) +
           " tables deep at column " + std::to_string(at - line_start + 1) + " (limit " +
           std::to_string(max_depth) + ")";
  };
  auto new_part = [&](size_t at) -> std::string {  // checked as the key grows
    ++parts;
    part_open = true;
    return base() + parts > max_depth ? problem(at, base() + parts) : std::string();
  };
  auto start_key = [&] {
    key_context = true;
    parts = 0;
    part_open = false;
  };
  for (size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      line_start = i + 1;
      if (stack.empty()) {
        in_header = false;
        start_key();
      }
      continue;
    }
    if (c == '#') {  // comment to the end of the line
      while (i + 1 < n && text[i + 1] != '\n') ++i;
      continue;
    }
    if (c == '"' || c == '\'') {  // a string (a quoted key part in key context): skipped
      if ((key_context || in_header) && !part_open)
        if (auto p = new_part(i); !p.empty()) return p;
      i = skip_string(text, i, line, line_start);
      continue;
    }
    if (c == ' ' || c == '\t' || c == '\r') continue;
    if (in_header) {
      if (c == ']') {
        header_depth = parts;
        in_header = false;
        key_context = false;
        value_depth = 0;
      } else if (c == '.') {
        part_open = false;
      } else if (c != '[' && !part_open) {
        if (auto p = new_part(i); !p.empty()) return p;
      }
      continue;
    }
    if (key_context) {
      if (c == '[' && stack.empty() && parts == 0) {
        in_header = true;
        part_open = false;
        header_depth = 0;
      } else if (c == '=') {
        value_depth = base() + parts;
        key_context = false;
      } else if (c == '.') {
        part_open = false;
      } else if (c == '}' && !stack.empty()) {  // empty inline table, or a trailing ','
        stack.pop_back();
        key_context = false;
        value_depth = stack.empty() ? 0 : stack.back().depth;
      } else if (!part_open) {
        if (auto p = new_part(i); !p.empty()) return p;
      }
      continue;
    }
    // value context
    if (c == '[') {
      stack.push_back({'[', value_depth});
    } else if (c == '{') {
      stack.push_back({'{', value_depth});
      start_key();
    } else if (c == ']' || c == '}') {
      if (!stack.empty()) stack.pop_back();
      value_depth = stack.empty() ? 0 : stack.back().depth;
    } else if (c == ',') {
      if (!stack.empty() && stack.back().bracket == '{') start_key();
      else if (!stack.empty()) value_depth = stack.back().depth;
    }
  }
  return {};
}

}  // namespace bf
