(* The named error allowances of optimized/gauss6/numeric/error_allowances.h,
   proved in Flocq: for each, the rounding error of the expression at its
   sites, evaluated as the code evaluates it (the same operations in the same
   order, each rounded to nearest binary64: Rounding.v's `fl`), is within the
   allowance, under the stated magnitude hypotheses. Same model as Rounding.v
   (finite results, gradual underflow, no fused multiply-add unless said). *)

From Coq Require Import Reals Psatz.
From Coq Require Import List.
Import ListNotations.
From Flocq Require Import Core Relative Plus_error.
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

(* finite_of HF x as Fx: Fx : F x from HF : forall y, In y [...] -> F y, x one
   of the list's values (the theorems take their doubles as one such list). *)
Tactic Notation "finite_of" constr(HF) constr(x) "as" ident(H) :=
  assert (H : F x) by (apply HF; simpl; tauto).

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
   The code (ccd/linear_queries.cpp): make_linear_points computes dx = fl(x1 - x0) per
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

(* covers optimized/gauss6/ccd/linear_queries.cpp "LinearPoints make_linear_points(" sha256:badaaa4fc2f7da52 *)
(* covers optimized/gauss6/ccd/linear_queries.cpp "void enclose_linear(" sha256:b914611386face38 *)
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
(* covers optimized/gauss6/ccd/linear_queries.cpp "void enclose_linear(" sha256:b914611386face38 *)
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
(* covers optimized/gauss6/ccd/linear_queries.cpp "LinearPoints make_linear_points(" sha256:badaaa4fc2f7da52 *)
Theorem linear_corner_error_bound M :
  0 <= M ->
  kLinearCornerRounding * M + kLinearCornerUnderflow
    <= next_up (fl (next_up (fl (kLinearCornerRounding * M)) + kLinearCornerUnderflow)).
Proof.
  intros HM. apply upper_add; [|lra].
  apply next_up_ge.
Qed.


(* ---- kRelativeRounding, kRelativeRoundingWide and kNormFloor at the norm sites ----
   rounding.h's norm_up(n, k) = max(round_up(n (1 + k)), Upper{kNormFloor})
   and norm_down(n, k) = (d > kNormFloor ? d : 0), d = round_down(n (1 - k)),
   with n the computed norm of a double 3-vector v: Eigen's v.norm() (or
   std::sqrt(v.squaredNorm())), the square root of the sum of the three rounded
   squares. The statements are symmetric in x, y, z, so they hold for any order
   of the sum. The constant 1 + k is the double fl(1 + fl(k)) (the compiler
   folds it, rounding to nearest). No fused multiply-add (x86-64 without FMA
   in the build's flags).
   Below |v|^2 = 2^-1000 the squares underflow and the computed norm may be 0
   for a vector of norm 2^-537: the floor kNormFloor speaks there (this was a
   finding: the form without it, round_up(n (1 + k)), fell 2^63 times below
   |v| at such a v, and round_down(n (1 - k)) was <= 0, a divisor of
   Upper / Lower whose double must be > 0). *)
(* allowance kRelativeRounding = 1e-15 *)
Definition kRelativeRounding := fl (/ 1000000000000000).
(* allowance kRelativeRoundingWide = 1e-12 *)
Definition kRelativeRoundingWide := fl (/ 1000000000000).

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

(* The folded constants: fl(1 + 1e-15) >= 1 + 8 u, fl(1 + 1e-12) >= 1 + 8 u,
   0 <= fl(1 - 1e-12) <= 1 - 8 u. *)
Lemma one_plus_fl c : / 1000000000000000 <= c <= 1 -> 1 + 8 * u <= fl (1 + fl c).
Proof.
  intros Hc. pose proof eta_pos. pose proof eta_small.
  assert (bpow radix2 (-1022) <= / 1000000000000000000) by (simpl; lra).
  assert (Hk : (1 - u) * c - eta <= fl c) by (apply fl_lower; lra).
  assert (0 <= fl c) by (apply fl_nonneg; lra).
  pose proof (fl_lower (1 + fl c) ltac:(lra)).
  unfold u in *. lra.
Qed.
Lemma one_plus_relative : 1 + 8 * u <= fl (1 + kRelativeRounding).
Proof. apply one_plus_fl. lra. Qed.
Lemma one_plus_wide : 1 + 8 * u <= fl (1 + kRelativeRoundingWide).
Proof. apply one_plus_fl. lra. Qed.
Lemma one_minus_wide : 0 <= fl (1 - kRelativeRoundingWide) <= 1 - 8 * u.
Proof.
  pose proof eta_pos. pose proof eta_small.
  assert (bpow radix2 (-1022) <= / 1000000000000000000) by (simpl; lra).
  assert (Hk : (1 - u) * / 1000000000000 - eta <= kRelativeRoundingWide) by (apply fl_lower; lra).
  assert (Hk' : kRelativeRoundingWide <= (1 + u) * / 1000000000000 + eta) by (apply fl_upper; lra).
  split; [apply fl_nonneg; unfold u in *; lra|].
  pose proof (fl_upper (1 - kRelativeRoundingWide) ltac:(unfold u in *; lra)).
  unfold u in *. lra.
Qed.

Lemma bpow_m53 : u = bpow radix2 (-53).
Proof. unfold u; simpl; lra. Qed.

(* S >= 2^-1002: the absolute errors of underflow, eta, are below 2^-20 u S. *)
Lemma eta_rel S : bpow radix2 (-1002) <= S -> 1000000 * eta <= u * S.
Proof.
  intros HS. pose proof eta_pos. assert (0 < u) by (unfold u; lra).
  apply Rle_trans with (u * bpow radix2 (-1002)); [|apply Rmult_le_compat_l; lra].
  rewrite bpow_m53, <- bpow_plus. unfold eta.
  apply Rle_trans with (bpow radix2 20 * bpow radix2 (-1075)).
  - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
  - rewrite <- bpow_plus. apply bpow_le. lia.
Qed.

(* The sum of the three rounded squares, from below and from above. *)
Lemma mul_le_l k a b : 0 <= k -> a <= b -> k * a <= k * b.
Proof. intros; apply Rmult_le_compat_l; assumption. Qed.
Lemma sumsq_lower x y z : let S := x * x + y * y + z * z in
  bpow radix2 (-1002) <= S -> (1 - 4 * u) * S <= fl (fl (fl (x * x) + fl (y * y)) + fl (z * z)).
Proof.
  intros S HS. pose proof (eta_rel S HS). pose proof eta_pos. assert (0 < u < / 1000000) by (unfold u; lra).
  assert (0 <= x * x) by nra. assert (0 <= y * y) by nra. assert (0 <= z * z) by nra.
  pose proof (fl_lower (x * x) ltac:(lra)). pose proof (fl_lower (y * y) ltac:(lra)).
  pose proof (fl_lower (z * z) ltac:(lra)).
  set (a := fl (x * x)) in *; set (b := fl (y * y)) in *; set (c := fl (z * z)) in *.
  assert (0 <= a) by (apply fl_nonneg; lra). assert (0 <= b) by (apply fl_nonneg; lra).
  assert (0 <= c) by (apply fl_nonneg; lra).
  pose proof (fl_lower (a + b) ltac:(lra)). set (t := fl (a + b)) in *.
  assert (0 <= t) by (apply fl_nonneg; lra).
  pose proof (fl_lower (t + c) ltac:(lra)).
  assert (K1 : (1 - u) * S - 3 * eta <= a + b + c) by (unfold S; lra).
  assert (K2 : (1 - u) * (a + b) - eta + c <= t + c) by lra.
  assert (K3 : (1 - u) * ((1 - u) * (a + b) - eta + c) - eta <= fl (t + c))
    by (apply Rle_trans with ((1 - u) * (t + c) - eta); [assert ((1 - u) * ((1 - u) * (a + b) - eta + c) <= (1 - u) * (t + c)) by (apply mul_le_l; lra); lra | lra]).
  assert (0 <= (1 - u) * u * c) by (apply Rmult_le_pos; [nra | lra]).
  assert (K4 : (1 - u) * (1 - u) * (a + b + c) - 2 * eta <= (1 - u) * ((1 - u) * (a + b) - eta + c) - eta) by nra.
  assert (K5 : (1 - u) * (1 - u) * ((1 - u) * S - 3 * eta) <= (1 - u) * (1 - u) * (a + b + c))
    by (apply mul_le_l; [nra | lra]).
  assert (0 <= S) by (pose proof (bpow_ge_0 radix2 (-1002)); lra).
  assert (Q1 : (1 - 3 * u) * S <= (1 - u) * (1 - u) * (1 - u) * S)
    by (apply Rmult_le_compat_r; [lra | nra]).
  assert (Q2 : (1 - u) * (1 - u) * eta <= 1 * eta) by (apply Rmult_le_compat_r; nra).
  assert (u * eta <= / 1000 * eta) by (apply Rmult_le_compat_r; lra).
  lra.
Qed.
Lemma sumsq_upper x y z : let S := x * x + y * y + z * z in
  fl (fl (fl (x * x) + fl (y * y)) + fl (z * z)) <= (1 + 4 * u) * S + 6 * eta.
Proof.
  intros S. pose proof eta_pos. assert (0 < u < / 1000000) by (unfold u; lra).
  assert (0 <= x * x) by nra. assert (0 <= y * y) by nra. assert (0 <= z * z) by nra.
  pose proof (fl_upper (x * x) ltac:(lra)). pose proof (fl_upper (y * y) ltac:(lra)).
  pose proof (fl_upper (z * z) ltac:(lra)).
  set (a := fl (x * x)) in *; set (b := fl (y * y)) in *; set (c := fl (z * z)) in *.
  assert (0 <= a) by (apply fl_nonneg; lra). assert (0 <= b) by (apply fl_nonneg; lra).
  assert (0 <= c) by (apply fl_nonneg; lra).
  pose proof (fl_upper (a + b) ltac:(lra)). set (t := fl (a + b)) in *.
  assert (0 <= t) by (apply fl_nonneg; lra).
  pose proof (fl_upper (t + c) ltac:(lra)).
  assert (K1 : a + b + c <= (1 + u) * S + 3 * eta) by (unfold S; lra).
  assert (K3 : fl (t + c) <= (1 + u) * ((1 + u) * (a + b) + eta + c) + eta)
    by (apply Rle_trans with ((1 + u) * (t + c) + eta); [lra | assert ((1 + u) * (t + c) <= (1 + u) * ((1 + u) * (a + b) + eta + c)) by (apply mul_le_l; lra); lra]).
  assert (K4 : (1 + u) * ((1 + u) * (a + b) + eta + c) + eta <= (1 + u) * (1 + u) * (a + b + c) + (2 + u) * eta) by nra.
  assert (K5 : (1 + u) * (1 + u) * (a + b + c) <= (1 + u) * (1 + u) * ((1 + u) * S + 3 * eta))
    by (apply mul_le_l; [nra | lra]).
  assert (0 <= S) by (unfold S; lra).
  assert (Q1 : (1 + u) * (1 + u) * (1 + u) * S <= (1 + 4 * u) * S) by (apply Rmult_le_compat_r; nra).
  assert (Q2 : (1 + u) * (1 + u) * eta <= (1 + / 1000) * eta) by (apply Rmult_le_compat_r; nra).
  assert (u * eta <= / 1000 * eta) by (apply Rmult_le_compat_r; lra).
  lra.
Qed.

(* sqrt (2^-2e) = 2^-e. *)
Lemma sqrt_bpow2 e : sqrt (bpow radix2 (2 * e)) = bpow radix2 e.
Proof.
  replace (2 * e)%Z with (e + e)%Z by lia. rewrite bpow_plus.
  apply sqrt_square. apply bpow_ge_0.
Qed.
Lemma sqrt_scale k S : 0 <= k -> 0 <= S -> sqrt (k * k * S) = k * sqrt S.
Proof. intros. rewrite sqrt_mult by nra. rewrite sqrt_square by lra. reflexivity. Qed.

(* A norm N >= 2^-501: the absolute errors of underflow, eta, are below
   2^-20 u N. *)
Lemma eta_norm N : bpow radix2 (-501) <= N -> 1000000 * eta <= u * N.
Proof.
  intros HN. pose proof eta_pos. assert (0 < u) by (unfold u; lra).
  apply Rle_trans with (u * bpow radix2 (-501)); [|apply Rmult_le_compat_l; lra].
  rewrite bpow_m53, <- bpow_plus. unfold eta.
  apply Rle_trans with (bpow radix2 20 * bpow radix2 (-1075)).
  - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
  - rewrite <- bpow_plus. apply bpow_le. lia.
Qed.

Definition norm_c x y z := fl (sqrt (fl (fl (fl (x * x) + fl (y * y)) + fl (z * z)))).

(* allowance kNormFloor = 0x1p-500 *)
Definition kNormFloor := bpow radix2 (-500).

Theorem norm_upper_bound x y z k : 1 + 8 * u <= k ->
  sqrt (x * x + y * y + z * z) <= Rmax (next_up (fl (norm_c x y z * k))) kNormFloor.
Proof.
  intros Hk. set (S := x * x + y * y + z * z).
  assert (HS0 : 0 <= S) by (unfold S; nra).
  destruct (Rlt_or_le S (bpow radix2 (-1000))) as [Hs|Hs].
  - (* below the floor *)
    apply Rle_trans with kNormFloor; [|apply Rmax_r].
    unfold kNormFloor. rewrite <- (sqrt_bpow2 (-500)). apply sqrt_le_1_alt. simpl (2 * -500)%Z. lra.
  - apply Rle_trans with (next_up (fl (norm_c x y z * k))); [|apply Rmax_l].
    assert (HS2 : bpow radix2 (-1002) <= S)
      by (eapply Rle_trans; [apply bpow_le with (e2 := (-1000)%Z); lia | exact Hs]).
    pose proof (sumsq_lower x y z HS2) as Hs'. fold S in Hs'.
    set (s := fl (fl (fl (x * x) + fl (y * y)) + fl (z * z))) in *.
    pose proof eta_pos. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
    set (N := sqrt S).
    assert (HN : bpow radix2 (-500) <= N)
      by (unfold N; rewrite <- (sqrt_bpow2 (-500)); apply sqrt_le_1_alt; exact Hs).
    assert (HeN : 1000000 * eta <= u * N)
      by (apply eta_norm; eapply Rle_trans; [apply bpow_le with (e2 := (-500)%Z); lia | exact HN]).
    assert (HN0 : 0 <= N) by apply sqrt_pos.
    assert (Hr : (1 - 3 * u) * N <= sqrt s).
    { unfold N. rewrite <- sqrt_scale by lra. apply sqrt_le_1_alt.
      apply Rle_trans with ((1 - 4 * u) * S); [apply Rmult_le_compat_r; nra | exact Hs']. }
    pose proof (fl_lower (sqrt s) (sqrt_pos s)) as Hf.
    assert (Hf' : (1 - 5 * u) * N <= fl (sqrt s)).
    { assert ((1 - u) * ((1 - 3 * u) * N) <= (1 - u) * sqrt s) by (apply mul_le_l; lra).
      assert ((1 - 4 * u) * N <= ((1 - u) * (1 - 3 * u)) * N) by (apply Rmult_le_compat_r; nra).
      lra. }
    fold (norm_c x y z) in Hf'. unfold norm_c in *. fold s in Hf'.
    assert (Hp : (1 + 2 * u) * N <= fl (sqrt s) * k).
    { apply Rle_trans with (((1 - 5 * u) * N) * (1 + 8 * u)).
      - assert (0 <= (1 + 2 * u) * N) by nra. apply Rle_trans with ((1 - 5 * u) * (1 + 8 * u) * N).
        + apply Rmult_le_compat_r; nra.
        + lra.
      - apply Rmult_le_compat; nra. }
    pose proof (fl_lower (fl (sqrt s) * k) ltac:(nra)) as Hq.
    assert ((1 - u) * ((1 + 2 * u) * N) <= (1 - u) * (fl (sqrt s) * k)) by (apply mul_le_l; lra).
    assert ((1 + / 2 * u) * N <= ((1 - u) * (1 + 2 * u)) * N) by (apply Rmult_le_compat_r; nra).
    apply Rle_trans with (fl (fl (sqrt s) * k)); [|apply next_up_ge_F, F_fl]. lra.
Qed.

Theorem norm_lower_bound x y z k : 0 <= k <= 1 - 8 * u ->
  let d := next_down (fl (norm_c x y z * k)) in
  (if Rlt_dec kNormFloor d then d else 0) <= sqrt (x * x + y * y + z * z).
Proof.
  intros Hk d. set (S := x * x + y * y + z * z).
  assert (HS0 : 0 <= S) by (unfold S; nra). pose proof eta_pos. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  unfold norm_c in d. set (s := fl (fl (fl (x * x) + fl (y * y)) + fl (z * z))) in *.
  pose proof (sumsq_upper x y z) as Hs'. fold S s in Hs'.
  assert (Hd : d <= fl (fl (sqrt s) * k)) by (apply next_down_le_F, F_fl).
  destruct (Rlt_or_le S (bpow radix2 (-1002))) as [Hs|Hs].
  - (* d is at most the floor: the result is 0 *)
    assert (He : 6 * eta <= bpow radix2 (-1002)).
    { unfold eta. apply Rle_trans with (bpow radix2 3 * bpow radix2 (-1075)).
      - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
      - rewrite <- bpow_plus. apply bpow_le. lia. }
    assert (Hb : bpow radix2 (-1000) = 4 * bpow radix2 (-1002))
      by (replace (-1000)%Z with (2 + -1002)%Z by lia; rewrite bpow_plus; simpl; lra).
    assert (Hss : s <= bpow radix2 (2 * -500)).
    { simpl (2 * -500)%Z. rewrite Hb. assert (4 * u * S <= bpow radix2 (-1002)) by nra. nra. }
    assert (Hq : sqrt s <= kNormFloor) by (unfold kNormFloor; rewrite <- sqrt_bpow2; apply sqrt_le_1_alt; exact Hss).
    assert (HF : F kNormFloor) by (apply generic_format_bpow; unfold FLT_exp; lia).
    assert (Hq' : fl (sqrt s) <= kNormFloor) by (apply fl_le_F; assumption).
    assert (0 <= fl (sqrt s)) by (apply fl_nonneg, sqrt_pos).
    assert (0 < kNormFloor) by apply bpow_gt_0.
    assert (fl (fl (sqrt s) * k) <= kNormFloor) by (apply fl_le_F; [exact HF | nra]).
    destruct (Rlt_dec kNormFloor d); [lra | apply sqrt_pos].
  - assert (d <= sqrt S).
    { pose proof (eta_rel S Hs) as HeS. set (N := sqrt S).
      assert (HN0 : 0 <= N) by apply sqrt_pos.
      assert (HN : bpow radix2 (-501) <= N).
      { unfold N. rewrite <- (sqrt_bpow2 (-501)). apply sqrt_le_1_alt. simpl (2 * -501)%Z. exact Hs. }
      assert (HeN : 1000000 * eta <= u * N) by (apply eta_norm; exact HN).
      assert (Hr : sqrt s <= (1 + 3 * u) * N).
      { unfold N. rewrite <- sqrt_scale by lra. apply sqrt_le_1_alt.
        apply Rle_trans with ((1 + 5 * u) * S); [nra | apply Rmult_le_compat_r; nra]. }
      pose proof (fl_upper (sqrt s) (sqrt_pos s)) as Hf.
      assert (Hf' : fl (sqrt s) <= (1 + 5 * u) * N).
      { assert ((1 + u) * sqrt s <= (1 + u) * ((1 + 3 * u) * N)) by (apply mul_le_l; lra).
        assert (((1 + u) * (1 + 3 * u)) * N <= (1 + 9 / 2 * u) * N) by (apply Rmult_le_compat_r; nra).
        lra. }
      assert (0 <= fl (sqrt s)) by (apply fl_nonneg, sqrt_pos).
      assert (Hp : fl (sqrt s) * k <= (1 - 2 * u) * N).
      { apply Rle_trans with (((1 + 5 * u) * N) * (1 - 8 * u)).
        - apply Rmult_le_compat; lra.
        - apply Rle_trans with ((1 + 5 * u) * (1 - 8 * u) * N); [lra | apply Rmult_le_compat_r; nra]. }
      pose proof (fl_upper (fl (sqrt s) * k) ltac:(nra)) as Hq.
      assert ((1 + u) * (fl (sqrt s) * k) <= (1 + u) * ((1 - 2 * u) * N)) by (apply mul_le_l; lra).
      assert (((1 + u) * (1 - 2 * u)) * N <= (1 - / 2 * u) * N) by (apply Rmult_le_compat_r; nra).
      lra. }
    destruct (Rlt_dec kNormFloor d); [assumption | apply sqrt_pos].
Qed.

(* The code's forms, at its sites. *)
(* covers optimized/gauss6/numeric/rounding.h "GAUSS6_ALWAYS_INLINE Upper norm_up(double norm, double relative)" sha256:b4b3280a1e614758 *)
(* covers optimized/gauss6/ccd/motion_bounds.cpp "void StartFrame::set(const CcdMotion& m, double u, double rho_in)" sha256:cfac9ee869768b2c *)
(* covers optimized/gauss6/ccd/motion_bounds.h "PosedObb pose_checked(const Obb& b, bool check_frame) const" sha256:3c631a4b53f4d403 *)
(* covers optimized/gauss6/ccd/motion_bounds.h "double radius(double r2) const" sha256:6689317b141e2024 *)
Theorem norm_up_relative x y z :
  sqrt (x * x + y * y + z * z) <= Rmax (next_up (fl (norm_c x y z * fl (1 + kRelativeRounding)))) kNormFloor.
Proof. apply norm_upper_bound, one_plus_relative. Qed.

(* covers optimized/gauss6/numeric/rounding.h "GAUSS6_ALWAYS_INLINE Upper norm_up(double norm, double relative)" sha256:b4b3280a1e614758 *)
(* covers optimized/gauss6/geometry/distance.h "GAUSS6_ALWAYS_INLINE void for_each_separating_axis(const SatSide& A" sha256:f9abadb85b78baa3 *)
Theorem norm_up_wide x y z :
  sqrt (x * x + y * y + z * z) <= Rmax (next_up (fl (norm_c x y z * fl (1 + kRelativeRoundingWide)))) kNormFloor.
Proof. apply norm_upper_bound, one_plus_wide. Qed.

(* covers optimized/gauss6/numeric/rounding.h "GAUSS6_ALWAYS_INLINE Lower norm_down(double norm, double relative)" sha256:981268e19c3ba706 *)
(* covers optimized/gauss6/ccd/motion_bounds.h "inline double triangle_time_lower_bound(const SatSide& A, const Vec3 r[3]" sha256:e6fe43232891e550 *)
Theorem norm_down_wide x y z :
  let d := next_down (fl (norm_c x y z * fl (1 - kRelativeRoundingWide))) in
  (if Rlt_dec kNormFloor d then d else 0) <= sqrt (x * x + y * y + z * z).
Proof. apply norm_lower_bound, one_minus_wide. Qed.

(* next_up moves a nonnegative r up by at least 2^-602 (its widening is at
   least kTiny = 2^-600 and at least about 2 u r). *)
Lemma next_up_plus r : 0 <= r -> r + bpow radix2 (-602) <= next_up r.
Proof.
  intros Hr. unfold next_up, widening. rewrite Rabs_pos_eq by exact Hr.
  pose proof eta_pos. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  assert (HU : kUlp = 2 * u) by (unfold kUlp, u; simpl; lra).
  rewrite HU.
  assert (HT : bpow radix2 (-600) = 4 * bpow radix2 (-602))
    by (replace (-600)%Z with (2 + -602)%Z by lia; rewrite bpow_plus; simpl; lra).
  assert (He : 1000 * eta <= bpow radix2 (-602)).
  { unfold eta. apply Rle_trans with (bpow radix2 10 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  assert (0 <= r * (2 * u)) by nra.
  pose proof (fl_lower (r * (2 * u)) ltac:(lra)) as G1.
  assert (0 <= fl (r * (2 * u))) by (apply fl_nonneg; lra).
  assert (HFt : F kTiny) by (apply generic_format_bpow; unfold FLT_exp; lia).
  assert (Hk : 0 < kTiny) by apply bpow_gt_0.
  set (t := fl (fl (r * (2 * u)) + kTiny)).
  assert (T1 : kTiny <= t) by (apply fl_ge_F; [exact HFt | lra]).
  assert (T2 : fl (r * (2 * u)) <= t) by (apply fl_ge_F; [apply F_fl | lra]).
  pose proof (fl_lower (r + t) ltac:(lra)) as G2.
  unfold kTiny in T1. rewrite HT in T1.
  set (B := bpow radix2 (-602)) in *.
  assert (Q1 : 3 / 5 * (1 - u) * ((1 - u) * (2 * u) * r - eta) <= 3 / 5 * (1 - u) * t)
    by (apply mul_le_l; lra).
  assert (Q2 : 2 / 5 * (1 - u) * (4 * B) <= 2 / 5 * (1 - u) * t) by (apply mul_le_l; lra).
  assert (Q3 : u * r <= (3 / 5 * (1 - u) * (1 - u) * (2 * u)) * r) by (apply Rmult_le_compat_r; nra).
  assert (Q4 : u * B <= / 1000000 * B) by (apply Rmult_le_compat_r; lra).
  assert (Q5 : 0 <= u * eta) by nra.
  lra.
Qed.

(* A sum or difference of two doubles rounds within u of itself, relatively
   (no underflow term: below the normal range it is exact). *)
Lemma sub_rel x y : F x -> F y -> Rabs (fl (x - y) - (x - y)) <= u * Rabs (x - y).
Proof.
  intros Fx Fy.
  destruct (FLT_plus_error_N_ex radix2 (-1074) 53 (fun t => negb (Z.even t)) x (- y) Fx (F_opp y Fy))
    as (eps & He & E).
  unfold fl. change (round radix2 (FLT_exp (-1074) 53) ZnearestE (x - y))
    with (round radix2 (FLT_exp (-1074) 53) (Znearest (fun t => negb (Z.even t))) (x + - y)).
  rewrite E. replace ((x + - y) * (1 + eps) - (x - y)) with ((x - y) * eps) by ring.
  rewrite Rabs_mult, Rmult_comm. apply Rmult_le_compat_r; [apply Rabs_pos|].
  assert (Hu : u_ro radix2 53 = u) by (unfold u_ro, u; simpl; lra).
  rewrite Hu in He. assert (0 < u) by (unfold u; lra).
  eapply Rle_trans; [exact He|]. apply Rmult_le_reg_r with (1 + u); [lra|].
  unfold Rdiv. rewrite Rmult_assoc, Rinv_l by lra. nra.
Qed.

(* A decimal allowance c >= 1e-15, rounded to its double, is at least k u
   whenever (1 - u) c - 2^-1000 is. *)
Lemma fl_decimal_ge c k : / 1000000000000000 <= c -> k * u <= (1 - u) * c - bpow radix2 (-1000) -> k * u <= fl c.
Proof.
  intros Hc Hk. pose proof eta_pos.
  assert (eta <= bpow radix2 (-1000)) by (unfold eta; apply bpow_le; lia).
  assert ((1 - u) * c - eta <= fl c) by (apply fl_lower; lra). lra.
Qed.
Lemma bpow_m1000 : bpow radix2 (-1000) <= / 1000000000000000000000000.
Proof. simpl; lra. Qed.
Lemma kRelativeRounding_ge : 9 * u <= kRelativeRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.

(* ---- kRelativeRounding at the sub-interval's step ----
   StartFrame::obb_frame: step = (u1 - u0) * dp_mid, each coordinate the
   double fl(fl(u1 - u0) d) (u0, u1, d doubles), and its rounding covered by
   step_error = round_up(kRelativeRounding * m * 2), m = |step|_inf (the
   computed coordinates' largest magnitude, exact): within it of the exact
   (u1 - u0) d, for every double input (the underflow of the product, eta,
   is covered by next_up's absolute 2^-600). *)
(* covers optimized/gauss6/ccd/motion_bounds.cpp "SweptObbFrame StartFrame::obb_frame(double u1, double d) const" sha256:1da7beb7e3e9eb96 *)
Theorem step_rounding u0 u1 d m :
  F u0 -> F u1 -> F d -> Rabs (fl (fl (u1 - u0) * d)) <= m ->
  Rabs (fl (fl (u1 - u0) * d) - (u1 - u0) * d) <= next_up (fl (fl (kRelativeRounding * m) * 2)).
Proof.
  intros F0 F1 Fd Hm. pose proof eta_pos. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  assert (He : 1000 * eta <= bpow radix2 (-602)).
  { unfold eta. apply Rle_trans with (bpow radix2 10 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  pose proof (sub_rel u1 u0 F1 F0) as Ha. set (a := u1 - u0) in *. set (fa := fl a) in *.
  pose proof (fl_err (fa * d)) as Hs. set (s := fl (fa * d)) in *.
  set (X := Rabs (fa * d)) in *. set (Y := Rabs (a * d)).
  assert (HX0 : 0 <= X) by apply Rabs_pos. assert (HY0 : 0 <= Y) by apply Rabs_pos.
  assert (Hm0 : 0 <= m) by (pose proof (Rabs_pos s); lra).
  (* |fa d - a d| <= u Y; (1 - u) Y <= X; (1 - u) X - eta <= |s| <= m *)
  assert (E1 : Rabs (fa * d - a * d) <= u * Y).
  { unfold Y. replace (fa * d - a * d) with ((fa - a) * d) by ring. rewrite !Rabs_mult.
    rewrite <- Rmult_assoc. apply Rmult_le_compat_r; [apply Rabs_pos | exact Ha]. }
  assert (E2 : (1 - u) * Y <= X).
  { assert (Rabs a - Rabs fa <= u * Rabs a)
      by (pose proof (Rabs_triang_inv a fa); rewrite Rabs_minus_sym in Ha; lra).
    unfold X, Y. rewrite !Rabs_mult.
    assert (0 <= Rabs d) by apply Rabs_pos.
    assert ((1 - u) * Rabs a <= Rabs fa) by lra.
    apply Rle_trans with (((1 - u) * Rabs a) * Rabs d); [lra | apply Rmult_le_compat_r; assumption]. }
  assert (E3 : (1 - u) * X - eta <= m).
  { pose proof (Rabs_triang_inv (fa * d) (s - fa * d)).
    replace (fa * d - (s - fa * d)) with (2 * (fa * d) - s) in * by ring.
    assert (X - Rabs s <= u * X + eta).
    { pose proof (Rabs_triang_inv (fa * d) s). rewrite Rabs_minus_sym in Hs.
      unfold X in *. lra. }
    lra. }
  assert (Q1 : u * X <= / 1000000 * X) by (apply Rmult_le_compat_r; lra).
  assert (Q2 : u * Y <= / 1000000 * Y) by (apply Rmult_le_compat_r; lra).
  assert (B1 : X <= 100001 / 100000 * (m + eta)) by lra.
  assert (B2 : Y <= 10001 / 10000 * (m + eta)) by lra.
  assert (C1 : u * X <= u * (100001 / 100000 * (m + eta))) by (apply mul_le_l; lra).
  assert (C2 : u * Y <= u * (10001 / 10000 * (m + eta))) by (apply mul_le_l; lra).
  assert (Err : Rabs (s - a * d) <= 21 / 10 * u * m + 2 * eta).
  { replace (s - a * d) with ((s - fa * d) + (fa * d - a * d)) by ring.
    eapply Rle_trans; [apply Rabs_triang|].
    assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra). assert (0 <= u * m) by nra. unfold X in *. lra. }
  (* the bound: at least 17.9 u m - 3 eta + 2^-602 *)
  pose proof kRelativeRounding_ge as Hk.
  assert (K1 : 9 * u * m <= kRelativeRounding * m) by (apply Rmult_le_compat_r; lra).
  assert (0 <= kRelativeRounding * m) by nra.
  pose proof (fl_lower (kRelativeRounding * m) ltac:(lra)) as K2.
  assert (0 <= fl (kRelativeRounding * m)) by (apply fl_nonneg; lra).
  pose proof (fl_lower (fl (kRelativeRounding * m) * 2) ltac:(lra)) as K3.
  assert (0 <= fl (fl (kRelativeRounding * m) * 2)) by (apply fl_nonneg; lra).
  pose proof (next_up_plus _ ltac:(eassumption)) as K4.
  assert (K5 : (1 - u) * ((1 - u) * (9 * u * m)) <= (1 - u) * fl (kRelativeRounding * m) + (1 - u) * eta).
  { assert ((1 - u) * (9 * u * m) <= (1 - u) * (kRelativeRounding * m)) by (apply mul_le_l; lra).
    assert ((1 - u) * ((1 - u) * (kRelativeRounding * m) - eta) <= (1 - u) * fl (kRelativeRounding * m))
      by (apply mul_le_l; lra).
    assert ((1 - u) * ((1 - u) * (9 * u * m)) <= (1 - u) * ((1 - u) * (kRelativeRounding * m)))
      by (apply mul_le_l; lra).
    lra. }
  assert (K6 : 89 / 10 * (u * m) <= ((1 - u) * (1 - u) * 9) * (u * m)) by (apply Rmult_le_compat_r; nra).
  assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (0 <= u * eta) by nra. assert (0 <= u * m) by nra.
  lra.
Qed.

Lemma add_rel x y : F x -> F y -> Rabs (fl (x + y) - (x + y)) <= u * Rabs (x + y).
Proof.
  intros Fx Fy. replace (x + y) with (x - - y) by ring. apply sub_rel; [exact Fx | apply F_opp, Fy].
Qed.
Lemma fl_lower_normal z : bpow radix2 (-1022) <= z -> (1 - u) * z <= fl z.
Proof.
  intros Hz. assert (0 < z) by (pose proof (bpow_gt_0 radix2 (-1022)); lra).
  pose proof (relative_error_N_FLT radix2 (-1074) 53 ltac:(lia) (fun t => negb (Z.even t)) z) as G.
  rewrite (Rabs_pos_eq z) in G by lra.
  assert (Hb : bpow radix2 (-1074 + 53 - 1) = bpow radix2 (-1022)) by (f_equal; lia).
  rewrite Hb in G. specialize (G Hz).
  assert (Hu : / 2 * bpow radix2 (- (53) + 1) = u) by (unfold u; simpl; lra). rewrite Hu in G.
  unfold fl. change ZnearestE with (Znearest (fun t => negb (Z.even t))).
  unfold Rabs in G; destruct Rcase_abs; lra.
Qed.

(* The dot product of two double 3-vectors, (a0 v0 + a1 v1) + a2 v2 rounded
   at each step, within 3.02 u T + 5.02 eta of the exact one, T the sum of the
   terms' magnitudes (any order of the three terms: the statement is symmetric). *)
Definition dot3 a0 a1 a2 v0 v1 v2 := fl (fl (fl (a0 * v0) + fl (a1 * v1)) + fl (a2 * v2)).
Lemma dot3_err a0 a1 a2 v0 v1 v2 :
  let T := Rabs (a0 * v0) + Rabs (a1 * v1) + Rabs (a2 * v2) in
  Rabs (dot3 a0 a1 a2 v0 v1 v2 - (a0 * v0 + a1 * v1 + a2 * v2)) <= 302 / 100 * u * T + 502 / 100 * eta.
Proof.
  intros T. pose proof eta_pos. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  pose proof (fl_err (a0 * v0)). pose proof (fl_err (a1 * v1)). pose proof (fl_err (a2 * v2)).
  pose proof (Rabs_pos (a0 * v0)). pose proof (Rabs_pos (a1 * v1)). pose proof (Rabs_pos (a2 * v2)).
  assert (S1 : Rabs (fl (fl (a0 * v0) + fl (a1 * v1)) - (a0 * v0 + a1 * v1))
               <= (u * (Rabs (a0 * v0) + Rabs (a1 * v1)) + 2 * eta)
                  + u * ((Rabs (a0 * v0) + Rabs (a1 * v1)) + (u * (Rabs (a0 * v0) + Rabs (a1 * v1)) + 2 * eta)) + eta).
  { apply step; [apply abs_sum_le; lra|].
    replace (fl (a0 * v0) + fl (a1 * v1) - (a0 * v0 + a1 * v1))
      with ((fl (a0 * v0) - a0 * v0) + (fl (a1 * v1) - a1 * v1)) by ring.
    eapply Rle_trans; [apply Rabs_triang | lra]. }
  set (T1 := Rabs (a0 * v0) + Rabs (a1 * v1)) in *.
  assert (0 <= u * T1) by (unfold T1; nra). assert (u * (u * T1) <= / 1000000 * (u * T1)) by (apply Rmult_le_compat_r; lra).
  assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (S1' : Rabs (fl (fl (a0 * v0) + fl (a1 * v1)) - (a0 * v0 + a1 * v1)) <= 201 / 100 * u * T1 + 301 / 100 * eta) by lra.
  assert (S2 : Rabs (dot3 a0 a1 a2 v0 v1 v2 - (a0 * v0 + a1 * v1 + a2 * v2))
     <= ((201 / 100 * u * T1 + 301 / 100 * eta) + (u * Rabs (a2 * v2) + eta))
        + u * (T + ((201 / 100 * u * T1 + 301 / 100 * eta) + (u * Rabs (a2 * v2) + eta))) + eta).
  { unfold dot3. apply step.
    - unfold T, T1. apply abs_sum_le; [apply abs_sum_le|]; lra.
    - replace (fl (fl (a0 * v0) + fl (a1 * v1)) + fl (a2 * v2) - (a0 * v0 + a1 * v1 + a2 * v2))
        with ((fl (fl (a0 * v0) + fl (a1 * v1)) - (a0 * v0 + a1 * v1)) + (fl (a2 * v2) - a2 * v2)) by ring.
      eapply Rle_trans; [apply Rabs_triang | lra]. }
  assert (0 <= u * T) by (unfold T; try unfold T1; nra). assert (u * (u * T) <= / 1000000 * (u * T)) by (apply Rmult_le_compat_r; lra).
  assert (u * Rabs (a2 * v2) <= u * T) by (apply mul_le_l; unfold T; try unfold T1; lra).
  assert (0 <= u * Rabs (a2 * v2)) by nra.
  assert (u * (u * Rabs (a2 * v2)) <= / 1000000 * (u * Rabs (a2 * v2))) by (apply Rmult_le_compat_r; lra).
  assert (u * T1 <= u * T) by (apply mul_le_l; unfold T, T1; lra).
  assert (u * T1 + u * Rabs (a2 * v2) = u * T) by (unfold T, T1; ring).
  lra.
Qed.

Lemma rel_lower z w : Rabs (z - w) <= u * w -> (1 - u) * w <= z.
Proof. intros H. pose proof (Rle_abs (w - z)). rewrite Rabs_minus_sym in H. lra. Qed.

(* ---- kAxisVelocityRounding ----
   triangle_time_lower_bound (motion_bounds.h), the velocity term of an axis a
   (doubles): along_v = side * a.dot(v) (side = +-1, exact), its slack
   kAxisVelocityRounding * a_1 * v_inf (a_1 = |a|_1 summed in doubles, v_inf =
   |v|_inf, exact), and toward = max(0, round_up(along_v)) + slack, rounded up:
   toward is at least the exact side (a . v). Hypothesis |a|_1 >= 2^-900: the
   axis is used only when norm_down(|a|) > 0 (the guard after it), which
   proves |a| > kNormFloor = 2^-500 (norm_down_wide). *)
(* allowance kAxisVelocityRounding = 1e-14 *)
Definition kAxisVelocityRounding := fl (/ 100000000000000).

Lemma kAxisVelocityRounding_ge : 90 * u <= kAxisVelocityRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.

Lemma fl_side side x : (side = 1 \/ side = -1) -> F x -> fl (side * x) = side * x.
Proof.
  intros [-> | ->] Fx.
  - rewrite Rmult_1_l. apply fl_F, Fx.
  - replace (-1 * x) with (- x) by ring. apply fl_F, F_opp, Fx.
Qed.

(* covers optimized/gauss6/ccd/motion_bounds.h "inline double triangle_time_lower_bound(const SatSide& A, const Vec3 r[3]" sha256:e6fe43232891e550 *)
Theorem axis_velocity_rounding side a0 a1 a2 v0 v1 v2 vinf :
  (side = 1 \/ side = -1) -> F a0 -> F a1 -> F a2 ->
  Rabs v0 <= vinf -> Rabs v1 <= vinf -> Rabs v2 <= vinf ->
  bpow radix2 (-900) <= Rabs a0 + Rabs a1 + Rabs a2 ->
  let along_v := fl (side * dot3 a0 a1 a2 v0 v1 v2) in
  let a_1 := fl (fl (Rabs a0 + Rabs a1) + Rabs a2) in
  let slack := fl (fl (kAxisVelocityRounding * a_1) * vinf) in
  side * (a0 * v0 + a1 * v1 + a2 * v2) <= next_up (fl (Rmax 0 (next_up along_v) + slack)).
Proof.
  intros Hside F0 F1 F2 V0 V1 V2 HA along_v a_1 slack.
  pose proof eta_pos. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  assert (HB : 1000 * eta <= bpow radix2 (-602)).
  { unfold eta. apply Rle_trans with (bpow radix2 10 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  set (B := bpow radix2 (-602)) in *.
  assert (Hv : 0 <= vinf) by (pose proof (Rabs_pos v0); lra).
  set (A := Rabs a0 + Rabs a1 + Rabs a2) in *.
  set (T := Rabs (a0 * v0) + Rabs (a1 * v1) + Rabs (a2 * v2)).
  assert (HT : T <= A * vinf).
  { unfold T, A. rewrite !Rabs_mult.
    pose proof (Rabs_pos a0). pose proof (Rabs_pos a1). pose proof (Rabs_pos a2).
    assert (Rabs a0 * Rabs v0 <= Rabs a0 * vinf) by (apply mul_le_l; lra).
    assert (Rabs a1 * Rabs v1 <= Rabs a1 * vinf) by (apply mul_le_l; lra).
    assert (Rabs a2 * Rabs v2 <= Rabs a2 * vinf) by (apply mul_le_l; lra). lra. }
  assert (HT0 : 0 <= T) by (unfold T; pose proof (Rabs_pos (a0 * v0)); pose proof (Rabs_pos (a1 * v1));
                            pose proof (Rabs_pos (a2 * v2)); lra).
  (* the computed dot product *)
  pose proof (dot3_err a0 a1 a2 v0 v1 v2) as Hd. fold T in Hd.
  set (dt := dot3 a0 a1 a2 v0 v1 v2) in *.
  assert (Fd : F dt) by apply F_fl.
  assert (Hc : along_v = side * dt) by (apply fl_side; assumption).
  set (E := side * (a0 * v0 + a1 * v1 + a2 * v2)).
  assert (HE : E <= along_v + (302 / 100 * u * T + 502 / 100 * eta)).
  { rewrite Hc. unfold E. pose proof (Rle_abs (dt - (a0 * v0 + a1 * v1 + a2 * v2))).
    pose proof (Rle_abs ((a0 * v0 + a1 * v1 + a2 * v2) - dt)). rewrite Rabs_minus_sym in H1.
    destruct Hside as [-> | ->]; lra. }
  (* a_1 >= (1 - u)^2 A *)
  assert (Fa0 : F (Rabs a0)) by (apply generic_format_abs, F0).
  assert (Fa1 : F (Rabs a1)) by (apply generic_format_abs, F1).
  assert (Fa2 : F (Rabs a2)) by (apply generic_format_abs, F2).
  pose proof (add_rel _ _ Fa0 Fa1) as G1. set (t := fl (Rabs a0 + Rabs a1)) in *.
  pose proof (add_rel _ _ (F_fl (Rabs a0 + Rabs a1)) Fa2) as G2. fold t in G2. fold a_1 in G2.
  pose proof (Rabs_pos a0). pose proof (Rabs_pos a1). pose proof (Rabs_pos a2).
  rewrite (Rabs_pos_eq (Rabs a0 + Rabs a1)) in G1 by lra.
  assert (Ht : (1 - u) * (Rabs a0 + Rabs a1) <= t) by (apply rel_lower; exact G1).
  assert (0 <= t) by nra.
  rewrite (Rabs_pos_eq (t + Rabs a2)) in G2 by lra.
  assert (Ha1 : (1 - u) * (t + Rabs a2) <= a_1) by (apply rel_lower; exact G2).
  assert (Ha1' : (1 - u) * (1 - u) * A <= a_1).
  { assert ((1 - u) * ((1 - u) * (Rabs a0 + Rabs a1) + Rabs a2) <= (1 - u) * (t + Rabs a2)) by (apply mul_le_l; lra).
    assert ((1 - u) * (1 - u) * Rabs a2 <= (1 - u) * Rabs a2) by (apply Rmult_le_compat_r; nra).
    unfold A. lra. }
  (* the slack, at least 89 u T - eta *)
  pose proof kAxisVelocityRounding_ge as Hk.
  assert (HA0 : 0 <= A) by (pose proof (bpow_ge_0 radix2 (-900)); lra).
  assert (Z1 : 90 * u * ((1 - u) * (1 - u) * A) <= kAxisVelocityRounding * a_1)
    by (apply Rmult_le_compat; nra).
  assert (Z2 : bpow radix2 (-1022) <= kAxisVelocityRounding * a_1).
  { apply Rle_trans with (90 * u * ((1 - u) * (1 - u) * A)); [|exact Z1].
    apply Rle_trans with (u * bpow radix2 (-900)).
    - rewrite bpow_m53, <- bpow_plus. apply bpow_le. lia.
    - assert (1 <= 90 * ((1 - u) * (1 - u))) by nra.
      assert (0 <= u * bpow radix2 (-900)) by (pose proof (bpow_ge_0 radix2 (-900)); nra).
      assert (u * bpow radix2 (-900) <= u * A) by (apply mul_le_l; lra).
      assert (u * A <= (90 * ((1 - u) * (1 - u))) * (u * A)) by (apply Rle_trans with (1 * (u * A)); [lra | apply Rmult_le_compat_r; nra]).
      lra. }
  pose proof (fl_lower_normal _ Z2) as Z3.
  assert (0 <= fl (kAxisVelocityRounding * a_1)) by (apply fl_nonneg; pose proof (bpow_ge_0 radix2 (-1022)); lra).
  pose proof (fl_lower (fl (kAxisVelocityRounding * a_1) * vinf) ltac:(nra)) as Z4. fold slack in Z4.
  assert (Z5 : (1 - u) * ((1 - u) * (kAxisVelocityRounding * a_1)) * vinf <= (1 - u) * (fl (kAxisVelocityRounding * a_1) * vinf)).
  { assert ((1 - u) * (kAxisVelocityRounding * a_1) * vinf <= fl (kAxisVelocityRounding * a_1) * vinf)
      by (apply Rmult_le_compat_r; lra).
    assert ((1 - u) * ((1 - u) * (kAxisVelocityRounding * a_1) * vinf) <= (1 - u) * (fl (kAxisVelocityRounding * a_1) * vinf))
      by (apply mul_le_l; lra).
    lra. }
  assert (Z6 : (1 - u) * ((1 - u) * (90 * u * ((1 - u) * (1 - u) * A))) * vinf
               <= (1 - u) * ((1 - u) * (kAxisVelocityRounding * a_1)) * vinf).
  { apply Rmult_le_compat_r; [lra|]. apply mul_le_l; [lra|]. apply mul_le_l; lra. }
  assert (Z7 : 89 * u * (A * vinf) <= (1 - u) * ((1 - u) * (90 * u * ((1 - u) * (1 - u) * A))) * vinf).
  { assert (0 <= u * (A * vinf)) by (apply Rmult_le_pos; [lra | apply Rmult_le_pos; lra]).
    assert (89 * (u * (A * vinf)) <= ((1 - u) * (1 - u) * (1 - u) * (1 - u) * 90) * (u * (A * vinf)))
      by (apply Rmult_le_compat_r; nra).
    lra. }
  assert (Hs : 89 * u * T - eta <= slack).
  { assert (u * T <= u * (A * vinf)) by (apply mul_le_l; lra). lra. }
  assert (Hs0 : 0 <= slack) by (apply fl_nonneg; nra).
  assert (0 <= u * T) by nra. assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (Fa : F along_v) by apply F_fl.
  destruct (Rle_or_lt 0 along_v) as [Hp|Hn].
  - pose proof (next_up_plus along_v Hp) as N1. fold B in N1.
    assert (N2 : next_up along_v <= Rmax 0 (next_up along_v)) by apply Rmax_r.
    pose proof (next_up_ge (Rmax 0 (next_up along_v) + slack)). lra.
  - assert (FM : F (Rmax 0 (next_up along_v))).
    { unfold Rmax. destruct Rle_dec; [apply F_fl | apply generic_format_0]. }
    assert (M0 : 0 <= Rmax 0 (next_up along_v)) by apply Rmax_l.
    pose proof (add_rel _ _ FM (F_fl (fl (kAxisVelocityRounding * a_1) * vinf))) as G3. fold slack in G3.
    set (M := Rmax 0 (next_up along_v)) in *.
    rewrite (Rabs_pos_eq (M + slack)) in G3 by lra.
    assert (G4 : (1 - u) * (M + slack) <= fl (M + slack)) by (apply rel_lower; exact G3).
    assert (HMs : 0 <= fl (M + slack)) by (apply fl_nonneg; lra).
    pose proof (next_up_plus (fl (M + slack)) HMs) as N1. fold B in N1.
    assert ((1 - u) * (89 * u * T - eta) <= (1 - u) * slack) by (apply mul_le_l; lra).
    assert (u * M <= / 1000000 * M) by (apply Rmult_le_compat_r; lra).
    assert (u * (u * T) <= / 1000000 * (u * T)) by (apply Rmult_le_compat_r; lra).
    assert (0 <= u * eta) by nra. lra.
Qed.

(* ---- kCornerOffsetRounding ----
   corner_offsets (motion_bounds.h): r_k = A_k - centre, each coordinate one
   rounded difference of two doubles (the god corner X at u0 and G = p).
   StartFrame's motion() adds turn_rate (static_error + kCornerOffsetRounding r)
   to the speed bound: static_error covers the double corner's distance from the
   exact one, kCornerOffsetRounding r the subtraction's rounding, which the
   theorem bounds in the Euclidean norm (what the turn acts on). A difference
   of doubles errs by at most u of itself, underflow included (it is exact
   there: sub_rel), so no absolute term. Hypotheses: |X - p| <= r + s (r >=
   the exact corner's |r_B|, s = static_error >= the double corner's distance
   from the exact one) and s <= 9000 r. The latter is not checked by the code:
   static_error (kPoseRounding (|p|_inf + rho) plus the stop pose's deviation)
   passes 9000 r only for a body more than ~10^16 of its size from the origin
   (or a stop deviation 9000 times the triangle's radius); there the
   subtraction's u s is covered by round_up's widening of the sum, which this
   theorem does not model. *)
(* allowance kCornerOffsetRounding = 1e-12 *)
Definition kCornerOffsetRounding := fl (/ 1000000000000).

Lemma abs_sq t : Rabs t * Rabs t = t * t.
Proof. rewrite <- Rabs_mult. apply Rabs_pos_eq. nra. Qed.

(* covers optimized/gauss6/ccd/motion_bounds.h "GAUSS6_ALWAYS_INLINE double corner_offsets(" sha256:a6814e84c72b62d0 *)
(* covers optimized/gauss6/ccd/motion_bounds.h "bool motion(double r, double u_limit" sha256:e360e4764b160611 *)
Theorem corner_offset_rounding x y z px py pz r s :
  F x -> F y -> F z -> F px -> F py -> F pz ->
  sqrt ((x - px) * (x - px) + (y - py) * (y - py) + (z - pz) * (z - pz)) <= r + s ->
  0 <= s <= 9000 * r ->
  let dx := fl (x - px) - (x - px) in let dy := fl (y - py) - (y - py) in
  let dz := fl (z - pz) - (z - pz) in
  sqrt (dx * dx + dy * dy + dz * dz) <= kCornerOffsetRounding * r.
Proof.
  intros Fx Fy Fz Fpx Fpy Fpz Hn Hs dx dy dz.
  assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  set (S := (x - px) * (x - px) + (y - py) * (y - py) + (z - pz) * (z - pz)) in *.
  assert (Sq : forall a b, F a -> F b -> (fl (a - b) - (a - b)) * (fl (a - b) - (a - b)) <= u * u * ((a - b) * (a - b))).
  { intros a b Fa Fb. pose proof (sub_rel a b Fa Fb) as H.
    set (e := fl (a - b) - (a - b)) in *.
    rewrite <- (abs_sq e), <- (abs_sq (a - b)).
    replace (u * u * (Rabs (a - b) * Rabs (a - b))) with ((u * Rabs (a - b)) * (u * Rabs (a - b))) by ring.
    apply Rmult_le_compat; try apply Rabs_pos; lra. }
  assert (H1 : dx * dx + dy * dy + dz * dz <= (u * sqrt S) * (u * sqrt S)).
  { pose proof (Sq x px Fx Fpx); pose proof (Sq y py Fy Fpy); pose proof (Sq z pz Fz Fpz).
    assert (0 <= S) by (unfold S; pose proof (Rle_0_sqr (x - px)); pose proof (Rle_0_sqr (y - py));
      pose proof (Rle_0_sqr (z - pz)); unfold Rsqr in *; lra).
    replace ((u * sqrt S) * (u * sqrt S)) with (u * u * (sqrt S * sqrt S)) by ring.
    rewrite sqrt_sqrt by lra. unfold dx, dy, dz, S. lra. }
  assert (H2 : sqrt (dx * dx + dy * dy + dz * dz) <= u * sqrt S).
  { rewrite <- (sqrt_square (u * sqrt S)) by (pose proof (sqrt_pos S); nra). apply sqrt_le_1_alt. exact H1. }
  assert (Hk : (1 - u) * / 1000000000000 - eta <= kCornerOffsetRounding) by (apply fl_lower; lra).
  pose proof eta_pos. pose proof eta_small.
  assert (bpow radix2 (-1022) <= / 1000000000000000000) by (simpl; lra).
  assert (0 <= r) by lra.
  assert (u * sqrt S <= u * (r + s)) by (apply mul_le_l; lra).
  assert (Hk2 : 9001 * u <= kCornerOffsetRounding) by (unfold u in *; lra).
  assert (9001 * u * r <= kCornerOffsetRounding * r) by (apply Rmult_le_compat_r; lra).
  assert (u * s <= u * (9000 * r)) by (apply mul_le_l; lra).
  lra.
Qed.

(* ---- kBoxProductRounding, kUnderflowFloor at swept_box ----
   swept_box (motion_bounds.cpp), one world coordinate i, the row (m_j) of
   R_mid, (a_j) = |m_j| of R_abs and (q_j) >= 0 of R_rad, the body box's centre
   c and half-widths h (doubles): reach_j = fl(|c_j| + h_j), centre =
   sum3(fl(m_j c_j)), half = fl(sum3(fl(a_j h_j)) + sum3(fl(q_j reach_j))),
   scale = sum3(fl(fl(a_j + q_j) reach_j)), sum3 the sum of three doubles in
   any order. Every R within q of R_mid entrywise maps every r within h of c
   to within half + kBoxProductRounding scale + kUnderflowFloor of centre
   (grow rounds that sum up: Rounding.v's upper_add, upper_mul). No
   hypothesis on magnitudes: the sums of doubles err relatively only (exact
   where they underflow) and the nine products' underflow, at most 12 2^-1075
   in all with the factor kBoxProductRounding, is under kUnderflowFloor. *)
(* allowance kBoxProductRounding = 2e-15 *)
Definition kBoxProductRounding := fl (2 / 1000000000000000).
(* allowance kUnderflowFloor = 1e-300 *)
Definition kUnderflowFloor := fl (/ IZR (Z.pow 10 300)).

Definition sum3 x y z := fl (fl (x + y) + z).

Lemma sum_lower x y : F x -> F y -> 0 <= x -> 0 <= y -> (1 - u) * (x + y) <= fl (x + y).
Proof.
  intros Fx Fy Hx Hy. apply rel_lower. pose proof (add_rel x y Fx Fy) as H.
  rewrite (Rabs_pos_eq (x + y)) in H by lra. exact H.
Qed.
Lemma sum3_lower x y z : F x -> F y -> F z -> 0 <= x -> 0 <= y -> 0 <= z ->
  (1 - u) * (1 - u) * (x + y + z) <= sum3 x y z.
Proof.
  intros. unfold sum3. assert (0 < u < / 1000000) by (unfold u; lra).
  pose proof (sum_lower x y H H0 H2 H3).
  assert (0 <= fl (x + y)) by (apply fl_nonneg; lra).
  pose proof (sum_lower (fl (x + y)) z (F_fl _) H1 H7 H4).
  assert ((1 - u) * ((1 - u) * (x + y)) <= (1 - u) * fl (x + y)) by (apply mul_le_l; lra).
  assert (0 <= (1 - u) * u * z) by (apply Rmult_le_pos; nra).
  nra.
Qed.
Lemma sum3_err x y z : F x -> F y -> F z ->
  Rabs (sum3 x y z - (x + y + z)) <= 2 * u * (Rabs x + Rabs y) + u * (1 + u) * (Rabs x + Rabs y) + u * Rabs z.
Proof.
  intros Fx Fy Fz. unfold sum3. assert (0 < u < / 1000000) by (unfold u; lra).
  pose proof (add_rel x y Fx Fy) as E1. pose proof (add_rel (fl (x + y)) z (F_fl _) Fz) as E2.
  pose proof (Rabs_triang x y).
  assert (Rabs (fl (x + y)) <= (1 + u) * (Rabs x + Rabs y)).
  { replace (fl (x + y)) with ((fl (x + y) - (x + y)) + (x + y)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. assert (u * Rabs (x + y) <= u * (Rabs x + Rabs y)) by (apply mul_le_l; lra). lra. }
  assert (Rabs (fl (x + y) + z) <= (1 + u) * (Rabs x + Rabs y) + Rabs z)
    by (eapply Rle_trans; [apply Rabs_triang | lra]).
  assert (u * Rabs (fl (x + y) + z) <= u * ((1 + u) * (Rabs x + Rabs y) + Rabs z)) by (apply mul_le_l; lra).
  assert (u * Rabs (x + y) <= u * (Rabs x + Rabs y)) by (apply mul_le_l; lra).
  replace (fl (fl (x + y) + z) - (x + y + z)) with ((fl (fl (x + y) + z) - (fl (x + y) + z)) + (fl (x + y) - (x + y))) by ring.
  eapply Rle_trans; [apply Rabs_triang|]. pose proof (Rabs_pos x); pose proof (Rabs_pos y). unfold u in *; lra.
Qed.
Lemma prod_lower a b : 0 <= a -> 0 <= b -> (1 - u) * (a * b) - eta <= fl (a * b).
Proof. intros. apply fl_lower. nra. Qed.
Lemma term_exact m q c h R r :
  0 <= h -> Rabs (R - m) <= q -> Rabs (r - c) <= h ->
  Rabs (R * r - m * c) <= Rabs m * h + q * (Rabs c + h).
Proof.
  intros Hh HR Hr. replace (R * r - m * c) with (m * (r - c) + (R - m) * r) by ring.
  eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult.
  assert (Rabs r <= Rabs c + h) by (replace r with (c + (r - c)) by ring; eapply Rle_trans; [apply Rabs_triang | lra]).
  pose proof (Rabs_pos m). pose proof (Rabs_pos (R - m)). pose proof (Rabs_pos r). pose proof (Rabs_pos (r - c)).
  assert (Rabs m * Rabs (r - c) <= Rabs m * h) by (apply mul_le_l; lra).
  assert (Rabs (R - m) * Rabs r <= q * (Rabs c + h)) by (apply Rmult_le_compat; lra).
  lra.
Qed.
(* A term's lower bounds: fl(q reach) and fl(fl(a + q) reach), reach = fl(|c| + h). *)
Lemma reach_lower c h : F c -> F h -> 0 <= h -> (1 - u) * (Rabs c + h) <= fl (Rabs c + h).
Proof. intros. apply sum_lower; [apply generic_format_abs; assumption | assumption | apply Rabs_pos | assumption]. Qed.
Lemma qreach_lower q c h : F c -> F h -> 0 <= h -> 0 <= q ->
  (1 - u) * (1 - u) * (q * (Rabs c + h)) - eta <= fl (q * fl (Rabs c + h)).
Proof.
  intros. assert (0 < u < / 1000000) by (unfold u; lra). pose proof (reach_lower c h H H0 H1).
  pose proof (Rabs_pos c).
  assert (q * ((1 - u) * (Rabs c + h)) <= q * fl (Rabs c + h)) by (apply mul_le_l; lra).
  pose proof (prod_lower q (fl (Rabs c + h)) H2 ltac:(nra)). nra.
Qed.
Lemma sreach_lower a q c h : F a -> F q -> F c -> F h -> 0 <= h -> 0 <= q -> 0 <= a ->
  (1 - u) * (1 - u) * (1 - u) * ((a + q) * (Rabs c + h)) - eta <= fl (fl (a + q) * fl (Rabs c + h)).
Proof.
  intros. assert (0 < u < / 1000000) by (unfold u; lra). pose proof (reach_lower c h H1 H2 H3).
  pose proof (sum_lower a q H H0 H5 H4). pose proof (Rabs_pos c).
  assert (0 <= fl (a + q)) by (apply fl_nonneg; lra).
  assert (0 <= fl (Rabs c + h)) by (apply fl_nonneg; lra).
  assert ((1 - u) * (a + q) * ((1 - u) * (Rabs c + h)) <= fl (a + q) * fl (Rabs c + h))
    by (apply Rmult_le_compat; nra).
  pose proof (prod_lower (fl (a + q)) (fl (Rabs c + h)) H10 H11). nra.
Qed.

(* covers optimized/gauss6/ccd/motion_bounds.cpp "Aabb swept_box(const MotionEnclosure& e, const Aabb& body)" sha256:17e777d36e576019 *)
Theorem swept_box_rounding m0 m1 m2 q0 q1 q2 c0 c1 c2 h0 h1 h2 R0 R1 R2 r0 r1 r2 :
  (forall x, In x [m0; m1; m2; q0; q1; q2; c0; c1; c2; h0; h1; h2] -> F x) ->
  0 <= q0 -> 0 <= q1 -> 0 <= q2 -> 0 <= h0 -> 0 <= h1 -> 0 <= h2 ->
  Rabs (R0 - m0) <= q0 -> Rabs (R1 - m1) <= q1 -> Rabs (R2 - m2) <= q2 ->
  Rabs (r0 - c0) <= h0 -> Rabs (r1 - c1) <= h1 -> Rabs (r2 - c2) <= h2 ->
  let centre := sum3 (fl (m0 * c0)) (fl (m1 * c1)) (fl (m2 * c2)) in
  let half := fl (sum3 (fl (Rabs m0 * h0)) (fl (Rabs m1 * h1)) (fl (Rabs m2 * h2))
                  + sum3 (fl (q0 * fl (Rabs c0 + h0))) (fl (q1 * fl (Rabs c1 + h1))) (fl (q2 * fl (Rabs c2 + h2)))) in
  let scale := sum3 (fl (fl (Rabs m0 + q0) * fl (Rabs c0 + h0))) (fl (fl (Rabs m1 + q1) * fl (Rabs c1 + h1)))
                    (fl (fl (Rabs m2 + q2) * fl (Rabs c2 + h2))) in
  Rabs ((R0 * r0 + R1 * r1 + R2 * r2) - centre) <= half + kBoxProductRounding * scale + kUnderflowFloor.
Proof.
  intros HF Hq0 Hq1 Hq2 Hh0 Hh1 Hh2 HR0 HR1 HR2 Hr0 Hr1 Hr2 centre half scale.
  assert (Hu : 0 < u < / 1000000) by (unfold u; lra). pose proof eta_pos. pose proof eta_small.
  assert (Hsmall : 5 * bpow radix2 (-1000) <= / IZR (Z.pow 10 300) * / 2) by (simpl; lra).
  assert (bpow radix2 (-1022) <= bpow radix2 (-1000)) by (apply bpow_le; lia).
  finite_of HF m0 as Fm0. finite_of HF m1 as Fm1.
  finite_of HF m2 as Fm2. finite_of HF q0 as Fq0.
  finite_of HF q1 as Fq1. finite_of HF q2 as Fq2.
  finite_of HF c0 as Fc0. finite_of HF c1 as Fc1.
  finite_of HF c2 as Fc2. finite_of HF h0 as Fh0.
  finite_of HF h1 as Fh1. finite_of HF h2 as Fh2.
  pose proof (Rabs_pos m0). pose proof (Rabs_pos m1). pose proof (Rabs_pos m2).
  pose proof (Rabs_pos c0). pose proof (Rabs_pos c1). pose proof (Rabs_pos c2).
  (* exact: within H of the exact R_mid c *)
  set (HB := (Rabs m0 * h0 + q0 * (Rabs c0 + h0)) + (Rabs m1 * h1 + q1 * (Rabs c1 + h1))
            + (Rabs m2 * h2 + q2 * (Rabs c2 + h2))).
  set (A := Rabs m0 * Rabs c0 + Rabs m1 * Rabs c1 + Rabs m2 * Rabs c2).
  set (T := (Rabs m0 + q0) * (Rabs c0 + h0) + (Rabs m1 + q1) * (Rabs c1 + h1) + (Rabs m2 + q2) * (Rabs c2 + h2)).
  assert (HT : T = HB + A) by (unfold T, HB, A; ring).
  assert (HA : 0 <= A) by (unfold A; nra).
  assert (HH : 0 <= HB) by (unfold HB; nra).
  assert (E1 : Rabs ((R0 * r0 + R1 * r1 + R2 * r2) - (m0 * c0 + m1 * c1 + m2 * c2)) <= HB).
  { pose proof (term_exact m0 q0 c0 h0 R0 r0 Hh0 HR0 Hr0). pose proof (term_exact m1 q1 c1 h1 R1 r1 Hh1 HR1 Hr1).
    pose proof (term_exact m2 q2 c2 h2 R2 r2 Hh2 HR2 Hr2).
    replace ((R0 * r0 + R1 * r1 + R2 * r2) - (m0 * c0 + m1 * c1 + m2 * c2))
      with ((R0 * r0 - m0 * c0) + (R1 * r1 - m1 * c1) + (R2 * r2 - m2 * c2)) by ring.
    unfold HB. eapply Rle_trans; [apply Rabs_triang|]. pose proof (Rabs_triang (R0 * r0 - m0 * c0) (R1 * r1 - m1 * c1)). lra. }
  (* the centre's rounding: within 6 u A + 4 eta *)
  assert (P : forall m c, Rabs (fl (m * c) - m * c) <= u * (Rabs m * Rabs c) + eta /\
                         Rabs (fl (m * c)) <= (1 + u) * (Rabs m * Rabs c) + eta).
  { intros m c. pose proof (fl_err (m * c)) as G. rewrite Rabs_mult in G. split; [exact G|].
    replace (fl (m * c)) with ((fl (m * c) - m * c) + m * c) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_mult. lra. }
  destruct (P m0 c0) as [P0 B0]; destruct (P m1 c1) as [P1 B1]; destruct (P m2 c2) as [P2 B2].
  pose proof (sum3_err (fl (m0 * c0)) (fl (m1 * c1)) (fl (m2 * c2)) (F_fl _) (F_fl _) (F_fl _)) as S3.
  fold centre in S3.
  assert (E2 : Rabs (centre - (m0 * c0 + m1 * c1 + m2 * c2)) <= 6 * u * A + 4 * eta).
  { replace (centre - (m0 * c0 + m1 * c1 + m2 * c2))
      with ((centre - (fl (m0 * c0) + fl (m1 * c1) + fl (m2 * c2)))
            + ((fl (m0 * c0) - m0 * c0) + (fl (m1 * c1) - m1 * c1) + (fl (m2 * c2) - m2 * c2))) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. unfold A.
    pose proof (Rabs_triang (fl (m0 * c0) - m0 * c0 + (fl (m1 * c1) - m1 * c1)) (fl (m2 * c2) - m2 * c2)).
    pose proof (Rabs_triang (fl (m0 * c0) - m0 * c0) (fl (m1 * c1) - m1 * c1)).
    set (a0 := Rabs m0 * Rabs c0) in *. set (a1 := Rabs m1 * Rabs c1) in *. set (a2 := Rabs m2 * Rabs c2) in *.
    set (y0 := Rabs (fl (m0 * c0))) in *. set (y1 := Rabs (fl (m1 * c1))) in *. set (y2 := Rabs (fl (m2 * c2))) in *.
    assert (0 <= a0) by (unfold a0; nra). assert (0 <= a1) by (unfold a1; nra). assert (0 <= a2) by (unfold a2; nra).
    unfold u in *. lra. }
  (* half from below: (1 - u)^5 H - 6 eta *)
  assert (HQ : forall m q c h, F m -> F q -> F c -> F h -> 0 <= q -> 0 <= h ->
     0 <= fl (Rabs m * h) /\ 0 <= fl (q * fl (Rabs c + h)) /\ 0 <= fl (fl (Rabs m + q) * fl (Rabs c + h))).
  { intros m q c h Fm Fq Fc Fh Hq Hh. pose proof (Rabs_pos m). pose proof (Rabs_pos c).
    assert (0 <= fl (Rabs c + h)) by (apply fl_nonneg; lra).
    assert (0 <= fl (Rabs m + q)) by (apply fl_nonneg; lra).
    split; [|split]; apply fl_nonneg; nra. }
  destruct (HQ m0 q0 c0 h0) as (N0 & M0 & K0); try assumption.
  destruct (HQ m1 q1 c1 h1) as (N1 & M1 & K1); try assumption.
  destruct (HQ m2 q2 c2 h2) as (N2 & M2 & K2); try assumption.
  pose proof (sum3_lower _ _ _ (F_fl (Rabs m0 * h0)) (F_fl (Rabs m1 * h1)) (F_fl (Rabs m2 * h2)) N0 N1 N2) as L1.
  pose proof (sum3_lower _ _ _ (F_fl (q0 * fl (Rabs c0 + h0))) (F_fl (q1 * fl (Rabs c1 + h1))) (F_fl (q2 * fl (Rabs c2 + h2))) M0 M1 M2) as L2.
  pose proof (sum3_lower _ _ _ (F_fl (fl (Rabs m0 + q0) * fl (Rabs c0 + h0))) (F_fl (fl (Rabs m1 + q1) * fl (Rabs c1 + h1)))
     (F_fl (fl (Rabs m2 + q2) * fl (Rabs c2 + h2))) K0 K1 K2) as L3. fold scale in L3.
  pose proof (prod_lower (Rabs m0) h0 ltac:(lra) Hh0). pose proof (prod_lower (Rabs m1) h1 ltac:(lra) Hh1).
  pose proof (prod_lower (Rabs m2) h2 ltac:(lra) Hh2).
  pose proof (qreach_lower q0 c0 h0) as Q0. pose proof (qreach_lower q1 c1 h1) as Q1. pose proof (qreach_lower q2 c2 h2) as Q2.
  pose proof (sreach_lower (Rabs m0) q0 c0 h0 (generic_format_abs _ _ _ Fm0)) as T0.
  pose proof (sreach_lower (Rabs m1) q1 c1 h1 (generic_format_abs _ _ _ Fm1)) as T1.
  pose proof (sreach_lower (Rabs m2) q2 c2 h2 (generic_format_abs _ _ _ Fm2)) as T2.
  specialize (Q0 Fc0 Fh0 Hh0 Hq0). specialize (Q1 Fc1 Fh1 Hh1 Hq1). specialize (Q2 Fc2 Fh2 Hh2 Hq2).
  specialize (T0 Fq0 Fc0 Fh0 Hh0 Hq0 ltac:(lra)). specialize (T1 Fq1 Fc1 Fh1 Hh1 Hq1 ltac:(lra)).
  specialize (T2 Fq2 Fc2 Fh2 Hh2 Hq2 ltac:(lra)).
  set (S1 := sum3 (fl (Rabs m0 * h0)) (fl (Rabs m1 * h1)) (fl (Rabs m2 * h2))) in *.
  set (S2 := sum3 (fl (q0 * fl (Rabs c0 + h0))) (fl (q1 * fl (Rabs c1 + h1))) (fl (q2 * fl (Rabs c2 + h2)))) in *.
  assert (0 <= S1) by (unfold u in *; lra). assert (0 <= S2) by (unfold u in *; lra).
  assert (Hhalf : (1 - u) * (S1 + S2) <= half) by (apply sum_lower; [apply F_fl | apply F_fl | lra | lra]).
  assert (Ehalf : (1 - 6 * u) * HB - 7 * eta <= half).
  { unfold HB. unfold u in *. lra. }
  assert (Escale : (1 - 6 * u) * T - 4 * eta <= scale).
  { assert (0 <= T) by lra. unfold T. unfold u in *. lra. }
  assert (0 <= scale) by (unfold scale, sum3; apply fl_nonneg; apply Rplus_le_le_0_compat; [apply fl_nonneg|]; lra).
  (* the allowances' doubles *)
  assert (Hk : (1 - u) * (2 / 1000000000000000) - eta <= kBoxProductRounding) by (apply fl_lower; lra).
  assert (Hf : (1 - u) * / IZR (Z.pow 10 300) - eta <= kUnderflowFloor) by (apply fl_lower; apply Rlt_le, Rinv_0_lt_compat; apply IZR_lt; reflexivity).
  assert (Hk17 : 17 * u <= kBoxProductRounding) by (unfold u in *; lra).
  assert (17 * u * scale <= kBoxProductRounding * scale) by (apply Rmult_le_compat_r; lra).
  assert (17 * u * ((1 - 6 * u) * T - 4 * eta) <= 17 * u * scale) by (apply mul_le_l; lra).
  assert (/ IZR (Z.pow 10 300) * / 2 <= kUnderflowFloor) by (unfold u in *; lra).
  replace ((R0 * r0 + R1 * r1 + R2 * r2) - centre)
    with (((R0 * r0 + R1 * r1 + R2 * r2) - (m0 * c0 + m1 * c1 + m2 * c2)) - (centre - (m0 * c0 + m1 * c1 + m2 * c2))) by ring.
  eapply Rle_trans; [apply abs_diff_le; [exact E1 | exact E2]|].
  assert (0 <= T) by lra. unfold u in *. lra.
Qed.

(* The theorems, each answered by tools/check_proofs.sh. *)
Print Assumptions linear_corner_rounding.
Print Assumptions linear_corner_selection.
Print Assumptions linear_corner_error_bound.
Print Assumptions norm_upper_bound.
Print Assumptions norm_lower_bound.
Print Assumptions norm_up_relative.
Print Assumptions norm_up_wide.
Print Assumptions norm_down_wide.
Print Assumptions step_rounding.
Print Assumptions axis_velocity_rounding.
Print Assumptions corner_offset_rounding.
Print Assumptions swept_box_rounding.
