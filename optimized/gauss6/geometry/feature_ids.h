// Canonical feature ids: a feature pair named by the mesh features themselves
// (a vertex by its index, an edge by its sorted pair of vertex indices, a face
// by its index), whichever triangle owned them. The optimized step reports a
// FeaturePair as (triangle, corner) on each side; the exact reference reports
// the features it solved. Mapped to these ids, the two can be compared
// (`gauss6 crosscheck ccd`).
//
// Header-only: shared by both implementations, no algorithm of either.
#pragma once

#include <algorithm>
#include <cstdint>

#include "gauss6/geometry/feature_pair.h"
#include "gauss6/geometry/mesh.h"

namespace gauss6 {

// One feature of a mesh: a vertex {v, -1}, an edge {i, j} with i < j (its
// vertex indices), or a face {f, -1}.
struct FeatureId {
  Feature feature = Feature::kVertex;
  int32_t a = -1, b = -1;
  friend bool operator==(const FeatureId&, const FeatureId&) = default;
};

inline FeatureId vertex_id(int32_t v) { return {Feature::kVertex, v, -1}; }
inline FeatureId edge_id(int32_t i, int32_t j) { return {Feature::kEdge, std::min(i, j), std::max(i, j)}; }
inline FeatureId face_id(int32_t f) { return {Feature::kFace, f, -1}; }

// The features of one pair: the god-object's and the obstacle's, of the kinds
// kPairKinds[kind] names.
struct FeaturePairIds {
  PairKind kind = PairKind::kGodVertexObstacleFace;
  FeatureId god, obstacle;
  friend bool operator==(const FeaturePairIds&, const FeaturePairIds&) = default;
};

// The feature of triangle `face` of F that `corner` names when the feature is
// of kind `feature`: vertex F(face, corner), edge F(face, corner) ->
// F(face, (corner + 1) % 3), or the face itself (corner ignored).
inline FeatureId feature_id(const MatrixX3i& F, Feature feature, int face, int corner) {
  switch (feature) {
    case Feature::kVertex: return vertex_id(F(face, corner));
    case Feature::kEdge: return edge_id(F(face, corner), F(face, (corner + 1) % 3));
    case Feature::kFace: return face_id(face);
  }
  return {};
}

// The canonical ids of an optimized FeaturePair, given the god-object's faces
// and the faces of the obstacle it names (p.obstacle).
inline FeaturePairIds feature_ids(const FeaturePair& p, const MatrixX3i& god_F, const MatrixX3i& obstacle_F) {
  const PairKindInfo& info = kPairKinds[static_cast<int>(p.kind)];
  return {p.kind, feature_id(god_F, info.god, p.god_face, p.god_corner),
          feature_id(obstacle_F, info.obstacle, p.obstacle_face, p.obstacle_corner)};
}

}  // namespace gauss6
