(* Issue 45's item 6, the stop pose (ccd/motion.cpp make_stop_pose, lines
   173-192; its contract: step/ccd_step.h, lines 45-48, motion.h StopPose): every
   body point r (|r_j| <= rho) placed at the double pose the code returns,
   exactly (p + R(q) r, R(q) the rational rotation of the double quaternion),
   lies within the returned `deviation` of where the exact motion puts it at u
   (p(u) + R(u) r); hence its distance from any obstacle point differs from the
   exact motion's by at most `deviation`: a CCD run at min_separation d that
   stopped at u (every pair at least d apart on the motion up to u, the pair
   that stopped it within d + the distance tolerance) leaves the double pose
   at least d - deviation from every obstacle (exactly free when deviation <
   d) and its stopping pair within d + tolerance + deviation. The deviation is
   computed as the code computes it: per world axis i, magnitude(p_i - e.p_i)
   + rho (sum_j magnitude(Rq_ij - e.R_ij)), squared, summed, square-rooted,
   every step an Upper operation of rounding.h (Rounding.v). Same model as
   Rounding.v. *)

From Coq Require Import Reals Psatz.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding.
Open Scope R_scope.

(* ---- The Euclidean norm of R^3 and its triangle inequality ---- *)

Definition norm3 x y z := sqrt (x * x + y * y + z * z).

Lemma norm3_nonneg x y z : 0 <= norm3 x y z.
Proof. apply sqrt_pos. Qed.

Lemma sq_nonneg3 x y z : 0 <= x * x + y * y + z * z.
Proof. pose proof (Rle_0_sqr x); pose proof (Rle_0_sqr y); pose proof (Rle_0_sqr z); unfold Rsqr in *; lra. Qed.

(* Cauchy-Schwarz: a . b <= |a| |b| (Lagrange's identity: |a|^2 |b|^2 - (a . b)^2 = |a x b|^2). *)
Lemma cauchy_schwarz3 a0 a1 a2 b0 b1 b2 :
  a0 * b0 + a1 * b1 + a2 * b2 <= norm3 a0 a1 a2 * norm3 b0 b1 b2.
Proof.
  unfold norm3. rewrite <- sqrt_mult by apply sq_nonneg3.
  set (s := a0 * b0 + a1 * b1 + a2 * b2).
  assert (L : (a0 * a0 + a1 * a1 + a2 * a2) * (b0 * b0 + b1 * b1 + b2 * b2) - s * s =
              (a1 * b2 - a2 * b1) * (a1 * b2 - a2 * b1) + (a2 * b0 - a0 * b2) * (a2 * b0 - a0 * b2) +
              (a0 * b1 - a1 * b0) * (a0 * b1 - a1 * b0)) by (unfold s; ring).
  pose proof (Rle_0_sqr (a1 * b2 - a2 * b1)). pose proof (Rle_0_sqr (a2 * b0 - a0 * b2)).
  pose proof (Rle_0_sqr (a0 * b1 - a1 * b0)). unfold Rsqr in *.
  destruct (Rle_or_lt s 0) as [Hs|Hs]; [pose proof (sqrt_pos ((a0 * a0 + a1 * a1 + a2 * a2) * (b0 * b0 + b1 * b1 + b2 * b2))); lra|].
  rewrite <- (sqrt_square s) by lra. apply sqrt_le_1_alt. lra.
Qed.

Lemma norm3_triangle a0 a1 a2 b0 b1 b2 :
  norm3 (a0 + b0) (a1 + b1) (a2 + b2) <= norm3 a0 a1 a2 + norm3 b0 b1 b2.
Proof.
  pose proof (norm3_nonneg a0 a1 a2). pose proof (norm3_nonneg b0 b1 b2).
  pose proof (cauchy_schwarz3 a0 a1 a2 b0 b1 b2) as CS.
  unfold norm3 at 1. rewrite <- (sqrt_square (norm3 a0 a1 a2 + norm3 b0 b1 b2)) by lra.
  apply sqrt_le_1_alt.
  assert (Ha : norm3 a0 a1 a2 * norm3 a0 a1 a2 = a0 * a0 + a1 * a1 + a2 * a2)
    by (unfold norm3; apply sqrt_sqrt, sq_nonneg3).
  assert (Hb : norm3 b0 b1 b2 * norm3 b0 b1 b2 = b0 * b0 + b1 * b1 + b2 * b2)
    by (unfold norm3; apply sqrt_sqrt, sq_nonneg3).
  nra.
Qed.

(* |  |x - y| - |z - y|  | <= |x - z|, in R^3. *)
Lemma norm3_reverse x0 x1 x2 z0 z1 z2 y0 y1 y2 :
  Rabs (norm3 (x0 - y0) (x1 - y1) (x2 - y2) - norm3 (z0 - y0) (z1 - y1) (z2 - y2)) <=
  norm3 (x0 - z0) (x1 - z1) (x2 - z2).
Proof.
  pose proof (norm3_triangle (x0 - z0) (x1 - z1) (x2 - z2) (z0 - y0) (z1 - y1) (z2 - y2)) as T1.
  pose proof (norm3_triangle (z0 - x0) (z1 - x1) (z2 - x2) (x0 - y0) (x1 - y1) (x2 - y2)) as T2.
  replace (x0 - z0 + (z0 - y0)) with (x0 - y0) in T1 by ring.
  replace (x1 - z1 + (z1 - y1)) with (x1 - y1) in T1 by ring.
  replace (x2 - z2 + (z2 - y2)) with (x2 - y2) in T1 by ring.
  replace (z0 - x0 + (x0 - y0)) with (z0 - y0) in T2 by ring.
  replace (z1 - x1 + (x1 - y1)) with (z1 - y1) in T2 by ring.
  replace (z2 - x2 + (x2 - y2)) with (z2 - y2) in T2 by ring.
  assert (E : norm3 (z0 - x0) (z1 - x1) (z2 - x2) = norm3 (x0 - z0) (x1 - z1) (x2 - z2))
    by (unfold norm3; f_equal; ring).
  rewrite E in T2. apply Rabs_le. lra.
Qed.

(* ---- make_stop_pose's deviation ---- *)

(* One world axis: the Upper sum row = ((0 + m0) + m1) + m2 of the rotation
   entries' magnitudes, and a = magnitude(dp) + rho row, as the code computes
   them (`Upper row{0}; row = row + magnitude(...)`, `magnitude(dp) +
   body_radius * row`). *)
Definition urow m0 m1 m2 := next_up (fl (next_up (fl (next_up (fl (0 + m0)) + m1)) + m2)).
Definition uaxis dp rho row := next_up (fl (dp + next_up (fl (rho * row)))).
Definition pt (x : R) := {| lo := x; hi := x |}.

(* The body point's i-th world coordinate at the double pose and at the
   motion's pose differ by at most uaxis (p_i the pose's double, pu_i the
   motion's exact position held by the interval EP; Rq_ij R(q)'s exact entry
   held by RQ_ij, Ru_ij the motion's exact rotation entry held by ER_ij). *)
Lemma axis_bound p pu EP Rq0 Rq1 Rq2 Ru0 Ru1 Ru2 RQ0 RQ1 RQ2 ER0 ER1 ER2 r0 r1 r2 rho :
  holds EP pu -> holds RQ0 Rq0 -> holds RQ1 Rq1 -> holds RQ2 Rq2 ->
  holds ER0 Ru0 -> holds ER1 Ru1 -> holds ER2 Ru2 ->
  Rabs r0 <= rho -> Rabs r1 <= rho -> Rabs r2 <= rho ->
  Rabs ((p + (Rq0 * r0 + Rq1 * r1 + Rq2 * r2)) - (pu + (Ru0 * r0 + Ru1 * r1 + Ru2 * r2))) <=
  uaxis (mag (isub (pt p) EP)) rho (urow (mag (isub RQ0 ER0)) (mag (isub RQ1 ER1)) (mag (isub RQ2 ER2))).
Proof.
  intros HP H0 H1 H2 E0 E1 E2 B0 B1 B2.
  assert (Hrho : 0 <= rho) by (pose proof (Rabs_pos r0); lra).
  assert (Hp : Rabs (p - pu) <= mag (isub (pt p) EP))
    by (apply magnitude_bounds, interval_sub_encloses; [unfold holds, pt; simpl; lra | exact HP]).
  assert (M0 : Rabs (Rq0 - Ru0) <= mag (isub RQ0 ER0)) by (apply magnitude_bounds, interval_sub_encloses; assumption).
  assert (M1 : Rabs (Rq1 - Ru1) <= mag (isub RQ1 ER1)) by (apply magnitude_bounds, interval_sub_encloses; assumption).
  assert (M2 : Rabs (Rq2 - Ru2) <= mag (isub RQ2 ER2)) by (apply magnitude_bounds, interval_sub_encloses; assumption).
  set (m0 := mag (isub RQ0 ER0)) in *. set (m1 := mag (isub RQ1 ER1)) in *. set (m2 := mag (isub RQ2 ER2)) in *.
  (* the row: m0 + m1 + m2 <= urow *)
  assert (Hrow : m0 + m1 + m2 <= urow m0 m1 m2).
  { unfold urow. apply upper_add; [|lra]. apply upper_add; [|lra].
    replace m0 with (0 + m0) at 1 by ring. apply upper_add; lra. }
  (* each term |dR_j| |r_j| <= m_j rho *)
  assert (T : forall a b m, Rabs a <= m -> Rabs b <= rho -> Rabs (a * b) <= m * rho).
  { intros a b m Ha Hb. rewrite Rabs_mult. apply Rmult_le_compat; try apply Rabs_pos; assumption. }
  pose proof (T _ _ _ M0 B0). pose proof (T _ _ _ M1 B1). pose proof (T _ _ _ M2 B2).
  assert (Hsum : Rabs ((Rq0 - Ru0) * r0 + (Rq1 - Ru1) * r1 + (Rq2 - Ru2) * r2) <= rho * urow m0 m1 m2).
  { eapply Rle_trans; [apply Rabs_triang|]. pose proof (Rabs_triang ((Rq0 - Ru0) * r0) ((Rq1 - Ru1) * r1)).
    assert (rho * (m0 + m1 + m2) <= rho * urow m0 m1 m2) by (apply Rmult_le_compat_l; lra). nra. }
  unfold uaxis. apply Rle_trans with (Rabs (p - pu) + Rabs ((Rq0 - Ru0) * r0 + (Rq1 - Ru1) * r1 + (Rq2 - Ru2) * r2)).
  - replace (p + (Rq0 * r0 + Rq1 * r1 + Rq2 * r2) - (pu + (Ru0 * r0 + Ru1 * r1 + Ru2 * r2)))
      with ((p - pu) + ((Rq0 - Ru0) * r0 + (Rq1 - Ru1) * r1 + (Rq2 - Ru2) * r2)) by ring.
    apply Rabs_triang.
  - apply upper_add; [exact Hp|]. apply up_ge; exact Hsum.
Qed.

(* The deviation: sum2 = ((0 + sqr a0) + sqr a1) + sqr a2, deviation =
   sqrt(sum2), every step rounded up (`Upper sum2{0}; sum2 = sum2 + sqr(...)`,
   `sqrt(sum2).v`). *)
Definition udeviation a0 a1 a2 :=
  let s0 := next_up (fl (0 + next_up (fl (a0 * a0)))) in
  let s1 := next_up (fl (s0 + next_up (fl (a1 * a1)))) in
  let s2 := next_up (fl (s1 + next_up (fl (a2 * a2)))) in
  next_up (fl (sqrt s2)).

Lemma deviation_bound x0 x1 x2 a0 a1 a2 :
  Rabs x0 <= a0 -> Rabs x1 <= a1 -> Rabs x2 <= a2 -> norm3 x0 x1 x2 <= udeviation a0 a1 a2.
Proof.
  intros H0 H1 H2. unfold udeviation, norm3.
  assert (S : forall x a, Rabs x <= a -> x * x <= next_up (fl (a * a))).
  { intros x a Ha. replace (x * x) with (Rabs x * Rabs x)
      by (rewrite <- Rabs_mult; apply Rabs_pos_eq, Rle_0_sqr).
    apply upper_sqr. split; [apply Rabs_pos | exact Ha]. }
  apply upper_sqrt. split; [apply sq_nonneg3|].
  apply upper_add; [|apply S; exact H2]. apply upper_add; [|apply S; exact H1].
  replace (x0 * x0) with (0 + x0 * x0) by ring. apply upper_add; [lra | apply S; exact H0].
Qed.

(* The theorem: the whole deviation, then the separations. The intervals are
   make_stop_pose's: e.p (EP), e.R (ER: enclose_motion at the point u) and Rq
   (RQ: rational_rotation of the returned q); p the returned position. *)
Definition stop_deviation (p0 p1 p2 : R) (EP0 EP1 EP2 : Interval)
    (RQ00 RQ01 RQ02 RQ10 RQ11 RQ12 RQ20 RQ21 RQ22 : Interval)
    (ER00 ER01 ER02 ER10 ER11 ER12 ER20 ER21 ER22 : Interval) rho :=
  udeviation
    (uaxis (mag (isub (pt p0) EP0)) rho (urow (mag (isub RQ00 ER00)) (mag (isub RQ01 ER01)) (mag (isub RQ02 ER02))))
    (uaxis (mag (isub (pt p1) EP1)) rho (urow (mag (isub RQ10 ER10)) (mag (isub RQ11 ER11)) (mag (isub RQ12 ER12))))
    (uaxis (mag (isub (pt p2) EP2)) rho (urow (mag (isub RQ20 ER20)) (mag (isub RQ21 ER21)) (mag (isub RQ22 ER22)))).

(* covers optimized/gauss6/ccd/motion.cpp "StopPose make_stop_pose(const CcdMotion& m, double u, double body_radius)" sha256:2e6cb16de2221255 *)
Theorem stop_pose_deviation p0 p1 p2 pu0 pu1 pu2 EP0 EP1 EP2
    Rq00 Rq01 Rq02 Rq10 Rq11 Rq12 Rq20 Rq21 Rq22 RQ00 RQ01 RQ02 RQ10 RQ11 RQ12 RQ20 RQ21 RQ22
    Ru00 Ru01 Ru02 Ru10 Ru11 Ru12 Ru20 Ru21 Ru22 ER00 ER01 ER02 ER10 ER11 ER12 ER20 ER21 ER22 r0 r1 r2 rho :
  holds EP0 pu0 -> holds EP1 pu1 -> holds EP2 pu2 ->
  holds RQ00 Rq00 -> holds RQ01 Rq01 -> holds RQ02 Rq02 -> holds RQ10 Rq10 -> holds RQ11 Rq11 ->
  holds RQ12 Rq12 -> holds RQ20 Rq20 -> holds RQ21 Rq21 -> holds RQ22 Rq22 ->
  holds ER00 Ru00 -> holds ER01 Ru01 -> holds ER02 Ru02 -> holds ER10 Ru10 -> holds ER11 Ru11 ->
  holds ER12 Ru12 -> holds ER20 Ru20 -> holds ER21 Ru21 -> holds ER22 Ru22 ->
  Rabs r0 <= rho -> Rabs r1 <= rho -> Rabs r2 <= rho ->
  let X0 := p0 + (Rq00 * r0 + Rq01 * r1 + Rq02 * r2) in
  let X1 := p1 + (Rq10 * r0 + Rq11 * r1 + Rq12 * r2) in
  let X2 := p2 + (Rq20 * r0 + Rq21 * r1 + Rq22 * r2) in
  let U0 := pu0 + (Ru00 * r0 + Ru01 * r1 + Ru02 * r2) in
  let U1 := pu1 + (Ru10 * r0 + Ru11 * r1 + Ru12 * r2) in
  let U2 := pu2 + (Ru20 * r0 + Ru21 * r1 + Ru22 * r2) in
  let dev := stop_deviation p0 p1 p2 EP0 EP1 EP2 RQ00 RQ01 RQ02 RQ10 RQ11 RQ12 RQ20 RQ21 RQ22
                            ER00 ER01 ER02 ER10 ER11 ER12 ER20 ER21 ER22 rho in
  norm3 (X0 - U0) (X1 - U1) (X2 - U2) <= dev /\
  forall y0 y1 y2,
    Rabs (norm3 (X0 - y0) (X1 - y1) (X2 - y2) - norm3 (U0 - y0) (U1 - y1) (U2 - y2)) <= dev.
Proof.
  intros. assert (D : norm3 (X0 - U0) (X1 - U1) (X2 - U2) <= dev).
  { apply deviation_bound; apply axis_bound; assumption. }
  split; [exact D|]. intros y0 y1 y2.
  eapply Rle_trans; [apply norm3_reverse | exact D].
Qed.
Print Assumptions stop_pose_deviation.

(* The stop: a CCD at min_separation d that stopped at u keeps every body
   point of the exact motion's pose at u at least d from every obstacle point
   (its guarantee: u_hit <= u*, the narrow phase's conservative bounds), and
   the pair that stopped it within d + tol there (the narrow phase's
   distance_tolerance): at the returned double pose, every body point is at
   least d - deviation from every obstacle point (so no obstacle point is
   touched when deviation < d), and the stopping pair's points within d + tol
   + deviation. *)
Theorem stop_pose_separation (dev d tol : R) (X U : R -> R -> R -> R * R * R) :
  (forall r0 r1 r2 y0 y1 y2,
     let '(x0, x1, x2) := X r0 r1 r2 in let '(v0, v1, v2) := U r0 r1 r2 in
     Rabs (norm3 (x0 - y0) (x1 - y1) (x2 - y2) - norm3 (v0 - y0) (v1 - y1) (v2 - y2)) <= dev) ->
  (forall r0 r1 r2 y0 y1 y2, let '(v0, v1, v2) := U r0 r1 r2 in d <= norm3 (v0 - y0) (v1 - y1) (v2 - y2)) ->
  (forall r0 r1 r2 y0 y1 y2, let '(x0, x1, x2) := X r0 r1 r2 in d - dev <= norm3 (x0 - y0) (x1 - y1) (x2 - y2)) /\
  (forall r0 r1 r2 y0 y1 y2,
     (let '(v0, v1, v2) := U r0 r1 r2 in norm3 (v0 - y0) (v1 - y1) (v2 - y2) <= d + tol) ->
     let '(x0, x1, x2) := X r0 r1 r2 in norm3 (x0 - y0) (x1 - y1) (x2 - y2) <= d + tol + dev).
Proof.
  intros HD HS. split.
  - intros r0 r1 r2 y0 y1 y2. specialize (HD r0 r1 r2 y0 y1 y2). specialize (HS r0 r1 r2 y0 y1 y2).
    destruct (X r0 r1 r2) as [[x0 x1] x2]. destruct (U r0 r1 r2) as [[v0 v1] v2].
    apply Rabs_le_inv in HD. lra.
  - intros r0 r1 r2 y0 y1 y2 HT. specialize (HD r0 r1 r2 y0 y1 y2).
    destruct (X r0 r1 r2) as [[x0 x1] x2]. destruct (U r0 r1 r2) as [[v0 v1] v2].
    apply Rabs_le_inv in HD. lra.
Qed.
Print Assumptions stop_pose_separation.
