// Content hashes of cached files (see file_integrity.h).
#include "experiments/run/file_integrity.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace bf {

namespace fs = std::filesystem;

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::string Fnv1a64::hex() const { return hex64(h_); }

std::string describe_file_type(const fs::path& path) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  switch (st.type()) {
    case fs::file_type::symlink: {
      const fs::path target = fs::read_symlink(path, ec);
      return "a symbolic link" + (ec ? std::string() : " (to " + target.string() + ")");
    }
    case fs::file_type::regular: return "a regular file";
    case fs::file_type::directory: return "a folder";
    case fs::file_type::fifo: return "a FIFO";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::not_found: return "missing";
    default: return "not a regular file";
  }
}

namespace {

// Opens a regular file for reading: no link followed, no blocking on a FIFO.
int open_regular(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    if (e == ELOOP) throw std::runtime_error(path.string() + ": expected a regular file, found " + describe_file_type(path));
    throw std::runtime_error(path.string() + ": cannot open: " + std::strerror(e));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw std::runtime_error(path.string() + ": expected a regular file, found " + describe_file_type(path));
  }
  return fd;
}

// Reads the whole of fd in chunks, handing each to `sink`.
template <class Sink>
void read_all(int fd, const fs::path& path, Sink&& sink) {
  std::vector<char> buf(1 << 16);
  for (;;) {
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    if (n == 0) return;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(path.string() + ": cannot read: " + std::strerror(errno));
    }
    sink(buf.data(), static_cast<size_t>(n));
  }
}

}  // namespace

std::string regular_file_hash(const fs::path& path) {
  const int fd = open_regular(path);
  Fnv1a64 h;
  try {
    read_all(fd, path, [&](const char* p, size_t n) { h.update(p, n); });
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return h.hex();
}

std::string copy_regular_file(const fs::path& src, const fs::path& dst) {
  const int in = open_regular(src);
  const int out = ::open(dst.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (out < 0) {
    const int e = errno;
    ::close(in);
    throw std::runtime_error(dst.string() + ": cannot create: " + std::strerror(e));
  }
  Fnv1a64 h;
  bool out_open = true;
  try {
    read_all(in, src, [&](const char* p, size_t n) {
      h.update(p, n);
      while (n > 0) {
        const ssize_t w = ::write(out, p, n);
        if (w < 0) {
          if (errno == EINTR) continue;
          throw std::runtime_error(dst.string() + ": cannot write: " + std::strerror(errno));
        }
        p += w;
        n -= static_cast<size_t>(w);
      }
    });
    out_open = false;
    if (::close(out) != 0) throw std::runtime_error(dst.string() + ": cannot write: " + std::strerror(errno));
  } catch (...) {
    ::close(in);
    if (out_open) ::close(out);
    throw;
  }
  ::close(in);
  return h.hex();
}

}  // namespace bf
