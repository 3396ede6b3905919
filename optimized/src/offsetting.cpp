// Constraint offsetting of new contacts (METHOD.md section 3): the offset
// profile, the matching of a new set's rows to the cached ones, and the
// right-hand sides of each coupling step. See offsetting.h.
#include "gauss6/offsetting.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace gauss6 {

bool valid_offset_settings(const OffsetSettings& s) noexcept {
  return std::isfinite(s.eps) && s.eps < 0 && std::isfinite(s.T) && s.T > 0;
}

bool needs_offset(double d_k, const OffsetSettings& s) noexcept { return d_k < s.eps; }

double offset_rhs(double d_k, double t, const OffsetSettings& s) noexcept {
  const double u = std::clamp(t / s.T, 0.0, 1.0);
  const double smooth = u * u * (3.0 - 2.0 * u);
  return u >= 1.0 ? 0.0 : d_k * (1.0 - smooth);
}

// A row that is the same constraint as a cached one (same body-frame point
// within match_distance, same normal) keeps its offset. A new row k is measured
// against what the user felt just before it arrived: d_k = J_k ac_old, with
// ac_old the projection of au on the previous set's rows with their right-hand
// sides at t (ac_old = au when there were none: METHOD.md's d_k = J_k au). A new
// row with d_k < eps starts an offset at f_k(0) = d_k: ac_old stays feasible and
// optimal, so the force does not jump. Measured against au instead, a contact
// that slides across triangles (its rows change identity at every set) would be
// offset again and again and the force would keep dropping to zero; so would a
// row that the old rows already enforce (an edge crossing a face the god-object
// slides on).
int start_offsets(const OffsetRule& rule, double t, const Vec6& au, const Mat6& M, const Pose& xs,
                  const OffsetRows& rows, OffsetState* s) noexcept {
  const OffsetSettings& offsets = rule.offsets;
  // The runtime sizes the state for its contact capacity, so m never exceeds it;
  // rows beyond it would have no room and are not cached (nor offset).
  const int m = std::min(rows.num_rows, s->capacity());
  const Mat3 Rt = rotation_matrix(xs.q).transpose();
  // The previous set's rows and their right-hand sides now: the "before" problem.
  // After an empty set, the last non-empty one (arrived or emptied less than
  // offset_time ago) stands in for it, without offsets.
  const int num_old = s->num_rows;
  const bool use_last = num_old == 0 && s->num_last_rows > 0 && t - s->last_rows_time < offsets.T;
  const int num_before = use_last ? s->num_last_rows : num_old;
  for (int j = 0; j < num_before; ++j) {
    std::memcpy(&s->kept_J[6 * j], &s->cached_J[6 * j], 6 * sizeof(double));
    const double dt = t - s->t0[j];
    s->kept_b[j] = !use_last && s->start[j] < 0 && dt < offsets.T ? offset_rhs(s->start[j], dt, offsets) : 0.0;
  }
  int num_new = 0;
  for (int k = 0; k < m; ++k) {
    const Vec3 point_W(rows.point[k][0], rows.point[k][1], rows.point[k][2]);
    const Vec3 normal_W(rows.normal[k][0], rows.normal[k][1], rows.normal[k][2]);
    s->new_point_B[k] = Rt * (point_W - xs.p);
    s->new_normal_W[k] = normal_W;
    int match = -1;
    for (int j = 0; j < num_old && match < 0; ++j)
      if ((s->point_B[j] - s->new_point_B[k]).norm() <= rule.match_distance &&
          s->normal_W[j].dot(normal_W) >= rule.match_cosine)
        match = j;
    s->matched[k] = match >= 0;
    if (match < 0) {
      ++num_new;
      continue;
    }
    // Kept: its offset (if any) runs on.
    s->new_start[k] = s->start[match];
    s->new_t0[k] = s->t0[match];
  }
  int started = 0;
  if (num_new > 0) {
    Vec6 ac_old = au;
    if (num_before > 0) {
      ProjectionProblem before;
      before.M = &M;
      before.au = au;
      before.J = s->kept_J.data();
      before.b = s->kept_b.data();
      before.num_rows = num_before;
      const ProjectionStatus status = project(before, rule.projection, &s->arrival_ws, &s->arrival);
      if (status == ProjectionStatus::kOptimal) ac_old = s->arrival.ac;
    }
    const bool valid = valid_offset_settings(offsets);
    for (int k = 0; k < m; ++k) {
      if (s->matched[k]) continue;
      const double d_k = Eigen::Map<const Vec6>(rows.J + 6 * k).dot(ac_old);
      const bool offset = valid && needs_offset(d_k, offsets);
      s->new_start[k] = offset ? d_k : 0.0;
      s->new_t0[k] = t;
      started += offset ? 1 : 0;
    }
  }
  for (int k = 0; k < m; ++k) {
    s->start[k] = s->new_start[k];
    s->t0[k] = s->new_t0[k];
    s->point_B[k] = s->new_point_B[k];
    s->normal_W[k] = s->new_normal_W[k];
  }
  if (m > 0) {
    std::memcpy(s->cached_J.data(), rows.J, sizeof(double) * 6 * static_cast<size_t>(m));
    s->num_last_rows = m;
    s->last_rows_time = t;
  } else if (num_old > 0) {
    s->last_rows_time = t;  // the set just emptied: the stand-in's clock starts now
  }
  s->num_rows = m;
  return started;
}

OffsetState::OffsetState(int max_rows)
    : start(static_cast<size_t>(std::max(max_rows, 0))),
      t0(start.size()),
      rhs(start.size()),
      point_B(start.size(), Vec3::Zero()),
      normal_W(start.size(), Vec3::Zero()),
      cached_J(6 * start.size()),
      new_start(start.size()),
      new_t0(start.size()),
      new_point_B(start.size(), Vec3::Zero()),
      new_normal_W(start.size(), Vec3::Zero()),
      matched(start.size()),
      kept_J(6 * start.size()),
      kept_b(start.size()),
      arrival_ws(std::max(max_rows, 1)),
      arrival(std::max(max_rows, 1)) {}

int fill_offsets(const OffsetSettings& settings, double t, OffsetState* s) noexcept {
  int running = 0;
  for (int k = 0; k < s->num_rows; ++k) {
    const double dt = t - s->t0[k];
    const bool runs = s->start[k] < 0 && dt < settings.T;
    s->rhs[k] = runs ? offset_rhs(s->start[k], dt, settings) : 0.0;
    running += runs ? 1 : 0;
  }
  return running;
}

}  // namespace gauss6
