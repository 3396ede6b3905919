(* kBoxPoseRounding at generate_contacts' `tie` (contact/contacts.cpp,
   generate_contacts' `tie`; held_beside's `reach`): the vertex/face rule
   leaves a face's row out when a face g that shares the edge (or corner) the
   vertex p lies beyond holds p, g's computed separation at most the face's
   plus `tie`. Two faces whose exact closest points of p are one point of
   their shared edge must then compute separations within `tie` of each
   other. geometry/distance.cpp closest_point_on_triangle decides and computes
   each corner and edge branch from the dot products of that edge's own ends,
   e = (b - a) . (p - a) and f = (b - a) . (p - b) for the edge from a to b:
   the start a when e <= 0, the end b when f >= 0, a + (e / (e - f)) (b - a)
   when e >= 0 >= f (the edge rule, `edge_rule`). These theorems prove that
   the point the edge rule returns, whichever face and whichever direction of
   the edge, is within 200 u M + 2^-533 (Euclidean) of the exact closest point
   of the segment to p, and so that two such separations are within `tie`.
   The premise that each face takes that edge's branch or its ends' (the
   region tests' selection) is not needed since closest_point_on_triangle
   keeps the nearest of the three edges' points: ClosestPoint.v tie_closest. The
   model's x / 0 = 0 where IEEE gives NaN: e = f = 0 computed (a degenerate
   edge, whose face generate_contacts drops) is outside the statements.
   Same model as Rounding.v (binary64, round to nearest, gradual underflow,
   finite results, no fused multiply-add); u = 2^-53, eta = 2^-1075. *)

From Coq Require Import Reals Psatz List.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances BoxPose ContactApart StopPose.
Open Scope R_scope.

(* ---- The exact closest point of a segment ---- *)

(* The parameter of the exact closest point of the segment from A to B to P,
   X / (X + Y) clamped to [0, 1], X = (B - A) . (P - A), Y = (B - A) . (B - P),
   X + Y = |B - A|^2. *)
Definition clamp01 z := Rmax 0 (Rmin 1 z).

Lemma clamp01_unit z : 0 <= clamp01 z <= 1.
Proof. unfold clamp01, Rmax, Rmin; repeat destruct Rle_dec; lra. Qed.

(* Clamping moves no point of [0, 1] farther from z. *)
Lemma clamp01_near r z : 0 <= r <= 1 -> Rabs (r - clamp01 z) <= Rabs (r - z).
Proof. intros. unfold clamp01, Rmax, Rmin, Rabs; repeat destruct Rle_dec; repeat destruct Rcase_abs; lra. Qed.

Lemma clamp01_flip z : clamp01 (1 - z) = 1 - clamp01 z.
Proof. unfold clamp01, Rmax, Rmin; repeat destruct Rle_dec; lra. Qed.

(* ---- The parameter's error ---- *)

(* x, y the computed e and -f of the edge rule (doubles), X, Y the exact
   ones, N = X + Y = l^2 the squared length (l >= 0), each computed within
   A l + eta' of the exact; T^2 >= 8 eta'. The parameter t the rule takes
   (0 when x <= 0, 1 when y <= 0, fl(x / fl(x + y)) when x, y >= 0) is within
   (8 A + T + 4 u l) / l of the exact clamped one: |t - tau| l <= 8 A + T + 4 u l.
   Where l is at most 8 A + T, |t - tau| <= 1 suffices; otherwise N >= 4 (A l +
   eta'), the computed x + y >= N / 2, and x / (x + y) is within 3 (A l + eta') / N
   of X / N. *)
Lemma rule_param x y X Y l A e T t :
  F x -> F y -> 0 <= l -> 0 <= A -> 0 <= e -> 0 <= T -> 8 * e <= T * T -> X + Y = l * l ->
  Rabs (x - X) <= A * l + e -> Rabs (y - Y) <= A * l + e ->
  (x <= 0 /\ t = 0) \/ (y <= 0 /\ t = 1) \/ (0 <= x /\ 0 <= y /\ t = ratio x y) ->
  Rabs (t - clamp01 (X / (X + Y))) * l <= 8 * A + T + 4 * u * l.
Proof.
  intros Fx Fy Hl HA He HT HTe HN Hx Hy Ht. pose proof u_small as Hu. pose proof eta_pos.
  assert (Ht01 : 0 <= t <= 1).
  { destruct Ht as [[_ ->]|[[_ ->]|(H1 & H2 & ->)]]; [lra|lra|apply ratio_unit; assumption]. }
  pose proof (clamp01_unit (X / (X + Y))) as Hc.
  assert (H1 : Rabs (t - clamp01 (X / (X + Y))) <= 1) by (apply Rabs_le; lra).
  pose proof (Rabs_pos (t - clamp01 (X / (X + Y)))).
  assert (0 <= u * l) by nra.
  destruct (Rle_lt_dec l (8 * A + T)) as [Hsmall|Hbig].
  - assert (Rabs (t - clamp01 (X / (X + Y))) * l <= 1 * l) by (apply Rmult_le_compat_r; lra). lra.
  - set (E := A * l + e) in *. set (N := X + Y) in *.
    assert (Hl0 : 0 < l) by lra.
    assert (HlT : T < l) by lra. assert (HlA : 8 * A <= l) by lra.
    assert (HE : 4 * E <= N).
    { unfold E. rewrite HN.
      assert (8 * A * l <= l * l) by (apply Rmult_le_compat_r; lra).
      assert (T * T <= l * l) by (apply Rmult_le_compat; lra). lra. }
    assert (HN0 : 0 < N) by (rewrite HN; nra).
    assert (HE0 : 0 <= E) by (unfold E; nra).
    (* E / N * l <= A / 4 + T / 8... bounded through E l / N <= E / l *)
    assert (HEl : E * l <= (A + T / 8) * N).
    { rewrite HN. unfold E.
      assert (e * l <= T / 8 * (l * l)).
      { assert (e <= T * T / 8) by lra.
        assert (e * l <= T * T / 8 * l) by (apply Rmult_le_compat_r; lra).
        assert (T * T / 8 * l <= T / 8 * (l * l)) by (assert (T * T <= T * l) by (apply Rmult_le_compat_l; lra); nra).
        lra. }
      nra. }
    (* the distance of a parameter r from X / N, times N, bounds |r - tau| N *)
    assert (Hcl : forall r, 0 <= r <= 1 -> Rabs (r - clamp01 (X / N)) * l <= Rabs (r - X / N) * l)
      by (intros r Hr; apply Rmult_le_compat_r; [lra | apply clamp01_near; exact Hr]).
    destruct Ht as [[Hx0 ->]|[[Hy0 ->]|(Hx0 & Hy0 & ->)]].
    + (* the start: X <= E, tau <= E / N *)
      assert (HX : X <= E) by (apply Rabs_le_inv in Hx; lra).
      assert (Hc' : clamp01 (X / N) <= Rmax 0 (E / N)).
      { unfold clamp01. apply Rle_max_compat_l. apply Rle_trans with (X / N); [apply Rmin_r|].
        unfold Rdiv. apply Rmult_le_compat_r; [left; apply Rinv_0_lt_compat; lra | exact HX]. }
      assert (0 <= E / N) by (apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]).
      rewrite Rmax_right in Hc' by lra. fold N.
      rewrite Rabs_minus_sym, Rminus_0_r, Rabs_pos_eq by (pose proof (clamp01_unit (X / N)); lra).
      assert (clamp01 (X / N) * l <= E / N * l) by (apply Rmult_le_compat_r; lra).
      assert (E / N * l <= A + T / 8).
      { apply Rmult_le_reg_r with N; [lra|]. unfold Rdiv.
        replace (E * / N * l * N) with (E * l) by (field; lra). lra. }
      lra.
    + (* the end: Y <= E, tau >= 1 - E / N *)
      assert (HY : Y <= E) by (apply Rabs_le_inv in Hy; lra).
      assert (HXN : X / N = 1 - Y / N) by (unfold N in *; field; lra).
      fold N. rewrite HXN, clamp01_flip.
      replace (1 - (1 - clamp01 (Y / N))) with (clamp01 (Y / N)) by ring.
      assert (Hc' : clamp01 (Y / N) <= Rmax 0 (E / N)).
      { unfold clamp01. apply Rle_max_compat_l. apply Rle_trans with (Y / N); [apply Rmin_r|].
        unfold Rdiv. apply Rmult_le_compat_r; [left; apply Rinv_0_lt_compat; lra | exact HY]. }
      assert (0 <= E / N) by (apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]).
      rewrite Rmax_right in Hc' by lra.
      rewrite Rabs_pos_eq by (pose proof (clamp01_unit (Y / N)); lra).
      assert (clamp01 (Y / N) * l <= E / N * l) by (apply Rmult_le_compat_r; lra).
      assert (E / N * l <= A + T / 8).
      { apply Rmult_le_reg_r with N; [lra|]. unfold Rdiv.
        replace (E * / N * l * N) with (E * l) by (field; lra). lra. }
      lra.
    + (* the interior of the edge *)
      set (D := x + y).
      assert (HXl : - E <= X) by (apply Rabs_le_inv in Hx; lra).
      assert (HYl : - E <= Y) by (apply Rabs_le_inv in Hy; lra).
      assert (HD : N - 2 * E <= D) by (apply Rabs_le_inv in Hx; apply Rabs_le_inv in Hy; unfold D, N; lra).
      assert (HD0 : 0 < D) by lra.
      set (r := x / D).
      assert (Hr : 0 <= r <= 1).
      { unfold r. split; [apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]|].
        apply Rmult_le_reg_r with D; [lra|]. unfold Rdiv. rewrite Rmult_assoc, Rinv_l, Rmult_1_r by lra.
        unfold D; lra. }
      (* |r - X / N| <= 2 E / N *)
      assert (Hnum : Rabs (x * Y - X * y) <= E * (N + 2 * E)).
      { replace (x * Y - X * y) with ((x - X) * Y - X * (y - Y)) by ring.
        eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_Ropp, !Rabs_mult.
        assert (HXY : Rabs X + Rabs Y <= N + 2 * E) by (unfold N in *; unfold Rabs; repeat destruct Rcase_abs; lra).
        pose proof (Rabs_pos X). pose proof (Rabs_pos Y). pose proof (Rabs_pos (x - X)). pose proof (Rabs_pos (y - Y)).
        assert (Rabs (x - X) * Rabs Y <= E * Rabs Y) by (apply Rmult_le_compat_r; lra).
        assert (Rabs X * Rabs (y - Y) <= Rabs X * E) by (apply Rmult_le_compat_l; lra).
        nra. }
      assert (Hdiff : Rabs (r - X / N) <= 3 * E / N).
      { assert (Eq : r - X / N = (x * Y - X * y) / (D * N)) by (unfold r, D, N in *; field; split; lra).
        rewrite Eq. unfold Rdiv. rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq (D * N)) by nra.
        apply Rmult_le_reg_r with (D * N); [nra|].
        replace (Rabs (x * Y - X * y) * / (D * N) * (D * N)) with (Rabs (x * Y - X * y)) by (field; split; lra).
        replace (3 * E * / N * (D * N)) with (3 * E * D) by (field; lra).
        assert (E * (N + 2 * E) <= E * (3 * D)) by (apply Rmult_le_compat_l; lra). lra. }
      (* the rounding of x / fl(x + y): within 2.02 u + eta of r *)
      assert (Hs : Rabs (fl (x + y) - D) <= u * D) by (unfold D; pose proof (add_rel x y Fx Fy) as G; rewrite (Rabs_pos_eq (x + y)) in G by lra; exact G).
      apply Rabs_le_inv in Hs.
      set (s := fl (x + y)) in *.
      assert (Hs0 : 0 < s) by nra.
      assert (Hq : Rabs (x / s - r) <= 102 / 100 * u).
      { assert (Eq : x / s - r = r * ((D - s) / s)) by (unfold r; field; split; lra).
        rewrite Eq, Rabs_mult, (Rabs_pos_eq r) by lra. unfold Rdiv. rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq s) by lra.
        assert (Rabs (D - s) <= u * D) by (apply Rabs_le; lra).
        assert (Hk : Rabs (D - s) * / s <= 102 / 100 * u).
        { apply Rmult_le_reg_r with s; [lra|]. rewrite Rmult_assoc, Rinv_l, Rmult_1_r by lra.
          assert (u * D <= / 1000000 * D) by (apply Rmult_le_compat_r; lra).
          assert (D <= 101 / 100 * s) by lra. nra. }
        pose proof (Rabs_pos (D - s)). assert (0 <= / s) by (left; apply Rinv_0_lt_compat; lra).
        assert (0 <= Rabs (D - s) * / s) by nra.
        assert (r * (Rabs (D - s) * / s) <= 1 * (Rabs (D - s) * / s)) by (apply Rmult_le_compat_r; lra). lra. }
      assert (Hf : Rabs (ratio x y - x / s) <= u * (102 / 100) + eta).
      { unfold ratio. fold s. eapply Rle_trans; [apply fl_err|].
        assert (Rabs (x / s) <= 102 / 100) by (apply Rabs_le_inv in Hq; apply Rabs_le; lra).
        assert (u * Rabs (x / s) <= u * (102 / 100)) by (apply Rmult_le_compat_l; lra). lra. }
      assert (Hrt : Rabs (ratio x y - r) <= 205 / 100 * u)
        by (apply Rle_trans with (Rabs (ratio x y - x / s) + Rabs (x / s - r));
            [replace (ratio x y - r) with ((ratio x y - x / s) + (x / s - r)) by ring; apply Rabs_triang
            | assert (eta <= / 1000 * u) by (pose proof (eta_rel 1 ltac:(apply Rle_trans with (bpow radix2 0); [apply bpow_le; lia | simpl; lra])); lra); lra]).
      fold N.
      assert (Htri : Rabs (ratio x y - clamp01 (X / N)) <= Rabs (ratio x y - r) + Rabs (r - clamp01 (X / N)))
        by (replace (ratio x y - clamp01 (X / N)) with ((ratio x y - r) + (r - clamp01 (X / N))) by ring; apply Rabs_triang).
      pose proof (clamp01_near r (X / N) Hr).
      assert (Hm : 3 * E / N * l <= 3 * (A + T / 8)).
      { apply Rmult_le_reg_r with N; [lra|]. unfold Rdiv.
        replace (3 * E * / N * l * N) with (3 * (E * l)) by (field; lra). nra. }
      assert (Rabs (ratio x y - clamp01 (X / N)) * l <= (205 / 100 * u + 3 * E / N) * l)
        by (apply Rmult_le_compat_r; lra).
      nra.
Qed.

(* ---- The edge's dot products ---- *)

(* One product of two rounded differences: e within u |E| of E, w within u |W|
   of W, |W| <= L. *)
Lemma prod_rel e E w W L : Rabs (e - E) <= u * Rabs E -> Rabs (w - W) <= u * Rabs W -> Rabs W <= L ->
  Rabs (e * w) <= 101 / 100 * (L * Rabs E) /\ Rabs (e * w - E * W) <= 21 / 10 * u * (L * Rabs E).
Proof.
  intros He Hw HL. pose proof u_small. pose proof (Rabs_pos E). pose proof (Rabs_pos W).
  assert (He' : Rabs e <= (1 + u) * Rabs E)
    by (replace e with (E + (e - E)) by ring; eapply Rle_trans; [apply Rabs_triang | lra]).
  assert (Hw' : Rabs w <= (1 + u) * L)
    by (replace w with (W + (w - W)) by ring; eapply Rle_trans; [apply Rabs_triang | nra]).
  pose proof (Rabs_pos e). pose proof (Rabs_pos w).
  assert (0 <= L) by lra. assert (0 <= L * Rabs E) by nra.
  split.
  - rewrite Rabs_mult. apply Rle_trans with (((1 + u) * Rabs E) * ((1 + u) * L)); [apply Rmult_le_compat; lra|].
    assert (0 <= u * (L * Rabs E)) by nra. assert (u * (u * (L * Rabs E)) <= / 1000000 * (u * (L * Rabs E))) by (apply Rmult_le_compat_r; lra).
    assert (u * (L * Rabs E) <= / 1000000 * (L * Rabs E)) by (apply Rmult_le_compat_r; lra).
    replace ((1 + u) * Rabs E * ((1 + u) * L)) with (L * Rabs E + 2 * (u * (L * Rabs E)) + u * (u * (L * Rabs E))) by ring.
    lra.
  - replace (e * w - E * W) with ((e - E) * w + E * (w - W)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult.
    assert (Rabs (e - E) * Rabs w <= (u * Rabs E) * ((1 + u) * L)) by (apply Rmult_le_compat; try apply Rabs_pos; lra).
    assert (Rabs E * Rabs (w - W) <= Rabs E * (u * L)) by (apply Rmult_le_compat_l; nra).
    assert (0 <= u * (L * Rabs E)) by nra. assert (u * (u * (L * Rabs E)) <= / 1000000 * (u * (L * Rabs E))) by (apply Rmult_le_compat_r; lra).
    replace (u * Rabs E * ((1 + u) * L)) with (u * (L * Rabs E) + u * (u * (L * Rabs E))) by ring.
    replace (Rabs E * (u * L)) with (u * (L * Rabs E)) in * by ring.
    lra.
Qed.

(* The computed dot product of the rounded differences b - a and p - c (c = a
   or b: the edge's e and f), Eigen's sum of three rounded products (any
   order: Allowances.v dot3_err is symmetric), within 5.2 u L s1 + 5.02 eta of
   the exact one, s1 = |b - a|_1, L >= each |p_i - c_i|. *)
Lemma diff_dot a0 a1 a2 b0 b1 b2 p0 p1 p2 c0 c1 c2 L :
  F a0 -> F a1 -> F a2 -> F b0 -> F b1 -> F b2 -> F p0 -> F p1 -> F p2 -> F c0 -> F c1 -> F c2 ->
  Rabs (p0 - c0) <= L -> Rabs (p1 - c1) <= L -> Rabs (p2 - c2) <= L ->
  Rabs (dot3 (fl (b0 - a0)) (fl (b1 - a1)) (fl (b2 - a2)) (fl (p0 - c0)) (fl (p1 - c1)) (fl (p2 - c2))
        - ((b0 - a0) * (p0 - c0) + (b1 - a1) * (p1 - c1) + (b2 - a2) * (p2 - c2)))
  <= 52 / 10 * u * (L * (Rabs (b0 - a0) + Rabs (b1 - a1) + Rabs (b2 - a2))) + 502 / 100 * eta.
Proof.
  intros Fa0 Fa1 Fa2 Fb0 Fb1 Fb2 Fp0 Fp1 Fp2 Fc0 Fc1 Fc2 H0 H1 H2. pose proof u_small.
  destruct (prod_rel (fl (b0 - a0)) (b0 - a0) (fl (p0 - c0)) (p0 - c0) L (sub_rel _ _ Fb0 Fa0) (sub_rel _ _ Fp0 Fc0) H0) as [P0 Q0].
  destruct (prod_rel (fl (b1 - a1)) (b1 - a1) (fl (p1 - c1)) (p1 - c1) L (sub_rel _ _ Fb1 Fa1) (sub_rel _ _ Fp1 Fc1) H1) as [P1 Q1].
  destruct (prod_rel (fl (b2 - a2)) (b2 - a2) (fl (p2 - c2)) (p2 - c2) L (sub_rel _ _ Fb2 Fa2) (sub_rel _ _ Fp2 Fc2) H2) as [P2 Q2].
  pose proof (dot3_err (fl (b0 - a0)) (fl (b1 - a1)) (fl (b2 - a2)) (fl (p0 - c0)) (fl (p1 - c1)) (fl (p2 - c2))) as D.
  cbv zeta in D.
  set (S := L * (Rabs (b0 - a0) + Rabs (b1 - a1) + Rabs (b2 - a2))).
  assert (HT : Rabs (fl (b0 - a0) * fl (p0 - c0)) + Rabs (fl (b1 - a1) * fl (p1 - c1)) + Rabs (fl (b2 - a2) * fl (p2 - c2)) <= 101 / 100 * S)
    by (unfold S; lra).
  assert (u * (Rabs (fl (b0 - a0) * fl (p0 - c0)) + Rabs (fl (b1 - a1) * fl (p1 - c1)) + Rabs (fl (b2 - a2) * fl (p2 - c2))) <= u * (101 / 100 * S))
    by (apply Rmult_le_compat_l; lra).
  set (d := dot3 _ _ _ _ _ _) in *.
  replace (d - ((b0 - a0) * (p0 - c0) + (b1 - a1) * (p1 - c1) + (b2 - a2) * (p2 - c2)))
    with ((d - (fl (b0 - a0) * fl (p0 - c0) + fl (b1 - a1) * fl (p1 - c1) + fl (b2 - a2) * fl (p2 - c2)))
          + ((fl (b0 - a0) * fl (p0 - c0) - (b0 - a0) * (p0 - c0)) + (fl (b1 - a1) * fl (p1 - c1) - (b1 - a1) * (p1 - c1))
             + (fl (b2 - a2) * fl (p2 - c2) - (b2 - a2) * (p2 - c2)))) by ring.
  eapply Rle_trans; [apply Rabs_triang|].
  assert (Rabs ((fl (b0 - a0) * fl (p0 - c0) - (b0 - a0) * (p0 - c0)) + (fl (b1 - a1) * fl (p1 - c1) - (b1 - a1) * (p1 - c1))
             + (fl (b2 - a2) * fl (p2 - c2) - (b2 - a2) * (p2 - c2))) <= 21 / 10 * u * S).
  { eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    unfold S. lra. }
  assert (0 <= S) by (unfold S; pose proof (Rabs_pos (p0 - c0)); pose proof (Rabs_pos (b0 - a0));
                      pose proof (Rabs_pos (b1 - a1)); pose proof (Rabs_pos (b2 - a2)); nra).
  assert (0 <= u * S) by nra.
  lra.
Qed.

(* ---- The edge rule's point ---- *)

(* The nine inputs' facts, from the list hypothesis of the theorems below. *)
Lemma nine (P : R -> Prop) a0 a1 a2 b0 b1 b2 p0 p1 p2 :
  (forall v, In v [a0; a1; a2; b0; b1; b2; p0; p1; p2] -> P v) ->
  P a0 /\ P a1 /\ P a2 /\ P b0 /\ P b1 /\ P b2 /\ P p0 /\ P p1 /\ P p2.
Proof. intros H. repeat split; apply H; simpl; tauto. Qed.

Lemma abs_diff2 x y M : Rabs x <= M -> Rabs y <= M -> Rabs (x - y) <= 2 * M.
Proof. intros. replace (2 * M) with (M + M) by ring. apply abs_diff_le; assumption. Qed.

Lemma norm3_scale k x y z : norm3 (k * x) (k * y) (k * z) = Rabs k * norm3 x y z.
Proof.
  unfold norm3.
  replace (k * x * (k * x) + k * y * (k * y) + k * z * (k * z)) with ((k * k) * (x * x + y * y + z * z)) by ring.
  rewrite sqrt_mult_alt by apply Rle_0_sqr. change (k * k) with (Rsqr k). rewrite sqrt_Rsqr_abs. reflexivity.
Qed.

Lemma norm3_coords x y z c : Rabs x <= c -> Rabs y <= c -> Rabs z <= c -> norm3 x y z <= 2 * c.
Proof.
  intros Hx Hy Hz. pose proof (Rabs_pos x). unfold norm3.
  rewrite <- (sqrt_square (2 * c)) by lra. apply sqrt_le_1_alt.
  rewrite <- (abs_sq x), <- (abs_sq y), <- (abs_sq z).
  pose proof (Rabs_pos y). pose proof (Rabs_pos z). nra.
Qed.

(* The edge from a to b and the point p (doubles): e = (b - a) . (p - a) and
   -f = -((b - a) . (p - b)) as closest_point_on_triangle computes them
   (d1, -d3 for ab; d2, -d6 for ac; eb, -ec for bc). *)
Definition edge_e a0 a1 a2 b0 b1 b2 p0 p1 p2 :=
  dot3 (fl (b0 - a0)) (fl (b1 - a1)) (fl (b2 - a2)) (fl (p0 - a0)) (fl (p1 - a1)) (fl (p2 - a2)).
Definition edge_f a0 a1 a2 b0 b1 b2 p0 p1 p2 :=
  - dot3 (fl (b0 - a0)) (fl (b1 - a1)) (fl (b2 - a2)) (fl (p0 - b0)) (fl (p1 - b1)) (fl (p2 - b2)).

(* The point the edge rule returns: a when x <= 0, b when y <= 0, a + t (b -
   a) at t = fl(x / fl(x + y)) computed as the code computes it (Allowances.v
   point_c, per coordinate) when x, y >= 0. The corner branches are this rule
   for both edges at their corner: a for d1 <= 0 (ab) and d2 <= 0 (ac), b for
   d3 >= 0 (ab) and eb <= 0 (bc), c for d6 >= 0 (ac) and ec >= 0 (bc). *)
Definition edge_rule x y a0 a1 a2 b0 b1 b2 q0 q1 q2 : Prop :=
  (x <= 0 /\ q0 = a0 /\ q1 = a1 /\ q2 = a2) \/ (y <= 0 /\ q0 = b0 /\ q1 = b1 /\ q2 = b2) \/
  (0 <= x /\ 0 <= y /\ q0 = point_c (ratio x y) a0 b0 /\ q1 = point_c (ratio x y) a1 b1 /\
   q2 = point_c (ratio x y) a2 b2).

(* The exact closest point of the segment from a to b to p is a + tau (b - a). *)
Definition seg_tau a0 a1 a2 b0 b1 b2 p0 p1 p2 :=
  clamp01 (((b0 - a0) * (p0 - a0) + (b1 - a1) * (p1 - a1) + (b2 - a2) * (p2 - a2)) /
           ((b0 - a0) * (b0 - a0) + (b1 - a1) * (b1 - a1) + (b2 - a2) * (b2 - a2))).

Lemma T534 : 8 * (502 / 100 * eta) <= bpow radix2 (-534) * bpow radix2 (-534).
Proof.
  rewrite <- bpow_plus. replace (-534 + -534)%Z with (7 + -1075)%Z by lia. rewrite bpow_plus.
  unfold eta. pose proof (bpow_gt_0 radix2 (-1075)). simpl (bpow radix2 7). lra.
Qed.

(* covers optimized/gauss6/geometry/distance.cpp "Vec3 edge_point(const Vec3& s, const Vec3& t, const Vec3& st, double e, double f)" sha256:d2f624d780071625 *)
(* covers optimized/gauss6/geometry/distance.cpp "Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b)" sha256:d103371e3f2661db *)
Theorem edge_rule_point a0 a1 a2 b0 b1 b2 p0 p1 p2 q0 q1 q2 M :
  (forall v, In v [a0; a1; a2; b0; b1; b2; p0; p1; p2] -> F v) ->
  (forall v, In v [a0; a1; a2; b0; b1; b2; p0; p1; p2] -> Rabs v <= M) ->
  edge_rule (edge_e a0 a1 a2 b0 b1 b2 p0 p1 p2) (edge_f a0 a1 a2 b0 b1 b2 p0 p1 p2) a0 a1 a2 b0 b1 b2 q0 q1 q2 ->
  let t := seg_tau a0 a1 a2 b0 b1 b2 p0 p1 p2 in
  norm3 (q0 - (a0 + t * (b0 - a0))) (q1 - (a1 + t * (b1 - a1))) (q2 - (a2 + t * (b2 - a2)))
  <= 200 * u * M + bpow radix2 (-533).
Proof.
  intros HF HM Hr t. pose proof u_small. pose proof eta_pos.
  destruct (nine F _ _ _ _ _ _ _ _ _ HF) as (Fa0 & Fa1 & Fa2 & Fb0 & Fb1 & Fb2 & Fp0 & Fp1 & Fp2).
  destruct (nine (fun v => Rabs v <= M) _ _ _ _ _ _ _ _ _ HM) as (Ma0 & Ma1 & Ma2 & Mb0 & Mb1 & Mb2 & Mp0 & Mp1 & Mp2).
  assert (HM0 : 0 <= M) by (pose proof (Rabs_pos a0); lra).
  assert (0 <= u * M) by nra.
  set (E0 := b0 - a0) in *. set (E1 := b1 - a1) in *. set (E2 := b2 - a2) in *.
  set (N := E0 * E0 + E1 * E1 + E2 * E2).
  assert (HN0 : 0 <= N) by (unfold N; apply sq_nonneg3).
  set (l := sqrt N).
  assert (Hll : l * l = N) by (apply sqrt_sqrt; exact HN0).
  assert (Hl0 : 0 <= l) by apply sqrt_pos.
  assert (HE0 : Rabs E0 <= 2 * M) by (apply abs_diff2; assumption).
  assert (HE1 : Rabs E1 <= 2 * M) by (apply abs_diff2; assumption).
  assert (HE2 : Rabs E2 <= 2 * M) by (apply abs_diff2; assumption).
  assert (Hl4 : l <= 4 * M) by (unfold l, N; replace (4 * M) with (2 * (2 * M)) by ring; apply norm3_coords; assumption).
  set (s1 := Rabs E0 + Rabs E1 + Rabs E2).
  assert (Hs1 : s1 <= 2 * l).
  { pose proof (Rabs_pos E0). pose proof (Rabs_pos E1). pose proof (Rabs_pos E2).
    assert (s1 * s1 <= 3 * N).
    { unfold s1, N. rewrite <- (abs_sq E0), <- (abs_sq E1), <- (abs_sq E2).
      pose proof (Rle_0_sqr (Rabs E0 - Rabs E1)). pose proof (Rle_0_sqr (Rabs E1 - Rabs E2)).
      pose proof (Rle_0_sqr (Rabs E0 - Rabs E2)). unfold Rsqr in *. nra. }
    assert (0 <= s1) by (unfold s1; lra). nra. }
  assert (0 <= u * M * l) by nra.
  assert (Hsl : 52 / 10 * u * (2 * M * s1) <= 208 / 10 * u * M * l).
  { assert (u * M * s1 <= u * M * (2 * l)) by (apply Rmult_le_compat_l; lra). nra. }
  (* the computed e and -f within 20.8 u M l + 5.02 eta *)
  set (X := E0 * (p0 - a0) + E1 * (p1 - a1) + E2 * (p2 - a2)).
  set (Y := - (E0 * (p0 - b0) + E1 * (p1 - b1) + E2 * (p2 - b2))).
  assert (HXY : X + Y = l * l) by (rewrite Hll; unfold X, Y, N, E0, E1, E2; ring).
  assert (Hx : Rabs (edge_e a0 a1 a2 b0 b1 b2 p0 p1 p2 - X) <= 208 / 10 * u * M * l + 502 / 100 * eta).
  { pose proof (diff_dot a0 a1 a2 b0 b1 b2 p0 p1 p2 a0 a1 a2 (2 * M) Fa0 Fa1 Fa2 Fb0 Fb1 Fb2 Fp0 Fp1 Fp2 Fa0 Fa1 Fa2
      ltac:(apply abs_diff2; assumption) ltac:(apply abs_diff2; assumption) ltac:(apply abs_diff2; assumption)) as G.
    unfold edge_e. fold E0 E1 E2 s1 in G |- *. fold X in G |- *. lra. }
  assert (Hy : Rabs (edge_f a0 a1 a2 b0 b1 b2 p0 p1 p2 - Y) <= 208 / 10 * u * M * l + 502 / 100 * eta).
  { pose proof (diff_dot a0 a1 a2 b0 b1 b2 p0 p1 p2 b0 b1 b2 (2 * M) Fa0 Fa1 Fa2 Fb0 Fb1 Fb2 Fp0 Fp1 Fp2 Fb0 Fb1 Fb2
      ltac:(apply abs_diff2; assumption) ltac:(apply abs_diff2; assumption) ltac:(apply abs_diff2; assumption)) as G.
    unfold edge_f. fold E0 E1 E2 s1 in G |- *. unfold Y.
    replace (- dot3 (fl E0) (fl E1) (fl E2) (fl (p0 - b0)) (fl (p1 - b1)) (fl (p2 - b2)) - - (E0 * (p0 - b0) + E1 * (p1 - b1) + E2 * (p2 - b2)))
      with (- (dot3 (fl E0) (fl E1) (fl E2) (fl (p0 - b0)) (fl (p1 - b1)) (fl (p2 - b2)) - (E0 * (p0 - b0) + E1 * (p1 - b1) + E2 * (p2 - b2)))) by ring.
    rewrite Rabs_Ropp. lra. }
  assert (Ht : t = clamp01 (X / (X + Y))) by (unfold t, seg_tau; rewrite HXY, Hll; reflexivity).
  set (x := edge_e a0 a1 a2 b0 b1 b2 p0 p1 p2) in *. set (y := edge_f a0 a1 a2 b0 b1 b2 p0 p1 p2) in *.
  assert (Fx : F x) by (unfold x, edge_e, dot3; apply F_fl).
  assert (Fy : F y) by (unfold y, edge_f, dot3; apply F_opp, F_fl).
  assert (HA : 0 <= 208 / 10 * u * M) by nra.
  (* the rule's parameter c and its point's rounding *)
  assert (Hc : exists c, ((x <= 0 /\ c = 0) \/ (y <= 0 /\ c = 1) \/ (0 <= x /\ 0 <= y /\ c = ratio x y)) /\
                         norm3 (q0 - (a0 + c * E0)) (q1 - (a1 + c * E1)) (q2 - (a2 + c * E2)) <= 14 * u * M + 10 * eta).
  { destruct Hr as [(Hr0 & -> & -> & ->)|[(Hr0 & -> & -> & ->)|(Hr0 & Hr1 & -> & -> & ->)]].
    - exists 0. split; [tauto|]. apply Rle_trans with (2 * 0); [apply norm3_coords; rewrite Rmult_0_l, Rplus_0_r, Rminus_diag_eq, Rabs_R0 by reflexivity; lra | lra].
    - exists 1. split; [tauto|]. apply Rle_trans with (2 * 0); [apply norm3_coords; unfold E0, E1, E2; replace (a0 + 1 * (b0 - a0)) with b0 by ring;
        replace (a1 + 1 * (b1 - a1)) with b1 by ring; replace (a2 + 1 * (b2 - a2)) with b2 by ring; rewrite !Rminus_diag_eq, Rabs_R0 by reflexivity; lra | lra].
    - exists (ratio x y). split; [tauto|].
      pose proof (ratio_unit x y Fx Fy Hr0 Hr1) as Hu01.
      destruct (point_err (ratio x y) a0 b0 M Hu01 Ma0 Mb0) as [_ P0].
      destruct (point_err (ratio x y) a1 b1 M Hu01 Ma1 Mb1) as [_ P1].
      destruct (point_err (ratio x y) a2 b2 M Hu01 Ma2 Mb2) as [_ P2].
      unfold point_x in P0, P1, P2. replace (14 * u * M + 10 * eta) with (2 * (7 * u * M + 5 * eta)) by ring.
      apply norm3_coords; assumption. }
  destruct Hc as (c & Hcr & Hcn).
  pose proof (rule_param x y X Y l (208 / 10 * u * M) (502 / 100 * eta) (bpow radix2 (-534)) c Fx Fy Hl0 HA
                ltac:(lra) ltac:(apply bpow_ge_0) T534 HXY Hx Hy Hcr) as Hp.
  rewrite <- Ht in Hp.
  pose proof (norm3_triangle (q0 - (a0 + c * E0)) (q1 - (a1 + c * E1)) (q2 - (a2 + c * E2))
                ((c - t) * E0) ((c - t) * E1) ((c - t) * E2)) as Tri.
  assert (Hnl : norm3 E0 E1 E2 = l) by reflexivity.
  rewrite norm3_scale, Hnl in Tri.
  replace (q0 - (a0 + c * E0) + (c - t) * E0) with (q0 - (a0 + t * E0)) in Tri by ring.
  replace (q1 - (a1 + c * E1) + (c - t) * E1) with (q1 - (a1 + t * E1)) in Tri by ring.
  replace (q2 - (a2 + c * E2) + (c - t) * E2) with (q2 - (a2 + t * E2)) in Tri by ring.
  assert (Hb : bpow radix2 (-534) + 10 * eta <= bpow radix2 (-533)).
  { unfold eta. replace (-533)%Z with (1 + -534)%Z by lia. rewrite (bpow_plus _ 1).
    assert (bpow radix2 (-1075) <= / 1024 * bpow radix2 (-534)).
    { replace (/ 1024) with (bpow radix2 (-10)) by (simpl; lra). rewrite <- bpow_plus. apply bpow_le. lia. }
    pose proof (bpow_gt_0 radix2 (-534)). simpl (bpow radix2 1). lra. }
  assert (u * l <= u * (4 * M)) by (apply Rmult_le_compat_l; lra).
  lra.
Qed.
Print Assumptions edge_rule_point.

(* ---- The computed norm against the exact one ---- *)

Lemma sqrt_plus a b : 0 <= a -> 0 <= b -> sqrt (a + b) <= sqrt a + sqrt b.
Proof.
  intros Ha Hb. pose proof (sqrt_pos a). pose proof (sqrt_pos b).
  rewrite <- (sqrt_square (sqrt a + sqrt b)) by lra. apply sqrt_le_1_alt.
  pose proof (sqrt_sqrt a Ha). pose proof (sqrt_sqrt b Hb). nra.
Qed.

Lemma sqrt_small_eta k : 0 <= k <= 8 -> sqrt (k * eta) <= bpow radix2 (-536).
Proof.
  intros Hk. rewrite <- (sqrt_bpow2 (-536)). apply sqrt_le_1_alt. simpl (2 * -536)%Z.
  unfold eta. replace (-1072)%Z with (3 + -1075)%Z by lia. rewrite bpow_plus.
  pose proof (bpow_gt_0 radix2 (-1075)). simpl (bpow radix2 3). nra.
Qed.

(* A rounded square: nonnegative, and at least (1 - u) x^2 - eta. *)
Lemma sq_lower x : 0 <= x * x /\ ((1 - u) * (x * x) - eta <= fl (x * x) /\ 0 <= fl (x * x)).
Proof.
  assert (0 <= x * x) by apply Rle_0_sqr.
  split; [exact H | split; [apply fl_lower; exact H | apply fl_nonneg; exact H]].
Qed.

Lemma sumsq_lower_abs x y z :
  (1 - 3 * u) * (x * x + y * y + z * z) - 5 * eta <= fl (fl (fl (x * x) + fl (y * y)) + fl (z * z)).
Proof.
  pose proof u_small. pose proof eta_pos.
  destruct (sq_lower x) as [Hx Ha]. destruct (sq_lower y) as [Hy Hb]. destruct (sq_lower z) as [Hz Hc].
  set (a := fl (x * x)) in *; set (b := fl (y * y)) in *; set (c := fl (z * z)) in *.
  pose proof (fl_lower (a + b) ltac:(lra)). set (t := fl (a + b)) in *.
  assert (0 <= t) by (apply fl_nonneg; lra).
  pose proof (fl_lower (t + c) ltac:(lra)).
  assert (K1 : (1 - u) * ((1 - u) * (x * x + y * y) - 2 * eta) <= (1 - u) * (a + b)) by (apply mul_le_l; lra).
  assert (K2 : (1 - u) * ((1 - u) * ((1 - u) * (x * x + y * y) - 2 * eta) - eta + c) <= (1 - u) * (t + c))
    by (apply mul_le_l; lra).
  assert (K3 : (1 - u) * ((1 - u) * (z * z) - eta) <= (1 - u) * c) by (apply mul_le_l; lra).
  set (S := x * x + y * y + z * z).
  assert (0 <= S) by (unfold S; lra).
  assert (Hc3 : 1 - 3 * u <= (1 - u) * ((1 - u) * (1 - u))).
  { assert (0 <= u * u) by nra. assert (u * (u * u) <= 1 * (u * u)) by (apply Rmult_le_compat_r; lra).
    replace ((1 - u) * ((1 - u) * (1 - u))) with (1 - 3 * u + 3 * (u * u) - u * (u * u)) by ring. lra. }
  assert (Hc2 : 1 - 3 * u <= (1 - u) * (1 - u)).
  { assert (0 <= u * u) by nra. replace ((1 - u) * (1 - u)) with (1 - 2 * u + u * u) by ring. lra. }
  assert (K4 : (1 - 3 * u) * S <= (1 - u) * ((1 - u) * ((1 - u) * (x * x + y * y))) + (1 - u) * ((1 - u) * (z * z))).
  { assert ((1 - 3 * u) * (x * x + y * y) <= (1 - u) * ((1 - u) * (1 - u)) * (x * x + y * y)) by (apply Rmult_le_compat_r; lra).
    assert ((1 - 3 * u) * (z * z) <= (1 - u) * (1 - u) * (z * z)) by (apply Rmult_le_compat_r; lra).
    unfold S. lra. }
  assert (0 <= u * eta) by (apply Rmult_le_pos; lra).
  assert (u * (u * eta) <= 1 * (u * eta)) by (apply Rmult_le_compat_r; lra).
  lra.
Qed.

(* The computed norm (Eigen's sqrt of the rounded sum of rounded squares, any
   order) within 4 u of the exact one and 2^-535 (the squares' underflow). *)
Lemma norm_c_upper x y z : norm_c x y z <= (1 + 4 * u) * norm3 x y z + bpow radix2 (-535).
Proof.
  pose proof u_small. pose proof eta_pos. unfold norm_c, norm3.
  set (S := x * x + y * y + z * z). assert (HS : 0 <= S) by (unfold S; apply sq_nonneg3).
  pose proof (sumsq_upper x y z) as G. fold S in G. set (s := fl (fl (fl (x * x) + fl (y * y)) + fl (z * z))) in *.
  assert (Hs : sqrt s <= (1 + 2 * u) * sqrt S + bpow radix2 (-536)).
  { apply Rle_trans with (sqrt ((1 + 4 * u) * S + 6 * eta)); [apply sqrt_le_1_alt; exact G|].
    eapply Rle_trans; [apply sqrt_plus; nra|]. pose proof (sqrt_small_eta 6 ltac:(lra)).
    assert (sqrt ((1 + 4 * u) * S) <= (1 + 2 * u) * sqrt S).
    { rewrite <- (sqrt_square (1 + 2 * u)) by lra. rewrite <- sqrt_mult_alt by nra.
      apply sqrt_le_1_alt. apply Rmult_le_compat_r; nra. }
    lra. }
  pose proof (sqrt_pos s). pose proof (fl_upper (sqrt s) ltac:(lra)).
  pose proof (sqrt_pos S). pose proof (bpow_gt_0 radix2 (-536)).
  assert (bpow radix2 (-535) = 2 * bpow radix2 (-536)) by (replace (-535)%Z with (1 + -536)%Z by lia; rewrite bpow_plus; reflexivity).
  assert (eta <= / 1000 * bpow radix2 (-536)) by (unfold eta; replace (/ 1000) with (/ 1000) by reflexivity;
    assert (bpow radix2 (-1075) <= bpow radix2 (-10) * bpow radix2 (-536)) by (rewrite <- bpow_plus; apply bpow_le; lia);
    assert (bpow radix2 (-10) <= / 1000) by (simpl; lra); nra).
  assert ((1 + u) * sqrt s <= (1 + u) * ((1 + 2 * u) * sqrt S + bpow radix2 (-536))) by (apply mul_le_l; lra).
  assert (0 <= u * sqrt S) by nra. assert (u * (u * sqrt S) <= / 1000000 * (u * sqrt S)) by (apply Rmult_le_compat_r; lra).
  assert (u * bpow radix2 (-536) <= / 1000000 * bpow radix2 (-536)) by (apply Rmult_le_compat_r; lra).
  replace ((1 + u) * ((1 + 2 * u) * sqrt S + bpow radix2 (-536)))
    with (sqrt S + 3 * (u * sqrt S) + 2 * (u * (u * sqrt S)) + bpow radix2 (-536) + u * bpow radix2 (-536)) in * by ring.
  lra.
Qed.

Lemma norm_c_lower x y z : (1 - 4 * u) * norm3 x y z - bpow radix2 (-535) <= norm_c x y z.
Proof.
  pose proof u_small. pose proof eta_pos. unfold norm_c, norm3.
  set (S := x * x + y * y + z * z). assert (HS : 0 <= S) by (unfold S; apply sq_nonneg3).
  pose proof (sumsq_lower_abs x y z) as G. fold S in G. set (s := fl (fl (fl (x * x) + fl (y * y)) + fl (z * z))) in *.
  assert (Hs0 : 0 <= s).
  { unfold s. apply fl_nonneg. pose proof (fl_nonneg (x * x) ltac:(nra)). pose proof (fl_nonneg (y * y) ltac:(nra)).
    pose proof (fl_nonneg (z * z) ltac:(nra)). pose proof (fl_nonneg (fl (x * x) + fl (y * y)) ltac:(lra)). lra. }
  assert (Hs : (1 - 2 * u) * sqrt S - bpow radix2 (-536) <= sqrt s).
  { assert (sqrt ((1 - 3 * u) * S) <= sqrt s + sqrt (5 * eta)).
    { eapply Rle_trans; [|apply sqrt_plus; lra]. apply sqrt_le_1_alt. lra. }
    pose proof (sqrt_small_eta 5 ltac:(lra)).
    assert ((1 - 2 * u) * sqrt S <= sqrt ((1 - 3 * u) * S)).
    { rewrite <- (sqrt_square (1 - 2 * u)) at 1 by lra. rewrite <- sqrt_mult_alt by nra.
      apply sqrt_le_1_alt. apply Rmult_le_compat_r; nra. }
    lra. }
  pose proof (sqrt_pos s). pose proof (fl_lower (sqrt s) ltac:(lra)).
  pose proof (sqrt_pos S). pose proof (bpow_gt_0 radix2 (-536)).
  assert (bpow radix2 (-535) = 2 * bpow radix2 (-536)) by (replace (-535)%Z with (1 + -536)%Z by lia; rewrite bpow_plus; reflexivity).
  assert (eta <= / 1000 * bpow radix2 (-536)) by (unfold eta;
    assert (bpow radix2 (-1075) <= bpow radix2 (-10) * bpow radix2 (-536)) by (rewrite <- bpow_plus; apply bpow_le; lia);
    assert (bpow radix2 (-10) <= / 1000) by (simpl; lra); nra).
  assert ((1 - u) * ((1 - 2 * u) * sqrt S - bpow radix2 (-536)) <= (1 - u) * sqrt s) by (apply mul_le_l; lra).
  assert (0 <= u * sqrt S) by nra. assert (0 <= u * (u * sqrt S)) by nra.
  replace ((1 - u) * ((1 - 2 * u) * sqrt S - bpow radix2 (-536)))
    with (sqrt S - 3 * (u * sqrt S) + 2 * (u * (u * sqrt S)) - bpow radix2 (-536) + u * bpow radix2 (-536)) in * by ring.
  assert (0 <= u * bpow radix2 (-536)) by nra.
  lra.
Qed.

(* ---- The separation of the edge rule's point ---- *)

Lemma coord_le_norm3 x y z : Rabs x <= norm3 x y z.
Proof.
  unfold norm3. rewrite <- sqrt_Rsqr_abs. apply sqrt_le_1_alt. unfold Rsqr.
  pose proof (Rle_0_sqr y). pose proof (Rle_0_sqr z). unfold Rsqr in *. lra.
Qed.

Lemma coord1_le_norm3 x y z : Rabs y <= norm3 x y z.
Proof.
  unfold norm3. rewrite <- sqrt_Rsqr_abs. apply sqrt_le_1_alt. unfold Rsqr.
  pose proof (Rle_0_sqr x). pose proof (Rle_0_sqr z). unfold Rsqr in *. lra.
Qed.
Lemma coord2_le_norm3 x y z : Rabs z <= norm3 x y z.
Proof.
  unfold norm3. rewrite <- sqrt_Rsqr_abs. apply sqrt_le_1_alt. unfold Rsqr.
  pose proof (Rle_0_sqr x). pose proof (Rle_0_sqr y). unfold Rsqr in *. lra.
Qed.

Lemma norm3_opp x y z : norm3 (- x) (- y) (- z) = norm3 x y z.
Proof. unfold norm3. f_equal. ring. Qed.

(* The computed separation of p from the rule's point q, norm_c of the rounded
   differences (feature_pair's (x - closest_point_on_triangle(...)).norm() and
   held_beside's), within 230 u M + 2^-531 of p's exact distance from the
   segment's exact closest point. *)
Definition sep_c p0 p1 p2 q0 q1 q2 := norm_c (fl (p0 - q0)) (fl (p1 - q1)) (fl (p2 - q2)).

Theorem edge_rule_separation a0 a1 a2 b0 b1 b2 p0 p1 p2 q0 q1 q2 M :
  (forall v, In v [a0; a1; a2; b0; b1; b2; p0; p1; p2] -> F v) ->
  (forall v, In v [a0; a1; a2; b0; b1; b2; p0; p1; p2] -> Rabs v <= M) ->
  edge_rule (edge_e a0 a1 a2 b0 b1 b2 p0 p1 p2) (edge_f a0 a1 a2 b0 b1 b2 p0 p1 p2) a0 a1 a2 b0 b1 b2 q0 q1 q2 ->
  let t := seg_tau a0 a1 a2 b0 b1 b2 p0 p1 p2 in
  Rabs (sep_c p0 p1 p2 q0 q1 q2 - norm3 (p0 - (a0 + t * (b0 - a0))) (p1 - (a1 + t * (b1 - a1))) (p2 - (a2 + t * (b2 - a2))))
  <= 230 * u * M + bpow radix2 (-531).
Proof.
  intros HF HM Hr t. pose proof u_small. pose proof eta_pos.
  pose proof (edge_rule_point a0 a1 a2 b0 b1 b2 p0 p1 p2 q0 q1 q2 M HF HM Hr) as Hq. cbv zeta in Hq. fold t in Hq.
  destruct (nine F _ _ _ _ _ _ _ _ _ HF) as (Fa0 & Fa1 & Fa2 & Fb0 & Fb1 & Fb2 & Fp0 & Fp1 & Fp2).
  destruct (nine (fun v => Rabs v <= M) _ _ _ _ _ _ _ _ _ HM) as (Ma0 & Ma1 & Ma2 & Mb0 & Mb1 & Mb2 & Mp0 & Mp1 & Mp2).
  assert (HM0 : 0 <= M) by (pose proof (Rabs_pos a0); lra).
  assert (Fq : F q0 /\ F q1 /\ F q2)
    by (destruct Hr as [(_ & -> & -> & ->)|[(_ & -> & -> & ->)|(_ & _ & -> & -> & ->)]]; unfold point_c; repeat split; try apply F_fl; assumption).
  destruct Fq as (Fq0 & Fq1 & Fq2).
  assert (Ht : 0 <= t <= 1) by (unfold t, seg_tau; apply clamp01_unit).
  set (Q0 := a0 + t * (b0 - a0)) in *. set (Q1 := a1 + t * (b1 - a1)) in *. set (Q2 := a2 + t * (b2 - a2)) in *.
  set (dl := 200 * u * M + bpow radix2 (-533)) in *.
  assert (Hdl : 0 <= dl) by (unfold dl; pose proof (bpow_gt_0 radix2 (-533)); nra).
  assert (HQ : forall a b, Rabs a <= M -> Rabs b <= M -> Rabs (a + t * (b - a)) <= M).
  { intros a b Ha Hb. replace (a + t * (b - a)) with ((1 - t) * a + t * b) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult, (Rabs_pos_eq t), (Rabs_pos_eq (1 - t)) by lra.
    assert ((1 - t) * Rabs a <= (1 - t) * M) by (apply Rmult_le_compat_l; lra).
    assert (t * Rabs b <= t * M) by (apply Rmult_le_compat_l; lra). lra. }
  pose proof (HQ a0 b0 Ma0 Mb0) as MQ0. pose proof (HQ a1 b1 Ma1 Mb1) as MQ1. pose proof (HQ a2 b2 Ma2 Mb2) as MQ2.
  fold Q0 Q1 Q2 in MQ0, MQ1, MQ2.
  (* each coordinate of q within dl of Q's *)
  assert (D0 : Rabs (q0 - Q0) <= dl) by (eapply Rle_trans; [apply coord_le_norm3|exact Hq]).
  assert (D1 : Rabs (q1 - Q1) <= dl) by (eapply Rle_trans; [apply coord1_le_norm3|exact Hq]).
  assert (D2 : Rabs (q2 - Q2) <= dl) by (eapply Rle_trans; [apply coord2_le_norm3|exact Hq]).
  (* the rounded differences w within u (2 M + dl) of p - q *)
  assert (W : forall p q Q, F p -> F q -> Rabs p <= M -> Rabs Q <= M -> Rabs (q - Q) <= dl ->
                Rabs (fl (p - q) - (p - q)) <= u * (2 * M + dl)).
  { intros p q Q Fp Fq' Hp HQ' Hd. eapply Rle_trans; [apply sub_rel; assumption|]. apply Rmult_le_compat_l; [lra|].
    replace (p - q) with ((p - Q) - (q - Q)) by ring. eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_Ropp.
    pose proof (abs_diff2 p Q M Hp HQ'). lra. }
  pose proof (W p0 q0 Q0 Fp0 Fq0 Mp0 MQ0 D0) as W0. pose proof (W p1 q1 Q1 Fp1 Fq1 Mp1 MQ1 D1) as W1.
  pose proof (W p2 q2 Q2 Fp2 Fq2 Mp2 MQ2 D2) as W2.
  set (w0 := fl (p0 - q0)) in *. set (w1 := fl (p1 - q1)) in *. set (w2 := fl (p2 - q2)) in *.
  (* |w - (p - Q)| <= 2 u (2 M + dl) + dl *)
  assert (HD : norm3 (w0 - (p0 - Q0)) (w1 - (p1 - Q1)) (w2 - (p2 - Q2)) <= 2 * (u * (2 * M + dl)) + dl).
  { pose proof (norm3_triangle (w0 - (p0 - q0)) (w1 - (p1 - q1)) (w2 - (p2 - q2)) (- (q0 - Q0)) (- (q1 - Q1)) (- (q2 - Q2))) as T1.
    rewrite norm3_opp in T1.
    replace (w0 - (p0 - q0) + - (q0 - Q0)) with (w0 - (p0 - Q0)) in T1 by ring.
    replace (w1 - (p1 - q1) + - (q1 - Q1)) with (w1 - (p1 - Q1)) in T1 by ring.
    replace (w2 - (p2 - q2) + - (q2 - Q2)) with (w2 - (p2 - Q2)) in T1 by ring.
    pose proof (norm3_coords _ _ _ _ W0 W1 W2). lra. }
  set (Dl := norm3 (w0 - (p0 - Q0)) (w1 - (p1 - Q1)) (w2 - (p2 - Q2))) in *.
  set (rho := norm3 (p0 - Q0) (p1 - Q1) (p2 - Q2)).
  assert (Hrho : rho <= 4 * M).
  { unfold rho. replace (4 * M) with (2 * (2 * M)) by ring. apply norm3_coords; apply abs_diff2; assumption. }
  pose proof (norm3_triangle (p0 - Q0) (p1 - Q1) (p2 - Q2) (w0 - (p0 - Q0)) (w1 - (p1 - Q1)) (w2 - (p2 - Q2))) as T2.
  replace (p0 - Q0 + (w0 - (p0 - Q0))) with w0 in T2 by ring.
  replace (p1 - Q1 + (w1 - (p1 - Q1))) with w1 in T2 by ring.
  replace (p2 - Q2 + (w2 - (p2 - Q2))) with w2 in T2 by ring.
  pose proof (norm3_triangle w0 w1 w2 (- (w0 - (p0 - Q0))) (- (w1 - (p1 - Q1))) (- (w2 - (p2 - Q2)))) as T3.
  rewrite norm3_opp in T3.
  replace (w0 + - (w0 - (p0 - Q0))) with (p0 - Q0) in T3 by ring.
  replace (w1 + - (w1 - (p1 - Q1))) with (p1 - Q1) in T3 by ring.
  replace (w2 + - (w2 - (p2 - Q2))) with (p2 - Q2) in T3 by ring.
  fold rho Dl in T2, T3.
  pose proof (norm_c_upper w0 w1 w2) as U. pose proof (norm_c_lower w0 w1 w2) as L.
  pose proof (norm3_nonneg w0 w1 w2). pose proof (norm3_nonneg (p0 - Q0) (p1 - Q1) (p2 - Q2)) as Hrho0. fold rho in Hrho0.
  unfold sep_c. fold w0 w1 w2.
  set (nw := norm3 w0 w1 w2) in *.
  assert (u * nw <= u * (4 * M + (2 * (u * (2 * M + dl)) + dl))) by (apply Rmult_le_compat_l; lra).
  assert (Hb : bpow radix2 (-533) + bpow radix2 (-535) + / 100 * bpow radix2 (-533) <= bpow radix2 (-531)).
  { replace (-531)%Z with (2 + -533)%Z by lia. replace (-535)%Z with (-2 + -533)%Z by lia. rewrite !bpow_plus.
    pose proof (bpow_gt_0 radix2 (-533)). simpl (bpow radix2 2). simpl (bpow radix2 (-2)). lra. }
  assert (0 <= u * M) by nra.
  assert (u * dl <= / 1000000 * dl) by (apply Rmult_le_compat_r; lra).
  assert (u * (u * M) <= / 1000000 * (u * M)) by (apply Rmult_le_compat_r; lra).
  assert (u * (u * dl) <= / 1000000 * dl) by (assert (u * (u * dl) <= / 1000000 * (u * dl)) by (apply Rmult_le_compat_r; nra); nra).
  assert (Hdl2 : dl <= 200 * u * M + bpow radix2 (-533)) by (unfold dl; lra).
  assert (u * bpow radix2 (-533) <= / 1000000 * bpow radix2 (-533)) by (apply Rmult_le_compat_r; [left; apply bpow_gt_0 | lra]).
  assert (u * (200 * u * M) <= / 1000000 * (200 * u * M)) by (apply Rmult_le_compat_r; nra).
  apply Rabs_le. split.
  - (* nw - Dl <= rho: sep >= rho - ... *)
    assert (4 * u * nw <= 4 * (u * (4 * M + (2 * (u * (2 * M + dl)) + dl)))) by lra.
    unfold dl in *. nra.
  - unfold dl in *. nra.
Qed.
Print Assumptions edge_rule_separation.

(* ---- Two faces that share an edge ---- *)

(* The exact closest point is the same from either end of the segment. *)
Lemma seg_flip a0 a1 a2 b0 b1 b2 p0 p1 p2 :
  let t := seg_tau a0 a1 a2 b0 b1 b2 p0 p1 p2 in let t' := seg_tau b0 b1 b2 a0 a1 a2 p0 p1 p2 in
  b0 + t' * (a0 - b0) = a0 + t * (b0 - a0) /\ b1 + t' * (a1 - b1) = a1 + t * (b1 - a1) /\
  b2 + t' * (a2 - b2) = a2 + t * (b2 - a2).
Proof.
  intros t t'. set (N := (b0 - a0) * (b0 - a0) + (b1 - a1) * (b1 - a1) + (b2 - a2) * (b2 - a2)).
  destruct (Req_dec N 0) as [HN|HN].
  - pose proof (Rle_0_sqr (b0 - a0)). pose proof (Rle_0_sqr (b1 - a1)). pose proof (Rle_0_sqr (b2 - a2)). unfold Rsqr in *.
    assert (E0 : b0 - a0 = 0) by (apply Rsqr_0_uniq; unfold Rsqr, N in *; lra).
    assert (E1 : b1 - a1 = 0) by (apply Rsqr_0_uniq; unfold Rsqr, N in *; lra).
    assert (E2 : b2 - a2 = 0) by (apply Rsqr_0_uniq; unfold Rsqr, N in *; lra).
    assert (b0 = a0) by lra. assert (b1 = a1) by lra. assert (b2 = a2) by lra. subst b0 b1 b2.
    repeat split; ring.
  - assert (Ht' : t' = 1 - t).
    { unfold t, t', seg_tau. rewrite <- clamp01_flip. f_equal. fold N.
      replace ((a0 - b0) * (a0 - b0) + (a1 - b1) * (a1 - b1) + (a2 - b2) * (a2 - b2)) with N by (unfold N; ring).
      field_simplify_eq; [unfold N; ring | exact HN]. }
    rewrite Ht'. repeat split; ring.
Qed.

(* `tie` as generate_contacts computes it: std::max((Upper{kBoxPoseRounding} *
   Upper{scale}).v, kNormFloor). *)
Definition tie scale := Rmax (next_up (fl (kBoxPoseRounding * scale))) kNormFloor.

(* A double separation x at most 480 u M + 2^-528 above y is within `tie` of
   it as generate_contacts compares them: x <= fl(y + tie scale), for
   coordinates within M <= 4 scale + 2^-490 (tie is at least 9000 u scale,
   which covers the relative part, and at least kNormFloor = 2^-500, which
   covers the rest). The one step tie_shared_edge and ClosestPoint.v
   tie_closest share. *)
Lemma tie_covers x y M scale :
  F x -> 0 <= scale -> 0 <= M -> M <= 4 * scale + bpow radix2 (-490) ->
  x <= y + 480 * u * M + 2 * bpow radix2 (-529) -> x <= fl (y + tie scale).
Proof.
  intros Fx Hs HM0 HMs H. pose proof u_small.
  assert (T1 : 9000 * u * scale <= tie scale).
  { unfold tie. eapply Rle_trans; [|apply Rmax_l]. eapply Rle_trans; [|apply next_up_ge].
    apply Rmult_le_compat_r; [lra | apply kBoxPoseRounding_ge]. }
  assert (T2 : kNormFloor <= tie scale) by (unfold tie; apply Rmax_r).
  assert (HuM : u * M <= u * (4 * scale + bpow radix2 (-490))) by (apply Rmult_le_compat_l; lra).
  assert (Hb : 480 * (u * bpow radix2 (-490)) + 2 * bpow radix2 (-529) <= / 2 * kNormFloor).
  { unfold kNormFloor. rewrite bpow_m53, <- bpow_plus.
    replace (-529)%Z with (-29 + -500)%Z by lia. replace (-53 + -490)%Z with (-43 + -500)%Z by lia. rewrite !bpow_plus.
    pose proof (bpow_gt_0 radix2 (-500)). simpl (bpow radix2 (-29)). simpl (bpow radix2 (-43)). lra. }
  assert (0 < kNormFloor) by (unfold kNormFloor; apply bpow_gt_0).
  apply fl_ge_F; [exact Fx|]. lra.
Qed.

(* Two faces that share the edge from a to b (either face may see it from b to
   a), each returning for p the point of its edge rule (their branch of that
   edge or of one of its ends: q, q'), coordinates within M <= 4 scale +
   2^-490: the second's computed separation is within `tie` of the first's,
   so that held_beside's reach = min(d, fl(sep + tie)) takes it in (the
   comparison sep' <= reach, sep' a double, holds iff sep' <= fl(sep + tie)
   when sep' <= d). The separations are within 460 u M + 2^-530 of each other,
   `tie` at least 9000 u scale and 2^-500. *)
(* covers optimized/gauss6/contact/contacts.cpp "ContactStatus generate_contacts(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X_WB," sha256:f7318906decf3db7 *)
(* covers optimized/gauss6/contact/contacts.cpp "bool held_beside(const Vec3& p, const Side<AtV>& V, int vf, int vc, const Side<AtW>& W, int face, const Vec3& nF," sha256:ffbaa960d7c4b290 *)
Theorem tie_shared_edge a0 a1 a2 b0 b1 b2 p0 p1 p2 q0 q1 q2 r0 r1 r2 M scale :
  (forall v, In v [a0; a1; a2; b0; b1; b2; p0; p1; p2] -> F v) ->
  (forall v, In v [a0; a1; a2; b0; b1; b2; p0; p1; p2] -> Rabs v <= M) ->
  0 <= scale -> M <= 4 * scale + bpow radix2 (-490) ->
  edge_rule (edge_e a0 a1 a2 b0 b1 b2 p0 p1 p2) (edge_f a0 a1 a2 b0 b1 b2 p0 p1 p2) a0 a1 a2 b0 b1 b2 q0 q1 q2 ->
  edge_rule (edge_e a0 a1 a2 b0 b1 b2 p0 p1 p2) (edge_f a0 a1 a2 b0 b1 b2 p0 p1 p2) a0 a1 a2 b0 b1 b2 r0 r1 r2 \/
  edge_rule (edge_e b0 b1 b2 a0 a1 a2 p0 p1 p2) (edge_f b0 b1 b2 a0 a1 a2 p0 p1 p2) b0 b1 b2 a0 a1 a2 r0 r1 r2 ->
  sep_c p0 p1 p2 r0 r1 r2 <= fl (sep_c p0 p1 p2 q0 q1 q2 + tie scale).
Proof.
  intros HF HM Hs HMs Hq Hr. pose proof u_small. pose proof eta_pos.
  assert (HF' : forall v, In v [b0; b1; b2; a0; a1; a2; p0; p1; p2] -> F v) by (intros v Hv; apply HF; simpl in *; tauto).
  assert (HM' : forall v, In v [b0; b1; b2; a0; a1; a2; p0; p1; p2] -> Rabs v <= M) by (intros v Hv; apply HM; simpl in *; tauto).
  pose proof (edge_rule_separation a0 a1 a2 b0 b1 b2 p0 p1 p2 q0 q1 q2 M HF HM Hq) as S1. cbv zeta in S1.
  set (rho := norm3 _ _ _) in S1.
  assert (S2 : Rabs (sep_c p0 p1 p2 r0 r1 r2 - rho) <= 230 * u * M + bpow radix2 (-531)).
  { destruct Hr as [Hr|Hr].
    - pose proof (edge_rule_separation a0 a1 a2 b0 b1 b2 p0 p1 p2 r0 r1 r2 M HF HM Hr) as S2. exact S2.
    - pose proof (edge_rule_separation b0 b1 b2 a0 a1 a2 p0 p1 p2 r0 r1 r2 M HF' HM' Hr) as S2. cbv zeta in S2.
      destruct (seg_flip a0 a1 a2 b0 b1 b2 p0 p1 p2) as (E0 & E1 & E2). cbv zeta in E0, E1, E2.
      rewrite E0, E1, E2 in S2. exact S2. }
  apply Rabs_le_inv in S1. apply Rabs_le_inv in S2.
  assert (HM0 : 0 <= M) by (assert (Rabs a0 <= M) by (apply HM; simpl; tauto); pose proof (Rabs_pos a0); lra).
  assert (Fr : F (sep_c p0 p1 p2 r0 r1 r2)) by (unfold sep_c, norm_c; apply F_fl).
  apply (tie_covers _ _ M scale Fr Hs HM0 HMs).
  assert (0 <= u * M) by (apply Rmult_le_pos; lra).
  assert (bpow radix2 (-531) <= bpow radix2 (-529)) by (apply bpow_le; lia).
  lra.
Qed.
Print Assumptions tie_shared_edge.
