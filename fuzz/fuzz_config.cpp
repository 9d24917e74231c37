// libFuzzer target: the experiment config parser (experiments/plan/plan.h
// parse_plan: TOML, validation, sweep expansion) on text, no file needed.
#include <exception>
#include <string>

#include "experiments/config/config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    bf::parse_plan(text, "/tmp/bf_fuzz_config/fuzz.toml");
  } catch (const std::exception&) {
  }
  return 0;
}
