(* The named error allowances of optimized/include/gauss6/numeric/error_allowances.h,
   proved in Flocq: for each, the rounding error of the expression at its
   sites, evaluated as the code evaluates it (the same operations in the same
   order, each rounded to nearest binary64: Rounding.v's `fl`), is within the
   allowance, under the stated magnitude hypotheses. Same model as Rounding.v
   (finite results, gradual underflow, no fused multiply-add unless said). *)

From Coq Require Import Reals Psatz.
From Coq Require Import List.
Import ListNotations.
From Flocq Require Import Core Relative.
From Gauss6 Require Import Rounding.
Open Scope R_scope.

(* u = 2^-53, the unit roundoff; eta = 2^-1075, half the least subnormal. *)
Definition u := / 9007199254740992.
Definition eta := bpow radix2 (-1075).
Lemma eta_pos : 0 < eta. Proof. apply bpow_gt_0. Qed.
Lemma eta_small : eta <= / 1024 * bpow radix2 (-1022).
Proof.
  unfold eta. replace (/ 1024) with (bpow radix2 (-10)) by (simpl; lra).
  rewrite <- bpow_plus. apply bpow_le. lia.
Qed.

(* Every rounding to nearest errs by at most u |z| + eta (Flocq's
   error_N_FLT: a relative error u or, below the normal range, an absolute
   one of half the least subnormal). *)
Lemma fl_err z : Rabs (fl z - z) <= u * Rabs z + eta.
Proof.
  destruct (error_N_FLT radix2 (-1074) 53 ltac:(lia) (fun t => negb (Z.even t)) z)
    as (eps & et & He & Ht & _ & E).
  unfold fl. (* ZnearestE is Znearest (fun x => negb (Z.even x)) *)
  change (round radix2 (FLT_exp (-1074) 53) ZnearestE z)
    with (round radix2 (FLT_exp (-1074) 53) (Znearest (fun t => negb (Z.even t))) z).
  rewrite E. replace (z * (1 + eps) + et - z) with (z * eps + et) by ring.
  assert (Hu : / 2 * bpow radix2 (- (53) + 1) = u) by (unfold u; simpl; lra).
  assert (He' : / 2 * bpow radix2 (-1074) = eta)
    by (unfold eta; replace (-1074)%Z with (-1075 + 1)%Z by lia; rewrite bpow_plus; simpl; lra).
  rewrite Hu in He; rewrite He' in Ht.
  eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_mult.
  assert (0 <= Rabs z) by apply Rabs_pos. nra.
Qed.

(* One rounded step: an operand z within Ez of the exact Z, |Z| <= Bz. *)
Lemma step z Z Bz Ez :
  Rabs Z <= Bz -> Rabs (z - Z) <= Ez -> Rabs (fl z - Z) <= Ez + u * (Bz + Ez) + eta.
Proof.
  intros HB HE. pose proof (fl_err z).
  assert (Rabs z <= Bz + Ez)
    by (replace z with (Z + (z - Z)) by ring; eapply Rle_trans; [apply Rabs_triang | lra]).
  assert (0 < u) by (unfold u; lra).
  replace (fl z - Z) with ((fl z - z) + (z - Z)) by ring.
  eapply Rle_trans; [apply Rabs_triang|]. nra.
Qed.

Lemma abs_sub a A b B Ea Eb :
  Rabs (a - A) <= Ea -> Rabs (b - B) <= Eb -> Rabs ((a - b) - (A - B)) <= Ea + Eb.
Proof. intros; unfold Rabs in *; repeat destruct Rcase_abs; lra. Qed.
Lemma abs_add a A b B Ea Eb :
  Rabs (a - A) <= Ea -> Rabs (b - B) <= Eb -> Rabs ((a + b) - (A + B)) <= Ea + Eb.
Proof. intros; unfold Rabs in *; repeat destruct Rcase_abs; lra. Qed.
Lemma abs_diff_le x y Mx My : Rabs x <= Mx -> Rabs y <= My -> Rabs (x - y) <= Mx + My.
Proof. intros; unfold Rabs in *; repeat destruct Rcase_abs; lra. Qed.
Lemma abs_sum_le x y Mx My : Rabs x <= Mx -> Rabs y <= My -> Rabs (x + y) <= Mx + My.
Proof. intros; unfold Rabs in *; repeat destruct Rcase_abs; lra. Qed.
Lemma abs_scale t a A Ea :
  0 <= t <= 1 -> Rabs (a - A) <= Ea -> Rabs (t * a - t * A) <= Ea.
Proof.
  intros Ht H. replace (t * a - t * A) with (t * (a - A)) by ring.
  rewrite Rabs_mult, Rabs_pos_eq by lra. pose proof (Rabs_pos (a - A)). nra.
Qed.
Lemma abs_scale_le t A B : 0 <= t <= 1 -> Rabs A <= B -> Rabs (t * A) <= B.
Proof. intros Ht H. rewrite Rabs_mult, Rabs_pos_eq by lra. pose proof (Rabs_pos A). nra. Qed.

(* ---- kLinearCornerRounding, kLinearCornerUnderflow ----
   The code (ccd.cpp): make_linear_points computes dx = fl(x1 - x0) per
   coordinate of each of the four points; enclose_linear, at a box corner
   (t, a, b) (doubles in [0, 1]), p = fl(x0 + fl(t dx)) for each point,
   w = fl(p_w0 - p_w1), ea = fl(p_a0 - p_a1), eb = fl(p_b0 - p_b1), and the
   corner value c = fl(fl(w + fl(a ea)) - fl(b eb)). The exact value is
   F = (P_w0 - P_w1) + a (P_a0 - P_a1) - b (P_b0 - P_b1), P = x0 + t (x1 - x0). *)

(* allowance kLinearCornerRounding = 0x1p-46 *)
Definition kLinearCornerRounding := bpow radix2 (-46).
(* allowance kLinearCornerUnderflow = 64 * std::numeric_limits<double>::min() *)
Definition kLinearCornerUnderflow := 64 * bpow radix2 (-1022).

(* A point's computed position, within 7 u M + 5 eta of the exact one. *)
Definition point_c t x0 x1 := fl (x0 + fl (t * fl (x1 - x0))).
Definition point_x t x0 x1 := x0 + t * (x1 - x0).
Lemma point_err t x0 x1 M :
  0 <= t <= 1 -> Rabs x0 <= M -> Rabs x1 <= M ->
  Rabs (point_x t x0 x1) <= M /\ Rabs (point_c t x0 x1 - point_x t x0 x1) <= 7 * u * M + 5 * eta.
Proof.
  intros Ht H0 H1. assert (0 <= M) by (pose proof (Rabs_pos x0); lra).
  pose proof eta_pos. assert (0 < u) by (unfold u; lra).
  assert (HP : Rabs (point_x t x0 x1) <= M).
  { unfold point_x. replace (x0 + t * (x1 - x0)) with ((1 - t) * x0 + t * x1) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult, (Rabs_pos_eq t), (Rabs_pos_eq (1 - t)) by lra.
    nra. }
  split; [exact HP|].
  assert (Hd : Rabs (fl (x1 - x0) - (x1 - x0)) <= 0 + u * (M + M + 0) + eta).
  { apply step; [apply abs_diff_le; assumption | rewrite Rminus_diag_eq by reflexivity; rewrite Rabs_R0; lra]. }
  assert (Hq : Rabs (fl (t * fl (x1 - x0)) - t * (x1 - x0)) <= 5 * u * M + 3 * eta).
  { eapply Rle_trans; [apply (step _ _ (M + M)); [apply abs_scale_le; [exact Ht|] | apply abs_scale; [exact Ht | exact Hd]]|].
    - apply abs_diff_le; assumption.
    - unfold u in *; lra. }
  unfold point_c.
  eapply Rle_trans; [apply (step _ _ M (5 * u * M + 3 * eta)); [exact HP|]|].
  - unfold point_x. replace (x0 + fl (t * fl (x1 - x0)) - (x0 + t * (x1 - x0)))
      with (fl (t * fl (x1 - x0)) - t * (x1 - x0)) by ring. exact Hq.
  - unfold u in *; lra.
Qed.

(* covers optimized/src/ccd/ccd.cpp "LinearPoints make_linear_points(" sha256:badaaa4fc2f7da52 *)
(* covers optimized/src/ccd/ccd.cpp "void enclose_linear(" sha256:b914611386face38 *)
Theorem linear_corner_rounding M t a b
    xw0 yw0 xw1 yw1 xa0 ya0 xa1 ya1 xb0 yb0 xb1 yb1 :
  0 <= t <= 1 -> 0 <= a <= 1 -> 0 <= b <= 1 ->
  (forall x, In x [xw0; yw0; xw1; yw1; xa0; ya0; xa1; ya1; xb0; yb0; xb1; yb1] -> Rabs x <= M) ->
  let w := fl (point_c t xw0 yw0 - point_c t xw1 yw1) in
  let ea := fl (point_c t xa0 ya0 - point_c t xa1 ya1) in
  let eb := fl (point_c t xb0 yb0 - point_c t xb1 yb1) in
  let c := fl (fl (w + fl (a * ea)) - fl (b * eb)) in
  let F := (point_x t xw0 yw0 - point_x t xw1 yw1) + a * (point_x t xa0 ya0 - point_x t xa1 ya1)
           - b * (point_x t xb0 yb0 - point_x t xb1 yb1) in
  Rabs (c - F) <= kLinearCornerRounding * M + kLinearCornerUnderflow.
Proof.
  intros Ht Ha Hb HM w ea eb c F. unfold kLinearCornerRounding, kLinearCornerUnderflow.
  assert (HM0 : 0 <= M) by (pose proof (Rabs_pos xw0); assert (Rabs xw0 <= M) by (apply HM; simpl; tauto); lra).
  pose proof eta_pos. pose proof eta_small. assert (Hu : 0 < u) by (unfold u; lra).
  (* the difference of two computed points, within 17 u M + 12 eta *)
  assert (Hdiff : forall x0 y0 x1 y1, Rabs x0 <= M -> Rabs y0 <= M -> Rabs x1 <= M -> Rabs y1 <= M ->
    Rabs (point_x t x0 y0 - point_x t x1 y1) <= M + M /\
    Rabs (fl (point_c t x0 y0 - point_c t x1 y1) - (point_x t x0 y0 - point_x t x1 y1))
      <= 17 * u * M + 12 * eta).
  { intros x0 y0 x1 y1 G0 G1 G2 G3.
    destruct (point_err t x0 y0 M Ht G0 G1) as [B0 E0]; destruct (point_err t x1 y1 M Ht G2 G3) as [B1 E1].
    split; [apply abs_diff_le; assumption|].
    eapply Rle_trans; [apply (step _ _ (M + M) ((7 * u * M + 5 * eta) + (7 * u * M + 5 * eta)));
      [apply abs_diff_le; assumption | apply abs_sub; assumption]|].
    unfold u in *; lra. }
  destruct (Hdiff xw0 yw0 xw1 yw1) as [BW EW]; try (apply HM; simpl; tauto).
  destruct (Hdiff xa0 ya0 xa1 ya1) as [BA EA]; try (apply HM; simpl; tauto).
  destruct (Hdiff xb0 yb0 xb1 yb1) as [BB EB]; try (apply HM; simpl; tauto).
  fold w in EW; fold ea in EA; fold eb in EB.
  set (W := point_x t xw0 yw0 - point_x t xw1 yw1) in *.
  set (A := point_x t xa0 ya0 - point_x t xa1 ya1) in *.
  set (B := point_x t xb0 yb0 - point_x t xb1 yb1) in *.
  (* the products by a, b in [0, 1], within 20 u M + 14 eta *)
  assert (PA : Rabs (fl (a * ea) - a * A) <= 20 * u * M + 14 * eta).
  { eapply Rle_trans; [apply (step _ _ (M + M) (17 * u * M + 12 * eta));
      [apply abs_scale_le | apply abs_scale]; assumption|]. unfold u in *; lra. }
  assert (PB : Rabs (fl (b * eb) - b * B) <= 20 * u * M + 14 * eta).
  { eapply Rle_trans; [apply (step _ _ (M + M) (17 * u * M + 12 * eta));
      [apply abs_scale_le | apply abs_scale]; assumption|]. unfold u in *; lra. }
  assert (SA : Rabs (fl (w + fl (a * ea)) - (W + a * A)) <= 42 * u * M + 28 * eta).
  { eapply Rle_trans; [apply (step _ _ ((M + M) + (M + M)) ((17 * u * M + 12 * eta) + (20 * u * M + 14 * eta)));
      [apply abs_sum_le; [|apply abs_scale_le] | apply abs_add]; assumption|]. unfold u in *; lra. }
  assert (C : Rabs (c - F) <= 69 * u * M + 44 * eta).
  { unfold c, F. eapply Rle_trans; [apply (step _ _ (((M + M) + (M + M)) + (M + M)) ((42 * u * M + 28 * eta) + (20 * u * M + 14 * eta)));
      [apply abs_diff_le; [apply abs_sum_le; [|apply abs_scale_le] | apply abs_scale_le] | apply abs_sub]; assumption|].
    unfold u in *; lra. }
  replace (bpow radix2 (-46)) with (128 * u) by (unfold u; simpl; lra).
  unfold u in *; lra.
Qed.

(* enclose_linear takes, per coordinate, (w + min(pa0, pa1)) - max(pb0, pb1)
   as the least corner value (and the mirror for the largest) instead of all
   four: that value is one of the four computed corner values, and no larger
   than any of them, rounding being monotone. *)
(* covers optimized/src/ccd/ccd.cpp "void enclose_linear(" sha256:b914611386face38 *)
Theorem linear_corner_selection w pa0 pa1 pb0 pb1 :
  let corner pa pb := fl (fl (w + pa) - pb) in
  let least := fl (fl (w + Rmin pa0 pa1) - Rmax pb0 pb1) in
  let most := fl (fl (w + Rmax pa0 pa1) - Rmin pb0 pb1) in
  (least = corner pa0 pb0 \/ least = corner pa0 pb1 \/ least = corner pa1 pb0 \/ least = corner pa1 pb1) /\
  (most = corner pa0 pb0 \/ most = corner pa0 pb1 \/ most = corner pa1 pb0 \/ most = corner pa1 pb1) /\
  (forall pa pb, (pa = pa0 \/ pa = pa1) -> (pb = pb0 \/ pb = pb1) -> least <= corner pa pb <= most).
Proof.
  intros corner least most. unfold least, most, corner.
  split; [|split].
  - unfold Rmin, Rmax; repeat destruct Rle_dec; tauto.
  - unfold Rmin, Rmax; repeat destruct Rle_dec; tauto.
  - intros pa pb Ha Hb. split; apply fl_le.
    + assert (fl (w + Rmin pa0 pa1) <= fl (w + pa))
        by (apply fl_le; destruct Ha as [->| ->]; [pose proof (Rmin_l pa0 pa1) | pose proof (Rmin_r pa0 pa1)]; lra).
      assert (pb <= Rmax pb0 pb1)
        by (destruct Hb as [->| ->]; [apply Rmax_l | apply Rmax_r]). lra.
    + assert (fl (w + pa) <= fl (w + Rmax pa0 pa1))
        by (apply fl_le; destruct Ha as [->| ->]; [pose proof (Rmax_l pa0 pa1) | pose proof (Rmax_r pa0 pa1)]; lra).
      assert (Rmin pb0 pb1 <= pb)
        by (destruct Hb as [->| ->]; [apply Rmin_l | apply Rmin_r]). lra.
Qed.

(* make_linear_points' p.error = kLinearCornerRounding * Upper{M} +
   Upper{kLinearCornerUnderflow}, rounded up (Rounding.v): at least the bound
   of linear_corner_rounding. *)
(* covers optimized/src/ccd/ccd.cpp "LinearPoints make_linear_points(" sha256:badaaa4fc2f7da52 *)
Theorem linear_corner_error_bound M :
  0 <= M ->
  kLinearCornerRounding * M + kLinearCornerUnderflow
    <= next_up (fl (next_up (fl (kLinearCornerRounding * M)) + kLinearCornerUnderflow)).
Proof.
  intros HM. apply upper_add; [|lra].
  apply next_up_ge.
Qed.


(* ---- kRelativeRounding at its norm sites ----
   round_up(v.norm() * (1 + kRelativeRounding)): Eigen's norm of a double
   3-vector, sqrt of the sum of the three rounded squares (summed in any
   order: the statement is symmetric in x, y, z), times the double
   1 + kRelativeRounding (the compiler folds it, rounding to nearest), rounded
   up, is at least the exact norm, provided |v|^2 >= 2^-1000: below that the
   squares underflow and the bound can fall below |v| (proofs/README.md).
   Sites: StartFrame::set (omega_norm, omega a double vector) and the same
   form at SweptObbFrame::pose (|half|); not the shift of Displacement, whose
   components are rounded differences. *)
(* allowance kRelativeRounding = 1e-15 *)
Definition kRelativeRounding := fl (/ 1000000000000000).

Lemma fl_lower z : 0 <= z -> (1 - u) * z - eta <= fl z.
Proof.
  intros Hz. pose proof (fl_err z) as H. rewrite (Rabs_pos_eq z Hz) in H.
  unfold Rabs in H; destruct Rcase_abs; lra.
Qed.
Lemma fl_upper z : 0 <= z -> fl z <= (1 + u) * z + eta.
Proof.
  intros Hz. pose proof (fl_err z) as H. rewrite (Rabs_pos_eq z Hz) in H.
  unfold Rabs in H; destruct Rcase_abs; lra.
Qed.

Lemma one_plus_rel : 1 + 7 * u <= fl (1 + kRelativeRounding).
Proof.
  pose proof eta_pos. pose proof eta_small.
  assert (bpow radix2 (-1022) <= / 1000000000000000000) by (simpl; lra).
  assert (Hk : (1 - u) * / 1000000000000000 - eta <= kRelativeRounding) by (apply fl_lower; lra).
  assert (0 <= kRelativeRounding) by (apply fl_nonneg; lra).
  pose proof (fl_lower (1 + kRelativeRounding) ltac:(lra)).
  unfold u in *. lra.
Qed.

(* covers optimized/src/ccd/motion_bounds.cpp "void StartFrame::set(const CcdMotion& m, double u, double rho_in)" sha256:d727ef1e2605b2dd *)
Theorem norm_relative_rounding x y z :
  bpow radix2 (-1000) <= x * x + y * y + z * z ->
  let s := fl (fl (fl (x * x) + fl (y * y)) + fl (z * z)) in
  sqrt (x * x + y * y + z * z) <= next_up (fl (fl (sqrt s) * fl (1 + kRelativeRounding))).
Proof.
  intros HS s. pose proof eta_pos. pose proof eta_small. assert (Hu : 0 < u) by (unfold u; lra).
  set (S := x * x + y * y + z * z) in *.
  assert (E1 : 1000000 * eta <= u * bpow radix2 (-1000)).
  { unfold eta, u. replace (/ 9007199254740992) with (bpow radix2 (-53)) by (simpl; lra).
    rewrite <- bpow_plus. apply Rle_trans with (bpow radix2 22 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  assert (HeS : 1000000 * eta <= u * S)
    by (apply Rle_trans with (u * bpow radix2 (-1000)); [exact E1 | apply Rmult_le_compat_l; lra]).
  assert (X := fl_lower (x * x) ltac:(nra)); assert (Y := fl_lower (y * y) ltac:(nra));
  assert (Z := fl_lower (z * z) ltac:(nra)).
  assert (0 <= fl (x * x)) by (apply fl_nonneg; nra); assert (0 <= fl (y * y)) by (apply fl_nonneg; nra);
  assert (0 <= fl (z * z)) by (apply fl_nonneg; nra).
  assert (T := fl_lower (fl (x * x) + fl (y * y)) ltac:(lra)).
  assert (0 <= fl (fl (x * x) + fl (y * y))) by (apply fl_nonneg; lra).
  assert (Hs := fl_lower (fl (fl (x * x) + fl (y * y)) + fl (z * z)) ltac:(lra)). fold s in Hs.
  assert (Hs' : (1 - 4 * u) * S <= s).
  { unfold S in *. assert (0 <= x * x) by nra. assert (0 <= y * y) by nra. assert (0 <= z * z) by nra.
    unfold u in *. nra. }
  assert (HS0 : 0 < S) by (pose proof (bpow_gt_0 radix2 (-1000)); lra).
  assert (Hr : (1 - 4 * u) * sqrt S <= sqrt s).
  { apply Rle_trans with (sqrt ((1 - 4 * u) * S)); [|apply sqrt_le_1_alt; exact Hs'].
    rewrite sqrt_mult by (unfold u; lra). apply Rmult_le_compat_r; [apply sqrt_pos|].
    assert (0 <= 1 - 4 * u <= 1) by (unfold u; lra).
    rewrite <- (sqrt_Rsqr (1 - 4 * u)) at 1 by lra. apply sqrt_le_1_alt. unfold Rsqr. nra. }
  assert (Hn := fl_lower (sqrt s) (sqrt_pos s)).
  assert (HsS : eta <= u * sqrt S).
  { (* sqrt S >= S when S <= 1, and sqrt S >= 1 >= S... : use sqrt S >= S / sqrt S... simply: *)
    destruct (Rle_or_lt S 1).
    - assert (S <= sqrt S).
      { rewrite <- (sqrt_Rsqr S) at 1 by lra. apply sqrt_le_1_alt. unfold Rsqr. nra. }
      nra.
    - assert (1 <= sqrt S) by (rewrite <- sqrt_1; apply sqrt_le_1_alt; lra).
      unfold eta in *. apply Rle_trans with (bpow radix2 (-1075)); [lra|].
      apply Rle_trans with u; [|nra]. unfold u. replace (/ 9007199254740992) with (bpow radix2 (-53)) by (simpl; lra).
      apply bpow_le; lia. }
  pose proof one_plus_rel.
  assert (0 <= sqrt S) by apply sqrt_pos.
  assert (Hn' : (1 - 6 * u) * sqrt S <= fl (sqrt s)) by (unfold u in *; nra).
  apply up_ge. unfold u in *. nra.
Qed.

(* The theorems, each answered by tools/check_proofs.sh. *)
Print Assumptions linear_corner_rounding.
Print Assumptions linear_corner_selection.
Print Assumptions linear_corner_error_bound.
Print Assumptions norm_relative_rounding.
