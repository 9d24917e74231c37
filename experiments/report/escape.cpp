// Escapers by output context (see escape.h).
#include "experiments/report/escape.h"

#include <cctype>
#include <cstdio>
#include <cstring>

namespace bf {

namespace {

constexpr const char* kReplacement = "\xEF\xBF\xBD";  // U+FFFD

bool is_line_break(unsigned char c) { return c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f'; }
bool is_control(unsigned char c) { return c < 0x20 || c == 0x7f; }

}  // namespace

std::string md_text(const std::string& s) {
  std::string o;
  o.reserve(s.size() + 8);
  for (size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '\r' && i + 1 < s.size() && s[i + 1] == '\n') continue;  // CRLF: one space
    if (is_line_break(c)) o += ' ';
    else if (is_control(c)) o += kReplacement;
    else if (c == '&') o += "&amp;";
    else if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (std::strchr("\\`*_[]#|~$", c)) o += '\\', o += char(c);
    else o += char(c);
  }
  // Block markers matter where the text begins a line.
  if (!o.empty()) {
    const char c0 = o[0];
    if (c0 == ' ') {
      o.replace(0, 1, "&#32;");  // no indented code block
    } else if (c0 == '-' || c0 == '+' || c0 == '=') {
      // A list item, thematic break or setext underline; "-0.5" and "-D" stay.
      if (o.size() == 1 || !(std::isalnum(static_cast<unsigned char>(o[1])) || o[1] == '.')) o.insert(0, 1, '\\');
    } else if (std::isdigit(static_cast<unsigned char>(c0))) {
      size_t k = 0;
      while (k < o.size() && std::isdigit(static_cast<unsigned char>(o[k]))) ++k;
      // An ordered list item: up to 9 digits, '.' or ')', then a space or the end.
      if (k <= 9 && k < o.size() && (o[k] == '.' || o[k] == ')') && (k + 1 == o.size() || o[k + 1] == ' '))
        o.insert(k, 1, '\\');
    }
  }
  return o;
}

std::string md_code(const std::string& s) {
  std::string body;
  size_t run = 0, longest = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    run = c == '`' ? run + 1 : 0;
    longest = std::max(longest, run);
    if (c == '\r' && i + 1 < s.size() && s[i + 1] == '\n') continue;
    if (is_line_break(c)) body += ' ';
    else if (is_control(c)) body += kReplacement;
    else body += char(c);
  }
  const std::string fence(longest + 1, '`');
  // A space inside each fence when the body begins or ends with a backtick
  // (CommonMark strips one such space from each side).
  const bool pad = !body.empty() && (body.front() == '`' || body.back() == '`' || body.front() == ' ');
  return fence + (pad ? " " : "") + body + (pad ? " " : "") + fence;
}

std::string url_path(const std::string& rel) {
  std::string o;
  for (unsigned char c : rel) {
    if (std::isalnum(c) || c == '/' || c == '.' || c == '_' || c == '-') {
      o += static_cast<char>(c);
    } else {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", c);
      o += buf;
    }
  }
  return o;
}

std::string html_text(const std::string& s) {
  std::string o;
  o.reserve(s.size() + 8);
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string script_json(const nlohmann::json& j) {
  const std::string t = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string o;
  o.reserve(t.size() + 16);
  for (size_t i = 0; i < t.size(); ++i) {
    const char c = t[i];
    if (c == '<') o += "\\u003c";
    else if (c == '>') o += "\\u003e";
    else if (c == '&') o += "\\u0026";
    else if (c == '\'') o += "\\u0027";
    else if (c == '\xE2' && i + 2 < t.size() && t[i + 1] == '\x80' && (t[i + 2] == '\xA8' || t[i + 2] == '\xA9')) {
      o += t[i + 2] == '\xA8' ? "\\u2028" : "\\u2029";
      i += 2;
    } else {
      o += c;
    }
  }
  return o;
}

}  // namespace bf
