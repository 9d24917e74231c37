// Shared by the libFuzzer targets: the readers take paths, so each input is
// written to a per-process temporary file first.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace bf_fuzz {

// Writes data to $TMPDIR/bf_fuzz_<pid><ext> (overwritten each call) and returns the path.
inline std::string write_temp(const uint8_t* data, size_t size, const char* ext) {
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("bf_fuzz_" + std::to_string(::getpid()) + ext)).string();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

}  // namespace bf_fuzz
