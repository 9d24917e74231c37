// Unique temporaries (see temp_file.h).
#include "brdfs/temp_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace bf {

std::string create_unique_temp(const std::string& target) {
  namespace fs = std::filesystem;
  const fs::path p(target);
  const std::string name = "." + p.filename().string() + ".tmp-XXXXXX";
  const std::string tmpl = (p.has_parent_path() ? (p.parent_path() / name) : fs::path(name)).string();
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  const int fd = ::mkstemp(buf.data());  // O_CREAT | O_EXCL: never an existing file or link
  if (fd < 0)
    throw std::runtime_error(target + ": cannot open a temporary file next to it for writing: " +
                             std::strerror(errno));
  ::fchmod(fd, 0644);
  ::close(fd);
  return std::string(buf.data());
}

}  // namespace bf
