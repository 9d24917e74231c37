// Names read from files become paths only after these checks (docs/design.md §7,
// docs/robustness.md): a run id or experiment name is one plain folder name,
// a file a sidecar or record refers to stays inside its folder.
#pragma once

#include <string>

namespace bf {

// True for 1..255 characters of [A-Za-z0-9._-], other than "." and "..".
bool is_plain_name(const std::string& name);

// Throws std::invalid_argument("WHERE: expected a plain name (...), found \"NAME\"")
// unless is_plain_name(name). The name is quoted with bytes outside printable
// ASCII escaped as \xHH and cut at 80 characters.
void require_plain_name(const std::string& name, const std::string& where);

// True for a relative path (no leading '/') of 1..4096 characters whose every
// '/'-separated component is 1..255 bytes, not "." or "..", without control
// characters: it cannot leave its base folder lexically.
bool is_path_inside(const std::string& rel);

// True when some component of base/rel below `base` is a symbolic link (it
// could lead out of the folder). Call after is_path_inside(rel); it looks only
// at entries inside `base`, so its answer says nothing about files elsewhere.
bool has_symlink_below(const std::string& base, const std::string& rel);

// Throws std::invalid_argument("WHERE: expected a file name inside FOLDER_DESC
// (...), found \"REL\"") unless is_path_inside(rel). Decided from the text
// alone, so the message never depends on whether some file exists.
void require_path_inside(const std::string& rel, const std::string& where, const std::string& folder_desc);

// `text` quoted for a message: printable ASCII kept, other bytes as \xHH,
// at most `max` characters then "...".
std::string quote_for_message(const std::string& text, size_t max = 80);

}  // namespace bf
