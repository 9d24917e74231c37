// Text-parsing helpers shared by the measured-data readers (ASTM, pbrt .brdf,
// sample-list CSV): bounded line reads, strict number parsing, and safe
// excerpts of bad input for error messages.
#pragma once

#include <istream>
#include <string>

namespace bf::text {

// Reads one line into `line` (the '\n' is dropped, and a trailing '\r' too, so
// CRLF files read like LF files). Returns false at end of file when nothing
// was read. Never holds more than max_chars characters: a longer line throws
// std::invalid_argument "<path>:<lineno>: expected a line of at most
// <max_chars> characters, found a longer one".
bool read_line(std::istream& in, std::string& line, size_t max_chars, const std::string& path,
               size_t lineno);

// s without leading and trailing blanks (space, tab, CR).
std::string strip(const std::string& s);

// Parses all of `s` as a decimal number ("C" locale rules, strtod syntax; no
// leading or trailing blanks). Overflow gives +-inf, underflow 0; "nan" and
// "inf" parse (callers decide whether they are allowed). Returns false when s
// is empty or not entirely a number.
bool parse_number(const std::string& s, double& out);

// s quoted for an error message: at most max_chars characters, control and
// non-ASCII bytes shown as \xNN, "..." appended when cut.
std::string excerpt(const std::string& s, size_t max_chars = 40);

// "path:lineno"
std::string where(const std::string& path, size_t lineno);

}  // namespace bf::text
