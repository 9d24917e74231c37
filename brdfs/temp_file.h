// Temporary files for atomic writes (docs/robustness.md): every writer puts
// its bytes in a temporary next to the target and renames it into place. The
// temporary's name is unique and the file is created exclusively (mkstemp:
// O_CREAT | O_EXCL, which also refuses to follow a symbolic link planted at
// that name), so two writers never share a temporary and a planted link is
// never written through.
#pragma once

#include <string>

namespace bf {

// Creates an empty regular file "<dir of target>/.<name of target>.tmp-XXXXXX"
// (mode 0644) and returns its path. Throws std::runtime_error naming the
// target when it cannot.
std::string create_unique_temp(const std::string& target);

}  // namespace bf
