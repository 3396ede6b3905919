// libFuzzer entry point of one fuzz target (targets.h), chosen at build time by
// GAUSS6_FUZZ_TARGET (its name as a string). Built by fuzz/CMakeLists.txt with clang.
#include <cstdlib>

#include "targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const gauss6::fuzz::Target target = gauss6::fuzz::find_target(GAUSS6_FUZZ_TARGET);
  if (!target) std::abort();
  target(data, size);
  return 0;
}
