// Text-parsing helpers for the measured-data readers (see measured_text.h).
#include "brdfs/measured_text.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace bf::text {

bool read_line(std::istream& in, std::string& line, size_t max_chars, const std::string& path,
               size_t lineno) {
  line.clear();
  std::streambuf* sb = in.rdbuf();
  if (!sb) return false;
  bool any = false;
  for (;;) {
    const int c = sb->sbumpc();
    if (c == std::char_traits<char>::eof()) {
      in.setstate(std::ios::eofbit);
      break;
    }
    any = true;
    if (c == '\n') break;
    if (line.size() >= max_chars)
      throw std::invalid_argument(where(path, lineno) + ": expected a line of at most " +
                                  std::to_string(max_chars) +
                                  " characters, found a longer one (binary or corrupt file?)");
    line.push_back(static_cast<char>(c));
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return any;
}

std::string strip(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

bool parse_number(const std::string& s, double& out) {
  if (s.empty()) return false;
  const char c0 = s[0];
  // strtod skips leading blanks and accepts hex; we want plain decimal numbers.
  if (c0 == ' ' || c0 == '\t' || c0 == '\n' || c0 == '\r' || c0 == '\f' || c0 == '\v') return false;
  if (s.find("0x") != std::string::npos || s.find("0X") != std::string::npos) return false;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

std::string excerpt(const std::string& s, size_t max_chars) {
  std::string out = "'";
  size_t n = 0;
  for (unsigned char c : s) {
    if (n >= max_chars) {
      out += "...";
      break;
    }
    if (c >= 32 && c < 127) {
      out.push_back(static_cast<char>(c));
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    }
    ++n;
  }
  return out + "'";
}

std::string where(const std::string& path, size_t lineno) {
  return path + ":" + std::to_string(lineno);
}

}  // namespace bf::text
