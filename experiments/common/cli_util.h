// Small helpers shared by the subcommands: strict vector parsing and
// atomically written output files.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "brdfs/brdf.h"

namespace bf {

// Parses "x,y,z" (three finite numbers) into a unit vector; `what` names the
// option in messages ("--wi"). Throws std::invalid_argument on malformed input
// or a zero vector. Non-unit input is normalized.
Vec3 parse_direction(const std::string& text, const std::string& what);

// The strings joined with sep between them.
std::string join(const std::vector<std::string>& v, const std::string& sep = ", ");

// Writes a file through a temporary next to it and renames it into place, so a
// reader never sees a half-written file. Throws std::runtime_error naming the
// path when it cannot be written.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& body);

// As write_file_atomic, but leaves the file untouched (its bytes and mtime)
// when it is a regular file (not a link) that already holds exactly what body
// writes, so that pages regenerated from unchanged inputs keep their
// timestamps (report.html, results.md). Returns whether the file was written.
bool write_file_if_changed(const std::string& path, const std::function<void(std::ostream&)>& body);

}  // namespace bf
