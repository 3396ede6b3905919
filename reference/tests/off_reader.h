// Minimal OFF reader for the tests of the reference (the optimized mesh reader
// is not linked into the reference): triangles only, throws on a malformed file.
#pragma once

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "gauss6/geometry/mesh.h"

namespace gauss6::test {

inline gauss6::TriangleMesh read_off(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  auto next_line = [&] {
    std::string line;
    while (std::getline(in, line))
      if (!line.empty() && line[0] != '#') return line;
    throw std::runtime_error(path + ": truncated");
  };
  if (next_line().rfind("OFF", 0) != 0) throw std::runtime_error(path + ": not OFF");
  int nv = 0, nf = 0, ne = 0;
  std::istringstream(next_line()) >> nv >> nf >> ne;
  gauss6::TriangleMesh m;
  m.V.resize(nv, 3);
  m.F.resize(nf, 3);
  for (int v = 0; v < nv; ++v) std::istringstream(next_line()) >> m.V(v, 0) >> m.V(v, 1) >> m.V(v, 2);
  for (int f = 0; f < nf; ++f) {
    int k = 0;
    std::istringstream(next_line()) >> k >> m.F(f, 0) >> m.F(f, 1) >> m.F(f, 2);
    if (k != 3) throw std::runtime_error(path + ": non-triangle face");
  }
  m.source = path;
  return m;
}

}  // namespace gauss6::test
