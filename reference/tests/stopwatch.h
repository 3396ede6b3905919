// Wall-clock seconds for the reference tests that report how long an exact
// step takes (the numbers they print; no test passes or fails on them).
#pragma once

#include <chrono>

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
