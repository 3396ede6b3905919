// The parsers' fuzz targets, one function each: the bytes become a file of the
// reader's kind (the readers take paths) and the reader runs on it. A reader may
// refuse its input only with its documented error (a LoadError subclass; a hand
// script's std::invalid_argument); anything else escaping, a crash or a sanitizer
// report is a bug. Shared by the libFuzzer entry point (libfuzzer_main.cpp, clang
// build in build-fuzz/) and the regression replayer (replay_main.cpp, a normal
// ctest test of the main build).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace gauss6::fuzz {

using Target = void (*)(const uint8_t* data, size_t size);

struct NamedTarget {
  const char* name;  // also the folder of its corpus and regressions: fuzz/corpus/<name>/
  Target run;
};

// Every target, by name: scene, obj, off, ply, stl, trace, ccd_queries, qp_instances, hand_script,
// height_map (the PNG height maps of textured surfaces).
const std::vector<NamedTarget>& targets();
// The target of that name, or nullptr.
Target find_target(const std::string& name);

}  // namespace gauss6::fuzz
