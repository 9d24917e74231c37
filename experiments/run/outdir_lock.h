// One writer per output folder (docs/robustness.md): `run` and `merge` hold
// an exclusive lock on <out>/.brdf-factor.lock while they write. A second
// process on the same folder refuses at once, naming the holder, instead of
// deleting the first one's run folders and temporaries. The lock is flock(2)
// on an open descriptor: the kernel drops it when the holder exits, however it
// exits (crash, SIGKILL), so a stale lock file never blocks the next run.
#pragma once

#include <string>

namespace bf {

class OutdirLock {
 public:
  // Creates `dir` if needed and takes the lock. Throws std::runtime_error
  // "DIR: another brdf-factor process is writing to this output folder (pid
  // N, COMMAND, since TIME); wait for it to finish or choose another --out"
  // when it is held. When `dir` cannot be created or the lock file cannot be
  // opened, returns without a lock (the output-folder checks report why).
  explicit OutdirLock(const std::string& dir, const std::string& command);
  ~OutdirLock();
  OutdirLock(const OutdirLock&) = delete;
  OutdirLock& operator=(const OutdirLock&) = delete;

  bool held() const { return fd_ >= 0; }
  static constexpr const char* kFileName = ".brdf-factor.lock";

 private:
  int fd_ = -1;
};

}  // namespace bf
