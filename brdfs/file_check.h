// Input files are regular files of bounded size (docs/design.md §7,
// docs/robustness.md): a FIFO, device (/dev/zero), directory or socket given
// where a data file is expected is refused before any reader opens it, so
// nothing blocks on a pipe or reads an endless device.
#pragma once

#include <cstdint>
#include <string>

namespace bf {

// Measured data and sample CSVs (a MERL file is 33 MB; a CSV of 10^7 samples ~0.7 GB).
inline constexpr uint64_t kMaxDataFileBytes = uint64_t(2) << 30;
// JSON sidecars, records, manifests and TOML configs.
inline constexpr uint64_t kMaxTextFileBytes = uint64_t(64) << 20;
// Images (textures, environment maps); their pixel count is checked by the reader.
inline constexpr uint64_t kMaxImageFileBytes = uint64_t(1) << 30;

// Opens `path` without blocking (O_NONBLOCK, so a FIFO without writer does not
// hang), and throws std::invalid_argument unless it is a regular file of at most
// max_bytes: "PATH: WHAT: expected a regular file, found a FIFO" (character
// device, block device, directory, socket), "PATH: WHAT: N bytes, more than the
// limit of M", "PATH: cannot open WHAT: file not found" (or the system's
// reason). Returns the size in bytes.
uint64_t check_regular_file(const std::string& path, uint64_t max_bytes, const std::string& what);

// Reads a whole regular file checked as above; at most max_bytes are read even
// if the file grows meanwhile.
std::string read_regular_file(const std::string& path, uint64_t max_bytes, const std::string& what);

}  // namespace bf
