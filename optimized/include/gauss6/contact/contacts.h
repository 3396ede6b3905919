// Contact set generation at a stop pose (METHOD.md sections 1 and 4): every
// vertex/face and edge/edge pair of the god-object and the obstacles within a
// distance, with its point, unit normal, separation, features, and the m x 6
// Jacobian rows J_k = [n_k^T, ((I_k - G) x n_k)^T].
//
// Conventions (world frame W): n_k points out of the obstacle, towards the
// god-object: the obstacle face's normal for (god vertex, obstacle face), minus
// the god face's normal for (obstacle vertex, god face), and for edge/edge the
// normalised cross product of the two edges, signed to point from the
// obstacle's closest point to the god-object's. I_k is the god-object's closest
// point (the point whose motion the row constrains). Edge/edge pairs whose
// closest points are at an edge's end, or whose edges are parallel, are left
// out: such a contact is a vertex near an edge, already in the set as the
// vertex against the faces of that edge, with a well-defined face normal.
// Pairs with the same point (within merge_distance) and the same normal (within
// merge_angle) are merged, keeping the smallest separation: a vertex on an edge
// shared by two coplanar faces gives one contact, not two.
//
// Real time: no allocation (ContactSet and ContactWorkspace are sized once), no
// locks, no exceptions. When more contacts are found than the set holds, the
// set keeps the first ones found and says so (overflow).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "gauss6/geometry/bvh.h"
#include "gauss6/ccd/motion_bounds.h"
#include "gauss6/step/near_pairs.h"

namespace gauss6 {

struct ContactSettings {
  double distance = 0;            // pairs within this distance: delta (1 + a small factor) (scene units, > 0)
  double merge_distance = 0;      // merge contacts closer than this (scene units; 0: 1e-3 distance)
  double merge_angle = 1e-6;      // ... whose normals differ by less than this (radians)
  double parallel_sine = 1e-9;    // edges with |e1 x e2| <= this |e1| |e2| count as parallel
};

struct Contact {
  Vec3 point = Vec3::Zero();      // I_k, world frame, on the god-object
  Vec3 normal = Vec3::Zero();     // n_k, unit, world frame, out of the obstacle
  double separation = 0;          // distance of the two features (scene units, >= 0)
  FeaturePair features;
};

enum class ContactStatus { kOk = 0, kOverflow, kStackFull, kInvalidInput };
const char* to_string(ContactStatus s);

// A fixed-capacity contact set: contacts[0 .. num_contacts) and the rows
// J.topRows(num_contacts) (J has capacity rows and 6 columns: linear then angular).
struct ContactSet {
  explicit ContactSet(int capacity = 64) : contacts(static_cast<size_t>(capacity)), J(capacity, 6) {}
  int capacity() const { return static_cast<int>(contacts.size()); }
  int num_contacts = 0;
  int num_pairs_within = 0;       // pairs found within distance, before merging
  std::vector<Contact> contacts;
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> J;
};

// World positions of the god-object's vertices, posed on first use in each call
// (a vertex is current when its stamp equals `stamp`), the god nodes' world
// and oriented boxes likewise (each computed once per call however many
// obstacle nodes it meets), and the traversal stack.
struct ContactWorkspace {
  explicit ContactWorkspace(const TriangleMesh& god_mesh, int stack_capacity = 1024)
      : god_world(static_cast<size_t>(god_mesh.V.rows())), posed(god_world.size(), 0), stack(stack_capacity) {}
  std::vector<Vec3> god_world;
  std::vector<uint32_t> posed;
  uint32_t stamp = 0;
  SweptBoxCache boxes{12, 0};  // nodes, faces and node_obbs at the call's pose (no posed faces)
  BvhStack stack;
};

// The contact set of the god-object at pose X_WB (G = X_WB.p) against the
// obstacles (world frame). With near.listed(), the triangle pairs near[0 ..
// near.num_pairs) are tested instead of a descent of the trees: a list that
// holds every pair within settings.distance at X_WB (ccd_step's near pairs:
// CcdStepWorkspace::near_pairs(CcdStepResult::num_near_pairs)), which gives
// the same set.
ContactStatus generate_contacts(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X_WB,
                                const ContactSettings& settings, ContactWorkspace* ws, ContactSet* set,
                                const NearPairs& near = {}) noexcept;

}  // namespace gauss6
