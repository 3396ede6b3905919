// Constraint offsetting of new contacts (METHOD.md section 3): the offset
// profile, the matching of a new set's rows to the cached ones, the
// right-hand sides of each coupling step, and the energy account that keeps
// them passive. See offsetting.h.
#include "gauss6/contact/offsetting.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace gauss6 {

bool valid_offset_settings(const OffsetSettings& s) noexcept {
  return std::isfinite(s.eps) && s.eps < 0 && std::isfinite(s.T) && s.T > 0;
}

bool needs_offset(double d_k, const OffsetSettings& s) noexcept { return d_k < s.eps; }

namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

// f_k(t) of cached row k: its offset while it runs, 0 after it (or without one).
double ramp(const OffsetSettings& settings, double t, const OffsetState& s, int k) noexcept {
  const double dt = t - s.t0[k];
  return s.start[k] < 0 && dt < settings.T ? offset_rhs(s.start[k], dt, settings) : 0.0;
}

}  // namespace

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
    s->kept_b[j] = use_last ? 0.0 : ramp(offsets, t, *s, j) - s->give[j];
  }
  int num_new = 0;
  for (int k = 0; k < m; ++k) {
    const Vec3 point_W(rows.point[k][0], rows.point[k][1], rows.point[k][2]);
    const Vec3 normal_W(rows.normal[k][0], rows.normal[k][1], rows.normal[k][2]);
    s->new_point_B[k] = Rt * (point_W - xs.p);
    s->new_normal_W[k] = normal_W;
    s->new_feature[k] = rows.features != nullptr ? rows.features[k] : FeaturePair{};
    const FeaturePair& pair = s->new_feature[k];
    int match = -1;
    for (int j = 0; j < num_old && match < 0; ++j)
      if ((pair.obstacle >= 0 && s->feature[j] == pair) ||
          ((s->point_B[j] - s->new_point_B[k]).norm() <= rule.match_distance &&
           s->normal_W[j].dot(normal_W) >= rule.match_cosine))
        match = j;
    s->matched[k] = match >= 0;
    if (match < 0) {
      ++num_new;
      continue;
    }
    // Kept: its offset (if any) runs on, with its energy account.
    s->new_start[k] = s->start[match];
    s->new_t0[k] = s->t0[match];
    s->new_give[k] = s->give[match];
    s->new_last_x[k] = s->last_x[match];
    s->new_last_lambda[k] = s->last_lambda[match];
    s->new_last_rhs[k] = s->last_rhs[match];
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
      // Its start costs no energy against ac_old, but ac_old holds this
      // step's rises of the old rows' offsets: a row new at every set (its
      // normal turns, or it slides across triangles) starts each time where
      // the rising old rows put it. Its energy account starts from its level
      // at the last step, J_k ac_last, when that is lower than f_k(0), so the
      // rise is lent (account_offsets); never from above (a fresh contact
      // gives nothing back).
      s->new_give[k] = 0.0;
      s->new_last_x[k] = kNone;
      s->new_last_lambda[k] = 0.0;
      const double was = s->has_last_ac ? Eigen::Map<const Vec6>(rows.J + 6 * k).dot(s->last_ac) : s->new_start[k];
      s->new_last_rhs[k] = std::min(s->new_start[k], was);
      started += offset ? 1 : 0;
    }
  }
  for (int k = 0; k < m; ++k) {
    s->start[k] = s->new_start[k];
    s->t0[k] = s->new_t0[k];
    s->give[k] = s->new_give[k];
    s->last_x[k] = s->new_last_x[k];
    s->last_lambda[k] = s->new_last_lambda[k];
    s->last_rhs[k] = s->new_last_rhs[k];
    s->point_B[k] = s->new_point_B[k];
    s->normal_W[k] = s->new_normal_W[k];
    s->feature[k] = s->new_feature[k];
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
      feature(start.size()),
      give(start.size()),
      last_x(start.size(), std::numeric_limits<double>::quiet_NaN()),
      last_lambda(start.size()),
      last_rhs(start.size()),
      cached_J(6 * start.size()),
      new_start(start.size()),
      new_t0(start.size()),
      new_give(start.size()),
      new_last_x(start.size()),
      new_last_lambda(start.size()),
      new_last_rhs(start.size()),
      new_point_B(start.size(), Vec3::Zero()),
      new_normal_W(start.size(), Vec3::Zero()),
      new_feature(start.size()),
      matched(start.size()),
      kept_J(6 * start.size()),
      kept_b(start.size()),
      arrival_ws(std::max(max_rows, 1)),
      arrival(std::max(max_rows, 1)) {}

int fill_offsets(const OffsetSettings& settings, double t, OffsetState* s) noexcept {
  int running = 0;
  for (int k = 0; k < s->num_rows; ++k) {
    s->rhs[k] = ramp(settings, t, *s, k) - s->give[k];
    running += s->rhs[k] != 0.0 ? 1 : 0;
  }
  return running;
}

// The share c of the user's retreat by which a pushing row's right-hand side
// goes down. In one dimension, stored energy U = P + L (P the user's net
// input, L lent): a retreat dx returns dR = lambda dx to the user and, with
// b lowered by c dx, gives back c dR; c = L / P keeps L / P constant, so L
// and P reach 0 together and the user never gets back more than P.
int release_offsets(double energy_scale, const Vec6& au, const Vec6& hand, const double* J, OffsetState* s) noexcept {
  const bool lent = s->lent > 0 && energy_scale > 0;
  const double user = s->stored - s->lent;
  const double c = user > 0 ? s->lent / user : std::numeric_limits<double>::infinity();
  int nonzero = 0;
  for (int k = 0; k < s->num_rows; ++k) {
    nonzero += s->rhs[k] != 0.0 ? 1 : 0;
    // Every row below its surface goes down, pushing or not: a row that did
    // not push would take the force over as the pushing ones went down (the
    // thin wall's probe: its face's row given back, the four edge/edge rows at
    // its tip held 3.5 N and the account gave nothing back). A row that does
    // not push gives and takes nothing.
    if (!lent || !(s->rhs[k] < 0 || s->last_lambda[k] > 0)) continue;
    const Eigen::Map<const Vec6> Jk(J + 6 * k);
    const double x = Jk.dot(au);
    const double back = Jk.dot(hand);
    if (!(back > 0) || std::isnan(s->last_x[k])) continue;  // last_x NaN: a new row
    // Lowered by c back, but never below the hand's own value J_k au (there
    // the row no longer pushes: lowering it further gives nothing back).
    const double lower = std::min(c * back, s->rhs[k] - x);
    if (!(lower > 0)) continue;
    nonzero += s->rhs[k] == 0.0 ? 1 : 0;
    s->rhs[k] -= lower;
    s->give[k] += lower;
  }
  return nonzero;
}

void account_offsets(const OffsetSettings& settings, double energy_scale, double t, const Vec6& au, const Vec6& ac,
                     const double* lambda, bool optimal, const Mat6& M, const double* J, OffsetState* s) noexcept {
  const int m = s->num_rows;
  const Vec6 r = ac - au;
  s->stored = optimal && m > 0 ? 0.5 * energy_scale * r.dot(M * r) : 0.0;
  double lent = s->lent;
  for (int k = 0; k < m; ++k) {
    const Eigen::Map<const Vec6> Jk(J + 6 * k);
    s->last_x[k] = Jk.dot(au);
    if (!optimal) {
      s->last_lambda[k] = 0.0;
      s->last_rhs[k] = s->rhs[k];
      continue;
    }
    // The work of the moved right-hand side on the stored energy: lambda_k
    // after the step, above the step's mean when the rise pushed harder (a
    // rise is lent no less than it put in) and below it when a lowering
    // eased the row (given back no more than it took).
    lent += energy_scale * lambda[k] * (s->rhs[k] - s->last_rhs[k]);
    if (!(lambda[k] > 0) && s->rhs[k] < 0) {
      // Not pushing: b_k may come up to J_k ac (ac stays feasible and
      // optimal), never above f_k(t).
      const double f = ramp(settings, t, *s, k);
      const double up = std::min(f, Jk.dot(ac));
      if (up > s->rhs[k]) {
        s->rhs[k] = up;
        s->give[k] = f - up;
      }
    }
    s->last_lambda[k] = lambda[k];
    s->last_rhs[k] = s->rhs[k];
  }
  s->last_ac = ac;
  s->has_last_ac = optimal;
  // Lent energy is part of the stored energy: never more than it, never < 0.
  s->lent = std::clamp(lent, 0.0, s->stored);
}

}  // namespace gauss6
