// Feature pairs: which features of a god-object triangle and an obstacle
// triangle can touch (METHOD.md section 4: vertex/face both ways, edge/edge),
// named once for both implementations, and the one table of their kinds that
// every loop over a triangle pair's feature pairs runs on (the optimized pair
// tester, the contact generation, the exact reference), as MuJoCo's collision
// table serves its dispatch (mjCOLLISIONFUNC).
//
// Header-only and dependency-free: the exact reference (gauss6::reference)
// shares these types with the optimized code, never its algorithms.
#pragma once

#include <cstdint>

namespace gauss6 {

// Which features touch. A vertex is F(face, corner); an edge runs from
// F(face, corner) to F(face, (corner + 1) % 3); a face is `face` (corner -1).
enum class PairKind { kGodVertexObstacleFace = 0, kObstacleVertexGodFace, kEdgeEdge };
inline constexpr int kNumPairKinds = 3;

inline const char* to_string(PairKind k) {
  switch (k) {
    case PairKind::kGodVertexObstacleFace: return "god_vertex/obstacle_face";
    case PairKind::kObstacleVertexGodFace: return "obstacle_vertex/god_face";
    case PairKind::kEdgeEdge: return "edge/edge";
  }
  return "unknown";
}

struct FeaturePair {
  PairKind kind = PairKind::kGodVertexObstacleFace;
  int obstacle = -1;                       // index into the obstacle list
  int god_face = -1, god_corner = -1;
  int obstacle_face = -1, obstacle_corner = -1;
  friend bool operator==(const FeaturePair&, const FeaturePair&) = default;
};

// Feature ownership bits of a triangle (Bvh::owned): bit k owns vertex
// F(f, k); bit 3 + k owns the edge F(f, k) -> F(f, (k + 1) % 3). Each vertex
// and each undirected edge of a mesh is owned by exactly one of its triangles,
// so the owned feature pairs of all triangle pairs are every (vertex, face) and
// (edge, edge) pair exactly once.
inline constexpr uint8_t kOwnsVertex0 = 1u, kOwnsEdge0 = 8u;
inline constexpr uint8_t kOwnsAll = 0x3f;
constexpr bool owns_vertex(uint8_t owned, int corner) { return (owned & (kOwnsVertex0 << corner)) != 0; }
constexpr bool owns_edge(uint8_t owned, int corner) { return (owned & (kOwnsEdge0 << corner)) != 0; }

// The kinds, in the order every loop visits them: the god-object's vertices
// against the obstacle's face (god corner 0, 1, 2), the obstacle's vertices
// against the god-object's face (obstacle corner 0, 1, 2), then edge/edge
// (god edge k, obstacle edge j, j fastest). Per kind: which side gives a
// vertex, a face or an edge (the table the loops dispatch on).
enum class Feature { kVertex = 0, kEdge, kFace };
struct PairKindInfo {
  PairKind kind;
  Feature god, obstacle;
};
inline constexpr PairKindInfo kPairKinds[kNumPairKinds] = {
    {PairKind::kGodVertexObstacleFace, Feature::kVertex, Feature::kFace},
    {PairKind::kObstacleVertexGodFace, Feature::kFace, Feature::kVertex},
    {PairKind::kEdgeEdge, Feature::kEdge, Feature::kEdge},
};

// Calls visit(kind, god_corner, obstacle_corner) for every feature pair of a
// (god triangle, obstacle triangle) pair that the two triangles own (bits as
// above; kOwnsAll on both: all 15), in the order of kPairKinds; corners are
// -1 for a face. visit returns false to stop. Returns false when stopped.
template <class Visit>
inline bool for_each_feature_pair(uint8_t god_owned, uint8_t obstacle_owned, Visit&& visit) {
  for (int k = 0; k < 3; ++k)
    if (owns_vertex(god_owned, k) && !visit(PairKind::kGodVertexObstacleFace, k, -1)) return false;
  for (int k = 0; k < 3; ++k)
    if (owns_vertex(obstacle_owned, k) && !visit(PairKind::kObstacleVertexGodFace, -1, k)) return false;
  for (int k = 0; k < 3; ++k) {
    if (!owns_edge(god_owned, k)) continue;
    for (int j = 0; j < 3; ++j)
      if (owns_edge(obstacle_owned, j) && !visit(PairKind::kEdgeEdge, k, j)) return false;
  }
  return true;
}

}  // namespace gauss6
