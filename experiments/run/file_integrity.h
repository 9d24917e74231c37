// Content hashes of the files the runner writes and later reads back instead
// of recomputing them (docs/design.md §5.4): the sample cache and a finished
// run's files. Each is written with a 64-bit FNV-1a of its bytes and verified
// before it is trusted; files are opened without following links.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace bf {

// 64-bit FNV-1a, fed in pieces (the same function as content_hash in config.h).
class Fnv1a64 {
 public:
  void update(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    uint64_t h = h_;
    for (size_t i = 0; i < n; ++i) {
      h ^= p[i];
      h *= 1099511628211ull;
    }
    h_ = h;
  }
  uint64_t value() const { return h_; }
  std::string hex() const;

 private:
  uint64_t h_ = 1469598103934665603ull;
};

// "%016x" of v.
std::string hex64(uint64_t v);

// The FNV-1a of a regular file's bytes as 16 hex digits. The file is opened
// without following a link and without blocking; throws std::runtime_error
// naming the path when it is a link, not a regular file, or unreadable.
std::string regular_file_hash(const std::filesystem::path& path);

// Copies the regular file src (opened as regular_file_hash opens it) to dst,
// created exclusively (dst must not exist); returns the FNV-1a of the bytes
// copied. Throws std::runtime_error naming the path on any failure.
std::string copy_regular_file(const std::filesystem::path& src, const std::filesystem::path& dst);

// What a path is, for messages: "a symbolic link (to T)", "a FIFO", "a folder",
// "a character device", "a block device", "a socket", "a regular file",
// "missing". Does not follow links.
std::string describe_file_type(const std::filesystem::path& path);

}  // namespace bf
