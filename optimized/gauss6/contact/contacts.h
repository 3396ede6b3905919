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
// A vertex/face pair whose vertex lies beside the face (beyond one of its
// edges, seen along the face's normal) is a vertex/edge contact, and the face's
// normal is a contact normal of it only where it also supports the vertex's
// own body: where the plane through the vertex normal to it leaves the
// vertex's neighbours on the body's side (to the angle merge_angle). A flat
// plate's vertex just beside a tool's bottom edge is such a pair with the
// tool's side face, whose horizontal normal the plate's vertex does not
// support; the tool's bottom face across that edge gives the same vertex a
// row that does (its plate's normal). Such a pair is left out (counted in
// num_beside) when a face of the same body at that edge or corner gives the
// vertex a row as near as the pair's (to rounding) and within the distance,
// whose normal supports the vertex's body while no normal turned from it
// towards the left-out one by more than patch_angle does: the vertex's body
// leaves no room between the two (a flat plate). Otherwise both rows are
// kept, and the vertex is held by both: a sharp vertex on a sharp edge (a
// knife), where neither normal supports it; a curved body's vertex, which
// supports normals between the two, along which its contact with the edge
// pushes; a row nearer than every face that would hold it. Whether a row is
// left out does not depend on the distance (but for a holding row within
// rounding of it): a set within a larger distance holds every row of the set
// within a smaller one.
// Pairs with the same point (within merge_distance) and the same normal (within
// merge_angle) are merged, keeping the smallest separation: a vertex on an edge
// shared by two coplanar faces gives one contact, not two.
//
// A set that would exceed its capacity is reduced to the support of each patch
// (reduce_to_patch_supports): contacts whose normals agree within patch_angle
// form a patch, and a contact of a patch that lies inside the convex hull of
// the patch's other points (seen along the normal) is left out, except the
// patch's smallest separation. Its row [n, (I - G) x n] is affine in I, so it is
// a convex combination of the hull vertices' rows: the cone {J a >= 0} and the
// cone of contact wrenches {J^T lambda} are the same with or without it, to the
// angle between the normals (at most patch_angle: a tool tilted by 1e-5 rad on
// a plate turns its edge/edge normals by as much, each a patch of its own at
// merge_angle). A dense coplanar patch (a flat tool on a finely
// tessellated plate: thousands of pairs) is then its corners, wherever the
// search met them first. A set that fits is never reduced: every pair within
// the distance is in it, but for the vertices beside an edge above.
//
// Real time: no allocation (ContactSet and ContactWorkspace are sized once), no
// locks, no exceptions. When the reduced set still has no room (more distinct
// normals than the set holds), the set keeps the first ones found and says so
// (overflow).
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
  double patch_angle = 1e-3;      // a full set's patches: normals within this (radians; reduce_to_patch_supports)
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
  explicit ContactSet(int capacity = 64)
      : contacts(static_cast<size_t>(capacity)),
        J(capacity, 6),
        patch(contacts.size()),
        order(contacts.size()),
        hull(contacts.size() + 1),
        keep(contacts.size()),
        plane(contacts.size()),
        merge_head(merge_buckets(capacity), -1),
        merge_next(contacts.size()) {}
  int capacity() const { return static_cast<int>(contacts.size()); }
  int num_contacts = 0;
  int num_pairs_within = 0;       // pairs found within distance, before merging
  int num_reductions = 0;         // times the set was reduced to its patches' supports (0: every pair is in it)
  int num_beside = 0;             // vertex/face pairs within distance left out: a vertex beside an edge (above)
  std::vector<Contact> contacts;
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> J;
  // Scratch of reduce_to_patch_supports (one entry a contact).
  std::vector<int> patch, order, hull;
  std::vector<unsigned char> keep;
  std::vector<Eigen::Vector2d> plane;
  // Scratch of generate_contacts' merging: the set's contacts hashed by the
  // grid cell of their point's x and y (merge_head: a bucket's first contact,
  // -1 for none; merge_next: the next contact of its bucket), so that a new
  // contact is compared with the contacts of the nine cells around its own,
  // not with every contact.
  std::vector<int> merge_head, merge_next;
  // The number of buckets for a set of `capacity`: a power of two, at least four times it.
  static size_t merge_buckets(int capacity) {
    size_t n = 16;
    while (n < 4 * static_cast<size_t>(capacity > 0 ? capacity : 0)) n *= 2;
    return n;
  }
};

// Reduces contacts[0 .. num_contacts) to the support of each patch (above):
// keeps, in their order, the contacts of patches of one or two contacts, and of
// larger ones the vertices of the convex hull of their points projected on the
// plane normal to the patch's first normal, and the smallest separation.
// Contacts of one patch: normals within patch_angle (radians) of its first
// contact's. Rows J are not touched. Returns the number of contacts left out.
int reduce_to_patch_supports(double patch_angle, ContactSet* set) noexcept;

// Adds contacts to a set as generate_contacts adds each pair's contact: c is
// merged with the first contact of the set (in the set's order) whose point is
// within merge_distance of c's and whose normal is within merge_angle (the
// smaller separation stays); otherwise appended, a full set first reduced
// (reduce_to_patch_supports; overflow when that frees nothing, c then left
// out). Counts num_pairs_within and num_reductions.
// The set's contacts are indexed by grid cells of side 4 `reject` along x and
// y (ContactSet::merge_head): a contact within `reject` of another along x and
// along y lies in one of the nine cells around the other's, so the first of
// the contacts of those cells that merges is the first of the whole set, and
// the set is the same as when c is compared with every contact. Cells are
// formed only while every point's scaled coordinates stay below kMaxCell (each
// then rounds by at most 1/8, and two within `reject` differ by under 1/2
// before flooring); past that, or for a point that is not finite, every
// contact is compared for the rest of the collector's life.
// The set is used as it is (contacts already in it are kept and merged with).
struct ContactCollector {
  ContactCollector(const ContactSettings& settings, ContactSet* set) noexcept;
  void add(const Contact& c) noexcept;

  const ContactSettings& settings;
  double merge_distance, merge_cos;  // settings.merge_distance (or 1e-3 distance), cos(merge_angle)
  ContactSet* set;
  bool overflow = false;             // a contact was left out: the reduced set had no room
  double reject = 0;                 // merge_distance and its norm's rounding: farther along x or y never merges
  double inv_cell = 0;               // 1 / (4 reject)
  bool indexed = false;              // whether the cells are in use

 private:
  static constexpr double kMaxCell = 0x1p50;
  bool cell_of(const Vec3& p, int64_t* ix, int64_t* iy) const;
  size_t bucket(int64_t ix, int64_t iy) const;
  void insert(int i, int64_t ix, int64_t iy);
  void rebuild();
  bool merges(const Contact& o, const Contact& c) const;
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

// The world box of the body box `box` at the pose (R, G), R the double
// rotation_matrix of the pose and absR = |R| entrywise: it holds G + R v,
// computed in doubles as generate_contacts poses a vertex, for every double v
// within box (proofs/BoxPose.v, box_pose_encloses).
Aabb posed_body_box(const Mat3& R, const Mat3& absR, const Vec3& G, const Aabb& box) noexcept;

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
