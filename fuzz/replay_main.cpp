// Replays the checked-in inputs of the fuzz targets (targets.h) through the normal
// (gcc) build, so that `make test` re-checks every seed and every crash found
// without clang: gauss6_fuzz_replay TARGET FILE_OR_FOLDER... Exits non-zero if a
// target throws anything it may not (a crash or a sanitizer report ends the
// process anyway).
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "targets.h"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s TARGET FILE_OR_FOLDER...\n", argv[0]);
    return 2;
  }
  const gauss6::fuzz::Target target = gauss6::fuzz::find_target(argv[1]);
  if (!target) {
    std::fprintf(stderr, "unknown fuzz target '%s'\n", argv[1]);
    return 2;
  }
  std::vector<fs::path> files;
  for (int i = 2; i < argc; ++i) {
    if (fs::is_directory(argv[i])) {
      for (const auto& e : fs::directory_iterator(argv[i]))
        if (e.is_regular_file()) files.push_back(e.path());
    } else if (fs::exists(argv[i])) {
      files.push_back(argv[i]);
    }
  }
  int failures = 0;
  for (const fs::path& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
      target(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s: undocumented exception: %s\n", argv[1], f.c_str(), e.what());
      ++failures;
    }
  }
  std::printf("%s: %zu inputs replayed, %d failed\n", argv[1], files.size(), failures);
  return failures ? 1 : 0;
}
