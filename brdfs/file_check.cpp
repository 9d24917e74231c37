// Regular-file checks (see file_check.h).
#include "brdfs/file_check.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace bf {

namespace {

const char* kind_of(mode_t m) {
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISDIR(m)) return "a directory";
  if (S_ISSOCK(m)) return "a socket";
  return "a non-regular file";
}

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Opens and checks; returns the descriptor (caller closes) and the size.
int open_checked(const std::string& path, uint64_t max_bytes, const std::string& what, uint64_t& size) {
  const std::string head = path + ": " + (what.empty() ? "" : what + ": ");
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    throw std::invalid_argument(path + ": cannot open" + (what.empty() ? "" : " " + what) + ": " +
                                (e == ENOENT ? std::string("file not found") : std::string(std::strerror(e))));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    throw std::invalid_argument(head + "cannot stat: " + std::strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    throw std::invalid_argument(head + "expected a regular file, found " + kind_of(st.st_mode));
  }
  size = static_cast<uint64_t>(st.st_size);
  if (size > max_bytes) {
    ::close(fd);
    throw std::invalid_argument(head + std::to_string(size) + " bytes, more than the limit of " +
                                std::to_string(max_bytes));
  }
  return fd;
}

}  // namespace

uint64_t check_regular_file(const std::string& path, uint64_t max_bytes, const std::string& what) {
  uint64_t size = 0;
  Fd f{open_checked(path, max_bytes, what, size)};
  return size;
}

std::string read_regular_file(const std::string& path, uint64_t max_bytes, const std::string& what) {
  uint64_t size = 0;
  Fd f{open_checked(path, max_bytes, what, size)};
  std::string data;
  data.reserve(size);
  char buf[1 << 16];
  while (data.size() < max_bytes) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      throw std::invalid_argument(path + ": read failed: " + std::strerror(errno));
    }
    if (n == 0) break;
    data.append(buf, static_cast<size_t>(std::min<uint64_t>(uint64_t(n), max_bytes - data.size())));
  }
  return data;
}

}  // namespace bf
