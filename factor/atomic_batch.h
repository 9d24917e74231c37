// A batch of files written to temporaries and renamed into place together
// (the exports' "nothing is half-written"): temporaries are created
// exclusively with unique names (brdfs/temp_file.h), so a planted file or link
// is never written through.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "brdfs/temp_file.h"

namespace bf {

// Files written to hidden temporaries in the target folder, renamed into place
// by commit() in the order they were added; the destructor removes whatever
// was not committed.
class AtomicBatch {
 public:
  explicit AtomicBatch(std::filesystem::path dir) : dir_(std::move(dir)) {}
  AtomicBatch(const AtomicBatch&) = delete;
  AtomicBatch& operator=(const AtomicBatch&) = delete;
  ~AtomicBatch() {
    std::error_code ec;
    for (const auto& [tmp, final_path] : files_) std::filesystem::remove(tmp, ec);
  }

  // A fresh temporary path for the final file `name` (in the same folder, so
  // the rename is atomic).
  std::filesystem::path add(const std::string& name) {
    const std::filesystem::path tmp = create_unique_temp((dir_ / name).string());
    files_.emplace_back(tmp, dir_ / name);
    return tmp;
  }

  void commit() {
    for (const auto& [tmp, final_path] : files_) sync_path(tmp);
    for (const auto& [tmp, final_path] : files_) {
      std::error_code ec;
      std::filesystem::rename(tmp, final_path, ec);
      if (ec)
        throw std::runtime_error(final_path.string() + ": cannot rename the temporary " +
                                 tmp.string() + " into place: " + ec.message());
    }
    files_.clear();
    sync_path(dir_);
  }

 private:
  // Flush a file or folder to disk, so that a crash after the rename cannot
  // leave a complete name pointing at incomplete data. Best effort.
  static void sync_path(const std::filesystem::path& p) {
    const int fd = ::open(p.c_str(), O_RDONLY);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
  }

  std::filesystem::path dir_;
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> files_;
};

}  // namespace bf
