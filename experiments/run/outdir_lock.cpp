// Output-folder lock (see outdir_lock.h).
#include "experiments/run/outdir_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>
#include <filesystem>
#include <stdexcept>

namespace bf {

OutdirLock::OutdirLock(const std::string& dir, const std::string& command) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return;
  const std::string path = (fs::path(dir) / kFileName).string();
  // O_NOFOLLOW: a link planted at the lock's name is not opened through.
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) return;
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    std::string holder;
    char buf[512];
    const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
    if (n > 0) holder.assign(buf, static_cast<size_t>(n));
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\r')) holder.pop_back();
    for (char& c : holder)
      if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    ::close(fd);
    if (e == EWOULDBLOCK)
      throw std::runtime_error(dir + ": another brdf-factor process is writing to this output folder (" +
                               (holder.empty() ? std::string("holder unknown") : holder) +
                               "); wait for it to finish or choose another --out");
    return;  // no flock on this file system: proceed unlocked
  }
  // Record the holder for the message a second process prints.
  char when[32] = "";
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  if (::gmtime_r(&now, &tm)) std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tm);
  const std::string text = "pid " + std::to_string(::getpid()) + ", brdf-factor " + command + ", since " + when + "\n";
  if (::ftruncate(fd, 0) == 0) {
    const ssize_t w = ::pwrite(fd, text.data(), text.size(), 0);
    (void)w;
  }
  fd_ = fd;
}

OutdirLock::~OutdirLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

}  // namespace bf
