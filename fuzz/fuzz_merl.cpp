// libFuzzer target: the MERL .binary reader (brdfs/merl.h read_merl). Any
// std::exception is a clean rejection; crashes, sanitizer reports, hangs and
// out-of-memory are findings.
#include <exception>

#include "brdfs/merl.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = bf_fuzz::write_temp(data, size, ".binary");
  try {
    bf::read_merl(path);
  } catch (const std::exception&) {
  }
  return 0;
}
