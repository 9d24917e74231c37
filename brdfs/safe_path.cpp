// Path-name checks (see safe_path.h).
#include "brdfs/safe_path.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace bf {

bool is_plain_name(const std::string& name) {
  if (name.empty() || name.size() > 255 || name == "." || name == "..") return false;
  for (unsigned char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

std::string quote_for_message(const std::string& text, size_t max) {
  std::string q = "\"";
  size_t n = 0;
  for (unsigned char c : text) {
    if (n++ == max) {
      q += "...";
      break;
    }
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') {
      q += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      q += buf;
    }
  }
  return q + "\"";
}

void require_plain_name(const std::string& name, const std::string& where) {
  if (!is_plain_name(name))
    throw std::invalid_argument(where +
                                ": expected a plain name (1-255 letters, digits, '.', '_' or '-', not '.' or "
                                "'..'), found " +
                                quote_for_message(name));
}

bool has_symlink_below(const std::string& base, const std::string& rel) {
  std::filesystem::path p(base);
  for (const auto& part : std::filesystem::path(rel)) {
    p /= part;
    std::error_code ec;
    if (std::filesystem::is_symlink(std::filesystem::symlink_status(p, ec))) return true;
  }
  return false;
}

bool is_path_inside(const std::string& rel) {
  if (rel.empty() || rel.size() > 4096 || rel.front() == '/') return false;
  size_t start = 0;
  while (true) {
    const size_t slash = rel.find('/', start);
    const std::string part = rel.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (part.empty() || part.size() > 255 || part == "." || part == "..") return false;
    for (unsigned char c : part)
      if (c < 0x20 || c == 0x7f) return false;
    if (slash == std::string::npos) return true;
    start = slash + 1;
  }
}

void require_path_inside(const std::string& rel, const std::string& where, const std::string& folder_desc) {
  if (!is_path_inside(rel))
    throw std::invalid_argument(where + ": expected a file name inside " + folder_desc +
                                " (a relative path without '..' or control characters), found " +
                                quote_for_message(rel));
}

}  // namespace bf
