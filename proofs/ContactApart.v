(* kBoxPoseRounding at generate_contacts' `apart` (contact/contacts.cpp
   generate_contacts, `scale` and `apart`, lines 529-532; feature_pair's box
   tests (vertex_apart: boxes_apart for a vertex, its upper bounds grown once
   per triangle pair) and separations, lines 275-339; boxes_apart, line 192;
   geometry/distance.cpp closest_point_on_triangle): two features whose
   boxes (the min / max of their double corners) are more than `apart` apart
   along a world axis have a computed separation above the contact distance
   d, so that skipping them (feature_pair, every pair the triangles' boxes and
   axes keep) leaves the contact set as it is. The separation is computed as the code
   computes it: the closest point of a triangle (geometry/distance.cpp
   closest_point_on_triangle, every branch) or of two segments (the points
   g0 + s (g1 - g0) of feature_pair, 0 < s < 1 checked), the difference, its
   norm (Eigen's sqrt of the sum of squares, any order of the sum). Same model
   as Rounding.v (binary64, round to nearest, gradual underflow, finite
   results, no fused multiply-add). *)

From Coq Require Import Reals Psatz List.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances BoxPose.
Open Scope R_scope.

Lemma abs_bounds x e : Rabs x <= e -> - e <= x <= e.
Proof. unfold Rabs; destruct (Rcase_abs x); lra. Qed.

(* ---- The closest point's coordinate lies in the corners' box, to
   40 u M + 5 eta ---- *)

(* The parameter of an edge branch: fl(x / fl(x + y)) for doubles x, y >= 0
   (closest_point_on_triangle: d1 / (d1 - d3) with d1 >= 0 >= d3, d2 / (d2 -
   d6) with d2 >= 0 >= d6, eb / (eb - ec) with eb >= 0 >= ec, as computed)
   lies in [0, 1]. (A zero divisor, x = y = 0,
   gives NaN in IEEE, and a NaN point, whose separation fails `sep <= d`; the
   model's x / 0 = 0 stays in [0, 1] too.) *)
Definition ratio x y := fl (x / fl (x + y)).
Lemma ratio_unit x y : F x -> F y -> 0 <= x -> 0 <= y -> 0 <= ratio x y <= 1.
Proof.
  intros Fx Fy Hx Hy. unfold ratio.
  assert (HD : x <= fl (x + y)) by (apply fl_ge_F; [exact Fx | lra]).
  destruct (Req_dec x 0) as [->|Hx0].
  - unfold Rdiv. rewrite Rmult_0_l. rewrite fl_F by (apply generic_format_0). lra.
  - assert (0 < fl (x + y)) by lra.
    assert (0 <= x / fl (x + y)) by (apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]).
    assert (x / fl (x + y) <= 1).
    { apply Rmult_le_reg_r with (fl (x + y)); [lra|]. unfold Rdiv.
      rewrite Rmult_assoc, Rinv_l, Rmult_1_r, Rmult_1_l by lra. exact HD. }
    split; [apply fl_nonneg; lra|].
    apply fl_le_F; [apply generic_format_bpow with (e := 0%Z); unfold FLT_exp; lia | simpl; lra].
Qed.

(* The interior branch's weights v = fl(vb den), w = fl(vc den), den =
   fl(1 / fl(fl(va + vb) + vc)), for doubles va, vb, vc >= 0 (the branch's
   guard) and a finite sum: v, w >= 0 and v + w <= 1 + 8 u. *)
Theorem interior_weights va vb vc : F va -> F vb -> F vc -> 0 <= va -> 0 <= vb -> 0 <= vc ->
  let S := fl (fl (va + vb) + vc) in S < bpow radix2 1024 ->
  let den := fl (/ S) in
  0 <= fl (vb * den) /\ 0 <= fl (vc * den) /\ fl (vb * den) + fl (vc * den) <= 1 + 8 * u.
Proof.
  intros Fa Fb Fc Ha Hb Hc S HS den. pose proof u_small as Hu. pose proof eta_pos.
  assert (H1 : vb <= fl (va + vb)) by (apply fl_ge_F; [exact Fb | lra]).
  assert (H2 : fl (vb + vc) <= S) by (apply fl_le; lra).
  pose proof (sum_lower vb vc Fb Fc Hb Hc) as H3.
  assert (HS0 : 0 <= S) by (apply fl_nonneg; pose proof (fl_nonneg (va + vb)); lra).
  destruct (Req_dec S 0) as [HS1|HS1].
  - assert (Hd : den = 0) by (unfold den; rewrite HS1, Rinv_0, fl_F by apply generic_format_0; reflexivity).
    rewrite Hd, !Rmult_0_r, fl_F by apply generic_format_0. lra.
  - assert (HSp : 0 < S) by lra.
    assert (Hi : 0 < / S) by (apply Rinv_0_lt_compat; lra).
    assert (Hd0 : 0 <= den) by (apply fl_nonneg; lra).
    (* eta <= 4 u / S, S below 2^1024 *)
    assert (He : eta * S <= 4 * u).
    { apply Rle_trans with (eta * bpow radix2 1024); [apply Rmult_le_compat_l; lra|].
      unfold eta. rewrite bpow_m53, <- bpow_plus.
      replace (4 * bpow radix2 (-53)) with (bpow radix2 (-51)) by (simpl; lra).
      apply bpow_le. lia. }
    assert (Hden : den * S <= 1 + 5 * u).
    { pose proof (fl_upper (/ S) ltac:(lra)) as G. fold den in G.
      assert (den * S <= ((1 + u) * / S + eta) * S) by (apply Rmult_le_compat_r; lra).
      assert (((1 + u) * / S + eta) * S = (1 + u) + eta * S) by (field; lra). lra. }
    assert (Hv0 : 0 <= vb * den) by (apply Rmult_le_pos; lra).
    assert (Hw0 : 0 <= vc * den) by (apply Rmult_le_pos; lra).
    pose proof (fl_upper (vb * den) Hv0). pose proof (fl_upper (vc * den) Hw0).
    (* (vb + vc) den <= (1 + 5 u) / (1 - u) *)
    assert (Hsum : (1 - u) * ((vb + vc) * den) <= 1 + 5 * u).
    { assert ((1 - u) * (vb + vc) * den <= S * den) by (apply Rmult_le_compat_r; lra). lra. }
    assert (eta <= / 1000000 * u)
      by (pose proof (eta_rel 1 ltac:(apply Rle_trans with (bpow radix2 0); [apply bpow_le; lia | simpl; lra])); lra).
    split; [apply fl_nonneg; lra|]. split; [apply fl_nonneg; lra|].
    assert (HX : (vb + vc) * den <= 1.01) by (unfold u in *; lra).
    assert (fl (vb * den) + fl (vc * den) <= (1 + u) * ((vb + vc) * den) + 2 * eta) by lra.
    unfold u in *; lra.
Qed.
Print Assumptions interior_weights.

(* An edge branch's point e0 + t (e1 - e0), computed as the code computes it
   (Allowances.v point_c), t in [0, 1], e0, e1 in [lo, hi] and within M. *)
Lemma edge_in_box t e0 e1 lo hi M :
  0 <= t <= 1 -> lo <= e0 <= hi -> lo <= e1 <= hi -> Rabs e0 <= M -> Rabs e1 <= M ->
  lo - (7 * u * M + 5 * eta) <= point_c t e0 e1 <= hi + (7 * u * M + 5 * eta).
Proof.
  intros Ht H0 H1 M0 M1. destruct (point_err t e0 e1 M Ht M0 M1) as [_ HE].
  assert ((1 - t) * lo <= (1 - t) * e0 <= (1 - t) * hi) by (split; apply Rmult_le_compat_l; lra).
  assert (t * lo <= t * e1 <= t * hi) by (split; apply Rmult_le_compat_l; lra).
  assert (lo <= point_x t e0 e1 <= hi) by (unfold point_x; lra).
  apply abs_bounds in HE. lra.
Qed.

(* Weights s = v + w in (1, 1 + 8 u] on a corner z above m: (1 - s) (a - m) +
   s (z - m) = (z - m) + (s - 1) (z - a) >= -16 u M. *)
Lemma comb_side a z s m M : 1 < s -> s <= 1 + 8 * u -> m <= z -> Rabs (z - a) <= 2 * M ->
  - (16 * u * M) <= (1 - s) * (a - m) + s * (z - m).
Proof.
  intros H1 Hs Hz Hd.
  assert (E : (1 - s) * (a - m) + s * (z - m) = (z - m) + (s - 1) * (z - a)) by ring.
  assert (- (2 * M) <= z - a) by (apply abs_bounds in Hd; lra).
  assert ((s - 1) * (- (2 * M)) <= (s - 1) * (z - a)) by (apply Rmult_le_compat_l; lra).
  assert ((s - 1) * (2 * M) <= (8 * u) * (2 * M)) by (apply Rmult_le_compat_r; [pose proof (Rabs_pos (z - a)) |]; lra).
  lra.
Qed.

(* The combination a + v (b - a) + w (c - a) of three reals above m, v, w >= 0,
   v + w <= 1 + 8 u: at least m - 16 u M (a convex combination but for the
   8 u excess of v + w). *)
Lemma comb_lower a b c v w m M : 0 <= v -> 0 <= w -> v + w <= 1 + 8 * u ->
  m <= a -> m <= b -> m <= c -> Rabs a <= M -> Rabs b <= M -> Rabs c <= M ->
  m - 16 * u * M <= a + v * (b - a) + w * (c - a).
Proof.
  intros Hv Hw Hs Ha Hb Hc Ma Mb Mc. pose proof u_small.
  assert (Dba : Rabs (b - a) <= 2 * M) by (apply Rle_trans with (M + M); [apply abs_diff_le | ]; lra).
  assert (Dca : Rabs (c - a) <= 2 * M) by (apply Rle_trans with (M + M); [apply abs_diff_le | ]; lra).
  assert (E : a + v * (b - a) + w * (c - a) - m = (1 - (v + w)) * (a - m) + v * (b - m) + w * (c - m)) by ring.
  destruct (Rle_lt_dec (v + w) 1) as [H1|H1].
  - assert (0 <= (1 - (v + w)) * (a - m)) by (apply Rmult_le_pos; lra).
    assert (0 <= v * (b - m)) by (apply Rmult_le_pos; lra).
    assert (0 <= w * (c - m)) by (apply Rmult_le_pos; lra).
    assert (0 <= u * M) by (apply Rmult_le_pos; [lra | pose proof (Rabs_pos a); lra]). lra.
  - (* v + w > 1: the combination is at least (1 - s) (a - m) + s (z - m), z the
       lesser of b and c, s = v + w: one lemma for either *)
    destruct (Rle_lt_dec b c) as [Hbc|Hbc].
    + assert (w * (b - m) <= w * (c - m)) by (apply Rmult_le_compat_l; lra).
      pose proof (comb_side a b (v + w) m M ltac:(lra) Hs Hb Dba). lra.
    + assert (v * (c - m) <= v * (b - m)) by (apply Rmult_le_compat_l; lra).
      pose proof (comb_side a c (v + w) m M ltac:(lra) Hs Hc Dca). lra.
Qed.

(* The interior branch's point a + (b - a) v + (c - a) w, computed as the
   code computes it, v, w >= 0, v + w <= 1 + 8 u. *)
Definition interior_c a b c v w := fl (fl (a + fl (fl (b - a) * v)) + fl (fl (c - a) * w)).
(* The interior's coordinate within 24 u M + 5 eta of the exact
   a + v (b - a) + w (c - a). *)
Lemma interior_err a b c v w M : F a -> F b -> F c ->
  0 <= v -> 0 <= w -> v + w <= 1 + 8 * u -> Rabs a <= M -> Rabs b <= M -> Rabs c <= M ->
  Rabs (interior_c a b c v w - (a + v * (b - a) + w * (c - a))) <= 24 * u * M + 5 * eta.
Proof.
  intros Fa Fb Fc Hv Hw Hs Ma Mb Mc. pose proof u_small as Hu. pose proof eta_pos.
  assert (HM : 0 <= M) by (pose proof (Rabs_pos a); lra).
  assert (Hv1 : v <= 1 + 8 * u) by lra. assert (Hw1 : w <= 1 + 8 * u) by lra.
  set (X := a + v * (b - a) + w * (c - a)).
  pose proof (sub_rel b a Fb Fa) as E1. pose proof (sub_rel c a Fc Fa) as E2.
  assert (Dba : Rabs (b - a) <= 2 * M) by (apply Rle_trans with (M + M); [apply abs_diff_le | ]; lra).
  assert (Dca : Rabs (c - a) <= 2 * M) by (apply Rle_trans with (M + M); [apply abs_diff_le | ]; lra).
  assert (A1 : u * Rabs (b - a) <= u * (2 * M)) by (apply Rmult_le_compat_l; lra).
  assert (A2 : u * Rabs (c - a) <= u * (2 * M)) by (apply Rmult_le_compat_l; lra).
  assert (Q1 : Rabs (fl (b - a) * v - v * (b - a)) <= (1 + 8 * u) * (2 * u * M)).
  { replace (fl (b - a) * v - v * (b - a)) with (v * (fl (b - a) - (b - a))) by ring.
    rewrite Rabs_mult, Rabs_pos_eq by lra.
    apply Rmult_le_compat; [lra | apply Rabs_pos | lra | lra]. }
  assert (Q2 : Rabs (fl (c - a) * w - w * (c - a)) <= (1 + 8 * u) * (2 * u * M)).
  { replace (fl (c - a) * w - w * (c - a)) with (w * (fl (c - a) - (c - a))) by ring.
    rewrite Rabs_mult, Rabs_pos_eq by lra.
    apply Rmult_le_compat; [lra | apply Rabs_pos | lra | lra]. }
  assert (B1 : Rabs (v * (b - a)) <= (1 + 8 * u) * (2 * M))
    by (rewrite Rabs_mult, Rabs_pos_eq by lra; apply Rmult_le_compat; [lra | apply Rabs_pos | lra | lra]).
  assert (B2 : Rabs (w * (c - a)) <= (1 + 8 * u) * (2 * M))
    by (rewrite Rabs_mult, Rabs_pos_eq by lra; apply Rmult_le_compat; [lra | apply Rabs_pos | lra | lra]).
  pose proof (step _ _ _ _ B1 Q1) as P1. pose proof (step _ _ _ _ B2 Q2) as P2.
  set (p1 := fl (fl (b - a) * v)) in *. set (p2 := fl (fl (c - a) * w)) in *.
  set (e1 := (1 + 8 * u) * (2 * u * M) + u * ((1 + 8 * u) * (2 * M) + (1 + 8 * u) * (2 * u * M)) + eta) in *.
  assert (S1 : Rabs ((a + p1) - (a + v * (b - a))) <= e1)
    by (replace ((a + p1) - (a + v * (b - a))) with (p1 - v * (b - a)) by ring; exact P1).
  assert (BS1 : Rabs (a + v * (b - a)) <= M + (1 + 8 * u) * (2 * M))
    by (eapply Rle_trans; [apply Rabs_triang | lra]).
  pose proof (step _ _ _ _ BS1 S1) as P3. set (s1 := fl (a + p1)) in *.
  assert (S2 : Rabs ((s1 + p2) - X) <= (e1 + u * (M + (1 + 8 * u) * (2 * M) + e1) + eta) + e1).
  { unfold X. replace (s1 + p2 - (a + v * (b - a) + w * (c - a)))
      with ((s1 - (a + v * (b - a))) + (p2 - w * (c - a))) by ring.
    eapply Rle_trans; [apply Rabs_triang | lra]. }
  assert (BX : Rabs X <= M + 2 * ((1 + 8 * u) * (2 * M))).
  { unfold X. eapply Rle_trans; [apply Rabs_triang|].
    pose proof (Rabs_triang a (v * (b - a))). lra. }
  pose proof (step _ _ _ _ BX S2) as P4.
  unfold interior_c. fold p1 p2 s1.
  set (E := e1 + u * (M + (1 + 8 * u) * (2 * M) + e1) + eta + e1) in *.
  assert (HE : E + u * (M + 2 * ((1 + 8 * u) * (2 * M)) + E) + eta <= 24 * u * M + 5 * eta)
    by (unfold E, e1, u in *; lra).
  lra.
Qed.

Lemma interior_in_box a b c v w lo hi M : F a -> F b -> F c ->
  0 <= v -> 0 <= w -> v + w <= 1 + 8 * u ->
  lo <= a <= hi -> lo <= b <= hi -> lo <= c <= hi -> Rabs a <= M -> Rabs b <= M -> Rabs c <= M ->
  lo - (40 * u * M + 5 * eta) <= interior_c a b c v w <= hi + (40 * u * M + 5 * eta).
Proof.
  intros Fa Fb Fc Hv Hw Hs Ha Hb Hc Ma Mb Mc. pose proof u_small as Hu. pose proof eta_pos.
  assert (HM : 0 <= M) by (pose proof (Rabs_pos a); lra).
  (* the exact point X lies within 16 u M of [lo, hi] *)
  set (X := a + v * (b - a) + w * (c - a)).
  assert (HX : lo - 16 * u * M <= X <= hi + 16 * u * M).
  { pose proof (comb_lower a b c v w lo M Hv Hw Hs ltac:(lra) ltac:(lra) ltac:(lra) Ma Mb Mc).
    pose proof (comb_lower (- a) (- b) (- c) v w (- hi) M Hv Hw Hs ltac:(lra) ltac:(lra) ltac:(lra)
      ltac:(rewrite Rabs_Ropp; exact Ma) ltac:(rewrite Rabs_Ropp; exact Mb) ltac:(rewrite Rabs_Ropp; exact Mc)).
    unfold X. split; lra. }
  pose proof (interior_err a b c v w M Fa Fb Fc Hv Hw Hs Ma Mb Mc) as E. fold X in E. apply abs_bounds in E.
  assert (0 <= u * M) by nra. lra.
Qed.

(* closest_point_on_triangle's coordinate, one of its branches (the corners;
   an edge's point at a parameter in [0, 1]: the branches of edges ab, ac, bc
   by ratio_unit (edge_point, the edge rule); the interior
   at weights of interior_weights), lies in [lo, hi] of the corners, to
   40 u M + 5 eta. *)
Definition closest_coord (a b c q : R) : Prop :=
  q = a \/ q = b \/ q = c \/
  (exists t e0 e1, 0 <= t <= 1 /\ (e0 = a \/ e0 = b \/ e0 = c) /\ (e1 = a \/ e1 = b \/ e1 = c) /\
     q = point_c t e0 e1) \/
  (exists v w, 0 <= v /\ 0 <= w /\ v + w <= 1 + 8 * u /\ q = interior_c a b c v w).

Theorem closest_in_box a b c q lo hi M : F a -> F b -> F c ->
  lo <= a <= hi -> lo <= b <= hi -> lo <= c <= hi -> Rabs a <= M -> Rabs b <= M -> Rabs c <= M ->
  closest_coord a b c q -> lo - (40 * u * M + 5 * eta) <= q <= hi + (40 * u * M + 5 * eta).
Proof.
  intros Fa Fb Fc Ha Hb Hc Ma Mb Mc Hq. pose proof u_small. pose proof eta_pos.
  assert (0 <= M) by (pose proof (Rabs_pos a); lra).
  assert (0 <= u * M) by (apply Rmult_le_pos; lra).
  destruct Hq as [->|[->|[->|[(t & e0 & e1 & Ht & Hq0 & Hq1 & ->)|(v & w & Hv & Hw & Hs & ->)]]]]; try lra.
  - assert (lo <= e0 <= hi /\ Rabs e0 <= M) by (destruct Hq0 as [ -> | [ -> | -> ] ]; tauto).
    assert (lo <= e1 <= hi /\ Rabs e1 <= M) by (destruct Hq1 as [ -> | [ -> | -> ] ]; tauto).
    pose proof (edge_in_box t e0 e1 lo hi M Ht ltac:(tauto) ltac:(tauto) ltac:(tauto) ltac:(tauto)). lra.
  - apply interior_in_box; assumption.
Qed.
Print Assumptions closest_in_box.

(* ---- The computed separation ---- *)

(* The computed norm, sqrt of the sum of the three rounded squares in any
   order, is at least each coordinate's fl(sqrt(fl(t t))). *)
Lemma norm_ge_term x y z : fl (sqrt (fl (x * x))) <= norm_c x y z.
Proof.
  unfold norm_c. apply fl_le, sqrt_le_1_alt.
  assert (0 <= fl (y * y)) by (apply fl_nonneg, Rle_0_sqr).
  assert (0 <= fl (z * z)) by (apply fl_nonneg, Rle_0_sqr).
  assert (fl (x * x) <= fl (fl (x * x) + fl (y * y))) by (apply fl_ge_F; [apply F_fl | lra]).
  apply fl_ge_F; [apply F_fl | lra].
Qed.
Lemma norm_ge_any s x y z : (s = x \/ s = y \/ s = z) -> fl (sqrt (fl (s * s))) <= norm_c x y z.
Proof.
  intros [ -> | [ -> | -> ] ]; [apply norm_ge_term| |].
  - unfold norm_c. rewrite (Rplus_comm (fl (x * x))). apply norm_ge_term.
  - unfold norm_c. apply fl_le, sqrt_le_1_alt.
    assert (0 <= fl (x * x)) by (apply fl_nonneg, Rle_0_sqr).
    assert (0 <= fl (y * y)) by (apply fl_nonneg, Rle_0_sqr).
    assert (0 <= fl (fl (x * x) + fl (y * y))) by (apply fl_nonneg; lra).
    apply fl_ge_F; [apply F_fl | lra].
Qed.

(* A coordinate difference t with |t| >= (1 + 4 u) d, d >= 2^-500: its
   computed square root of its square is above d (both roundings relative:
   t t >= 2^-1000 is normal). *)
Lemma sqrt_sq_above t d : bpow radix2 (-500) <= d -> (1 + 4 * u) * d <= Rabs t ->
  d < fl (sqrt (fl (t * t))).
Proof.
  intros Hd Ht. pose proof u_small as Hu.
  assert (Hb : 0 < bpow radix2 (-500)) by apply bpow_gt_0.
  set (r := Rabs t) in *.
  assert (Hr : bpow radix2 (-500) <= r) by (unfold u in *; lra).
  assert (Htt : t * t = r * r).
  { unfold r. rewrite <- Rabs_mult, Rabs_pos_eq; [reflexivity | apply Rle_0_sqr]. }
  assert (Hn : bpow radix2 (-1022) <= bpow radix2 (-500) * bpow radix2 (-500))
    by (rewrite <- bpow_plus; apply bpow_le; lia).
  assert (Hr2 : bpow radix2 (-500) * bpow radix2 (-500) <= r * r) by (apply Rmult_le_compat; lra).
  pose proof (fl_lower_normal (t * t) ltac:(lra)) as G1. rewrite Htt in G1.
  assert (Hq : (1 - u) * (1 - u) * (r * r) <= (1 - u) * (r * r))
    by (apply Rmult_le_compat_r; [apply Rle_0_sqr | unfold u; lra]).
  assert (G2 : (1 - u) * r <= sqrt (fl (t * t))).
  { rewrite <- (sqrt_square ((1 - u) * r)) by (apply Rmult_le_pos; lra).
    apply sqrt_le_1_alt. rewrite Htt.
    replace ((1 - u) * r * ((1 - u) * r)) with ((1 - u) * (1 - u) * (r * r)) by ring. lra. }
  assert (Hs : bpow radix2 (-1022) <= sqrt (fl (t * t))).
  { assert (bpow radix2 (-1022) <= / 2 * bpow radix2 (-500)).
    { replace (/ 2) with (bpow radix2 (-1)) by (simpl; lra). rewrite <- bpow_plus. apply bpow_le. lia. }
    assert ((1 - u) * bpow radix2 (-500) <= (1 - u) * r) by (apply Rmult_le_compat_l; lra).
    unfold u in *; lra. }
  pose proof (fl_lower_normal _ Hs) as G3.
  assert (G4 : (1 - u) * ((1 - u) * r) <= (1 - u) * sqrt (fl (t * t))) by (apply mul_le_l; lra).
  assert (G5 : (1 - u) * ((1 - u) * ((1 + 4 * u) * d)) <= (1 - u) * ((1 - u) * r))
    by (apply mul_le_l; [lra|]; apply mul_le_l; lra).
  assert (G6 : d < (1 - u) * ((1 - u) * ((1 + 4 * u) * d))) by (unfold u in *; lra).
  lra.
Qed.

(* ---- The theorem: features apart by more than `apart` along an axis ---- *)

(* `apart` as generate_contacts computes it: (Upper{2 d} + Upper{kBoxPoseRounding}
   Upper{scale}).v, each Upper operation rounded to nearest then next_up. *)
Definition apart d scale := next_up (fl (fl (2 * d) + next_up (fl (kBoxPoseRounding * scale)))).

Lemma kBoxPoseRounding_ge : 9000 * u <= kBoxPoseRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.

Lemma apart_lower d scale : 0 <= d -> 0 <= scale ->
  (1 - u) * ((1 - u) * (2 * d) - eta + 9000 * u * scale) + bpow radix2 (-602) <= apart d scale.
Proof.
  intros Hd Hs. pose proof u_small. pose proof eta_pos. pose proof kBoxPoseRounding_ge.
  assert (HK : 9000 * u * scale <= kBoxPoseRounding * scale) by (apply Rmult_le_compat_r; lra).
  assert (HN : kBoxPoseRounding * scale <= next_up (fl (kBoxPoseRounding * scale))) by apply next_up_ge.
  pose proof (fl_lower (2 * d) ltac:(lra)).
  assert (H2d : 0 <= fl (2 * d)) by (apply fl_nonneg; lra).
  assert (0 <= kBoxPoseRounding * scale) by (apply Rmult_le_pos; lra).
  assert (HN0 : 0 <= next_up (fl (kBoxPoseRounding * scale))) by lra.
  unfold apart. set (N := next_up (fl (kBoxPoseRounding * scale))) in *.
  assert (FN : F N) by (unfold N, next_up; apply F_fl).
  pose proof (sum_lower (fl (2 * d)) N (F_fl _) FN H2d HN0) as G.
  assert (0 <= fl (fl (2 * d) + N)) by (apply fl_nonneg; lra).
  pose proof (next_up_plus (fl (fl (2 * d) + N)) ltac:(lra)).
  assert ((1 - u) * ((1 - u) * (2 * d) - eta + 9000 * u * scale) <= (1 - u) * (fl (2 * d) + N))
    by (apply mul_le_l; lra).
  lra.
Qed.

(* The core: computed coordinates P of one feature's point and Q of the
   other's, in boxes [alo, ahi] and [blo, bhi] widened by E = 40 u M + 5 eta,
   the box test boxes_apart passing along this axis (blo > next_up(fl(ahi +
   apart)), the code's Upper sum), M <= 4 scale + 2^-490, d >= 2^-500: the computed
   separation, the norm of the rounded difference (whichever coordinate the
   axis is, whichever order the sum takes), is above d. *)
(* covers optimized/gauss6/contact/contacts.cpp "bool boxes_apart(const Vec3& a_lo, const Vec3& a_hi, const Vec3& b_lo, const Vec3& b_hi, double gap)" sha256:f61afe30bf87fbb8 *)
(* covers optimized/gauss6/contact/contacts.cpp "ContactStatus generate_contacts(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X_WB," sha256:f7318906decf3db7 *)
(* allowance kBoxPoseRounding = 1e-12 *)
Theorem apart_separation d scale M ahi blo P Q y z : F d -> F P -> F Q ->
  bpow radix2 (-500) <= d -> 0 <= scale -> 0 <= M -> M <= 4 * scale + bpow radix2 (-490) ->
  next_up (fl (ahi + apart d scale)) < blo ->
  P <= ahi + (40 * u * M + 5 * eta) -> blo - (40 * u * M + 5 * eta) <= Q ->
  let t := fl (P - Q) in let t' := fl (Q - P) in
  d < norm_c t y z /\ d < norm_c y t z /\ d < norm_c y z t /\
  d < norm_c t' y z /\ d < norm_c y t' z /\ d < norm_c y z t'.
Proof.
  intros Fd FP FQ Hd Hs HM HMs Hbox HP HQ t t'. pose proof u_small. pose proof eta_pos.
  assert (Hd0 : 0 <= d) by (pose proof (bpow_gt_0 radix2 (-500)); lra).
  pose proof (apart_lower d scale Hd0 Hs) as HA.
  pose proof (next_up_ge (ahi + apart d scale)) as Hup.
  assert (He : 1000 * eta <= bpow radix2 (-602)).
  { unfold eta. apply Rle_trans with (bpow radix2 10 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  (* the exact difference, then the rounded one *)
  assert (Hb : bpow radix2 (-490) <= / 1024 * bpow radix2 (-480))
    by (replace (/ 1024) with (bpow radix2 (-10)) by (simpl; lra); rewrite <- bpow_plus; apply bpow_le; lia).
  assert (HG : (1 - u) * ((1 - u) * (2 * d)) - u * bpow radix2 (-480) <= Q - P).
  { assert (u * M <= u * (4 * scale + bpow radix2 (-490))) by (apply Rmult_le_compat_l; lra).
    assert (0 <= u * scale) by (apply Rmult_le_pos; lra).
    assert (u * bpow radix2 (-490) <= u * (/ 1024 * bpow radix2 (-480))) by (apply Rmult_le_compat_l; lra).
    unfold u in *; lra. }
  assert (Hd480 : u * bpow radix2 (-480) <= / 1000 * d).
  { rewrite bpow_m53.
    rewrite <- bpow_plus. apply Rle_trans with (/ 1000 * bpow radix2 (-500)); [|lra].
    apply Rle_trans with (bpow radix2 (-10) * bpow radix2 (-500)); [rewrite <- bpow_plus; apply bpow_le; lia|].
    apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra]. }
  pose proof (sub_rel P Q FP FQ) as E. fold t in E.
  rewrite (Rabs_left (P - Q)) in E by (unfold u in *; lra). apply abs_bounds in E.
  assert (Ht : (1 + 4 * u) * d <= Rabs t).
  { assert ((1 - u) * ((1 - u) * ((1 - u) * (2 * d)) - u * bpow radix2 (-480)) <= (1 - u) * (Q - P))
      by (apply mul_le_l; lra).
    assert (- t <= Rabs t) by (rewrite <- Rabs_Ropp; apply Rle_abs).
    unfold u in *; lra. }
  assert (Hsq : forall s, Rabs s = Rabs t -> d < fl (sqrt (fl (s * s)))).
  { intros s Hst. apply sqrt_sq_above; [exact Hd | rewrite Hst; exact Ht]. }
  assert (Hn : Rabs (fl (Q - P)) = Rabs t).
  { unfold t. replace (Q - P) with (- (P - Q)) by ring. rewrite fl_opp. apply Rabs_Ropp. }
  pose proof (Hsq t eq_refl) as S1. pose proof (Hsq _ Hn) as S2.
  repeat split; (eapply Rlt_le_trans; [exact S1 | apply norm_ge_any; tauto]) ||
                (eapply Rlt_le_trans; [exact S2 | apply norm_ge_any; tauto]).
Qed.
Print Assumptions apart_separation.

(* The box test either way round: P within its box [alo, ahi] and Q within
   [blo, bhi], each to 40 u M + 5 eta, and the boxes more than `apart` apart
   one way or the other: the computed |P - Q| is above d (apart_separation
   with the roles of the two boxes as the test found them). *)
Lemma apart_either d scale M alo ahi blo bhi P Q y z : F d -> F P -> F Q ->
  bpow radix2 (-500) <= d -> 0 <= scale -> 0 <= M -> M <= 4 * scale + bpow radix2 (-490) ->
  alo - (40 * u * M + 5 * eta) <= P <= ahi + (40 * u * M + 5 * eta) ->
  blo - (40 * u * M + 5 * eta) <= Q <= bhi + (40 * u * M + 5 * eta) ->
  next_up (fl (ahi + apart d scale)) < blo \/ next_up (fl (bhi + apart d scale)) < alo ->
  let w := fl (P - Q) in
  d < norm_c w y z /\ d < norm_c y w z /\ d < norm_c y z w.
Proof.
  intros Fd FP FQ Hd Hs HM HMs HP HQ Hbox w.
  destruct Hbox as [Hbox|Hbox].
  - destruct (apart_separation d scale M ahi blo P Q y z Fd FP FQ Hd Hs HM HMs Hbox ltac:(lra) ltac:(lra))
      as (? & ? & ? & _). tauto.
  - destruct (apart_separation d scale M bhi alo Q P y z Fd FQ FP Hd Hs HM HMs Hbox ltac:(lra) ltac:(lra))
      as (_ & _ & _ & ? & ? & ?). tauto.
Qed.

(* ---- closest_point_on_triangle's branches are closest_coord ---- *)

(* The code's branches, per coordinate (a, b, c the corners' coordinates):
   the corners (regions of a, b, c); a + t ab with t = d1 / (d1 - d3), d1 >=
   0 >= d3 (edge ab: ratio d1 (-d3)); a + t ac with t = d2 / (d2 - d6), d2 >=
   0 >= d6 (edge ac); b + t (c - b) with t = eb / (eb - ec), eb = bc . bp >=
   0 >= ec = bc . cp (edge bc); the interior a + ab v + ac w when
   va, vb, vc >= 0 (interior_weights). The code computes every edge's point
   this way (edge_point, the edge rule, also at the ends: a corner) and keeps
   the nearest of them and the interior's (ClosestPoint.v closest_c). Each is
   closest_coord. *)
(* covers optimized/gauss6/geometry/distance.cpp "Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c)" sha256:fdad0635e55c0607 *)
(* covers optimized/gauss6/geometry/distance.cpp "Vec3 edge_point(const Vec3& s, const Vec3& t, const Vec3& st, double e, double f)" sha256:d2f624d780071625 *)
Theorem closest_branches a b c :
  (forall x y e0 e1, F x -> F y -> 0 <= x -> 0 <= y -> (e0 = a \/ e0 = b \/ e0 = c) -> (e1 = a \/ e1 = b \/ e1 = c) ->
     closest_coord a b c (point_c (ratio x y) e0 e1)) /\
  (forall t e0 e1, 0 <= t <= 1 -> (e0 = a \/ e0 = b \/ e0 = c) -> (e1 = a \/ e1 = b \/ e1 = c) ->
     closest_coord a b c (point_c t e0 e1)) /\
  (forall va vb vc, F va -> F vb -> F vc -> 0 <= va -> 0 <= vb -> 0 <= vc ->
     let S := fl (fl (va + vb) + vc) in S < bpow radix2 1024 ->
     let den := fl (/ S) in closest_coord a b c (interior_c a b c (fl (vb * den)) (fl (vc * den)))).
Proof.
  split; [|split].
  - intros x y e0 e1 Fx Fy Hx Hy H0 H1. right; right; right; left.
    exists (ratio x y), e0, e1. repeat split; try tauto; apply ratio_unit; assumption.
  - intros t e0 e1 Ht H0 H1. right; right; right; left. exists t, e0, e1. tauto.
  - intros va vb vc Fa Fb Fc Ha Hb Hc S HS den.
    destruct (interior_weights va vb vc Fa Fb Fc Ha Hb Hc HS) as (Hv & Hw & Hs).
    right; right; right; right. exists (fl (vb * den)), (fl (vc * den)). tauto.
Qed.
Print Assumptions closest_branches.

Lemma closest_format a b c q : F a -> F b -> F c -> closest_coord a b c q -> F q.
Proof.
  intros Fa Fb Fc [->|[->|[->|[(t & e0 & e1 & _ & _ & _ & ->)|(v & w & _ & _ & _ & ->)]]]]; try assumption.
  - unfold point_c. apply F_fl.
  - unfold interior_c. apply F_fl.
Qed.

(* ---- The feature pairs of feature_pair ---- *)

(* A vertex x (god or obstacle: x's coordinate along the axis) and a face
   whose corners' coordinates a, b, c lie in [lo, hi] (the face's box: their
   min and max), q the coordinate of its computed closest point to x: the box
   test passing along this axis, either way round, makes the computed
   separation |x - q| (its three coordinates' rounded differences, the
   norm's sum in any order) above d. *)
(* covers optimized/gauss6/contact/contacts.cpp "void feature_pair(PairKind kind, int k, int j, int gf, int of, const Vec3 (&X)[3], const Vec3 (&Y)[3]," sha256:c5ac50ba849e9759 *)
Theorem apart_vertex_face d scale M x a b c q lo hi y z : F d -> F x -> F a -> F b -> F c ->
  bpow radix2 (-500) <= d -> 0 <= scale -> M <= 4 * scale + bpow radix2 (-490) ->
  lo <= a <= hi -> lo <= b <= hi -> lo <= c <= hi -> Rabs a <= M -> Rabs b <= M -> Rabs c <= M ->
  closest_coord a b c q ->
  next_up (fl (x + apart d scale)) < lo \/ next_up (fl (hi + apart d scale)) < x ->
  let t := fl (x - q) in
  d < norm_c t y z /\ d < norm_c y t z /\ d < norm_c y z t.
Proof.
  intros Fd Fx Fa Fb Fc Hd Hs HMs Ha Hb Hc Ma Mb Mc Hq Hbox t.
  pose proof u_small. pose proof eta_pos.
  assert (HM : 0 <= M) by (pose proof (Rabs_pos a); lra).
  assert (0 <= u * M) by (apply Rmult_le_pos; lra).
  pose proof (closest_in_box a b c q lo hi M Fa Fb Fc Ha Hb Hc Ma Mb Mc Hq) as Hin.
  pose proof (closest_format a b c q Fa Fb Fc Hq) as Fq.
  exact (apart_either d scale M x x lo hi x q y z Fd Fx Fq Hd Hs HM HMs ltac:(lra) ltac:(lra) Hbox).
Qed.
Print Assumptions apart_vertex_face.

(* Two edges: the god edge's point g0 + s (g1 - g0) and the obstacle edge's
   o0 + t (o1 - o0), s, t in [0, 1] (feature_pair goes on only for 0 < s, t <
   1), computed as the code computes them, each edge's ends in its box; the
   box test passing along this axis either way round: the computed |pg - po|
   is above d. *)
Theorem apart_edge_edge d scale M s g0 g1 t o0 o1 alo ahi blo bhi y z : F d ->
  bpow radix2 (-500) <= d -> 0 <= scale -> M <= 4 * scale + bpow radix2 (-490) ->
  0 <= s <= 1 -> 0 <= t <= 1 ->
  alo <= g0 <= ahi -> alo <= g1 <= ahi -> blo <= o0 <= bhi -> blo <= o1 <= bhi ->
  Rabs g0 <= M -> Rabs g1 <= M -> Rabs o0 <= M -> Rabs o1 <= M ->
  next_up (fl (ahi + apart d scale)) < blo \/ next_up (fl (bhi + apart d scale)) < alo ->
  let w := fl (point_c s g0 g1 - point_c t o0 o1) in
  d < norm_c w y z /\ d < norm_c y w z /\ d < norm_c y z w.
Proof.
  intros Fd Hd Hs HMs Hs01 Ht01 Hg0 Hg1 Ho0 Ho1 Mg0 Mg1 Mo0 Mo1 Hbox w.
  pose proof u_small. pose proof eta_pos.
  assert (HM : 0 <= M) by (pose proof (Rabs_pos g0); lra).
  assert (0 <= u * M) by (apply Rmult_le_pos; lra).
  pose proof (edge_in_box s g0 g1 alo ahi M Hs01 Hg0 Hg1 Mg0 Mg1) as HP.
  pose proof (edge_in_box t o0 o1 blo bhi M Ht01 Ho0 Ho1 Mo0 Mo1) as HQ.
  assert (FP : F (point_c s g0 g1)) by apply F_fl. assert (FQ : F (point_c t o0 o1)) by apply F_fl.
  exact (apart_either d scale M alo ahi blo bhi _ _ y z Fd FP FQ Hd Hs HM HMs ltac:(lra) ltac:(lra) Hbox).
Qed.
Print Assumptions apart_edge_edge.
