// The shared CCD sample queries (../shared/data/ccd-sample-queries) as the
// benchmark programs use them: converted to doubles (exact for every value of
// that data), run through the optimized linear-motion primitives (ccd.h).
// Shared by bench_ccd_queries.cpp (timed) and count_main.cpp (instruction counts).
// Load time: these functions allocate and throw.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_data.h"
#include "gauss6/ccd/ccd.h"
#include "gauss6/io/ccd_queries.h"

namespace gauss6::bench {

struct LinearQuery {
  CcdQuery::Kind kind;
  std::array<Vec3, 8> p;  // file order (see ccd_queries.h)
  bool expected;
};

inline Vec3 vec(const RationalPoint& r) {
  const auto d = to_double(r);
  return {d[0], d[1], d[2]};
}

// Every query of the files under <sample root>/<group>*/ of one kind.
inline std::vector<LinearQuery> load_queries(const std::string& group, CcdQuery::Kind kind) {
  std::vector<LinearQuery> out;
  const std::string root = shared_data_dir() + "/ccd-sample-queries";
  if (!std::filesystem::is_directory(root)) return out;
  for (const CcdQueryFile& f : list_ccd_query_files(root)) {
    if (f.kind != kind || f.path.find("/" + group) == std::string::npos) continue;
    for (const CcdQuery& q : read_ccd_queries(f.path, f.kind)) {
      LinearQuery l{q.kind, {}, q.expected};
      for (int k = 0; k < 8; ++k) l.p[k] = vec(q.points[k]);
      out.push_back(l);
    }
  }
  return out;
}

inline void run_query(const LinearQuery& q, const CcdSettings& s, CcdWorkspace* ws, CcdResult* r) {
  if (q.kind == CcdQuery::kVertexFace) {
    LinearVertexFaceQuery vf;
    vf.vertex = {q.p[0], q.p[4]};
    vf.face = {{{q.p[1], q.p[2], q.p[3]}, {q.p[5], q.p[6], q.p[7]}}};
    ccd_linear_vertex_face(vf, s, ws, r);
  } else {
    LinearEdgeEdgeQuery ee;
    ee.edge_a = {{{q.p[0], q.p[1]}, {q.p[4], q.p[5]}}};
    ee.edge_b = {{{q.p[2], q.p[3]}, {q.p[6], q.p[7]}}};
    ccd_linear_edge_edge(ee, s, ws, r);
  }
}

}  // namespace gauss6::bench
