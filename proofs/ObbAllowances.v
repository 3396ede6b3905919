(* The error allowances of the oriented-box and displacement bounds of
   optimized/gauss6/ccd/motion_bounds.h / .cpp, proved in Flocq's binary64
   model of Rounding.v: each expression evaluated as its site evaluates it
   (the same operations in the same order, each rounded to nearest: `fl`),
   under the stated hypotheses. Same model as Rounding.v and Allowances.v
   (finite results, gradual underflow, no fused multiply-add). Also the
   exact (real) argument that a separating axis whose projected intervals
   are disjoint proves two sets apart, the one for_each_separating_axis
   (distance.h) and obb_separated (motion_bounds.h) rest on. *)

From Coq Require Import Reals Psatz List.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances.
Open Scope R_scope.

(* ---- kRelativeRounding at Displacement's shift |p_b - p_a| ----
   The code (motion_bounds.cpp, Displacement::Displacement): d = b.p - a.p in
   doubles (each component fl(b_i - a_i)), then norm_up(d.norm(),
   kRelativeRounding) = max(next_up(fl(n fl(1 + kRelativeRounding))),
   kNormFloor), n = d.norm() the computed norm of the double vector d
   (Allowances.v's norm_c, any order of the sum). The exact shift is
   |b - a|, whose components are the exact differences, not d's: each
   component of d is within u of the exact one, relatively (a difference of
   doubles is exact where it underflows: Allowances.v sub_rel), so |b - a| <=
   |d| / (1 - u), and the norm's allowance, at least 8 u, covers that 1 u
   with the norm's own 3.6 u: (1 + 3 u) |d| <= fl(n k) above the floor. *)

(* The computed norm times k >= 1 + 8 u, rounded, is at least (1 + 3 u) of
   the exact norm of the double vector wherever its square is >= 2^-1002
   (Allowances.v's norm_upper_bound proves (1 + u / 2) above 2^-1000). *)
Lemma norm_c_margin x y z k : 1 + 8 * u <= k ->
  bpow radix2 (-1002) <= x * x + y * y + z * z ->
  (1 + 3 * u) * sqrt (x * x + y * y + z * z) <= fl (norm_c x y z * k).
Proof.
  intros Hk HS2. set (S := x * x + y * y + z * z) in *.
  assert (HS0 : 0 <= S) by (unfold S; nra).
  pose proof (sumsq_lower x y z HS2) as Hs'. fold S in Hs'.
  set (s := fl (fl (fl (x * x) + fl (y * y)) + fl (z * z))) in *.
  pose proof eta_pos. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  set (N := sqrt S).
  assert (HN : bpow radix2 (-501) <= N)
    by (unfold N; rewrite <- (sqrt_bpow2 (-501)); apply sqrt_le_1_alt; exact HS2).
  assert (HeN : 1000000 * eta <= u * N) by (apply eta_norm; exact HN).
  assert (HN0 : 0 <= N) by apply sqrt_pos.
  assert (Hr : (1 - 5 / 2 * u) * N <= sqrt s).
  { unfold N. rewrite <- sqrt_scale by lra. apply sqrt_le_1_alt.
    apply Rle_trans with ((1 - 4 * u) * S); [apply Rmult_le_compat_r; nra | exact Hs']. }
  pose proof (fl_lower (sqrt s) (sqrt_pos s)) as Hf.
  assert (Hf' : (1 - 18 / 5 * u) * N <= fl (sqrt s)).
  { assert ((1 - u) * ((1 - 5 / 2 * u) * N) <= (1 - u) * sqrt s) by (apply mul_le_l; lra).
    assert ((1 - 35 / 10 * u) * N <= ((1 - u) * (1 - 5 / 2 * u)) * N) by (apply Rmult_le_compat_r; nra).
    lra. }
  unfold norm_c. fold s.
  assert (Hp : (1 + 43 / 10 * u) * N <= fl (sqrt s) * k).
  { apply Rle_trans with (((1 - 18 / 5 * u) * N) * (1 + 8 * u)).
    - apply Rle_trans with ((1 - 18 / 5 * u) * (1 + 8 * u) * N).
      + apply Rmult_le_compat_r; nra.
      + lra.
    - apply Rmult_le_compat; nra. }
  pose proof (fl_lower (fl (sqrt s) * k) ltac:(nra)) as Hq.
  assert ((1 - u) * ((1 + 43 / 10 * u) * N) <= (1 - u) * (fl (sqrt s) * k)) by (apply mul_le_l; lra).
  assert ((1 + 32 / 10 * u) * N <= ((1 - u) * (1 + 43 / 10 * u)) * N) by (apply Rmult_le_compat_r; nra).
  lra.
Qed.

(* A component rounded within u of the exact one: the exact square is at most
   the rounded one over (1 - u)^2. *)
Lemma sq_rel d D : Rabs (d - D) <= u * Rabs D -> (1 - u) * (1 - u) * (D * D) <= d * d.
Proof.
  intros H. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  assert (Hd : (1 - u) * Rabs D <= Rabs d).
  { assert (Rabs D - Rabs d <= Rabs (d - D)).
    { replace D with (d - (d - D)) at 1 by ring. pose proof (Rabs_triang d (- (d - D))).
      rewrite Rabs_Ropp in H0. replace (d + - (d - D)) with (d - (d - D)) in H0 by ring. lra. }
    lra. }
  rewrite <- (abs_sq D), <- (abs_sq d).
  assert (0 <= (1 - u) * Rabs D) by (pose proof (Rabs_pos D); nra).
  nra.
Qed.

(* allowance kRelativeRounding = 1e-15 *)
(* covers optimized/gauss6/ccd/motion_bounds.cpp "Displacement::Displacement(const Pose& a, const Pose& b)" sha256:79b4d579aa69d2b4 *)
(* covers optimized/gauss6/numeric/rounding.h "GAUSS6_ALWAYS_INLINE Upper norm_up(double norm, double relative)" sha256:b4b3280a1e614758 *)
Theorem shift_rounding a0 a1 a2 b0 b1 b2 :
  F a0 -> F a1 -> F a2 -> F b0 -> F b1 -> F b2 ->
  let d0 := fl (b0 - a0) in let d1 := fl (b1 - a1) in let d2 := fl (b2 - a2) in
  sqrt ((b0 - a0) * (b0 - a0) + (b1 - a1) * (b1 - a1) + (b2 - a2) * (b2 - a2))
    <= Rmax (next_up (fl (norm_c d0 d1 d2 * fl (1 + kRelativeRounding)))) kNormFloor.
Proof.
  intros Fa0 Fa1 Fa2 Fb0 Fb1 Fb2 d0 d1 d2.
  assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  pose proof (sq_rel d0 (b0 - a0) (sub_rel b0 a0 Fb0 Fa0)) as E0.
  pose proof (sq_rel d1 (b1 - a1) (sub_rel b1 a1 Fb1 Fa1)) as E1.
  pose proof (sq_rel d2 (b2 - a2) (sub_rel b2 a2 Fb2 Fa2)) as E2.
  fold d0 in E0; fold d1 in E1; fold d2 in E2. clearbody d0 d1 d2.
  assert (Q0 : 0 <= (b0 - a0) * (b0 - a0)) by apply Rle_0_sqr.
  assert (Q1 : 0 <= (b1 - a1) * (b1 - a1)) by apply Rle_0_sqr.
  assert (Q2 : 0 <= (b2 - a2) * (b2 - a2)) by apply Rle_0_sqr.
  assert (P0 : 0 <= d0 * d0) by apply Rle_0_sqr.
  assert (P1 : 0 <= d1 * d1) by apply Rle_0_sqr.
  assert (P2 : 0 <= d2 * d2) by apply Rle_0_sqr.
  set (SD := (b0 - a0) * (b0 - a0) + (b1 - a1) * (b1 - a1) + (b2 - a2) * (b2 - a2)).
  set (Sd := d0 * d0 + d1 * d1 + d2 * d2).
  assert (HSD0 : 0 <= SD) by (unfold SD; lra).
  assert (HSd0 : 0 <= Sd) by (unfold Sd; lra).
  assert (HE : (1 - u) * (1 - u) * SD <= Sd) by (unfold SD, Sd; lra).
  (* sqrt SD <= sqrt Sd / (1 - u) <= (1 + 2 u) sqrt Sd *)
  assert (HD : sqrt SD <= (1 + 2 * u) * sqrt Sd).
  { assert (Hq : (1 - u) * sqrt SD <= sqrt Sd).
    { rewrite <- sqrt_scale by lra. apply sqrt_le_1_alt. lra. }
    pose proof (sqrt_pos SD). pose proof (sqrt_pos Sd).
    assert (0 <= (u - 2 * u * u) * sqrt SD) by (apply Rmult_le_pos; nra).
    assert (sqrt SD <= (1 + 2 * u) * ((1 - u) * sqrt SD)) by nra.
    assert ((1 + 2 * u) * ((1 - u) * sqrt SD) <= (1 + 2 * u) * sqrt Sd) by (apply mul_le_l; lra).
    lra. }
  destruct (Rlt_or_le Sd (bpow radix2 (-1002))) as [Hs|Hs].
  - (* below 2^-501: under the floor *)
    apply Rle_trans with kNormFloor; [|apply Rmax_r].
    assert (Hq : sqrt Sd <= bpow radix2 (-501)).
    { rewrite <- (sqrt_bpow2 (-501)). apply sqrt_le_1_alt. simpl (2 * -501)%Z. lra. }
    assert (Hb : kNormFloor = 2 * bpow radix2 (-501))
      by (unfold kNormFloor; replace (-500)%Z with (1 + -501)%Z by lia; rewrite bpow_plus; simpl; lra).
    pose proof (bpow_gt_0 radix2 (-501)). pose proof (sqrt_pos Sd).
    assert ((1 + 2 * u) * sqrt Sd <= (1 + 2 * u) * bpow radix2 (-501)) by (apply mul_le_l; lra).
    assert ((1 + 2 * u) * bpow radix2 (-501) <= 2 * bpow radix2 (-501)) by (apply Rmult_le_compat_r; lra).
    lra.
  - apply Rle_trans with (next_up (fl (norm_c d0 d1 d2 * fl (1 + kRelativeRounding)))); [|apply Rmax_l].
    pose proof (norm_c_margin d0 d1 d2 _ one_plus_relative Hs) as Hm. fold Sd in Hm.
    apply Rle_trans with (fl (norm_c d0 d1 d2 * fl (1 + kRelativeRounding))); [|apply next_up_ge_F, F_fl].
    pose proof (sqrt_pos Sd).
    assert ((1 + 2 * u) * sqrt Sd <= (1 + 3 * u) * sqrt Sd) by (apply Rmult_le_compat_r; lra).
    lra.
Qed.
Print Assumptions shift_rounding.

(* ---- kRelativeRoundingWide at |center| + |half| (SweptObbFrame::pose) ----
   The code: radius = norm_up(|center|, kRelativeRoundingWide) +
   norm_up(|half|, kRelativeRoundingWide) (Upper + Upper: next_up of the
   rounded sum), |center| and |half| the computed norms of the double vectors.
   This was a finding: the form it replaces, (1 + kRelativeRoundingWide)
   round_up(|center| + |half|), fell below the exact sum where the squares
   underflow (|center| ~ 2^-538: both computed norms 0, the bound ~2^-600,
   2^62 times too small). Each norm is bounded with its floor
   (Allowances.v norm_up_wide), the sum rounded up (Rounding.v upper_add). *)
Definition norm_up_c x y z k := Rmax (next_up (fl (norm_c x y z * k))) kNormFloor.

(* allowance kRelativeRoundingWide = 1e-12 *)
(* covers optimized/gauss6/ccd/motion_bounds.h "PosedObb pose_checked(const Obb& b, bool check_frame) const" sha256:3c631a4b53f4d403 *)
(* covers optimized/gauss6/numeric/rounding.h "GAUSS6_ALWAYS_INLINE Upper norm_up(double norm, double relative)" sha256:b4b3280a1e614758 *)
Theorem obb_radius_rounding c0 c1 c2 h0 h1 h2 :
  let W := fl (1 + kRelativeRoundingWide) in
  sqrt (c0 * c0 + c1 * c1 + c2 * c2) + sqrt (h0 * h0 + h1 * h1 + h2 * h2)
    <= next_up (fl (norm_up_c c0 c1 c2 W + norm_up_c h0 h1 h2 W)).
Proof. intros W. apply upper_add; apply norm_up_wide. Qed.
Print Assumptions obb_radius_rounding.

(* ---- Item 5: the swept box encloses every pose of the motion ----
   swept_box (motion_bounds.cpp), per world coordinate i, from the body box
   [lo, hi] (the node's vertices' exact min / max) and the motion's
   enclosure e over the sub-interval: c_j = fl(fl(lo_j / 2) + fl(hi_j / 2)),
   h_j = next_up(max(fl(hi_j - c_j), fl(c_j - lo_j))), centre, half and scale
   as Allowances.v's swept_box_rounding states them, grow = Upper{half} +
   (Upper{kBoxProductRounding} Upper{scale} + Upper{kUnderflowFloor}),
   local = [Lower{centre} - grow, Upper{centre} + grow], and the world
   interval e.p_i + local (Interval +). Hypotheses: the motion's enclosure
   (enclose_motion, motion.cpp: for every u in e.u, p_i(u) in e.p_i and
   every entry of R(u) within R_rad of R_mid, R_abs = |R_mid|; its interval
   arithmetic is Rounding.v's, the motion's algebra the Cayley proofs'), the
   body point r in the body box. Conclusion: the world coordinate p_i(u) +
   R(u)_i . r lies in the world interval. So every pose of the motion on the
   sub-interval, applied to every point of the node's body box, lies in the
   box swept_box returns. *)
Lemma half_extent lo hi c r : lo <= r <= hi ->
  Rabs (r - c) <= next_up (Rmax (fl (hi - c)) (fl (c - lo))) /\
  0 <= next_up (Rmax (fl (hi - c)) (fl (c - lo))).
Proof.
  intros Hr. rewrite fl_max.
  assert (Rabs (r - c) <= Rmax (hi - c) (c - lo)).
  { unfold Rabs, Rmax; repeat destruct Rcase_abs; repeat destruct Rle_dec; lra. }
  pose proof (up_ge _ _ H). split; [exact H0|]. pose proof (Rabs_pos (r - c)). lra.
Qed.

(* swept_box's world interval for world coordinate i, computed as the code
   computes it from row i of R_mid (m0, m1, m2) and R_rad (q0, q1, q2), the
   body box [lo, hi] and p_i's enclosure [plo, phi]. *)
Definition swept_world m0 m1 m2 q0 q1 q2 lo0 lo1 lo2 hi0 hi1 hi2 plo phi :=
  let c0 := fl (fl (/ 2 * lo0) + fl (/ 2 * hi0)) in
  let c1 := fl (fl (/ 2 * lo1) + fl (/ 2 * hi1)) in
  let c2 := fl (fl (/ 2 * lo2) + fl (/ 2 * hi2)) in
  let h0 := next_up (Rmax (fl (hi0 - c0)) (fl (c0 - lo0))) in
  let h1 := next_up (Rmax (fl (hi1 - c1)) (fl (c1 - lo1))) in
  let h2 := next_up (Rmax (fl (hi2 - c2)) (fl (c2 - lo2))) in
  let centre := sum3 (fl (m0 * c0)) (fl (m1 * c1)) (fl (m2 * c2)) in
  let half := fl (sum3 (fl (Rabs m0 * h0)) (fl (Rabs m1 * h1)) (fl (Rabs m2 * h2))
                  + sum3 (fl (q0 * fl (Rabs c0 + h0))) (fl (q1 * fl (Rabs c1 + h1))) (fl (q2 * fl (Rabs c2 + h2)))) in
  let scale := sum3 (fl (fl (Rabs m0 + q0) * fl (Rabs c0 + h0))) (fl (fl (Rabs m1 + q1) * fl (Rabs c1 + h1)))
                    (fl (fl (Rabs m2 + q2) * fl (Rabs c2 + h2))) in
  let grow := next_up (fl (half + next_up (fl (next_up (fl (kBoxProductRounding * scale)) + kUnderflowFloor)))) in
  let local := {| lo := next_down (fl (centre - grow)); hi := next_up (fl (centre + grow)) |} in
  iadd {| lo := plo; hi := phi |} local.

(* covers optimized/gauss6/ccd/motion_bounds.cpp "Aabb swept_box(const MotionEnclosure& e, const Aabb& body)" sha256:17e777d36e576019 *)
Theorem swept_box_encloses m0 m1 m2 q0 q1 q2 lo0 lo1 lo2 hi0 hi1 hi2 R0 R1 R2 r0 r1 r2 plo phi P :
  (forall x, In x [m0; m1; m2; q0; q1; q2; lo0; lo1; lo2; hi0; hi1; hi2] -> F x) ->
  0 <= q0 -> 0 <= q1 -> 0 <= q2 ->
  Rabs (R0 - m0) <= q0 -> Rabs (R1 - m1) <= q1 -> Rabs (R2 - m2) <= q2 ->
  lo0 <= r0 <= hi0 -> lo1 <= r1 <= hi1 -> lo2 <= r2 <= hi2 -> plo <= P <= phi ->
  holds (swept_world m0 m1 m2 q0 q1 q2 lo0 lo1 lo2 hi0 hi1 hi2 plo phi) (P + (R0 * r0 + R1 * r1 + R2 * r2)).
Proof.
  intros HF Hq0 Hq1 Hq2 HR0 HR1 HR2 Hr0 Hr1 Hr2 HP. unfold swept_world; cbv zeta.
  set (c0 := fl (fl (/ 2 * lo0) + fl (/ 2 * hi0))). set (c1 := fl (fl (/ 2 * lo1) + fl (/ 2 * hi1))).
  set (c2 := fl (fl (/ 2 * lo2) + fl (/ 2 * hi2))).
  set (h0 := next_up (Rmax (fl (hi0 - c0)) (fl (c0 - lo0)))). set (h1 := next_up (Rmax (fl (hi1 - c1)) (fl (c1 - lo1)))).
  set (h2 := next_up (Rmax (fl (hi2 - c2)) (fl (c2 - lo2)))).
  set (centre := sum3 (fl (m0 * c0)) (fl (m1 * c1)) (fl (m2 * c2))).
  set (half := fl (sum3 (fl (Rabs m0 * h0)) (fl (Rabs m1 * h1)) (fl (Rabs m2 * h2))
                  + sum3 (fl (q0 * fl (Rabs c0 + h0))) (fl (q1 * fl (Rabs c1 + h1))) (fl (q2 * fl (Rabs c2 + h2))))).
  set (scale := sum3 (fl (fl (Rabs m0 + q0) * fl (Rabs c0 + h0))) (fl (fl (Rabs m1 + q1) * fl (Rabs c1 + h1)))
                    (fl (fl (Rabs m2 + q2) * fl (Rabs c2 + h2)))).
  set (grow := next_up (fl (half + next_up (fl (next_up (fl (kBoxProductRounding * scale)) + kUnderflowFloor))))).
  set (local := {| lo := next_down (fl (centre - grow)); hi := next_up (fl (centre + grow)) |}).
  destruct (half_extent lo0 hi0 c0 r0 Hr0) as [E0 G0]; fold h0 in E0, G0.
  destruct (half_extent lo1 hi1 c1 r1 Hr1) as [E1 G1]; fold h1 in E1, G1.
  destruct (half_extent lo2 hi2 c2 r2 Hr2) as [E2 G2]; fold h2 in E2, G2.
  assert (HF' : forall x, In x [m0; m1; m2; q0; q1; q2; c0; c1; c2; h0; h1; h2] -> F x).
  { intros x Hx. simpl in Hx.
    repeat (destruct Hx as [<-|Hx]; [first [apply HF; simpl; tauto | apply F_fl] |]). destruct Hx. }
  pose proof (swept_box_rounding m0 m1 m2 q0 q1 q2 c0 c1 c2 h0 h1 h2 R0 R1 R2 r0 r1 r2 HF'
                Hq0 Hq1 Hq2 G0 G1 G2 HR0 HR1 HR2 E0 E1 E2) as H.
  fold centre half scale in H.
  assert (Hg : half + kBoxProductRounding * scale + kUnderflowFloor <= grow).
  { unfold grow. apply up_ge.
    pose proof (round_up_bounds (kBoxProductRounding * scale)).
    pose proof (up_ge (kBoxProductRounding * scale + kUnderflowFloor)
                      (next_up (fl (kBoxProductRounding * scale)) + kUnderflowFloor) ltac:(lra)).
    lra. }
  set (X := R0 * r0 + R1 * r1 + R2 * r2) in *.
  assert (Hl : holds local X).
  { unfold holds, local; simpl. split.
    - apply down_le. unfold Rabs in H; destruct Rcase_abs in H; lra.
    - apply up_ge. unfold Rabs in H; destruct Rcase_abs in H; lra. }
  apply interval_add_encloses; [unfold holds; simpl; lra | exact Hl].
Qed.
Print Assumptions swept_box_encloses.

(* ---- Item 5: a separating axis proves two sets apart ----
   for_each_separating_axis (distance.h) projects the corners of the two
   features on an axis a (a double vector), takes proven = max(b_lo - a_hi,
   a_lo - b_hi) less kAxisProductRounding |a|_1 s, and, when proven > 0,
   the gap g = Lower{proven} / norm_up(|a|, kRelativeRoundingWide). The
   exact argument: every point x of A (a convex combination of its corners)
   projects within [a_lo, a_hi] of the corners' exact projections
   (projection_convex), every y of B within [b_lo, b_hi]; if proven is at
   most the exact gap of the projections (the hypothesis Hp: the rounding
   of the projections, kAxisProductRounding's, not proved here), then
   g <= |y - x| for every such x and y (Cauchy-Schwarz: a . (y - x) <=
   |a| |y - x|), and the two features are at least g apart. The side
   a_lo - b_hi is the same statement with A and B exchanged. *)
Definition dot3 a0 a1 a2 x0 x1 x2 := a0 * x0 + a1 * x1 + a2 * x2.

Lemma cauchy_schwarz3 a0 a1 a2 w0 w1 w2 :
  dot3 a0 a1 a2 w0 w1 w2 <= sqrt (a0 * a0 + a1 * a1 + a2 * a2) * sqrt (w0 * w0 + w1 * w1 + w2 * w2).
Proof.
  assert (0 <= a0 * a0 + a1 * a1 + a2 * a2) by nra.
  assert (0 <= w0 * w0 + w1 * w1 + w2 * w2) by nra.
  rewrite <- sqrt_mult by assumption.
  destruct (Rle_or_lt (dot3 a0 a1 a2 w0 w1 w2) 0) as [H1|H1].
  - pose proof (sqrt_pos ((a0 * a0 + a1 * a1 + a2 * a2) * (w0 * w0 + w1 * w1 + w2 * w2))). lra.
  - rewrite <- (sqrt_square (dot3 a0 a1 a2 w0 w1 w2)) by lra. apply sqrt_le_1_alt.
    unfold dot3.
    assert (E : (a0 * a0 + a1 * a1 + a2 * a2) * (w0 * w0 + w1 * w1 + w2 * w2)
                - (a0 * w0 + a1 * w1 + a2 * w2) * (a0 * w0 + a1 * w1 + a2 * w2)
                = (a1 * w2 - a2 * w1) * (a1 * w2 - a2 * w1) + (a2 * w0 - a0 * w2) * (a2 * w0 - a0 * w2)
                  + (a0 * w1 - a1 * w0) * (a0 * w1 - a1 * w0)) by ring.
    pose proof (Rle_0_sqr (a1 * w2 - a2 * w1)). pose proof (Rle_0_sqr (a2 * w0 - a0 * w2)).
    pose proof (Rle_0_sqr (a0 * w1 - a1 * w0)). unfold Rsqr in *. lra.
Qed.

(* A convex combination of three points projects between the least and the
   largest of their projections. *)
Lemma projection_convex t0 t1 t2 s0 s1 s2 :
  0 <= t0 -> 0 <= t1 -> 0 <= t2 -> t0 + t1 + t2 = 1 ->
  Rmin (Rmin s0 s1) s2 <= t0 * s0 + t1 * s1 + t2 * s2 <= Rmax (Rmax s0 s1) s2.
Proof.
  intros. set (m := Rmin (Rmin s0 s1) s2). set (M := Rmax (Rmax s0 s1) s2).
  assert (m <= s0 /\ m <= s1 /\ m <= s2) as (? & ? & ?)
    by (unfold m, Rmin; repeat destruct Rle_dec; lra).
  assert (s0 <= M /\ s1 <= M /\ s2 <= M) as (? & ? & ?)
    by (unfold M, Rmax; repeat destruct Rle_dec; lra).
  split; nra.
Qed.

(* covers optimized/gauss6/geometry/distance.h "GAUSS6_ALWAYS_INLINE void for_each_separating_axis(const SatSide& A" sha256:f9abadb85b78baa3 *)
Theorem separating_axis_gap a0 a1 a2 x0 x1 x2 y0 y1 y2 a_hi b_lo p :
  dot3 a0 a1 a2 x0 x1 x2 <= a_hi -> b_lo <= dot3 a0 a1 a2 y0 y1 y2 ->
  0 < p -> p <= b_lo - a_hi ->
  next_down (fl (p / norm_up_c a0 a1 a2 (fl (1 + kRelativeRoundingWide))))
    <= sqrt ((y0 - x0) * (y0 - x0) + (y1 - x1) * (y1 - x1) + (y2 - x2) * (y2 - x2)).
Proof.
  intros Hx Hy Hp0 Hp.
  set (D := dot3 a0 a1 a2 (y0 - x0) (y1 - x1) (y2 - x2)).
  assert (HD : p <= D) by (unfold D, dot3 in *; lra).
  set (A2 := a0 * a0 + a1 * a1 + a2 * a2).
  assert (HA : 0 < A2).
  { destruct (Rle_or_lt A2 0) as [H|H]; [|exact H].
    assert (a0 = 0 /\ a1 = 0 /\ a2 = 0) as (-> & -> & ->) by (unfold A2 in H; repeat split; nra).
    unfold D, dot3 in HD. lra. }
  assert (HN : 0 < sqrt A2) by (apply sqrt_lt_R0; exact HA).
  pose proof (norm_up_wide a0 a1 a2) as HU. fold A2 in HU. fold (norm_up_c a0 a1 a2 (fl (1 + kRelativeRoundingWide))) in HU.
  pose proof (lower_div D (sqrt A2) p (norm_up_c a0 a1 a2 (fl (1 + kRelativeRoundingWide))) HD ltac:(lra) (conj HN HU)) as Hq.
  eapply Rle_trans; [exact Hq|].
  pose proof (cauchy_schwarz3 a0 a1 a2 (y0 - x0) (y1 - x1) (y2 - x2)) as CS. fold D A2 in CS.
  apply Rmult_le_reg_r with (sqrt A2); [exact HN|].
  unfold Rdiv. rewrite Rmult_assoc, Rinv_l by lra. lra.
Qed.
Print Assumptions separating_axis_gap.
