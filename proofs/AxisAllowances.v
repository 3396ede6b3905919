(* The separating-axis allowances of optimized/gauss6/numeric/error_allowances.h,
   proved in Flocq's binary64 model of Rounding.v: kAxisProductRounding at its
   two sites (for_each_separating_axis, distance.h: the projections of the
   corners on a double axis and the gap between them; triangle_time_lower_bound,
   motion_bounds.h: the turn term r.(a x omega) joined to the velocity term)
   and kSpinRounding (SweptObbFrame::pose, motion_bounds.h: the node's sweep
   step + spin x c). Each expression is evaluated as its site evaluates it (the
   same operations in the same order, each rounded to nearest: `fl`), under the
   stated hypotheses. Same model as Rounding.v and Allowances.v (finite
   results, gradual underflow, no fused multiply-add). With ObbAllowances.v's
   exact argument, `axis_gap_distance` closes issue 45's item 5 for the
   triangles: the gap for_each_separating_axis hands its callers is at most
   the distance of the two features. *)

From Coq Require Import Reals Psatz.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances.
From Gauss6 Require ObbAllowances.  (* projection_convex, separating_axis_gap, used qualified *)
From Gauss6 Require PoseAllowances.  (* norm_le_sum_abs, used qualified *)
Open Scope R_scope.

(* A 3-vector of reals (a double vector when every component is F). *)
Record V3 := mk3 { c0 : R; c1 : R; c2 : R }.
Definition dbl (x : V3) := F (c0 x) /\ F (c1 x) /\ F (c2 x).
Definition bounded (s : R) (x : V3) := Rabs (c0 x) <= s /\ Rabs (c1 x) <= s /\ Rabs (c2 x) <= s.
(* The exact dot product, and the one Eigen computes (Allowances.v dot3: the
   three products, summed left to right; its error bound is symmetric, so any
   order of the terms). *)
Definition edot (a x : V3) := c0 a * c0 x + c1 a * c1 x + c2 a * c2 x.
Definition cdot (a x : V3) := dot3 (c0 a) (c1 a) (c2 a) (c0 x) (c1 x) (c2 x).
(* |a|_1, exact and as a.cwiseAbs().sum() computes it. *)
Definition norm1 (a : V3) := Rabs (c0 a) + Rabs (c1 a) + Rabs (c2 a).
Definition abs1 (a : V3) := fl (fl (Rabs (c0 a) + Rabs (c1 a)) + Rabs (c2 a)).
Definition max3 p q r := Rmax (Rmax p q) r.
Definition min3 p q r := Rmin (Rmin p q) r.

Lemma u_pos : 0 < u < / 1000000. Proof. unfold u; lra. Qed.

(* ---- shared lemmas ---- *)

Lemma abs1_lower a : dbl a -> (1 - u) * (1 - u) * norm1 a <= abs1 a.
Proof.
  intros (F0 & F1 & F2). pose proof u_pos.
  assert (Fa0 : F (Rabs (c0 a))) by (apply generic_format_abs, F0).
  assert (Fa1 : F (Rabs (c1 a))) by (apply generic_format_abs, F1).
  assert (Fa2 : F (Rabs (c2 a))) by (apply generic_format_abs, F2).
  pose proof (Rabs_pos (c0 a)). pose proof (Rabs_pos (c1 a)). pose proof (Rabs_pos (c2 a)).
  pose proof (sum_lower _ _ Fa0 Fa1 ltac:(lra) ltac:(lra)) as G1.
  assert (0 <= fl (Rabs (c0 a) + Rabs (c1 a))) by (apply fl_nonneg; lra).
  pose proof (sum_lower _ _ (F_fl (Rabs (c0 a) + Rabs (c1 a))) Fa2 ltac:(lra) ltac:(lra)) as G2.
  unfold abs1, norm1.
  assert ((1 - u) * ((1 - u) * (Rabs (c0 a) + Rabs (c1 a)) + Rabs (c2 a))
          <= (1 - u) * (fl (Rabs (c0 a) + Rabs (c1 a)) + Rabs (c2 a))) by (apply mul_le_l; lra).
  assert ((1 - u) * (1 - u) * Rabs (c2 a) <= (1 - u) * Rabs (c2 a)) by (apply Rmult_le_compat_r; nra).
  lra.
Qed.

Lemma norm1_pos a : 0 <= norm1 a.
Proof. unfold norm1. pose proof (Rabs_pos (c0 a)). pose proof (Rabs_pos (c1 a)). pose proof (Rabs_pos (c2 a)). lra. Qed.

Lemma bounded_pos s x : bounded s x -> 0 <= s.
Proof. intros (H & _). pose proof (Rabs_pos (c0 x)). lra. Qed.

(* The terms' magnitudes of a . x, for |x_i| <= s: at most |a|_1 s. *)
Lemma terms_le a x s : bounded s x ->
  Rabs (c0 a * c0 x) + Rabs (c1 a * c1 x) + Rabs (c2 a * c2 x) <= norm1 a * s.
Proof.
  intros (H0 & H1 & H2). unfold norm1. rewrite !Rabs_mult.
  pose proof (Rabs_pos (c0 a)). pose proof (Rabs_pos (c1 a)). pose proof (Rabs_pos (c2 a)).
  assert (Rabs (c0 a) * Rabs (c0 x) <= Rabs (c0 a) * s) by (apply mul_le_l; lra).
  assert (Rabs (c1 a) * Rabs (c1 x) <= Rabs (c1 a) * s) by (apply mul_le_l; lra).
  assert (Rabs (c2 a) * Rabs (c2 x) <= Rabs (c2 a) * s) by (apply mul_le_l; lra).
  lra.
Qed.

Lemma edot_le a x s : bounded s x -> Rabs (edot a x) <= norm1 a * s.
Proof.
  intros H. pose proof (terms_le a x s H). unfold edot.
  eapply Rle_trans; [|exact H0].
  eapply Rle_trans; [apply Rabs_triang|]. pose proof (Rabs_triang (c0 a * c0 x) (c1 a * c1 x)). lra.
Qed.

(* A projection of a corner with coordinates <= s on a double axis, computed:
   within 3.02 u |a|_1 s + 5.02 eta of the exact one. *)
Lemma cdot_err a x s : bounded s x ->
  Rabs (cdot a x - edot a x) <= 302 / 100 * (u * (norm1 a * s)) + 502 / 100 * eta.
Proof.
  intros H. pose proof (terms_le a x s H). pose proof (dot3_err (c0 a) (c1 a) (c2 a) (c0 x) (c1 x) (c2 x)) as D.
  simpl in D. unfold cdot, edot. pose proof u_pos.
  assert (u * (Rabs (c0 a * c0 x) + Rabs (c1 a * c1 x) + Rabs (c2 a * c2 x)) <= u * (norm1 a * s))
    by (apply mul_le_l; lra).
  lra.
Qed.

(* A selection of three values, the largest or the least (the two roles of
   sel3_close and sel3_abs_le). *)
Definition is_sel3 (sel : R -> R -> R -> R) := sel = max3 \/ sel = min3.
Lemma max3_sel : is_sel3 max3. Proof. left; reflexivity. Qed.
Lemma min3_sel : is_sel3 min3. Proof. right; reflexivity. Qed.

(* The largest (least) of three values each within e of its exact one is
   within e of the exact largest (least). *)
Lemma sel3_close sel p0 p1 p2 P0 P1 P2 e : is_sel3 sel ->
  Rabs (p0 - P0) <= e -> Rabs (p1 - P1) <= e -> Rabs (p2 - P2) <= e ->
  Rabs (sel p0 p1 p2 - sel P0 P1 P2) <= e.
Proof.
  intros Hs H0 H1 H2. apply Rabs_le_inv in H0. apply Rabs_le_inv in H1. apply Rabs_le_inv in H2.
  apply Rabs_le. destruct Hs as [-> | ->]; unfold max3, min3, Rmax, Rmin; repeat destruct Rle_dec; lra.
Qed.
(* The largest (least) of three values within m in magnitude is. *)
Lemma sel3_abs_le sel P0 P1 P2 m : is_sel3 sel ->
  Rabs P0 <= m -> Rabs P1 <= m -> Rabs P2 <= m -> Rabs (sel P0 P1 P2) <= m.
Proof.
  intros Hs H0 H1 H2. apply Rabs_le_inv in H0. apply Rabs_le_inv in H1. apply Rabs_le_inv in H2.
  apply Rabs_le. destruct Hs as [-> | ->]; unfold max3, min3, Rmax, Rmin; repeat destruct Rle_dec; lra.
Qed.
(* The largest or least of three doubles is a double. *)
Lemma F_sel3 sel p q r : is_sel3 sel -> F p -> F q -> F r -> F (sel p q r).
Proof. intros [-> | ->] **; unfold max3, min3, Rmax, Rmin; repeat destruct Rle_dec; assumption. Qed.

(* kAxisProductRounding = fl(1e-13) >= 900 u. *)
(* allowance kAxisProductRounding = 1e-13 *)
Definition kAxisProductRounding := fl (/ 10000000000000).
Lemma kAxisProductRounding_ge : 900 * u <= kAxisProductRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.

(* A relative allowance k >= 1e-15 times a computed |a|_1 >= kNormFloor
   rounds within u of itself (the product is normal: >= 2^-1022). *)
Lemma scaled_norm1 k a : 9 * u <= k -> dbl a -> kNormFloor <= abs1 a ->
  (1 - u) * (1 - u) * (1 - u) * (k * norm1 a) <= fl (k * abs1 a).
Proof.
  intros Hk Ha Hf. pose proof u_pos. pose proof (abs1_lower a Ha) as L. pose proof (norm1_pos a).
  assert (N : bpow radix2 (-1022) <= k * abs1 a).
  { apply Rle_trans with (u * kNormFloor).
    - unfold kNormFloor. rewrite bpow_m53, <- bpow_plus. apply bpow_le. lia.
    - apply Rmult_le_compat; try lra. unfold kNormFloor; pose proof (bpow_ge_0 radix2 (-500)); lra. }
  pose proof (fl_lower_normal _ N).
  assert (0 <= k) by lra.
  assert ((1 - u) * (1 - u) * norm1 a * k <= abs1 a * k) by (apply Rmult_le_compat_r; lra).
  assert ((1 - u) * ((1 - u) * (1 - u) * norm1 a * k) <= (1 - u) * (abs1 a * k)) by (apply mul_le_l; lra).
  nra.
Qed.

(* ---- kAxisProductRounding at for_each_separating_axis (distance.h) ----
   For an axis a (doubles) and the corners x_k of A, y_k of B (doubles with
   every coordinate <= s in magnitude: s is the code's max of their
   |coordinate|s), the code computes each projection a.dot(P) (cdot), a_lo,
   a_hi, b_lo, b_hi their least and largest (std::min / max: exact), the two
   differences d1 = fl(b_lo - a_hi), d2 = fl(a_lo - b_hi), side = +1 when d1 >=
   d2 (-1 otherwise), and proven = fl(max(d1, d2) - slack) with slack =
   fl(fl(fl(kAxisProductRounding a_1) s) + kUnderflowFloor), a_1 = |a|_1 summed
   in doubles. The theorem: proven > 0 (the code's test) implies that proven
   is at most the exact gap of the corners' projections on the chosen side.
   Each projection errs by at most 3.02 u |a|_1 s + 5.02 eta (Allowances.v
   dot3_err), so do the least and largest; each difference adds u of itself
   (<= 2 |a|_1 s): under 8.1 u |a|_1 s + 10.1 eta in all, and the final
   subtraction u of the gap (<= 2 |a|_1 s); the slack is at least 890 u |a|_1 s
   + 1e-300 / 2 (kAxisProductRounding >= 900 u; kUnderflowFloor covers the
   underflow terms). Hypothesis a_1 >= kNormFloor: the code drops a shorter
   axis (distance.h, `if (!(a_1 >= kNormFloor)) return false;`), below which
   kAxisProductRounding a_1 could underflow. A feature (vertex, edge) repeats
   its corners, which repeats the same projections: the statement over three
   corners covers it. *)
(* allowance kUnderflowFloor = 1e-300 *)
Definition axis_slack a s := fl (fl (fl (kAxisProductRounding * abs1 a) * s) + kUnderflowFloor).

Lemma floor_lower : 9 / 10 * / IZR (Z.pow 10 300) <= kUnderflowFloor /\ 2000 * eta <= / IZR (Z.pow 10 300) * / 2.
Proof.
  pose proof u_pos. pose proof eta_pos.
  assert (Hsmall : 5000 * eta <= / IZR (Z.pow 10 300) * / 2) by (unfold eta; simpl; lra).
  assert (Hf : (1 - u) * / IZR (Z.pow 10 300) - eta <= kUnderflowFloor)
    by (apply fl_lower; apply Rlt_le, Rinv_0_lt_compat; apply IZR_lt; reflexivity).
  assert (0 < / IZR (Z.pow 10 300)) by (apply Rinv_0_lt_compat; apply IZR_lt; reflexivity).
  assert (u * / IZR (Z.pow 10 300) <= / 1000000 * / IZR (Z.pow 10 300)) by (apply Rmult_le_compat_r; lra).
  lra.
Qed.

Lemma axis_slack_lower a s : dbl a -> kNormFloor <= abs1 a -> 0 <= s ->
  890 * (u * (norm1 a * s)) + / IZR (Z.pow 10 300) * / 2 <= axis_slack a s /\ F (axis_slack a s).
Proof.
  intros Ha Hf Hs. split; [|apply F_fl]. pose proof u_pos. pose proof eta_pos. pose proof (norm1_pos a).
  pose proof kAxisProductRounding_ge as Hk.
  pose proof (scaled_norm1 kAxisProductRounding a ltac:(lra) Ha Hf) as HK.
  set (K := fl (kAxisProductRounding * abs1 a)) in *.
  assert (HK0 : 0 <= K).
  { assert (Z1 : 0 <= kAxisProductRounding * norm1 a) by (apply Rmult_le_pos; lra).
    assert (Z2 : 0 <= (1 - u) * (1 - u) * (1 - u)) by (repeat apply Rmult_le_pos; lra).
    pose proof (Rmult_le_pos _ _ Z2 Z1). lra. }
  pose proof (fl_lower (K * s) ltac:(nra)) as HP.
  assert (HP0 : 0 <= fl (K * s)) by (apply fl_nonneg; nra).
  destruct floor_lower as [Fl1 Fl2].
  assert (HF0 : 0 <= kUnderflowFloor) by lra.
  pose proof (sum_lower _ _ (F_fl (K * s)) (F_fl _) HP0 HF0) as HS. fold kUnderflowFloor in HS. unfold axis_slack. fold K.
  set (W := u * (norm1 a * s)).
  assert (HW0 : 0 <= W) by (unfold W; apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra]).
  (* K s >= (1 - u)^3 900 u |a|_1 s *)
  assert (Q1 : (1 - u) * (1 - u) * (1 - u) * (900 * W) <= K * s).
  { apply Rle_trans with ((1 - u) * (1 - u) * (1 - u) * (kAxisProductRounding * norm1 a) * s).
    - unfold W. replace ((1 - u) * (1 - u) * (1 - u) * (900 * (u * (norm1 a * s))))
        with ((1 - u) * (1 - u) * (1 - u) * ((900 * u) * norm1 a) * s) by ring.
      apply Rmult_le_compat_r; [lra|]. apply mul_le_l; [nra|]. apply Rmult_le_compat_r; lra.
    - apply Rmult_le_compat_r; lra. }
  assert (Q2 : 891 * W <= (1 - u) * (1 - u) * (1 - u) * (1 - u) * (1 - u) * (900 * W))
    by (assert (891 <= (1 - u) * (1 - u) * (1 - u) * (1 - u) * (1 - u) * 900) by nra; nra).
  assert (Q3 : (1 - u) * ((1 - u) * (K * s) - eta + kUnderflowFloor) <= (1 - u) * (fl (K * s) + kUnderflowFloor))
    by (apply mul_le_l; lra).
  assert (Q4 : (1 - u) * ((1 - u) * ((1 - u) * (1 - u) * (1 - u) * (900 * W))) <= (1 - u) * ((1 - u) * (K * s)))
    by (apply mul_le_l; [lra | apply mul_le_l; lra]).
  assert (u * kUnderflowFloor <= / 1000000 * kUnderflowFloor) by (apply Rmult_le_compat_r; lra).
  assert (0 <= u * eta) by nra.
  assert (T1 : (1 - u) * ((1 - u) * (K * s)) - eta + (1 - u) * kUnderflowFloor <= axis_slack a s) by (unfold axis_slack; fold K; lra).
  assert (T2 : 891 * W <= (1 - u) * ((1 - u) * (K * s))) by lra.
  assert (T3 : / IZR (Z.pow 10 300) * / 2 <= (1 - u) * kUnderflowFloor - eta) by lra.
  unfold axis_slack in T1; fold K in T1. lra.
Qed.

(* covers optimized/gauss6/geometry/distance.h "GAUSS6_ALWAYS_INLINE void for_each_separating_axis(const SatSide& A" sha256:f9abadb85b78baa3 *)
(* covers optimized/gauss6/geometry/distance.h "GAUSS6_ALWAYS_INLINE SatSide sat_side(const Vec3 P[3])" sha256:3a6fbe04d8d11102 *)
Theorem axis_gap_rounding (a x0 x1 x2 y0 y1 y2 : V3) s :
  dbl a -> bounded s x0 -> bounded s x1 -> bounded s x2 ->
  bounded s y0 -> bounded s y1 -> bounded s y2 -> kNormFloor <= abs1 a ->
  let a_lo := min3 (cdot a x0) (cdot a x1) (cdot a x2) in
  let a_hi := max3 (cdot a x0) (cdot a x1) (cdot a x2) in
  let b_lo := min3 (cdot a y0) (cdot a y1) (cdot a y2) in
  let b_hi := max3 (cdot a y0) (cdot a y1) (cdot a y2) in
  let d1 := fl (b_lo - a_hi) in
  let d2 := fl (a_lo - b_hi) in
  let proven := fl (Rmax d1 d2 - axis_slack a s) in
  0 < proven ->
  (d2 <= d1 -> proven <= min3 (edot a y0) (edot a y1) (edot a y2) - max3 (edot a x0) (edot a x1) (edot a x2)) /\
  (d1 < d2 -> proven <= min3 (edot a x0) (edot a x1) (edot a x2) - max3 (edot a y0) (edot a y1) (edot a y2)).
Proof.
  intros Ha Hx0 Hx1 Hx2 Hy0 Hy1 Hy2 Hf a_lo a_hi b_lo b_hi d1 d2 proven Hp.
  pose proof u_pos. pose proof eta_pos. pose proof (norm1_pos a).
  pose proof (bounded_pos s x0 Hx0) as Hs.
  set (W := u * (norm1 a * s)).
  assert (HW0 : 0 <= W) by (unfold W; apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra]).
  set (e := 302 / 100 * W + 502 / 100 * eta).
  set (Aa := norm1 a * s).
  assert (HA0 : 0 <= Aa) by (unfold Aa; apply Rmult_le_pos; lra).
  (* the computed extremes, within e of the exact ones, which are <= |a|_1 s *)
  assert (Ea_lo : Rabs (a_lo - min3 (edot a x0) (edot a x1) (edot a x2)) <= e)
    by (apply (sel3_close min3); [exact min3_sel|..]; apply cdot_err; assumption).
  assert (Ea_hi : Rabs (a_hi - max3 (edot a x0) (edot a x1) (edot a x2)) <= e)
    by (apply (sel3_close max3); [exact max3_sel|..]; apply cdot_err; assumption).
  assert (Eb_lo : Rabs (b_lo - min3 (edot a y0) (edot a y1) (edot a y2)) <= e)
    by (apply (sel3_close min3); [exact min3_sel|..]; apply cdot_err; assumption).
  assert (Eb_hi : Rabs (b_hi - max3 (edot a y0) (edot a y1) (edot a y2)) <= e)
    by (apply (sel3_close max3); [exact max3_sel|..]; apply cdot_err; assumption).
  assert (Ma_lo : Rabs (min3 (edot a x0) (edot a x1) (edot a x2)) <= Aa) by (apply (sel3_abs_le min3); [exact min3_sel|..]; apply edot_le; assumption).
  assert (Ma_hi : Rabs (max3 (edot a x0) (edot a x1) (edot a x2)) <= Aa) by (apply (sel3_abs_le max3); [exact max3_sel|..]; apply edot_le; assumption).
  assert (Mb_lo : Rabs (min3 (edot a y0) (edot a y1) (edot a y2)) <= Aa) by (apply (sel3_abs_le min3); [exact min3_sel|..]; apply edot_le; assumption).
  assert (Mb_hi : Rabs (max3 (edot a y0) (edot a y1) (edot a y2)) <= Aa) by (apply (sel3_abs_le max3); [exact max3_sel|..]; apply edot_le; assumption).
  set (XL := min3 (edot a x0) (edot a x1) (edot a x2)) in *.
  set (XH := max3 (edot a x0) (edot a x1) (edot a x2)) in *.
  set (YL := min3 (edot a y0) (edot a y1) (edot a y2)) in *.
  set (YH := max3 (edot a y0) (edot a y1) (edot a y2)) in *.
  assert (Fa_lo : F a_lo) by (apply F_sel3; [apply min3_sel | apply F_fl ..]).
  assert (Fa_hi : F a_hi) by (apply F_sel3; [apply max3_sel | apply F_fl ..]).
  assert (Fb_lo : F b_lo) by (apply F_sel3; [apply min3_sel | apply F_fl ..]).
  assert (Fb_hi : F b_hi) by (apply F_sel3; [apply max3_sel | apply F_fl ..]).
  (* each computed difference: at most the exact one plus 8.1 u |a|_1 s + 10.1 eta *)
  assert (Gen : forall p P q Q, F p -> F q -> Rabs (p - P) <= e -> Rabs (q - Q) <= e ->
                Rabs P <= Aa -> Rabs Q <= Aa -> fl (p - q) <= (P - Q) + (81 / 10 * W + 101 / 10 * eta)).
  { intros p P q Q Fp Fq EP EQ MP MQ. pose proof (sub_rel p q Fp Fq) as R.
    apply Rabs_le_inv in EP. apply Rabs_le_inv in EQ. apply Rabs_le_inv in MP. apply Rabs_le_inv in MQ.
    apply Rabs_le_inv in R.
    assert (Rabs (p - q) <= 2 * Aa + 2 * e) by (apply Rabs_le; lra).
    assert (u * Rabs (p - q) <= u * (2 * Aa + 2 * e)) by (apply mul_le_l; lra).
    assert (u * Aa = W) by (unfold W, Aa; ring).
    assert (u * W <= / 1000000 * W) by (apply Rmult_le_compat_r; lra).
    assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
    unfold e in *. lra. }
  pose proof (Gen b_lo YL a_hi XH Fb_lo Fa_hi Eb_lo Ea_hi Mb_lo Ma_hi) as D1. fold d1 in D1.
  pose proof (Gen a_lo XL b_hi YH Fa_lo Fb_hi Ea_lo Eb_hi Ma_lo Mb_hi) as D2. fold d2 in D2.
  destruct (axis_slack_lower a s Ha Hf Hs) as [HS FS]. fold W in HS.
  destruct floor_lower as [_ Fl2].
  (* the last subtraction: proven > 0 forces max - slack > 0, and proven <= (1 + u) of it *)
  assert (FM : F (Rmax d1 d2)) by (unfold Rmax; destruct Rle_dec; apply F_fl).
  pose proof (sub_rel _ _ FM FS) as R. fold proven in R.
  assert (Hpos : 0 < Rmax d1 d2 - axis_slack a s).
  { destruct (Rlt_or_le 0 (Rmax d1 d2 - axis_slack a s)) as [H'|H']; [exact H'|].
    assert (Z0 : fl (Rmax d1 d2 - axis_slack a s) <= fl 0) by (apply fl_le; exact H').
    rewrite (fl_F 0) in Z0 by apply generic_format_0. fold proven in Z0. lra. }
  rewrite (Rabs_pos_eq (Rmax d1 d2 - axis_slack a s)) in R by lra. apply Rabs_le_inv in R.
  assert (Hg : forall G, Rabs G <= 2 * Aa -> Rmax d1 d2 <= G + (81 / 10 * W + 101 / 10 * eta) -> proven <= G).
  { intros G HG HM. apply Rabs_le_inv in HG.
    assert (u * W <= / 1000000 * W) by (apply Rmult_le_compat_r; lra).
    assert (u * Aa = W) by (unfold W, Aa; ring).
    assert (HG0 : 880 * W <= G) by lra.
    assert (u * G <= u * (2 * Aa)) by (apply mul_le_l; lra).
    assert (u * (Rmax d1 d2 - axis_slack a s) <= u * (G - 880 * W)) by (apply mul_le_l; lra).
    assert (0 <= u * W) by (apply Rmult_le_pos; lra).
    lra. }
  assert (B1 : Rabs (YL - XH) <= 2 * Aa) by (apply Rabs_le; apply Rabs_le_inv in Mb_lo; apply Rabs_le_inv in Ma_hi; lra).
  assert (B2 : Rabs (XL - YH) <= 2 * Aa) by (apply Rabs_le; apply Rabs_le_inv in Ma_lo; apply Rabs_le_inv in Mb_hi; lra).
  split; intros Hside.
  - apply Hg; [exact B1|]. unfold Rmax. destruct Rle_dec; lra.
  - apply Hg; [exact B2|]. unfold Rmax. destruct Rle_dec; lra.
Qed.
Print Assumptions axis_gap_rounding.

(* Item 5 for the triangles: the gap g = (Lower{proven} / norm_up(|a|,
   kRelativeRoundingWide)).v that for_each_separating_axis hands to its
   callers (triangle_gap_lower_bound; the gap of triangle_time_lower_bound) is
   at most the distance between every point x of A (a convex combination of
   its corners) and every point y of B: axis_gap_rounding bounds proven by the
   exact gap of the corners' projections, ObbAllowances.v's projection_convex
   puts every point's projection between its corners', and its
   separating_axis_gap divides by |a| (Cauchy-Schwarz, rounded down). *)
Definition combo (t0 t1 t2 : R) (x0 x1 x2 : V3) :=
  mk3 (t0 * c0 x0 + t1 * c0 x1 + t2 * c0 x2) (t0 * c1 x0 + t1 * c1 x1 + t2 * c1 x2)
      (t0 * c2 x0 + t1 * c2 x1 + t2 * c2 x2).
Definition dist (x y : V3) :=
  sqrt ((c0 y - c0 x) * (c0 y - c0 x) + (c1 y - c1 x) * (c1 y - c1 x) + (c2 y - c2 x) * (c2 y - c2 x)).

Lemma combo_projection a t0 t1 t2 x0 x1 x2 :
  0 <= t0 -> 0 <= t1 -> 0 <= t2 -> t0 + t1 + t2 = 1 ->
  min3 (edot a x0) (edot a x1) (edot a x2) <= ObbAllowances.dot3 (c0 a) (c1 a) (c2 a)
    (c0 (combo t0 t1 t2 x0 x1 x2)) (c1 (combo t0 t1 t2 x0 x1 x2)) (c2 (combo t0 t1 t2 x0 x1 x2))
  <= max3 (edot a x0) (edot a x1) (edot a x2).
Proof.
  intros. unfold ObbAllowances.dot3, combo, min3, max3; simpl.
  replace (c0 a * (t0 * c0 x0 + t1 * c0 x1 + t2 * c0 x2) + c1 a * (t0 * c1 x0 + t1 * c1 x1 + t2 * c1 x2) +
           c2 a * (t0 * c2 x0 + t1 * c2 x1 + t2 * c2 x2))
    with (t0 * edot a x0 + t1 * edot a x1 + t2 * edot a x2) by (unfold edot; ring).
  apply ObbAllowances.projection_convex; assumption.
Qed.

(* covers optimized/gauss6/geometry/distance.h "GAUSS6_ALWAYS_INLINE void for_each_separating_axis(const SatSide& A" sha256:f9abadb85b78baa3 *)
Theorem axis_gap_distance (a x0 x1 x2 y0 y1 y2 : V3) s t0 t1 t2 w0 w1 w2 :
  dbl a -> bounded s x0 -> bounded s x1 -> bounded s x2 ->
  bounded s y0 -> bounded s y1 -> bounded s y2 -> kNormFloor <= abs1 a ->
  0 <= t0 -> 0 <= t1 -> 0 <= t2 -> t0 + t1 + t2 = 1 ->
  0 <= w0 -> 0 <= w1 -> 0 <= w2 -> w0 + w1 + w2 = 1 ->
  let a_lo := min3 (cdot a x0) (cdot a x1) (cdot a x2) in
  let a_hi := max3 (cdot a x0) (cdot a x1) (cdot a x2) in
  let b_lo := min3 (cdot a y0) (cdot a y1) (cdot a y2) in
  let b_hi := max3 (cdot a y0) (cdot a y1) (cdot a y2) in
  let proven := fl (Rmax (fl (b_lo - a_hi)) (fl (a_lo - b_hi)) - axis_slack a s) in
  let g := next_down (fl (proven / ObbAllowances.norm_up_c (c0 a) (c1 a) (c2 a) (fl (1 + kRelativeRoundingWide)))) in
  0 < proven -> g <= dist (combo t0 t1 t2 x0 x1 x2) (combo w0 w1 w2 y0 y1 y2).
Proof.
  intros Ha Hx0 Hx1 Hx2 Hy0 Hy1 Hy2 Hf Ht0 Ht1 Ht2 Ht Hw0 Hw1 Hw2 Hw. cbv zeta. intros Hp.
  destruct (axis_gap_rounding a x0 x1 x2 y0 y1 y2 s Ha Hx0 Hx1 Hx2 Hy0 Hy1 Hy2 Hf Hp) as [S1 S2].
  cbv zeta in S1, S2.
  set (a_lo := min3 (cdot a x0) (cdot a x1) (cdot a x2)) in *.
  set (a_hi := max3 (cdot a x0) (cdot a x1) (cdot a x2)) in *.
  set (b_lo := min3 (cdot a y0) (cdot a y1) (cdot a y2)) in *.
  set (b_hi := max3 (cdot a y0) (cdot a y1) (cdot a y2)) in *.
  set (proven := fl (Rmax (fl (b_lo - a_hi)) (fl (a_lo - b_hi)) - axis_slack a s)) in *.
  set (x := combo t0 t1 t2 x0 x1 x2). set (y := combo w0 w1 w2 y0 y1 y2).
  pose proof (combo_projection a t0 t1 t2 x0 x1 x2 Ht0 Ht1 Ht2 Ht) as PX. fold x in PX.
  pose proof (combo_projection a w0 w1 w2 y0 y1 y2 Hw0 Hw1 Hw2 Hw) as PY. fold y in PY.
  destruct (Rle_or_lt (fl (a_lo - b_hi)) (fl (b_lo - a_hi))) as [H|H].
  - specialize (S1 H).
    apply (ObbAllowances.separating_axis_gap (c0 a) (c1 a) (c2 a) (c0 x) (c1 x) (c2 x) (c0 y) (c1 y) (c2 y)
             (max3 (edot a x0) (edot a x1) (edot a x2)) (min3 (edot a y0) (edot a y1) (edot a y2)) proven);
      lra.
  - specialize (S2 H).
    unfold dist.
    replace ((c0 y - c0 x) * (c0 y - c0 x) + (c1 y - c1 x) * (c1 y - c1 x) + (c2 y - c2 x) * (c2 y - c2 x))
      with ((c0 x - c0 y) * (c0 x - c0 y) + (c1 x - c1 y) * (c1 x - c1 y) + (c2 x - c2 y) * (c2 x - c2 y)) by ring.
    apply (ObbAllowances.separating_axis_gap (c0 a) (c1 a) (c2 a) (c0 y) (c1 y) (c2 y) (c0 x) (c1 x) (c2 x)
             (max3 (edot a y0) (edot a y1) (edot a y2)) (min3 (edot a x0) (edot a x1) (edot a x2)) proven);
      lra.
Qed.
Print Assumptions axis_gap_distance.

(* ---- Cross products ----
   Eigen's p.cross(q): each component p_j q_k - p_k q_j, the two products
   rounded, then their difference. *)
Definition ccross (p q : V3) :=
  mk3 (fl (fl (c1 p * c2 q) - fl (c2 p * c1 q))) (fl (fl (c2 p * c0 q) - fl (c0 p * c2 q)))
      (fl (fl (c0 p * c1 q) - fl (c1 p * c0 q))).
Definition ecross (p q : V3) :=
  mk3 (c1 p * c2 q - c2 p * c1 q) (c2 p * c0 q - c0 p * c2 q) (c0 p * c1 q - c1 p * c0 q).
Definition sum_abs (x : V3) := Rabs (c0 x) + Rabs (c1 x) + Rabs (c2 x).
Definition sum_err (x y : V3) := Rabs (c0 x - c0 y) + Rabs (c1 x - c1 y) + Rabs (c2 x - c2 y).

(* A difference of two rounded products, rounded: within 2.01 u of the
   products' magnitudes and 2.01 eta (the difference of the two doubles
   errs relatively only: Allowances.v sub_rel). *)
Lemma fl_diff_prod x y :
  Rabs (fl (fl x - fl y) - (x - y)) <= 201 / 100 * (u * (Rabs x + Rabs y)) + 201 / 100 * eta.
Proof.
  pose proof u_pos. pose proof eta_pos. pose proof (fl_err x) as Ex. pose proof (fl_err y) as Ey.
  pose proof (sub_rel (fl x) (fl y) (F_fl x) (F_fl y)) as Ed.
  pose proof (Rabs_pos x). pose proof (Rabs_pos y).
  apply Rabs_le_inv in Ex. apply Rabs_le_inv in Ey. apply Rabs_le_inv in Ed.
  assert (Hd : Rabs (fl x - fl y) <= (Rabs x + Rabs y) + (u * (Rabs x + Rabs y) + 2 * eta)).
  { apply Rabs_le. pose proof (Rabs_le_inv x _ (Rle_refl _)). pose proof (Rabs_le_inv y _ (Rle_refl _)).
    assert (u * Rabs x + u * Rabs y = u * (Rabs x + Rabs y)) by ring. lra. }
  assert (Hm : u * Rabs (fl x - fl y) <= u * ((Rabs x + Rabs y) + (u * (Rabs x + Rabs y) + 2 * eta))) by (apply mul_le_l; lra).
  assert (0 <= u * (Rabs x + Rabs y)) by (apply Rmult_le_pos; lra).
  assert (u * (u * (Rabs x + Rabs y)) <= / 1000000 * (u * (Rabs x + Rabs y))) by (apply Rmult_le_compat_r; lra).
  assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (u * Rabs x + u * Rabs y = u * (Rabs x + Rabs y)) by ring.
  apply Rabs_le. lra.
Qed.

Lemma prod_le p q P Q : Rabs p <= P -> Rabs q <= Q -> Rabs (p * q) <= P * Q.
Proof.
  intros. rewrite Rabs_mult. pose proof (Rabs_pos p). pose proof (Rabs_pos q).
  apply Rmult_le_compat; assumption.
Qed.

(* a x w of a double axis a and any w with |w_i| <= winf: the computed
   components within 4.02 u |a|_1 winf + 6.03 eta of the exact ones, summed;
   the exact ones' magnitudes sum to at most 2 |a|_1 winf. *)
Lemma cross_err a w winf : bounded winf w ->
  sum_err (ccross a w) (ecross a w) <= 402 / 100 * (u * (norm1 a * winf)) + 603 / 100 * eta /\
  sum_abs (ecross a w) <= 2 * (norm1 a * winf).
Proof.
  intros (W0 & W1 & W2). pose proof u_pos. pose proof eta_pos.
  pose proof (Rabs_pos (c0 a)). pose proof (Rabs_pos (c1 a)). pose proof (Rabs_pos (c2 a)).
  assert (P01 := prod_le (c0 a) (c1 w) _ _ (Rle_refl _) W1). assert (P02 := prod_le (c0 a) (c2 w) _ _ (Rle_refl _) W2).
  assert (P10 := prod_le (c1 a) (c0 w) _ _ (Rle_refl _) W0). assert (P12 := prod_le (c1 a) (c2 w) _ _ (Rle_refl _) W2).
  assert (P20 := prod_le (c2 a) (c0 w) _ _ (Rle_refl _) W0). assert (P21 := prod_le (c2 a) (c1 w) _ _ (Rle_refl _) W1).
  assert (Hs : Rabs (c1 a * c2 w) + Rabs (c2 a * c1 w) + (Rabs (c2 a * c0 w) + Rabs (c0 a * c2 w))
               + (Rabs (c0 a * c1 w) + Rabs (c1 a * c0 w)) <= 2 * (norm1 a * winf)) by (unfold norm1; lra).
  split.
  - unfold sum_err, ccross, ecross; simpl.
    pose proof (fl_diff_prod (c1 a * c2 w) (c2 a * c1 w)).
    pose proof (fl_diff_prod (c2 a * c0 w) (c0 a * c2 w)).
    pose proof (fl_diff_prod (c0 a * c1 w) (c1 a * c0 w)).
    assert (u * (Rabs (c1 a * c2 w) + Rabs (c2 a * c1 w) + (Rabs (c2 a * c0 w) + Rabs (c0 a * c2 w))
               + (Rabs (c0 a * c1 w) + Rabs (c1 a * c0 w))) <= u * (2 * (norm1 a * winf))) by (apply mul_le_l; lra).
    lra.
  - unfold sum_abs, ecross; simpl.
    pose proof (Rabs_triang (c1 a * c2 w) (- (c2 a * c1 w))). pose proof (Rabs_triang (c2 a * c0 w) (- (c0 a * c2 w))).
    pose proof (Rabs_triang (c0 a * c1 w) (- (c1 a * c0 w))). rewrite !Rabs_Ropp in *.
    unfold Rminus. lra.
Qed.

(* The dot product of r (|r_i| <= rinf) with a computed vector c whose
   components are within e (summed) of C's, |C|_1 <= M: the computed r . c
   within 3.02 u rinf (M + e) + 5.02 eta + rinf e of the exact r . C. *)
Lemma dot_close r c C rinf e M : bounded rinf r -> sum_err c C <= e -> sum_abs C <= M ->
  Rabs (cdot r c - edot r C) <= 302 / 100 * (u * (rinf * (M + e))) + 502 / 100 * eta + rinf * e.
Proof.
  intros (R0 & R1 & R2) He HM. pose proof u_pos. pose proof eta_pos.
  unfold sum_err, sum_abs in *.
  assert (Hc : sum_abs c <= M + e).
  { unfold sum_abs. pose proof (Rabs_triang_inv (c0 c) (c0 C)). pose proof (Rabs_triang_inv (c1 c) (c1 C)).
    pose proof (Rabs_triang_inv (c2 c) (c2 C)). lra. }
  unfold sum_abs in Hc.
  pose proof (Rabs_pos (c0 c)). pose proof (Rabs_pos (c1 c)). pose proof (Rabs_pos (c2 c)).
  assert (T : Rabs (c0 r * c0 c) + Rabs (c1 r * c1 c) + Rabs (c2 r * c2 c) <= rinf * (M + e)).
  { rewrite !Rabs_mult.
    assert (Rabs (c0 r) * Rabs (c0 c) <= rinf * Rabs (c0 c)) by (apply Rmult_le_compat_r; lra).
    assert (Rabs (c1 r) * Rabs (c1 c) <= rinf * Rabs (c1 c)) by (apply Rmult_le_compat_r; lra).
    assert (Rabs (c2 r) * Rabs (c2 c) <= rinf * Rabs (c2 c)) by (apply Rmult_le_compat_r; lra).
    assert (0 <= rinf) by (pose proof (Rabs_pos (c0 r)); lra).
    assert (rinf * (Rabs (c0 c) + Rabs (c1 c) + Rabs (c2 c)) <= rinf * (M + e)) by (apply mul_le_l; lra).
    lra. }
  pose proof (dot3_err (c0 r) (c1 r) (c2 r) (c0 c) (c1 c) (c2 c)) as D. simpl in D.
  assert (u * (Rabs (c0 r * c0 c) + Rabs (c1 r * c1 c) + Rabs (c2 r * c2 c)) <= u * (rinf * (M + e)))
    by (apply mul_le_l; lra).
  assert (X : Rabs (edot r c - edot r C) <= rinf * e).
  { unfold edot. replace (c0 r * c0 c + c1 r * c1 c + c2 r * c2 c - (c0 r * c0 C + c1 r * c1 C + c2 r * c2 C))
      with (c0 r * (c0 c - c0 C) + c1 r * (c1 c - c1 C) + c2 r * (c2 c - c2 C)) by ring.
    pose proof (prod_le _ _ _ _ R0 (Rle_refl (Rabs (c0 c - c0 C)))).
    pose proof (prod_le _ _ _ _ R1 (Rle_refl (Rabs (c1 c - c1 C)))).
    pose proof (prod_le _ _ _ _ R2 (Rle_refl (Rabs (c2 c - c2 C)))).
    pose proof (Rabs_triang (c0 r * (c0 c - c0 C) + c1 r * (c1 c - c1 C)) (c2 r * (c2 c - c2 C))).
    pose proof (Rabs_triang (c0 r * (c0 c - c0 C)) (c1 r * (c1 c - c1 C))).
    assert (0 <= rinf) by (pose proof (Rabs_pos (c0 r)); lra).
    assert (rinf * (Rabs (c0 c - c0 C) + Rabs (c1 c - c1 C) + Rabs (c2 c - c2 C)) <= rinf * e) by (apply mul_le_l; lra).
    lra. }
  unfold cdot. replace (dot3 (c0 r) (c1 r) (c2 r) (c0 c) (c1 c) (c2 c) - edot r C)
    with ((dot3 (c0 r) (c1 r) (c2 r) (c0 c) (c1 c) (c2 c) - (c0 r * c0 c + c1 r * c1 c + c2 r * c2 c)) + (edot r c - edot r C))
    by (unfold edot; ring).
  eapply Rle_trans; [apply Rabs_triang | lra].
Qed.

Lemma edot_sum_le r C rinf : bounded rinf r -> Rabs (edot r C) <= rinf * sum_abs C.
Proof.
  intros (R0 & R1 & R2). unfold edot, sum_abs.
  pose proof (prod_le _ _ _ _ R0 (Rle_refl (Rabs (c0 C)))). pose proof (prod_le _ _ _ _ R1 (Rle_refl (Rabs (c1 C)))).
  pose proof (prod_le _ _ _ _ R2 (Rle_refl (Rabs (c2 C)))).
  pose proof (Rabs_triang (c0 r * c0 C + c1 r * c1 C) (c2 r * c2 C)).
  pose proof (Rabs_triang (c0 r * c0 C) (c1 r * c1 C)). lra.
Qed.

(* ---- kAxisProductRounding at triangle_time_lower_bound (motion_bounds.h) ----
   The turn term, for omega_inf > 0 (the velocity term alone, omega_inf = 0,
   is Allowances.v's axis_velocity_rounding). For the axis a (doubles) that
   for_each_separating_axis hands over with its side (+-1), the code computes
   c = a.cross(omega), along_v = side * a.dot(v), and for each corner offset
   r_k of A (k below A's Shape's corner count; a feature repeats its corners)
   b_k = side * r_k.dot(c) and the term fl(fl(along_v + b_k) + fl(lag
   max(0, -b_k))); approach = their max, slack = fl(fl(fl(kAxisVelocityRounding
   a_1) v_inf) + fl(fl(fl(kAxisProductRounding a_1) omega_inf) r_inf)), and
   toward = max(Upper{0}, round_up(approach)) + Upper{slack} =
   next_up(fl(max(0, next_up(approach)) + slack)). The theorem: toward is at
   least the exact rate side a.v + h(side a.(omega x r_k)) of every corner,
   h(b) = b + lag max(0, -b) (TriangleMotion: the turn lambda tau omega x r
   with lambda in [1 - lag, 1] moves r_k along side a by at most tau h(b)),
   with the code's doubles a, v, omega, r_k, lag exact. Each corner's term is
   within 8 u |a|_1 v_inf + 23 u |a|_1 omega_inf r_inf + 7 r_inf eta + 12 eta of
   its exact rate (the cross product 4.02 u, the dot product with r 6.04 u, the
   sums with along_v and the lag 12 u, of |a|_1 omega_inf r_inf); the slack
   is at least 89 u |a|_1 v_inf + 898 u |a|_1 omega_inf r_inf less 2 eta +
   r_inf eta, and next_up adds 2^-602 (Allowances.v next_up_plus), which
   covers the underflow terms for r_inf <= 2^400. Hypotheses: a_1 >=
   kNormFloor (the axis passed for_each_separating_axis's guard); |v_i| <=
   v_inf, |omega_i| <= omega_inf, |r_k,i| <= r_inf (the code takes the
   maxima); 0 <= lag <= 1 (StartFrame::lag returns min(l, 1) of a sum of
   products of nonnegative Uppers); r_inf <= 2^400 (ccd_step's inputs_valid
   refuses a god-object whose radius about G, which bounds every |r_B|, is
   beyond kMaxCoordinate = 1e30, and make_ccd_motion a pose beyond it: the
   posed corners' offsets from G stay below 2^103). *)
Definition turn_h lag b := b + lag * Rmax 0 (- b).
Definition turn_term side lag along_v (a w r : V3) :=
  fl (fl (along_v + fl (side * cdot r (ccross a w))) + fl (lag * Rmax 0 (- fl (side * cdot r (ccross a w))))).

Lemma turn_h_lip lag b B : 0 <= lag <= 1 -> turn_h lag B - turn_h lag b <= Rabs (b - B).
Proof.
  intros Hl. unfold turn_h, Rmax. apply Rle_trans with (Rabs (B - b)); [|rewrite Rabs_minus_sym; lra].
  pose proof (Rle_abs (B - b)). pose proof (Rabs_pos (B - b)).
  repeat destruct Rle_dec; nra.
Qed.

Lemma side_abs side x : (side = 1 \/ side = -1) -> Rabs (side * x) = Rabs x.
Proof. intros [-> | ->]; [rewrite Rmult_1_l | replace (-1 * x) with (- x) by ring; rewrite Rabs_Ropp]; reflexivity. Qed.

Lemma F_cdot a x : F (cdot a x).
Proof. unfold cdot, dot3. apply F_fl. Qed.

Lemma turn_term_err (a v w r : V3) side lag vinf winf rinf :
  dbl a -> (side = 1 \/ side = -1) -> 0 <= lag <= 1 ->
  bounded vinf v -> bounded winf w -> bounded rinf r ->
  let along_v := fl (side * cdot a v) in
  side * edot a v + turn_h lag (side * edot a (ecross w r))
    <= turn_term side lag along_v a w r
       + (8 * (u * (norm1 a * vinf)) + 23 * (u * (norm1 a * winf * rinf)) + 7 * (rinf * eta) + 12 * eta).
Proof.
  intros Ha Hside Hl Hv Hw Hr along_v.
  pose proof u_pos. pose proof eta_pos. pose proof (norm1_pos a).
  pose proof (bounded_pos _ _ Hv) as Hv0. pose proof (bounded_pos _ _ Hw) as Hw0. pose proof (bounded_pos _ _ Hr) as Hr0.
  set (Tv := norm1 a * vinf). set (Aw := norm1 a * winf). set (Tw := norm1 a * winf * rinf).
  assert (HTw : Tw = Aw * rinf) by (unfold Tw, Aw; ring).
  assert (Tv0 : 0 <= Tv) by (unfold Tv; apply Rmult_le_pos; lra).
  assert (Aw0 : 0 <= Aw) by (unfold Aw; apply Rmult_le_pos; lra).
  assert (Tw0 : 0 <= Tw) by (rewrite HTw; apply Rmult_le_pos; lra).
  set (Z := rinf * eta). assert (Z0 : 0 <= Z) by (unfold Z; apply Rmult_le_pos; lra).
  set (UV := u * Tv). set (UW := u * Tw).
  assert (UV0 : 0 <= UV) by (unfold UV; apply Rmult_le_pos; lra).
  assert (UW0 : 0 <= UW) by (unfold UW; apply Rmult_le_pos; lra).
  assert (UVs : UV <= / 1000000 * Tv) by (unfold UV; apply Rmult_le_compat_r; lra).
  assert (UWs : UW <= / 1000000 * Tw) by (unfold UW; apply Rmult_le_compat_r; lra).
  assert (uZ : 0 <= u * Z <= / 1000000 * Z) by (split; [apply Rmult_le_pos; lra | apply Rmult_le_compat_r; lra]).
  assert (ue : 0 <= u * eta <= / 1000000 * eta) by (split; [apply Rmult_le_pos; lra | apply Rmult_le_compat_r; lra]).
  assert (uUV : u * UV <= / 1000000 * UV) by (apply Rmult_le_compat_r; lra).
  assert (uUW : u * UW <= / 1000000 * UW) by (apply Rmult_le_compat_r; lra).
  (* the velocity term *)
  set (V := side * edot a v).
  assert (EV : Rabs (along_v - V) <= 302 / 100 * UV + 502 / 100 * eta).
  { unfold along_v, V. rewrite (fl_side side _ Hside (F_cdot a v)).
    replace (side * cdot a v - side * edot a v) with (side * (cdot a v - edot a v)) by ring.
    rewrite side_abs by exact Hside. apply cdot_err; exact Hv. }
  assert (MV : Rabs V <= Tv) by (unfold V; rewrite side_abs by exact Hside; apply edot_le; exact Hv).
  (* the turn term b of the corner *)
  destruct (cross_err a w winf Hw) as [Ec Mc]. fold Aw in Ec, Mc.
  set (c := ccross a w) in *. set (C := ecross a w) in *.
  pose proof (dot_close r c C rinf _ _ Hr Ec Mc) as Eb0.
  set (b := fl (side * cdot r c)).
  assert (Hb : b = side * cdot r c) by (apply fl_side; [exact Hside | apply F_cdot]).
  set (B := side * edot a (ecross w r)).
  assert (HB : B = side * edot r C) by (unfold B, C, edot, ecross; simpl; ring).
  assert (EB : Rabs (b - B) <= 101 / 10 * UW + 61 / 10 * Z + 502 / 100 * eta).
  { rewrite Hb, HB. replace (side * cdot r c - side * edot r C) with (side * (cdot r c - edot r C)) by ring.
    rewrite side_abs by exact Hside.
    eapply Rle_trans; [exact Eb0|].
    assert (E1 : u * (rinf * (2 * Aw + (402 / 100 * (u * Aw) + 603 / 100 * eta)))
                 = 2 * UW + 402 / 100 * (u * UW) + 603 / 100 * (u * Z)) by (unfold UW, Z; rewrite HTw; ring).
    assert (E2 : rinf * (402 / 100 * (u * Aw) + 603 / 100 * eta) = 402 / 100 * UW + 603 / 100 * Z)
      by (unfold UW, Z; rewrite HTw; ring).
    rewrite E1, E2. lra. }
  assert (MB : Rabs B <= 2 * Tw).
  { rewrite HB, side_abs by exact Hside. eapply Rle_trans; [apply (edot_sum_le r C rinf Hr)|].
    rewrite HTw. replace (2 * (Aw * rinf)) with (rinf * (2 * Aw)) by ring. apply mul_le_l; lra. }
  (* the sums: crude magnitudes, then three roundings *)
  assert (Mv : Rabs along_v <= 2 * Tv + 6 * eta).
  { apply Rabs_le_inv in EV. apply Rabs_le_inv in MV. apply Rabs_le. lra. }
  assert (Mb : Rabs b <= 3 * Tw + 7 * Z + 6 * eta).
  { apply Rabs_le_inv in EB. apply Rabs_le_inv in MB. apply Rabs_le. lra. }
  set (L := 2 * Tv + 3 * Tw + 7 * Z + 12 * eta).
  assert (uL : u * L = 2 * UV + 3 * UW + 7 * (u * Z) + 12 * (u * eta)) by (unfold L, UV, UW; ring).
  assert (Fa : F along_v) by apply F_fl. assert (Fb : F b) by apply F_fl.
  pose proof (add_rel along_v b Fa Fb) as D5.
  assert (Mab : Rabs (along_v + b) <= L) by (eapply Rle_trans; [apply Rabs_triang | unfold L; lra]).
  assert (D5' : Rabs (fl (along_v + b) - (along_v + b)) <= u * L) by (eapply Rle_trans; [exact D5 | apply mul_le_l; lra]).
  set (mx := Rmax 0 (- b)).
  assert (Mmx : 0 <= mx <= Rabs b).
  { pose proof (Rabs_pos b). pose proof (Rle_abs (- b)) as Hn. rewrite Rabs_Ropp in Hn.
    unfold mx, Rmax; destruct Rle_dec; lra. }
  assert (Mlm : Rabs (lag * mx) <= Rabs b) by (rewrite Rabs_pos_eq by nra; nra).
  pose proof (fl_err (lag * mx)) as D6.
  assert (D6' : Rabs (fl (lag * mx) - lag * mx) <= u * (3 * Tw + 7 * Z + 6 * eta) + eta)
    by (eapply Rle_trans; [exact D6|]; assert (u * Rabs (lag * mx) <= u * (3 * Tw + 7 * Z + 6 * eta)) by (apply mul_le_l; lra); lra).
  pose proof (add_rel (fl (along_v + b)) (fl (lag * mx)) (F_fl _) (F_fl _)) as D7.
  assert (Ms1 : Rabs (fl (along_v + b)) <= L + u * L)
    by (apply Rabs_le_inv in D5'; apply Rabs_le_inv in Mab; apply Rabs_le; lra).
  assert (Mm : Rabs (fl (lag * mx)) <= 3 * Tw + 7 * Z + 6 * eta + (u * (3 * Tw + 7 * Z + 6 * eta) + eta))
    by (apply Rabs_le_inv in D6'; apply Rabs_le_inv in Mlm; apply Rabs_le; lra).
  assert (D7' : Rabs (fl (fl (along_v + b) + fl (lag * mx)) - (fl (along_v + b) + fl (lag * mx)))
                <= u * ((L + u * L) + (3 * Tw + 7 * Z + 6 * eta + (u * (3 * Tw + 7 * Z + 6 * eta) + eta)))).
  { eapply Rle_trans; [exact D7|]. apply mul_le_l; [lra|]. eapply Rle_trans; [apply Rabs_triang | lra]. }
  assert (uuL : u * (u * L) <= / 1000000 * (u * L)) by (apply Rmult_le_compat_r; [rewrite uL; lra | lra]).
  assert (E3 : u * ((L + u * L) + (3 * Tw + 7 * Z + 6 * eta + (u * (3 * Tw + 7 * Z + 6 * eta) + eta)))
               = u * L + u * (u * L) + (3 * UW + 7 * (u * Z) + 6 * (u * eta)) + u * (3 * UW + 7 * (u * Z) + 6 * (u * eta)) + u * eta)
    by (unfold UW; ring).
  assert (uu : u * (3 * UW + 7 * (u * Z) + 6 * (u * eta)) <= / 1000000 * (3 * UW + 7 * (u * Z) + 6 * (u * eta)))
    by (apply Rmult_le_compat_r; lra).
  assert (E4 : u * (3 * Tw + 7 * Z + 6 * eta) = 3 * UW + 7 * (u * Z) + 6 * (u * eta)) by (unfold UW; ring).
  rewrite E3 in D7'. rewrite E4 in D6'.
  pose proof (turn_h_lip lag b B Hl) as Hh.
  unfold turn_term. fold c. fold b. fold mx. fold V B.
  unfold turn_h in Hh |- *. fold mx in Hh.
  apply Rabs_le_inv in EV. apply Rabs_le_inv in EB. apply Rabs_le_inv in D5'. apply Rabs_le_inv in D6'.
  apply Rabs_le_inv in D7'.
  assert (Rabs (b - B) <= 101 / 10 * UW + 61 / 10 * Z + 502 / 100 * eta) by (apply Rabs_le; lra).
  replace (u * (Aw * rinf)) with UW by (unfold UW; rewrite HTw; ring).
  lra.
Qed.

(* The slack of the turn site, from below. *)
Lemma turn_slack_lower a vinf winf rinf : dbl a -> kNormFloor <= abs1 a -> 0 <= vinf -> 0 <= winf -> 0 <= rinf ->
  let slack := fl (fl (fl (kAxisVelocityRounding * abs1 a) * vinf) + fl (fl (fl (kAxisProductRounding * abs1 a) * winf) * rinf)) in
  89 * (u * (norm1 a * vinf)) + 898 * (u * (norm1 a * winf * rinf)) - rinf * eta - 2 * eta <= (1 - u) * slack
  /\ 0 <= slack /\ F slack.
Proof.
  intros Ha Hf Hv Hw Hr slack. pose proof u_pos. pose proof eta_pos. pose proof (norm1_pos a).
  pose proof kAxisVelocityRounding_ge as Kv. pose proof kAxisProductRounding_ge as Kw.
  pose proof (scaled_norm1 kAxisVelocityRounding a ltac:(lra) Ha Hf) as K1. pose proof (scaled_norm1 kAxisProductRounding a ltac:(lra) Ha Hf) as K2.
  set (k1 := fl (kAxisVelocityRounding * abs1 a)) in *. set (k2 := fl (kAxisProductRounding * abs1 a)) in *.
  set (A1 := norm1 a) in *.
  assert (k1a : (1 - u) * (1 - u) * (1 - u) * (90 * u * A1) <= k1).
  { eapply Rle_trans; [|exact K1]. apply mul_le_l; [nra|]. apply Rmult_le_compat_r; lra. }
  assert (k2a : (1 - u) * (1 - u) * (1 - u) * (900 * u * A1) <= k2).
  { eapply Rle_trans; [|exact K2]. apply mul_le_l; [nra|]. apply Rmult_le_compat_r; lra. }
  assert (c3 : 0 <= (1 - u) * (1 - u) * (1 - u)) by (repeat apply Rmult_le_pos; lra).
  assert (k10 : 0 <= k1) by (eapply Rle_trans; [|exact k1a]; apply Rmult_le_pos; [lra | nra]).
  assert (k20 : 0 <= k2) by (eapply Rle_trans; [|exact k2a]; apply Rmult_le_pos; [lra | nra]).
  (* the velocity part *)
  pose proof (fl_lower (k1 * vinf) ltac:(nra)) as SV.
  set (sv := fl (k1 * vinf)) in *. assert (sv0 : 0 <= sv) by (apply fl_nonneg; nra).
  (* the turn part *)
  pose proof (fl_lower (k2 * winf) ltac:(nra)) as Y. set (y := fl (k2 * winf)) in *.
  assert (y0 : 0 <= y) by (apply fl_nonneg; nra).
  pose proof (fl_lower (y * rinf) ltac:(nra)) as SW. set (sw := fl (y * rinf)) in *.
  assert (sw0 : 0 <= sw) by (apply fl_nonneg; nra).
  pose proof (sum_lower sv sw (F_fl _) (F_fl _) sv0 sw0) as S. fold slack in S.
  assert (Fs : F slack) by apply F_fl. assert (s0 : 0 <= slack) by (apply fl_nonneg; lra).
  split; [|split; assumption].
  set (Tv := A1 * vinf). set (Tw := A1 * winf * rinf).
  assert (Tv0 : 0 <= Tv) by (unfold Tv; apply Rmult_le_pos; lra).
  assert (Tw0 : 0 <= Tw) by (unfold Tw; repeat apply Rmult_le_pos; lra).
  (* sv >= (1 - u)^4 90 u Tv - eta *)
  assert (V1 : (1 - u) * ((1 - u) * (1 - u) * (1 - u) * (90 * u * A1)) * vinf <= (1 - u) * (k1 * vinf)).
  { rewrite Rmult_assoc. apply mul_le_l; [lra|]. apply Rmult_le_compat_r; lra. }
  assert (V2 : 899 / 10 * (u * Tv) <= (1 - u) * ((1 - u) * (1 - u) * (1 - u) * (90 * u * A1)) * vinf).
  { replace ((1 - u) * ((1 - u) * (1 - u) * (1 - u) * (90 * u * A1)) * vinf)
      with (((1 - u) * (1 - u) * (1 - u) * (1 - u) * 90) * (u * Tv)) by (unfold Tv; ring).
    apply Rmult_le_compat_r; [apply Rmult_le_pos; lra | nra]. }
  (* sw >= (1 - u)^5 900 u Tw - (1 - u) rinf eta - eta *)
  assert (W1 : (1 - u) * ((1 - u) * (k2 * winf) - eta) * rinf <= (1 - u) * (y * rinf)).
  { rewrite Rmult_assoc. apply mul_le_l; [lra|]. apply Rmult_le_compat_r; lra. }
  assert (W2 : (1 - u) * ((1 - u) * (((1 - u) * (1 - u) * (1 - u) * (900 * u * A1)) * winf)) * rinf
               <= (1 - u) * ((1 - u) * (k2 * winf)) * rinf).
  { apply Rmult_le_compat_r; [lra|]. apply mul_le_l; [lra|]. apply mul_le_l; [lra|].
    apply Rmult_le_compat_r; lra. }
  assert (W3 : 8995 / 10 * (u * Tw) <= (1 - u) * ((1 - u) * (((1 - u) * (1 - u) * (1 - u) * (900 * u * A1)) * winf)) * rinf).
  { replace ((1 - u) * ((1 - u) * (((1 - u) * (1 - u) * (1 - u) * (900 * u * A1)) * winf)) * rinf)
      with (((1 - u) * (1 - u) * (1 - u) * (1 - u) * (1 - u) * 900) * (u * Tw)) by (unfold Tw; ring).
    apply Rmult_le_compat_r; [apply Rmult_le_pos; [lra | unfold Tw; repeat apply Rmult_le_pos; lra] | nra]. }
  assert (W4 : (1 - u) * ((1 - u) * (k2 * winf) - eta) * rinf = (1 - u) * ((1 - u) * (k2 * winf)) * rinf - (1 - u) * (rinf * eta))
    by ring.
  assert (0 <= u * (rinf * eta)) by (apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra]).
  assert (0 <= u * Tv) by (apply Rmult_le_pos; lra). assert (0 <= u * Tw) by (apply Rmult_le_pos; lra).
  assert (sumlo : 899 / 10 * (u * Tv) + 8995 / 10 * (u * Tw) - rinf * eta - 2 * eta <= sv + sw) by lra.
  assert (P : (1 - u) * (1 - u) * (899 / 10 * (u * Tv) + 8995 / 10 * (u * Tw) - rinf * eta - 2 * eta)
              <= (1 - u) * slack).
  { apply Rle_trans with ((1 - u) * ((1 - u) * (sv + sw))); [|apply mul_le_l; lra].
    rewrite Rmult_assoc. apply mul_le_l; [lra|]. apply mul_le_l; lra. }
  set (X := 899 / 10 * (u * Tv) + 8995 / 10 * (u * Tw)) in *. set (Yb := rinf * eta + 2 * eta) in *.
  assert (X0 : 0 <= X) by (unfold X; lra).
  assert (Y0 : 0 <= Yb) by (unfold Yb; assert (0 <= rinf * eta) by (apply Rmult_le_pos; lra); lra).
  assert (Q1 : (1 - 2 * u) * X <= (1 - u) * (1 - u) * X) by (apply Rmult_le_compat_r; nra).
  assert (Q2 : (1 - u) * (1 - u) * Yb <= Yb) by (assert ((1 - u) * (1 - u) <= 1) by nra; nra).
  assert (Q3 : (1 - u) * (1 - u) * (X - Yb) = (1 - u) * (1 - u) * X - (1 - u) * (1 - u) * Yb) by ring.
  assert (Q4 : u * X <= / 1000000 * X) by (apply Rmult_le_compat_r; lra).
  assert (P' : (1 - u) * (1 - u) * (X - Yb) <= (1 - u) * slack).
  { eapply Rle_trans; [|exact P]. right. unfold Yb. ring. }
  fold Tv Tw.
  assert (89 * (u * Tv) + 898 * (u * Tw) <= (1 - 2 * u) * X) by (unfold X in *; lra).
  assert (rinf * eta + 2 * eta = Yb) by reflexivity. lra.
Qed.

(* covers optimized/gauss6/ccd/motion_bounds.h "inline double triangle_time_lower_bound(const SatSide& A, const Vec3 r[3]" sha256:e6fe43232891e550 *)
(* covers optimized/gauss6/ccd/motion_bounds.h "GAUSS6_ALWAYS_INLINE double corner_offsets(const Vec3 A[3]" sha256:a6814e84c72b62d0 *)
(* covers optimized/gauss6/ccd/motion_bounds.h "double lag(double tau_max) const" sha256:b83ba4ce01a1244a *)
(* covers optimized/gauss6/step/ccd_step.cpp "bool inputs_valid(const CcdBody* obstacles" sha256:4e9f48e6837b3070 *)
(* allowance kAxisVelocityRounding = 1e-14 *)
Theorem axis_turn_rounding (a v w r0 r1 r2 : V3) side lag vinf winf rinf :
  dbl a -> (side = 1 \/ side = -1) -> 0 <= lag <= 1 ->
  bounded vinf v -> bounded winf w -> bounded rinf r0 -> bounded rinf r1 -> bounded rinf r2 ->
  rinf <= bpow radix2 400 -> kNormFloor <= abs1 a ->
  let along_v := fl (side * cdot a v) in
  let approach := max3 (turn_term side lag along_v a w r0) (turn_term side lag along_v a w r1)
                       (turn_term side lag along_v a w r2) in
  let slack := fl (fl (fl (kAxisVelocityRounding * abs1 a) * vinf)
                   + fl (fl (fl (kAxisProductRounding * abs1 a) * winf) * rinf)) in
  let toward := next_up (fl (Rmax 0 (next_up approach) + slack)) in
  forall r, r = r0 \/ r = r1 \/ r = r2 ->
  side * edot a v + turn_h lag (side * edot a (ecross w r)) <= toward.
Proof.
  intros Ha Hside Hl Hv Hw Hr0 Hr1 Hr2 Hrb Hf along_v approach slack toward r Hr.
  pose proof u_pos. pose proof eta_pos.
  pose proof (bounded_pos _ _ Hv) as Hv0. pose proof (bounded_pos _ _ Hw) as Hw0. pose proof (bounded_pos _ _ Hr0) as Hr00.
  assert (Hrr : bounded rinf r) by (destruct Hr as [-> | [-> | ->]]; assumption).
  pose proof (turn_term_err a v w r side lag vinf winf rinf Ha Hside Hl Hv Hw Hrr) as E. fold along_v in E.
  assert (Ht : turn_term side lag along_v a w r <= approach).
  { unfold approach, max3, Rmax. destruct Hr as [-> | [-> | ->]]; repeat destruct Rle_dec; lra. }
  destruct (turn_slack_lower a vinf winf rinf Ha Hf Hv0 Hw0 Hr00) as (Sl & S0 & FS). fold slack in Sl, S0, FS.
  (* the underflow terms, under next_up's 2^-602 *)
  assert (HZ : 8 * (rinf * eta) + 14 * eta <= bpow radix2 (-602)).
  { assert (Z1 : rinf * eta <= bpow radix2 400 * eta) by (apply Rmult_le_compat_r; lra).
    assert (Z2 : bpow radix2 400 * eta = bpow radix2 (-602) * bpow radix2 (-73)) by (unfold eta; rewrite <- !bpow_plus; f_equal).
    assert (Z3 : bpow radix2 (-73) <= / 32) by (simpl; lra).
    assert (Z4 : 32 * eta <= bpow radix2 (-602) * bpow radix2 (-73)) by (rewrite <- Z2; pose proof (bpow_ge_0 radix2 400);
                                                                          assert (32 <= bpow radix2 400) by (simpl; lra); nra).
    pose proof (bpow_gt_0 radix2 (-602)).
    assert (bpow radix2 (-602) * bpow radix2 (-73) <= bpow radix2 (-602) * / 32) by (apply mul_le_l; lra).
    lra. }
  set (err := 8 * (u * (norm1 a * vinf)) + 23 * (u * (norm1 a * winf * rinf)) + 7 * (rinf * eta) + 12 * eta) in *.
  assert (Herr : err <= (1 - u) * slack + bpow radix2 (-602)).
  { unfold err. pose proof (norm1_pos a).
    assert (0 <= u * (norm1 a * vinf)) by (apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra]).
    assert (0 <= u * (norm1 a * winf * rinf)) by (apply Rmult_le_pos; [lra | repeat apply Rmult_le_pos; lra]).
    lra. }
  assert (Fap : F approach) by (apply F_sel3; [apply max3_sel | apply F_fl ..]).
  destruct (Rle_or_lt 0 approach) as [Hp|Hn].
  - pose proof (next_up_plus approach Hp) as N1.
    assert (N2 : next_up approach <= Rmax 0 (next_up approach)) by apply Rmax_r.
    pose proof (next_up_ge (Rmax 0 (next_up approach) + slack)) as N3. fold toward in N3.
    assert ((1 - u) * slack <= slack) by nra.
    lra.
  - assert (FM : F (Rmax 0 (next_up approach))).
    { unfold Rmax. destruct Rle_dec; [apply F_fl | apply generic_format_0]. }
    assert (M0 : 0 <= Rmax 0 (next_up approach)) by apply Rmax_l.
    pose proof (sum_lower _ _ FM FS M0 S0) as G.
    assert (G0 : 0 <= fl (Rmax 0 (next_up approach) + slack)) by (apply fl_nonneg; lra).
    pose proof (next_up_plus _ G0) as N1. fold toward in N1.
    assert (0 <= u * Rmax 0 (next_up approach)) by (apply Rmult_le_pos; lra).
    assert (u * Rmax 0 (next_up approach) <= Rmax 0 (next_up approach)) by (apply Rle_trans with (1 * Rmax 0 (next_up approach)); [apply Rmult_le_compat_r; lra | lra]).
    lra.
Qed.
Print Assumptions axis_turn_rounding.

(* ---- kSpinRounding at SweptObbFrame::pose (motion_bounds.h) ----
   The directional sweep of a god node's oriented box: the code computes c =
   R * b.center (each coordinate a row of the double matrix R dotted with
   the double centre m, Allowances.v dot3), node_step = step + spin.cross(c)
   (each coordinate fl(step_i + x_i), x = ccross spin c), and rounding =
   fl(kSpinRounding fl(fl(spin_inf radius) + step_inf)), which joins the grow
   as Upper{spread} * half + Upper{rounding} = next_up(fl(S + rounding)), S
   >= 0 the spread's double. The theorem: the computed node_step is within
   that of the exact step + spin x (R m) in the Euclidean norm (the grow is a
   ball's radius), R, m, spin and step the code's doubles taken exactly (R's
   distance from the exact rotation is the posing's: kPoseRounding). Per
   coordinate the centre errs by 3.02 u rho |m|_1 + 5.02 eta, the cross
   product by 10.06 u spin_inf rho |m|_1 with it, the sum by u of itself: under
   12.1 u spin_inf rho |m|_1 + u step_inf + 10.1 spin_inf eta + 2.1 eta; the
   three coordinates' sum bounds the norm, and |m|_1 <= sqrt 3 |m| <= 1.7321
   radius: under 63.01 u spin_inf radius + 3 u step_inf + 6.3 eta in all, the
   allowance (>= 90 u) leaving 89.8 u of both less 2 eta, and next_up's
   2^-602 the underflow terms. Hypotheses: every entry of R at most 1.001 in
   magnitude (R = rotation_matrix(q) of StartFrame's stop pose, each entry
   within 30 u of the exact rotation's: PoseAllowances.v pose_rounding, for
   every q `rescaled` leaves, which is every non-zero finite q: a zero q is
   refused by is_valid_pose); |m| <= radius and radius >= kNormFloor (radius
   = norm_up(|center|) + norm_up(|half|) rounded up: ObbAllowances.v
   obb_radius_rounding, and each norm_up is at least kNormFloor, rounding.h);
   spin_inf, step_inf the code's maxima of |spin_i|, |step_i| (step_inf a
   double); S >= 0 a double. *)
(* allowance kSpinRounding = 1e-14 *)
Definition kSpinRounding := fl (/ 100000000000000).
Lemma kSpinRounding_ge : 90 * u <= kSpinRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.

Definition rho := 1 + / 1000.

(* One row of R (entries <= rho) dotted with m: within 3.02 u rho |m|_1 +
   5.02 eta, and the exact one at most rho |m|_1. *)
Lemma row_err Ri m : bounded rho Ri ->
  Rabs (cdot Ri m - edot Ri m) <= 302 / 100 * (u * (rho * sum_abs m)) + 502 / 100 * eta /\
  Rabs (edot Ri m) <= rho * sum_abs m.
Proof.
  intros (R0 & R1 & R2). pose proof u_pos.
  pose proof (prod_le _ _ _ _ R0 (Rle_refl (Rabs (c0 m)))). pose proof (prod_le _ _ _ _ R1 (Rle_refl (Rabs (c1 m)))).
  pose proof (prod_le _ _ _ _ R2 (Rle_refl (Rabs (c2 m)))).
  assert (T : Rabs (c0 Ri * c0 m) + Rabs (c1 Ri * c1 m) + Rabs (c2 Ri * c2 m) <= rho * sum_abs m) by (unfold sum_abs; lra).
  split.
  - pose proof (dot3_err (c0 Ri) (c1 Ri) (c2 Ri) (c0 m) (c1 m) (c2 m)) as D. simpl in D. unfold cdot, edot.
    assert (u * (Rabs (c0 Ri * c0 m) + Rabs (c1 Ri * c1 m) + Rabs (c2 Ri * c2 m)) <= u * (rho * sum_abs m))
      by (apply mul_le_l; lra).
    lra.
  - unfold edot. pose proof (Rabs_triang (c0 Ri * c0 m + c1 Ri * c1 m) (c2 Ri * c2 m)).
    pose proof (Rabs_triang (c0 Ri * c0 m) (c1 Ri * c1 m)). lra.
Qed.

(* One coordinate of the cross product p x c (|p_i| <= sig) of a computed c
   whose coordinates are within ec of C's, |C_i| <= K: within 4.02 u sig (K +
   ec) + 2.01 eta + 2 sig ec of the exact p x C's, and at most 2 sig (K + ec)
   (1 + 2.01 u) + 2.01 eta in magnitude. *)
Lemma cross_coord_err pj pk cj ck Cj Ck sig ec K :
  Rabs pj <= sig -> Rabs pk <= sig -> Rabs (cj - Cj) <= ec -> Rabs (ck - Ck) <= ec -> Rabs Cj <= K -> Rabs Ck <= K ->
  Rabs (fl (fl (pj * ck) - fl (pk * cj)) - (pj * Ck - pk * Cj)) <= 402 / 100 * (u * (sig * (K + ec))) + 201 / 100 * eta + 2 * (sig * ec).
Proof.
  intros Hj Hk Ej Ek Kj Kk. pose proof u_pos. pose proof eta_pos.
  pose proof (fl_diff_prod (pj * ck) (pk * cj)) as D.
  assert (Mk : Rabs ck <= K + ec) by (apply Rabs_le_inv in Ek; apply Rabs_le_inv in Kk; apply Rabs_le; lra).
  assert (Mj : Rabs cj <= K + ec) by (apply Rabs_le_inv in Ej; apply Rabs_le_inv in Kj; apply Rabs_le; lra).
  pose proof (prod_le _ _ _ _ Hj Mk). pose proof (prod_le _ _ _ _ Hk Mj).
  assert (u * (Rabs (pj * ck) + Rabs (pk * cj)) <= u * (2 * (sig * (K + ec)))) by (apply mul_le_l; lra).
  pose proof (prod_le _ _ _ _ Hj Ek) as Pk. pose proof (prod_le _ _ _ _ Hk Ej) as Pj.
  replace (pj * (ck - Ck)) with (pj * ck - pj * Ck) in Pk by ring.
  replace (pk * (cj - Cj)) with (pk * cj - pk * Cj) in Pj by ring.
  apply Rabs_le_inv in D. apply Rabs_le_inv in Pk. apply Rabs_le_inv in Pj. apply Rabs_le. lra.
Qed.

(* |m|_1 <= 1.7321 |m| <= 1.7321 radius. *)
Lemma sum_abs_norm m radius : sqrt (c0 m * c0 m + c1 m * c1 m + c2 m * c2 m) <= radius ->
  sum_abs m <= 17321 / 10000 * radius.
Proof.
  intros H. unfold sum_abs. set (Q := c0 m * c0 m + c1 m * c1 m + c2 m * c2 m) in *.
  assert (Q0 : 0 <= Q) by (unfold Q; nra).
  pose proof (sqrt_sqrt Q Q0) as E. pose proof (sqrt_pos Q).
  pose proof (Rabs_pos (c0 m)). pose proof (Rabs_pos (c1 m)). pose proof (Rabs_pos (c2 m)).
  assert (M2 : (Rabs (c0 m) + Rabs (c1 m) + Rabs (c2 m)) * (Rabs (c0 m) + Rabs (c1 m) + Rabs (c2 m)) <= 3 * Q).
  { unfold Q. rewrite <- (abs_sq (c0 m)), <- (abs_sq (c1 m)), <- (abs_sq (c2 m)).
    pose proof (Rle_0_sqr (Rabs (c0 m) - Rabs (c1 m))). pose proof (Rle_0_sqr (Rabs (c1 m) - Rabs (c2 m))).
    pose proof (Rle_0_sqr (Rabs (c0 m) - Rabs (c2 m))). unfold Rsqr in *. nra. }
  destruct (Rle_or_lt (Rabs (c0 m) + Rabs (c1 m) + Rabs (c2 m)) (17321 / 10000 * radius)) as [L|L]; [exact L|].
  exfalso. set (M := Rabs (c0 m) + Rabs (c1 m) + Rabs (c2 m)) in *.
  assert (A : 17321 / 10000 * sqrt Q < M) by lra.
  assert (B : 0 <= 17321 / 10000 * sqrt Q) by lra.
  assert (C : (17321 / 10000 * sqrt Q) * (17321 / 10000 * sqrt Q) <= (17321 / 10000 * sqrt Q) * M) by (apply mul_le_l; lra).
  assert (D : (17321 / 10000 * sqrt Q) * M < M * M) by (apply Rmult_lt_compat_r; lra).
  assert (Ee : (17321 / 10000 * sqrt Q) * (17321 / 10000 * sqrt Q) = 300017041 / 100000000 * (sqrt Q * sqrt Q))
    by field.
  rewrite E in Ee.
  lra.
Qed.

(* covers optimized/gauss6/ccd/motion_bounds.h "PosedObb pose_checked(const Obb& b, bool check_frame) const" sha256:3c631a4b53f4d403 *)
(* covers optimized/gauss6/numeric/rounding.h "GAUSS6_ALWAYS_INLINE Upper norm_up(double norm, double relative)" sha256:b4b3280a1e614758 *)
Theorem spin_rounding (R0 R1 R2 m sp st : V3) sig tau radius S :
  bounded rho R0 -> bounded rho R1 -> bounded rho R2 ->
  bounded sig sp -> bounded tau st -> dbl st -> F tau ->
  sqrt (c0 m * c0 m + c1 m * c1 m + c2 m * c2 m) <= radius -> kNormFloor <= radius ->
  F S -> 0 <= S ->
  let c := mk3 (cdot R0 m) (cdot R1 m) (cdot R2 m) in
  let x := ccross sp c in
  let node_step := mk3 (fl (c0 st + c0 x)) (fl (c1 st + c1 x)) (fl (c2 st + c2 x)) in
  let exact := mk3 (c0 st + c0 (ecross sp (mk3 (edot R0 m) (edot R1 m) (edot R2 m))))
                   (c1 st + c1 (ecross sp (mk3 (edot R0 m) (edot R1 m) (edot R2 m))))
                   (c2 st + c2 (ecross sp (mk3 (edot R0 m) (edot R1 m) (edot R2 m)))) in
  let rounding := fl (kSpinRounding * fl (fl (sig * radius) + tau)) in
  dist exact node_step <= next_up (fl (S + rounding)).
Proof.
  intros HR0 HR1 HR2 Hsp Hst Fst Ftau Hm Hrad FS S0 c x node_step exact rounding.
  pose proof u_pos. pose proof eta_pos.
  pose proof (bounded_pos _ _ Hsp) as sig0. pose proof (bounded_pos _ _ Hst) as tau0.
  assert (rad0 : 0 < radius) by (unfold kNormFloor in Hrad; pose proof (bpow_gt_0 radix2 (-500)); lra).
  set (M1 := sum_abs m).
  assert (M10 : 0 <= M1) by (unfold M1, sum_abs; pose proof (Rabs_pos (c0 m)); pose proof (Rabs_pos (c1 m)); pose proof (Rabs_pos (c2 m)); lra).
  pose proof (sum_abs_norm m radius Hm) as HM1. fold M1 in HM1.
  set (K := rho * M1). assert (K0 : 0 <= K) by (unfold K, rho; nra).
  set (ec := 302 / 100 * (u * K) + 502 / 100 * eta).
  destruct (row_err R0 m HR0) as [E0 K0']. destruct (row_err R1 m HR1) as [E1 K1']. destruct (row_err R2 m HR2) as [E2 K2'].
  fold M1 K ec in E0, E1, E2, K0', K1', K2'.
  destruct Hsp as (S0' & S1' & S2').
  set (C := mk3 (edot R0 m) (edot R1 m) (edot R2 m)).
  (* the cross product's coordinates *)
  set (ex := 402 / 100 * (u * (sig * (K + ec))) + 201 / 100 * eta + 2 * (sig * ec)).
  assert (X0 : Rabs (c0 x - c0 (ecross sp C)) <= ex) by (apply cross_coord_err; assumption).
  assert (X1 : Rabs (c1 x - c1 (ecross sp C)) <= ex) by (apply cross_coord_err; assumption).
  assert (X2 : Rabs (c2 x - c2 (ecross sp C)) <= ex) by (apply cross_coord_err; assumption).
  assert (XC : forall pj pk Cj Ck, Rabs pj <= sig -> Rabs pk <= sig -> Rabs Cj <= K -> Rabs Ck <= K ->
                 Rabs (pj * Ck - pk * Cj) <= 2 * (sig * K)).
  { intros pj pk Cj Ck A B Cc D. pose proof (prod_le _ _ _ _ A D). pose proof (prod_le _ _ _ _ B Cc).
    pose proof (Rabs_triang (pj * Ck) (- (pk * Cj))). rewrite Rabs_Ropp in H3. unfold Rminus. lra. }
  assert (MX0 : Rabs (c0 (ecross sp C)) <= 2 * (sig * K)) by (simpl; apply XC; assumption).
  assert (MX1 : Rabs (c1 (ecross sp C)) <= 2 * (sig * K)) by (simpl; apply XC; assumption).
  assert (MX2 : Rabs (c2 (ecross sp C)) <= 2 * (sig * K)) by (simpl; apply XC; assumption).
  (* magnitudes and the products' bounds *)
  set (W := u * (sig * K)). assert (W0 : 0 <= W) by (unfold W; apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra]).
  set (Z := sig * eta). assert (Z0 : 0 <= Z) by (unfold Z; apply Rmult_le_pos; lra).
  assert (uW : u * W <= / 1000000 * W) by (apply Rmult_le_compat_r; lra).
  assert (uZ : 0 <= u * Z <= / 1000000 * Z) by (split; [apply Rmult_le_pos | apply Rmult_le_compat_r]; lra).
  assert (ue : 0 <= u * eta <= / 1000000 * eta) by (split; [apply Rmult_le_pos | apply Rmult_le_compat_r]; lra).
  assert (Eex : ex = 402 / 100 * W + 402 / 100 * (302 / 100 * (u * W) + 502 / 100 * (u * Z)) + 201 / 100 * eta
                     + 2 * (302 / 100 * W + 502 / 100 * Z))
    by (unfold ex, ec, W, Z; ring).
  assert (uuW : u * (u * W) <= / 1000000 * (u * W)) by (apply Rmult_le_compat_r; [apply Rmult_le_pos|]; lra).
  assert (uuZ : u * (u * Z) <= / 1000000 * (u * Z)) by (apply Rmult_le_compat_r; lra).
  assert (uW0 : 0 <= u * W) by (apply Rmult_le_pos; lra).
  assert (Hex : ex <= 10061 / 1000 * W + 10041 / 1000 * Z + 201 / 100 * eta) by (rewrite Eex; lra).
  set (T := u * tau). assert (T0 : 0 <= T) by (unfold T; apply Rmult_le_pos; lra).
  (* each coordinate of node_step *)
  assert (Coord : forall s0 xi Xi, F s0 -> Rabs s0 <= tau -> Rabs (xi - Xi) <= ex -> Rabs Xi <= 2 * (sig * K) ->
            F xi -> Rabs (fl (s0 + xi) - (s0 + Xi)) <= 121 / 10 * W + T + 101 / 10 * Z + 21 / 10 * eta).
  { intros s0 xi Xi Fs Ms Ex Mx Fx. pose proof (add_rel s0 xi Fs Fx) as A.
    assert (Mxi : Rabs (s0 + xi) <= tau + 2 * (sig * K) + ex)
      by (apply Rabs_le_inv in Ms; apply Rabs_le_inv in Ex; apply Rabs_le_inv in Mx; apply Rabs_le; lra).
    assert (u * Rabs (s0 + xi) <= u * (tau + 2 * (sig * K) + ex)) by (apply mul_le_l; lra).
    assert (E' : u * (tau + 2 * (sig * K) + ex) = T + 2 * W + u * ex) by (unfold T, W; ring).
    assert (uex : u * ex <= u * (10061 / 1000 * W + 10041 / 1000 * Z + 201 / 100 * eta)) by (apply mul_le_l; lra).
    assert (E'' : u * (10061 / 1000 * W + 10041 / 1000 * Z + 201 / 100 * eta) = 10061 / 1000 * (u * W) + 10041 / 1000 * (u * Z) + 201 / 100 * (u * eta)) by ring.
    replace (fl (s0 + xi) - (s0 + Xi)) with ((fl (s0 + xi) - (s0 + xi)) + (xi - Xi)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. lra. }
  destruct Hst as (T0' & T1' & T2'). destruct Fst as (F0 & F1 & F2).
  assert (D0 : Rabs (c0 exact - c0 node_step) <= 121 / 10 * W + T + 101 / 10 * Z + 21 / 10 * eta).
  { rewrite Rabs_minus_sym. apply Coord; try assumption. unfold x, ccross; simpl; apply F_fl. }
  assert (D1 : Rabs (c1 exact - c1 node_step) <= 121 / 10 * W + T + 101 / 10 * Z + 21 / 10 * eta).
  { rewrite Rabs_minus_sym. apply Coord; try assumption. unfold x, ccross; simpl; apply F_fl. }
  assert (D2 : Rabs (c2 exact - c2 node_step) <= 121 / 10 * W + T + 101 / 10 * Z + 21 / 10 * eta).
  { rewrite Rabs_minus_sym. apply Coord; try assumption. unfold x, ccross; simpl; apply F_fl. }
  pose proof (PoseAllowances.norm_le_sum_abs (c0 node_step - c0 exact) (c1 node_step - c1 exact) (c2 node_step - c2 exact)) as N.
  rewrite !(Rabs_minus_sym (c0 node_step)), !(Rabs_minus_sym (c1 node_step)), !(Rabs_minus_sym (c2 node_step)) in N.
  unfold dist. eapply Rle_trans; [exact N|].
  (* the allowance *)
  pose proof kSpinRounding_ge as Ks.
  assert (Wr : W <= 17339 / 10000 * (u * (sig * radius))).
  { unfold W, K, rho. assert (0 <= u * sig) by (apply Rmult_le_pos; lra).
    replace (u * (sig * ((1 + / 1000) * M1))) with ((u * sig) * ((1 + / 1000) * M1)) by ring.
    replace (17339 / 10000 * (u * (sig * radius))) with ((u * sig) * (17339 / 10000 * radius)) by ring.
    apply mul_le_l; [lra|]. lra. }
  assert (Zr : Z <= / 100000 * (u * (sig * radius))).
  { unfold Z. replace (/ 100000 * (u * (sig * radius))) with (sig * (/ 100000 * (u * radius))) by ring.
    apply mul_le_l; [lra|]. pose proof (eta_norm radius) as En.
    assert (bpow radix2 (-501) <= radius) by (unfold kNormFloor in Hrad; pose proof (bpow_le radix2 (-501) (-500) ltac:(lia)); lra).
    specialize (En H1). lra. }
  pose proof (fl_lower (sig * radius) ltac:(apply Rmult_le_pos; lra)) as G1.
  assert (G10 : 0 <= fl (sig * radius)) by (apply fl_nonneg; apply Rmult_le_pos; lra).
  pose proof (sum_lower _ _ (F_fl (sig * radius)) Ftau G10 tau0) as G2.
  set (inner := fl (fl (sig * radius) + tau)) in *.
  assert (I0 : 0 <= inner) by (apply fl_nonneg; lra).
  pose proof (fl_lower (kSpinRounding * inner) ltac:(apply Rmult_le_pos; lra)) as G3. fold rounding in G3.
  assert (R0' : 0 <= rounding) by (apply fl_nonneg; apply Rmult_le_pos; lra).
  pose proof (sum_lower S rounding FS (F_fl _) S0 R0') as G4.
  assert (G5 : 0 <= fl (S + rounding)) by (apply fl_nonneg; lra).
  pose proof (next_up_plus _ G5) as G6.
  assert (He : 1000 * eta <= bpow radix2 (-602)).
  { unfold eta. apply Rle_trans with (bpow radix2 10 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  (* rounding >= 89.8 u (sig radius + tau) - 2 eta *)
  set (P := u * (sig * radius)). assert (P0 : 0 <= P) by (unfold P; apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra]).
  assert (J1 : (1 - u) * ((1 - u) * (sig * radius) - eta + tau) <= inner)
    by (eapply Rle_trans; [apply mul_le_l; [lra | apply Rplus_le_compat_r; exact G1] | exact G2]).
  assert (J2 : kSpinRounding * ((1 - u) * ((1 - u) * (sig * radius) - eta + tau)) <= kSpinRounding * inner)
    by (apply mul_le_l; lra).
  assert (J3 : 90 * u * ((1 - u) * ((1 - u) * (sig * radius) + tau)) <= kSpinRounding * ((1 - u) * ((1 - u) * (sig * radius) + tau)))
    by (apply Rmult_le_compat_r; [apply Rmult_le_pos; [lra | apply Rplus_le_le_0_compat; [apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra] | lra]] | lra]).
  assert (J4 : kSpinRounding * ((1 - u) * ((1 - u) * (sig * radius) - eta + tau))
               = kSpinRounding * ((1 - u) * ((1 - u) * (sig * radius) + tau)) - kSpinRounding * ((1 - u) * eta)) by ring.
  assert (J5 : kSpinRounding <= 1).
  { pose proof (fl_upper (/ 100000000000000) ltac:(lra)). pose proof eta_small.
    assert (bpow radix2 (-1022) <= 1) by (apply (bpow_le radix2 (-1022) 0); lia). unfold kSpinRounding. lra. }
  assert (J6 : kSpinRounding * ((1 - u) * eta) <= eta).
  { assert (0 <= kSpinRounding) by lra. assert (0 <= (1 - u) * eta) by (apply Rmult_le_pos; lra).
    apply Rle_trans with (1 * ((1 - u) * eta)); [apply Rmult_le_compat_r; lra | lra]. }
  assert (J7 : 90 * u * ((1 - u) * ((1 - u) * (sig * radius) + tau)) = 90 * ((1 - u) * (1 - u)) * P + 90 * (1 - u) * T)
    by (unfold P, T; ring).
  assert (J8 : 8999 / 100 * P <= 90 * ((1 - u) * (1 - u)) * P) by (apply Rmult_le_compat_r; [lra | nra]).
  assert (J9 : 8999 / 100 * T <= 90 * (1 - u) * T) by (apply Rmult_le_compat_r; [lra | nra]).
  assert (Lk : 8999 / 100 * P + 8999 / 100 * T - eta <= kSpinRounding * inner) by lra.
  assert (L1 : (1 - u) * (8999 / 100 * P + 8999 / 100 * T - eta) <= (1 - u) * (kSpinRounding * inner)) by (apply mul_le_l; lra).
  assert (uP : u * P <= / 1000000 * P) by (apply Rmult_le_compat_r; lra).
  assert (uT : u * T <= / 1000000 * T) by (apply Rmult_le_compat_r; lra).
  assert (L2 : 8998 / 100 * P + 8998 / 100 * T - 2 * eta <= rounding) by lra.
  assert (L3 : (1 - u) * (8998 / 100 * P + 8998 / 100 * T - 2 * eta) <= (1 - u) * rounding) by (apply mul_le_l; lra).
  assert (L4 : (1 - u) * rounding <= (1 - u) * (S + rounding)) by (apply mul_le_l; lra).
  assert (Wr' : 363 / 10 * W <= 6295 / 100 * P) by (fold P in Wr; lra).
  fold P in Zr. lra.
Qed.
Print Assumptions spin_rounding.
