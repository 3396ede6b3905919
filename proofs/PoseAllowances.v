(* The allowances of posing a body in doubles, proved in Flocq's binary64
   model of Rounding.v (finite results, gradual underflow, no fused
   multiply-add): kPoseRounding (a body point posed at a double pose,
   X = R(q) r_B + p, with R(q) = rotation_matrix(q) of geometry/pose.cpp),
   and kQuaternionTurnRounding (the turn between two double poses,
   Displacement), each expression evaluated as its site evaluates it (the same operations
   in the same order, each rounded to nearest: `fl`). *)

From Coq Require Import Reals Psatz.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances.
From Gauss6 Require ObbAllowances.  (* cauchy_schwarz3, used qualified *)
Open Scope R_scope.

(* ---- Error propagation, relative to a scale S ----
   U = u S; every absolute underflow error eta is below 10^-6 U once
   S >= 2^-1002 (Allowances.v eta_rel). *)

Lemma u_small : 0 < u < / 1000000000000000.
Proof. unfold u; lra. Qed.

(* A rounded operation on an operand within c U of the exact Z, |Z| <= S. *)
Lemma step_U z Z S c :
  0 < S -> 1000000 * eta <= u * S -> 0 <= c <= 1000 ->
  Rabs Z <= S -> Rabs (z - Z) <= c * (u * S) ->
  Rabs (fl z - Z) <= (c + 1 + / 100000) * (u * S).
Proof.
  intros HS He Hc HZ Hz. pose proof u_small. pose proof eta_pos.
  pose proof (step z Z S (c * (u * S)) HZ Hz) as Hst.
  assert (0 < u * S) by nra.
  assert (u * (c * (u * S)) <= / 1000000000 * (u * S)).
  { replace (u * (c * (u * S))) with ((u * c) * (u * S)) by ring.
    apply Rmult_le_compat_r; nra. }
  nra.
Qed.

(* The sum of four rounded terms, left to right, each term fl(T_i)
   (a product, or minus a product: fl(-t) = -fl(t)). *)
Definition sum4 a b c d := fl (fl (fl (fl a + fl b) + fl c) + fl d).

Lemma sum4_err T1 T2 T3 T4 S :
  0 < S -> 1000000 * eta <= u * S ->
  Rabs T1 + Rabs T2 + Rabs T3 + Rabs T4 <= S ->
  Rabs (sum4 T1 T2 T3 T4 - (T1 + T2 + T3 + T4)) <= 7001 / 1000 * (u * S).
Proof.
  intros HS He HT. pose proof u_small. pose proof eta_pos.
  assert (HU : 0 < u * S) by nra.
  pose proof (Rabs_pos T1). pose proof (Rabs_pos T2). pose proof (Rabs_pos T3). pose proof (Rabs_pos T4).
  assert (P : forall T, Rabs T <= S -> Rabs (fl T - T) <= (1 + / 100000) * (u * S)).
  { intros T HTS. pose proof (fl_err T). assert (u * Rabs T <= u * S) by (apply mul_le_l; lra). lra. }
  pose proof (P T1 ltac:(lra)). pose proof (P T2 ltac:(lra)).
  pose proof (P T3 ltac:(lra)). pose proof (P T4 ltac:(lra)).
  assert (E1 : Rabs (fl (fl T1 + fl T2) - (T1 + T2)) <= ((2 + 2 / 100000) + 1 + / 100000) * (u * S)).
  { apply step_U; [lra | lra | lra | eapply Rle_trans; [apply abs_sum_le; apply Rle_refl | lra] |].
    replace (fl T1 + fl T2 - (T1 + T2)) with ((fl T1 - T1) + (fl T2 - T2)) by ring.
    eapply Rle_trans; [apply Rabs_triang | lra]. }
  assert (E2 : Rabs (fl (fl (fl T1 + fl T2) + fl T3) - (T1 + T2 + T3)) <= ((((2 + 2 / 100000) + 1 + / 100000) + 1 + / 100000) + 1 + / 100000) * (u * S)).
  { apply step_U; [lra | lra | lra | |].
    - eapply Rle_trans; [apply abs_sum_le; [apply abs_sum_le; apply Rle_refl | apply Rle_refl] | lra].
    - replace (fl (fl T1 + fl T2) + fl T3 - (T1 + T2 + T3))
        with ((fl (fl T1 + fl T2) - (T1 + T2)) + (fl T3 - T3)) by ring.
      eapply Rle_trans; [apply Rabs_triang | lra]. }
  assert (E3 : Rabs (sum4 T1 T2 T3 T4 - (T1 + T2 + T3 + T4))
               <= ((((((2 + 2 / 100000) + 1 + / 100000) + 1 + / 100000) + 1 + / 100000) + 1 + / 100000) + 1 + / 100000) * (u * S)).
  { unfold sum4. apply step_U; [lra | lra | lra | |].
    - eapply Rle_trans; [apply abs_sum_le; [apply abs_sum_le; [apply abs_sum_le|]|]; apply Rle_refl | lra].
    - replace (fl (fl (fl T1 + fl T2) + fl T3) + fl T4 - (T1 + T2 + T3 + T4))
        with ((fl (fl (fl T1 + fl T2) + fl T3) - (T1 + T2 + T3)) + (fl T4 - T4)) by ring.
      eapply Rle_trans; [apply Rabs_triang | lra]. }
  lra.
Qed.

(* Twice the rounded sum of two rounded terms: 2 (a b -+ c d). *)
Definition twice2 a b := fl (2 * fl (fl a + fl b)).

Lemma twice2_err T1 T2 S :
  0 < S -> 1000000 * eta <= u * S -> 2 * (Rabs T1 + Rabs T2) <= S ->
  Rabs (twice2 T1 T2 - 2 * (T1 + T2)) <= 6 * (u * S).
Proof.
  intros HS He HT. pose proof u_small. pose proof eta_pos.
  assert (HU : 0 < u * S) by nra.
  pose proof (Rabs_pos T1). pose proof (Rabs_pos T2).
  assert (G1 : Rabs (fl T1 - T1) <= u * Rabs T1 + eta) by apply fl_err.
  assert (G2 : Rabs (fl T2 - T2) <= u * Rabs T2 + eta) by apply fl_err.
  assert (u * (Rabs T1 + Rabs T2) <= u * (S / 2)) by (apply mul_le_l; lra).
  assert (E1 : Rabs (fl (fl T1 + fl T2) - (T1 + T2)) <= (1 + 1 + / 100000) * (u * S)).
  { apply step_U; [lra | lra | lra | eapply Rle_trans; [apply abs_sum_le; apply Rle_refl | lra] |].
    replace (fl T1 + fl T2 - (T1 + T2)) with ((fl T1 - T1) + (fl T2 - T2)) by ring.
    eapply Rle_trans; [apply Rabs_triang | nra]. }
  assert (E2 : Rabs (2 * fl (fl T1 + fl T2) - 2 * (T1 + T2)) <= 2 * (1 + 1 + / 100000) * (u * S)).
  { replace (2 * fl (fl T1 + fl T2) - 2 * (T1 + T2)) with (2 * (fl (fl T1 + fl T2) - (T1 + T2))) by ring.
    rewrite Rabs_mult, Rabs_pos_eq by lra. lra. }
  assert (E3 := step_U (2 * fl (fl T1 + fl T2)) (2 * (T1 + T2)) S (2 * (1 + 1 + / 100000))
                  HS He ltac:(lra) ltac:(rewrite Rabs_mult, Rabs_pos_eq by lra; pose proof (Rabs_triang T1 T2); lra) E2).
  unfold twice2. lra.
Qed.

(* A rounded quotient of approximations: n within a S of N, s within b S of
   S > 0, |N| <= S, a and b at most 8 u: fl(n / s) within 30 u of N / S
   (which is at most 1). *)
Lemma quotient_err n s N S a b :
  0 < S -> Rabs N <= S -> 0 <= a <= 8 * u -> 0 <= b <= 8 * u ->
  Rabs (n - N) <= a * S -> Rabs (s - S) <= b * S ->
  Rabs (fl (n / s) - N / S) <= 30 * u /\ Rabs (N / S) <= 1.
Proof.
  intros HS HN Ha Hb Hn Hs. pose proof u_small. pose proof eta_pos.
  assert (eta <= / 1000000 * u) by (rewrite bpow_m53; unfold eta; simpl bpow; simpl IZR; lra).
  assert (Hs0 : (1 - b) * S <= s) by (unfold Rabs in Hs; destruct Rcase_abs; lra).
  assert (Hsp : 0 < s) by nra.
  assert (HR : Rabs (N / S) <= 1).
  { unfold Rdiv. rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq S) by lra.
    apply Rmult_le_reg_r with S; [lra|]. rewrite Rmult_assoc, Rinv_l by lra. lra. }
  split; [|exact HR].
  set (r := N / S) in *.
  assert (Hq : n / s - r = ((n - N) - r * (s - S)) / s).
  { unfold r. field. split; lra. }
  assert (Hnum : Rabs ((n - N) - r * (s - S)) <= (a + b) * S).
  { eapply Rle_trans; [apply abs_diff_le; [apply Rle_refl | apply Rle_refl]|].
    rewrite Rabs_mult. pose proof (Rabs_pos (s - S)). pose proof (Rabs_pos r). nra. }
  assert (Hd : Rabs (n / s - r) <= 17 / 10 * (a + b)).
  { rewrite Hq. unfold Rdiv. rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq s) by lra.
    apply Rmult_le_reg_r with s; [lra|]. rewrite Rmult_assoc, Rinv_l by lra.
    assert ((a + b) * S <= (17 / 10 * (a + b)) * s).
    { apply Rle_trans with ((17 / 10 * (a + b)) * ((1 - b) * S)).
      { apply Rle_trans with ((17 / 10 * (1 - b)) * ((a + b) * S)); [|right; ring].
        rewrite <- (Rmult_1_l ((a + b) * S)) at 1. apply Rmult_le_compat_r; nra. }
      apply Rmult_le_compat_l; nra. }
    lra. }
  pose proof (fl_err (n / s)).
  assert (Rabs (n / s) <= 2).
  { replace (n / s) with (r + (n / s - r)) by ring. pose proof (Rabs_triang r (n / s - r)). lra. }
  replace (fl (n / s) - r) with ((fl (n / s) - n / s) + (n / s - r)) by ring.
  assert (u * Rabs (n / s) <= u * 2) by (apply mul_le_l; lra).
  eapply Rle_trans; [apply Rabs_triang|]. lra.
Qed.

Lemma two_ab a b : 2 * Rabs (a * b) <= a * a + b * b.
Proof.
  rewrite Rabs_mult. rewrite <- (abs_sq a), <- (abs_sq b).
  pose proof (Rle_0_sqr (Rabs a - Rabs b)). unfold Rsqr in *. nra.
Qed.

(* ---- rotation_matrix (geometry/pose.cpp) ----
   On the rescaled quaternion (w, x, y, z): s = w w + x x + y y + z z (left to
   right) and the nine entries, each divided by s (Eigen's R / s, entry by
   entry). The exact rotation of q is N_ij / S, N_ij the same quadratics and
   S the exact sum of squares. *)
Definition rot_s w x y z := sum4 (w * w) (x * x) (y * y) (z * z).
Definition rot_c (w x y z : R) (i j : nat) : R :=
  let n := match i, j with
    | 0, 0 => fl (fl (fl (fl (w * w) + fl (x * x)) - fl (y * y)) - fl (z * z))
    | 0, 1 => fl (2 * fl (fl (x * y) - fl (w * z)))
    | 0, _ => fl (2 * fl (fl (x * z) + fl (w * y)))
    | 1, 0 => fl (2 * fl (fl (x * y) + fl (w * z)))
    | 1, 1 => fl (fl (fl (fl (w * w) - fl (x * x)) + fl (y * y)) - fl (z * z))
    | 1, _ => fl (2 * fl (fl (y * z) - fl (w * x)))
    | _, 0 => fl (2 * fl (fl (x * z) - fl (w * y)))
    | _, 1 => fl (2 * fl (fl (y * z) + fl (w * x)))
    | _, _ => fl (fl (fl (fl (w * w) - fl (x * x)) - fl (y * y)) + fl (z * z))
    end in fl (n / rot_s w x y z).
Definition rot_N (w x y z : R) (i j : nat) : R :=
  match i, j with
  | 0, 0 => w * w + x * x - y * y - z * z
  | 0, 1 => 2 * (x * y - w * z)
  | 0, _ => 2 * (x * z + w * y)
  | 1, 0 => 2 * (x * y + w * z)
  | 1, 1 => w * w - x * x + y * y - z * z
  | 1, _ => 2 * (y * z - w * x)
  | _, 0 => 2 * (x * z - w * y)
  | _, 1 => 2 * (y * z + w * x)
  | _, _ => w * w - x * x - y * y + z * z
  end.

(* The code's subtractions of rounded products are sums with the negated
   product, rounded the same: fl(a - fl(t)) = fl(a + fl(-t)). *)
Lemma fl_sub_prod a t : fl (a - fl t) = fl (a + fl (- t)).
Proof. rewrite fl_opp. reflexivity. Qed.

Lemma rot_entry_err w x y z i j :
  let S := w * w + x * x + y * y + z * z in
  bpow radix2 (-802) <= S ->
  Rabs (rot_c w x y z i j - rot_N w x y z i j / S) <= 30 * u /\ Rabs (rot_N w x y z i j / S) <= 1.
Proof.
  intros S HS. pose proof u_small.
  assert (HS0 : 0 < S) by (pose proof (bpow_gt_0 radix2 (-802)); lra).
  assert (He : 1000000 * eta <= u * S) by (apply eta_rel; eapply Rle_trans; [apply bpow_le | exact HS]; lia).
  assert (0 <= w * w) by nra. assert (0 <= x * x) by nra. assert (0 <= y * y) by nra. assert (0 <= z * z) by nra.
  assert (Hs : Rabs (rot_s w x y z - S) <= 8 * u * S).
  { pose proof (sum4_err (w * w) (x * x) (y * y) (z * z) S HS0 He) as Hq4.
    rewrite !Rabs_pos_eq in Hq4 by lra. specialize (Hq4 ltac:(unfold S; lra)).
    unfold rot_s. change (w * w + x * x + y * y + z * z) with S in Hq4. assert (7001 / 1000 * (u * S) <= 8 * u * S) by nra. lra. }
  assert (Q : forall n N, Rabs N <= S -> Rabs (n - N) <= 8 * u * S ->
              Rabs (fl (n / rot_s w x y z) - N / S) <= 30 * u /\ Rabs (N / S) <= 1).
  { intros n N HN Hn. apply (quotient_err n (rot_s w x y z) N S (8 * u) (8 * u)); try lra. }
  assert (D4 : forall T1 T2 T3 T4, Rabs T1 + Rabs T2 + Rabs T3 + Rabs T4 <= S ->
               Rabs (sum4 T1 T2 T3 T4 - (T1 + T2 + T3 + T4)) <= 8 * u * S).
  { intros T1 T2 T3 T4 HT. pose proof (sum4_err T1 T2 T3 T4 S HS0 He HT). nra. }
  assert (D2 : forall T1 T2, 2 * (Rabs T1 + Rabs T2) <= S ->
               Rabs (twice2 T1 T2 - 2 * (T1 + T2)) <= 8 * u * S).
  { intros T1 T2 HT. pose proof (twice2_err T1 T2 S HS0 He HT). nra. }
  pose proof (two_ab x y). pose proof (two_ab w z). pose proof (two_ab x z). pose proof (two_ab w y).
  pose proof (two_ab y z). pose proof (two_ab w x).
  assert (Ha : forall t, Rabs (- t) = Rabs t) by (intros; apply Rabs_Ropp).
  assert (Sq : forall t, Rabs (t * t) = t * t) by (intros; apply Rabs_pos_eq; nra).
  assert (E4 : forall T1 T2 T3 T4 N, Rabs T1 + Rabs T2 + Rabs T3 + Rabs T4 <= S -> N = T1 + T2 + T3 + T4 ->
    Rabs (fl (fl (fl (fl (fl T1 + fl T2) + fl T3) + fl T4) / rot_s w x y z) - N / S) <= 30 * u /\ Rabs (N / S) <= 1).
  { intros T1 T2 T3 T4 N HT ->. apply Q; [|apply D4, HT].
    eapply Rle_trans; [apply abs_sum_le; [apply abs_sum_le; [apply abs_sum_le|]|]; apply Rle_refl | exact HT]. }
  assert (E2 : forall T1 T2 N, 2 * (Rabs T1 + Rabs T2) <= S -> N = 2 * (T1 + T2) ->
    Rabs (fl (fl (2 * fl (fl T1 + fl T2)) / rot_s w x y z) - N / S) <= 30 * u /\ Rabs (N / S) <= 1).
  { intros T1 T2 N HT ->. apply Q; [|apply D2, HT].
    rewrite Rabs_mult, (Rabs_pos_eq 2) by lra. pose proof (Rabs_triang T1 T2). lra. }
  unfold rot_c, rot_N.
  destruct i as [|[|i]]; destruct j as [|[|j]]; rewrite ?fl_sub_prod;
  first [ eapply E4; [rewrite ?Ha, ?Sq; unfold S; lra | ring]
        | eapply E2; [rewrite ?Ha; unfold S; lra | ring] ].
Qed.

(* One world coordinate of the posed point: fl(fl(R~ r) + p) (pose(): R * r_B
   + p; transform_point: p + R * r_B, the same rounding), R~ a row of
   computed entries within 30 u of the exact row R, |R_j| <= 1, |r_j| <= rho,
   |p| <= P. *)
Lemma posed_coordinate_err a0 a1 a2 A0 A1 A2 r0 r1 r2 p rho P :
  Rabs (a0 - A0) <= 30 * u -> Rabs (a1 - A1) <= 30 * u -> Rabs (a2 - A2) <= 30 * u ->
  Rabs A0 <= 1 -> Rabs A1 <= 1 -> Rabs A2 <= 1 ->
  Rabs r0 <= rho -> Rabs r1 <= rho -> Rabs r2 <= rho -> Rabs p <= P ->
  Rabs (fl (dot3 a0 a1 a2 r0 r1 r2 + p) - (p + (A0 * r0 + A1 * r1 + A2 * r2))) <= 103 * u * (P + rho) + 7 * eta.
Proof.
  intros E0 E1 E2 B0 B1 B2 H0 H1 H2 Hp. pose proof u_small as Hu. pose proof eta_pos.
  assert (Hrho : 0 <= rho) by (pose proof (Rabs_pos r0); lra).
  assert (HP : 0 <= P) by (pose proof (Rabs_pos p); lra).
  (* each computed entry at most 1 + 30 u, each term |a_j r_j| <= (1 + 30 u) rho *)
  assert (T : forall a A r, Rabs (a - A) <= 30 * u -> Rabs A <= 1 -> Rabs r <= rho ->
              Rabs (a * r) <= (1 + 30 * u) * rho /\ Rabs (a * r - A * r) <= 30 * u * rho).
  { intros a A r Ea Ba Hr. pose proof (Rabs_pos r).
    assert (Rabs a <= 1 + 30 * u).
    { replace a with (A + (a - A)) by ring. pose proof (Rabs_triang A (a - A)). lra. }
    split; rewrite ?Rabs_mult.
    - pose proof (Rabs_pos a). apply Rmult_le_compat; lra.
    - replace (a * r - A * r) with ((a - A) * r) by ring. rewrite Rabs_mult.
      pose proof (Rabs_pos (a - A)). apply Rmult_le_compat; lra. }
  destruct (T a0 A0 r0 E0 B0 H0) as [T0 D0]. destruct (T a1 A1 r1 E1 B1 H1) as [T1 D1].
  destruct (T a2 A2 r2 E2 B2 H2) as [T2 D2].
  pose proof (dot3_err a0 a1 a2 r0 r1 r2) as Hd. simpl in Hd.
  set (Tm := Rabs (a0 * r0) + Rabs (a1 * r1) + Rabs (a2 * r2)) in Hd.
  assert (HT : Tm <= 3 * ((1 + 30 * u) * rho)) by (unfold Tm; lra).
  assert (HT' : u * Tm <= u * (3 * ((1 + 30 * u) * rho))) by (apply mul_le_l; lra).
  assert (u * (u * rho) <= / 1000000000000000 * (u * rho)) by (apply Rmult_le_compat_r; nra).
  set (y := dot3 a0 a1 a2 r0 r1 r2) in *.
  set (Y := A0 * r0 + A1 * r1 + A2 * r2).
  assert (Ey : Rabs (y - Y) <= 991 / 10 * u * rho + 51 / 10 * eta).
  { replace (y - Y) with ((y - (a0 * r0 + a1 * r1 + a2 * r2))
                           + ((a0 * r0 - A0 * r0) + (a1 * r1 - A1 * r1) + (a2 * r2 - A2 * r2))) by (unfold Y; ring).
    eapply Rle_trans; [apply Rabs_triang|].
    pose proof (Rabs_triang ((a0 * r0 - A0 * r0) + (a1 * r1 - A1 * r1)) (a2 * r2 - A2 * r2)).
    pose proof (Rabs_triang (a0 * r0 - A0 * r0) (a1 * r1 - A1 * r1)).
    assert (0 <= u * rho) by nra. lra. }
  assert (BY : Rabs (p + Y) <= P + 3 * rho).
  { unfold Y. pose proof (Rabs_triang p (A0 * r0 + A1 * r1 + A2 * r2)).
    pose proof (Rabs_triang (A0 * r0 + A1 * r1) (A2 * r2)). pose proof (Rabs_triang (A0 * r0) (A1 * r1)).
    assert (Ar : forall A r, Rabs A <= 1 -> Rabs r <= rho -> Rabs (A * r) <= rho).
    { intros A r HA Hr. rewrite Rabs_mult. pose proof (Rabs_pos A). pose proof (Rabs_pos r).
      replace rho with (1 * rho) by ring. apply Rmult_le_compat; lra. }
    pose proof (Ar A0 r0 B0 H0). pose proof (Ar A1 r1 B1 H1). pose proof (Ar A2 r2 B2 H2). lra. }
  pose proof (step (y + p) (p + Y) (P + 3 * rho) (991 / 10 * u * rho + 51 / 10 * eta) BY
                ltac:(replace (y + p - (p + Y)) with (y - Y) by ring; exact Ey)) as Hs.
  assert (u * (P + 3 * rho + (991 / 10 * u * rho + 51 / 10 * eta)) <= u * P + 3 * u * rho + / 10000000 * (u * rho) + / 10 * eta).
  { assert (u * (991 / 10 * u * rho) <= / 10000000 * (u * rho)) by nra.
    assert (u * (51 / 10 * eta) <= / 10 * eta) by nra. nra. }
  assert (0 <= u * P) by nra. assert (0 <= u * rho) by nra.
  lra.
Qed.

Lemma norm_le_sum_abs e0 e1 e2 : sqrt (e0 * e0 + e1 * e1 + e2 * e2) <= Rabs e0 + Rabs e1 + Rabs e2.
Proof.
  pose proof (Rabs_pos e0). pose proof (Rabs_pos e1). pose proof (Rabs_pos e2).
  rewrite <- (sqrt_square (Rabs e0 + Rabs e1 + Rabs e2)) by lra. apply sqrt_le_1_alt.
  rewrite <- (abs_sq e0), <- (abs_sq e1), <- (abs_sq e2). nra.
Qed.

(* The posed point in doubles, coordinate i (pose(): R * r_B + p), and the
   exact one p + R(q) r_B, R(q)_ij = N_ij / S. *)
Definition posed_c w x y z p r0 r1 r2 i :=
  fl (dot3 (rot_c w x y z i 0) (rot_c w x y z i 1) (rot_c w x y z i 2) r0 r1 r2 + p).
Definition posed_x w x y z p r0 r1 r2 i :=
  let S := w * w + x * x + y * y + z * z in
  p + (rot_N w x y z i 0 / S * r0 + rot_N w x y z i 1 / S * r1 + rot_N w x y z i 2 / S * r2).
Definition pose_err w x y z p0 p1 p2 r0 r1 r2 :=
  let e0 := posed_c w x y z p0 r0 r1 r2 0 - posed_x w x y z p0 r0 r1 r2 0 in
  let e1 := posed_c w x y z p1 r0 r1 r2 1 - posed_x w x y z p1 r0 r1 r2 1 in
  let e2 := posed_c w x y z p2 r0 r1 r2 2 - posed_x w x y z p2 r0 r1 r2 2 in
  sqrt (e0 * e0 + e1 * e1 + e2 * e2).

(* pose_rounding (kPoseRounding's expression, geometry/pose.cpp
   rotation_matrix and the product R r_B + p): a body point r_B posed in
   doubles at the double pose (p, q), every operation rounded as the code
   rounds it, lies within 309 u (|p|_inf + rho) + 21 eta of the exact
   p + R(q) r_B, in the Euclidean norm, for |r_B|_inf <= rho and q the
   quaternion rotation_matrix works on (after `rescaled`: its largest
   component is at least 2^-401, so S >= 2^-802). *)
(* covers optimized/gauss6/geometry/pose.cpp "Mat3 rotation_matrix(const Quat& q_in)" sha256:6e30996ccd25c184 *)
(* covers optimized/gauss6/geometry/pose.cpp "Quat rescaled(const Quat& q)" sha256:fb74734e83856b0e *)
(* covers optimized/gauss6/ccd/motion_bounds.h "Vec3 pose(const Vec3& r_B) const" sha256:a1cfd2440d7550c5 *)
Theorem pose_rounding w x y z p0 p1 p2 r0 r1 r2 P rho :
  bpow radix2 (-802) <= w * w + x * x + y * y + z * z ->
  Rabs p0 <= P -> Rabs p1 <= P -> Rabs p2 <= P ->
  Rabs r0 <= rho -> Rabs r1 <= rho -> Rabs r2 <= rho ->
  pose_err w x y z p0 p1 p2 r0 r1 r2 <= 309 * u * (P + rho) + 21 * eta.
Proof.
  intros HS Hp0 Hp1 Hp2 H0 H1 H2.
  assert (C : forall i p, Rabs p <= P ->
    Rabs (posed_c w x y z p r0 r1 r2 i - posed_x w x y z p r0 r1 r2 i) <= 103 * u * (P + rho) + 7 * eta).
  { intros i p Hp. unfold posed_c, posed_x.
    destruct (rot_entry_err w x y z i 0 HS). destruct (rot_entry_err w x y z i 1 HS).
    destruct (rot_entry_err w x y z i 2 HS).
    apply posed_coordinate_err; assumption. }
  unfold pose_err. eapply Rle_trans; [apply norm_le_sum_abs|].
  pose proof (C 0%nat p0 Hp0). pose proof (C 1%nat p1 Hp1). pose proof (C 2%nat p2 Hp2). lra.
Qed.
Print Assumptions pose_rounding.

(* allowance kPoseRounding = 1e-13 *)
Definition kPoseRounding := fl (/ 10000000000000).
Lemma kPoseRounding_ge : 800 * u <= kPoseRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.

(* pose_rounding_start_frame (StartFrame::set, motion_bounds.cpp):
   static_error = Upper{deviation} + kPoseRounding * (p_inf + Upper{rho}),
   the Upper operations of rounding.h (Rounding.v upper_add for the sum with
   the deviation); the posing's term, next_up(fl(kPoseRounding
   next_up(fl(p_inf + rho)))), bounds the posing error for every double
   pose and every body point with |r_B|_inf <= rho (p_inf = |p|_inf, exact). *)
(* covers optimized/gauss6/ccd/motion_bounds.cpp "void StartFrame::set(const CcdMotion& m, double u, double rho_in)" sha256:cfac9ee869768b2c *)
Theorem pose_rounding_start_frame w x y z p0 p1 p2 r0 r1 r2 P rho :
  bpow radix2 (-802) <= w * w + x * x + y * y + z * z ->
  Rabs p0 <= P -> Rabs p1 <= P -> Rabs p2 <= P ->
  Rabs r0 <= rho -> Rabs r1 <= rho -> Rabs r2 <= rho ->
  pose_err w x y z p0 p1 p2 r0 r1 r2 <= next_up (fl (kPoseRounding * next_up (fl (P + rho)))).
Proof.
  intros HS Hp0 Hp1 Hp2 H0 H1 H2.
  pose proof (pose_rounding w x y z p0 p1 p2 r0 r1 r2 P rho HS Hp0 Hp1 Hp2 H0 H1 H2) as E.
  pose proof u_small. pose proof eta_pos. pose proof kPoseRounding_ge.
  assert (0 <= P) by (pose proof (Rabs_pos p0); lra). assert (0 <= rho) by (pose proof (Rabs_pos r0); lra).
  assert (Y : P + rho <= next_up (fl (P + rho))) by (apply up_ge; lra).
  set (Yc := next_up (fl (P + rho))) in *.
  assert (K : 800 * u * (P + rho) <= kPoseRounding * Yc).
  { apply Rle_trans with (kPoseRounding * (P + rho)); [apply Rmult_le_compat_r; lra | apply mul_le_l; lra]. }
  assert (0 <= kPoseRounding * Yc) by nra.
  pose proof (fl_lower (kPoseRounding * Yc) ltac:(lra)) as L.
  assert (0 <= fl (kPoseRounding * Yc)) by (apply fl_nonneg; lra).
  pose proof (next_up_plus _ ltac:(eassumption)) as N.
  assert (He : 1000 * eta <= bpow radix2 (-602)).
  { unfold eta. apply Rle_trans with (bpow radix2 10 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  assert (u * (kPoseRounding * Yc) <= / 1000 * (kPoseRounding * Yc)) by (apply Rmult_le_compat_r; lra).
  assert (0 <= u * (P + rho)) by nra.
  lra.
Qed.
Print Assumptions pose_rounding_start_frame.

(* pose_rounding_stand_at (runtime/sim_step4.cpp, stand_at): posing_error =
   round_up(deviation + kPoseRounding * (p_inf + god_radius)), the inner
   operations plain doubles: deviation + the posing error is at most it,
   for rho >= 2^-1000 (a god-object radius above 1e-301: kMinBodyRadius,
   which RuntimeModel checks when it builds the model). *)
(* covers optimized/gauss6/runtime/sim_step4.cpp "void stand_at(const RuntimeModel& model, LegEnd* leg)" sha256:81108f2f6f8aa92e *)
Theorem pose_rounding_stand_at w x y z p0 p1 p2 r0 r1 r2 P rho dev :
  bpow radix2 (-802) <= w * w + x * x + y * y + z * z ->
  Rabs p0 <= P -> Rabs p1 <= P -> Rabs p2 <= P ->
  Rabs r0 <= rho -> Rabs r1 <= rho -> Rabs r2 <= rho -> bpow radix2 (-1000) <= rho ->
  dev + pose_err w x y z p0 p1 p2 r0 r1 r2 <= next_up (fl (dev + fl (kPoseRounding * fl (P + rho)))).
Proof.
  intros HS Hp0 Hp1 Hp2 H0 H1 H2 Hr.
  pose proof (pose_rounding w x y z p0 p1 p2 r0 r1 r2 P rho HS Hp0 Hp1 Hp2 H0 H1 H2) as E.
  pose proof u_small. pose proof eta_pos. pose proof kPoseRounding_ge.
  assert (0 <= P) by (pose proof (Rabs_pos p0); lra).
  pose proof (bpow_gt_0 radix2 (-1000)).
  assert (He : 1000000 * eta <= u * (P + rho)) by (apply eta_rel; apply Rle_trans with (bpow radix2 (-1000)); [apply bpow_le; lia | lra]).
  pose proof (fl_lower (P + rho) ltac:(lra)) as L1.
  assert (0 <= fl (P + rho)) by (apply fl_nonneg; lra).
  assert (K : kPoseRounding * ((1 - u) * (P + rho) - eta) <= kPoseRounding * fl (P + rho)) by (apply mul_le_l; lra).
  assert (0 <= kPoseRounding * fl (P + rho)) by nra.
  pose proof (fl_lower (kPoseRounding * fl (P + rho)) ltac:(lra)) as L2.
  assert (kPoseRounding <= 1) by (unfold kPoseRounding; apply fl_le_F; [apply generic_format_bpow with (e := 0%Z); unfold FLT_exp; lia | simpl; lra]).
  assert (800 * u * (P + rho) <= kPoseRounding * (P + rho)) by (apply Rmult_le_compat_r; lra).
  assert (u * (kPoseRounding * fl (P + rho)) <= / 1000 * (kPoseRounding * fl (P + rho))) by (apply Rmult_le_compat_r; lra).
  assert (kPoseRounding * (u * (P + rho)) <= u * (P + rho)) by (rewrite <- (Rmult_1_l (u * (P + rho))) at 2; apply Rmult_le_compat_r; nra).
  assert (kPoseRounding * eta <= eta) by (rewrite <- (Rmult_1_l eta) at 2; apply Rmult_le_compat_r; lra).
  assert (T : pose_err w x y z p0 p1 p2 r0 r1 r2 <= fl (kPoseRounding * fl (P + rho))) by nra.
  eapply Rle_trans; [|apply up_ge, Rle_refl]. lra.
Qed.
Print Assumptions pose_rounding_stand_at.

(* ---- kQuaternionTurnRounding ----
   Displacement::Displacement (motion_bounds.cpp): qa = normalized(a.q), qb =
   normalized(b.q) (pose.cpp: on the rescaled q, n = sqrt(w w + x x + y y +
   z z), each component q_i / n), v = qa.w qb.vec - qb.w qa.vec - qa.vec x
   qb.vec (each coordinate (p1 - p2) - (p3 - p4) of rounded products), and
   turn = round_up(2 |v|) + Upper{kQuaternionTurnRounding} (|v| the computed
   norm: Allowances.v norm_c, any order of the sum). The exact turn is
   2 |vec(conj(A) B)|, A = a / |a| and B = b / |b| the exact unit
   quaternions. *)

(* A rounded sum of approximations of nonnegative reals. *)
Lemma pos_sum x y X Y a b c :
  0 <= X -> 0 <= Y -> 0 <= a <= / 100 -> 0 <= b <= 100 -> 0 <= c <= 100 ->
  Rabs (x - X) <= a * X + b * eta -> Rabs (y - Y) <= a * Y + c * eta ->
  Rabs (fl (x + y) - (X + Y)) <= (a + u + u * a) * (X + Y) + (b + c + 1 + / 1000) * eta.
Proof.
  intros HX HY Ha Hb Hc Hx Hy. pose proof u_small. pose proof eta_pos.
  assert (E : Rabs (x + y - (X + Y)) <= a * (X + Y) + (b + c) * eta).
  { replace (x + y - (X + Y)) with ((x - X) + (y - Y)) by ring.
    eapply Rle_trans; [apply Rabs_triang | lra]. }
  assert (M : Rabs (x + y) <= (1 + a) * (X + Y) + (b + c) * eta).
  { replace (x + y) with ((X + Y) + (x + y - (X + Y))) by ring.
    pose proof (Rabs_triang (X + Y) (x + y - (X + Y))). rewrite (Rabs_pos_eq (X + Y)) in H1 by lra. lra. }
  pose proof (fl_err (x + y)) as F.
  assert (u * Rabs (x + y) <= u * ((1 + a) * (X + Y) + (b + c) * eta)) by (apply mul_le_l; lra).
  assert (u * ((b + c) * eta) <= / 1000 * eta) by (apply Rle_trans with ((u * (b + c)) * eta); [right; ring | apply Rmult_le_compat_r; nra]).
  replace (fl (x + y) - (X + Y)) with ((fl (x + y) - (x + y)) + (x + y - (X + Y))) by ring.
  eapply Rle_trans; [apply Rabs_triang|]. nra.
Qed.

(* The sum of four nonnegative rounded terms, within 4.01 u of itself. *)
Lemma sum4_pos T1 T2 T3 T4 S :
  0 <= T1 -> 0 <= T2 -> 0 <= T3 -> 0 <= T4 -> S = T1 + T2 + T3 + T4 ->
  1000000 * eta <= u * S ->
  Rabs (sum4 T1 T2 T3 T4 - S) <= 401 / 100 * u * S.
Proof.
  intros H1 H2 H3 H4 HS He. pose proof u_small. pose proof eta_pos. unfold sum4.
  assert (P : forall T, 0 <= T -> Rabs (fl T - T) <= u * T + 1 * eta).
  { intros T HT. pose proof (fl_err T) as F. rewrite (Rabs_pos_eq T) in F by lra. lra. }
  pose proof (pos_sum (fl T1) (fl T2) T1 T2 u 1 1 H1 H2 ltac:(lra) ltac:(lra) ltac:(lra) (P T1 H1) (P T2 H2)) as E1.
  set (a1 := u + u + u * u) in E1.
  assert (A1 : u <= a1 <= 20001 / 10000 * u) by (unfold a1; nra).
  assert (P3 : Rabs (fl T3 - T3) <= a1 * T3 + 1 * eta).
  { pose proof (P T3 H3). assert (u * T3 <= a1 * T3) by (apply Rmult_le_compat_r; lra). lra. }
  pose proof (pos_sum _ (fl T3) (T1 + T2) T3 a1 (1 + 1 + 1 + / 1000) 1 ltac:(lra) H3 ltac:(lra) ltac:(lra) ltac:(lra) E1 P3) as E2.
  set (a2 := a1 + u + u * a1) in E2.
  assert (A2 : u <= a2 <= 30002 / 10000 * u) by (unfold a2; nra).
  assert (P4 : Rabs (fl T4 - T4) <= a2 * T4 + 1 * eta).
  { pose proof (P T4 H4). assert (u * T4 <= a2 * T4) by (apply Rmult_le_compat_r; lra). lra. }
  pose proof (pos_sum _ (fl T4) (T1 + T2 + T3) T4 a2 ((1 + 1 + 1 + / 1000) + 1 + 1 + / 1000) 1 ltac:(lra) H4 ltac:(lra) ltac:(lra) ltac:(lra) E2 P4) as E3.
  set (a3 := a2 + u + u * a2) in E3.
  assert (A3 : a3 <= 4005 / 1000 * u) by (unfold a3; nra).
  rewrite HS. assert (a3 * (T1 + T2 + T3 + T4) <= 4005 / 1000 * u * (T1 + T2 + T3 + T4)) by (apply Rmult_le_compat_r; lra).
  rewrite <- HS in *. lra.
Qed.

(* normalized (pose.cpp) on a quaternion with S >= 2^-802 (rescaled): each
   component fl(c / n), n = fl(sqrt(s)), within 4.1 u (relatively) + eta of
   the exact unit quaternion's c / sqrt(S). *)
Definition qnorm_c w x y z := fl (sqrt (sum4 (w * w) (x * x) (y * y) (z * z))).
Lemma normalize_err w x y z c :
  let S := w * w + x * x + y * y + z * z in
  bpow radix2 (-802) <= S ->
  Rabs (fl (c / qnorm_c w x y z) - c / sqrt S) <= 41 / 10 * u * Rabs (c / sqrt S) + eta.
Proof.
  intros S HS. pose proof u_small. pose proof eta_pos.
  assert (HS0 : 0 < S) by (pose proof (bpow_gt_0 radix2 (-802)); lra).
  assert (He : 1000000 * eta <= u * S) by (apply eta_rel; eapply Rle_trans; [apply bpow_le | exact HS]; lia).
  assert (0 <= w * w) by nra. assert (0 <= x * x) by nra. assert (0 <= y * y) by nra. assert (0 <= z * z) by nra.
  pose proof (sum4_pos (w * w) (x * x) (y * y) (z * z) S ltac:(lra) ltac:(lra) ltac:(lra) ltac:(lra) eq_refl He) as Hs.
  set (s := sum4 (w * w) (x * x) (y * y) (z * z)) in *.
  set (N := sqrt S).
  assert (HN : bpow radix2 (-401) <= N)
    by (unfold N; rewrite <- (sqrt_bpow2 (-401)); apply sqrt_le_1_alt; exact HS).
  assert (HeN : 1000000 * eta <= u * N) by (apply eta_norm; eapply Rle_trans; [apply bpow_le | exact HN]; lia).
  assert (HN0 : 0 < N) by (pose proof (bpow_gt_0 radix2 (-401)); lra).
  assert (Hup : sqrt s <= (1 + 201 / 100 * u) * N).
  { unfold N. rewrite <- sqrt_scale by lra. apply sqrt_le_1_alt.
    apply Rle_trans with ((1 + 401 / 100 * u) * S); [unfold Rabs in Hs; destruct Rcase_abs; lra|].
    apply Rmult_le_compat_r; nra. }
  assert (Hlo : (1 - 201 / 100 * u) * N <= sqrt s).
  { unfold N. rewrite <- sqrt_scale by lra. apply sqrt_le_1_alt.
    apply Rle_trans with ((1 - 401 / 100 * u) * S); [apply Rmult_le_compat_r; nra|].
    unfold Rabs in Hs; destruct Rcase_abs; lra. }
  pose proof (fl_lower (sqrt s) (sqrt_pos s)) as L. pose proof (fl_upper (sqrt s) (sqrt_pos s)) as U.
  unfold qnorm_c. fold s. set (n := fl (sqrt s)) in *.
  assert (Hn : Rabs (n - N) <= 302 / 100 * u * N).
  { assert ((1 - u) * ((1 - 201 / 100 * u) * N) <= (1 - u) * sqrt s) by (apply mul_le_l; lra).
    assert ((1 + u) * sqrt s <= (1 + u) * ((1 + 201 / 100 * u) * N)) by (apply mul_le_l; lra).
    assert (u * (u * N) <= / 1000000000000000 * (u * N)) by (apply Rmult_le_compat_r; nra).
    unfold Rabs; destruct Rcase_abs; nra. }
  assert (Hn0 : (1 - 302 / 100 * u) * N <= n) by (unfold Rabs in Hn; destruct Rcase_abs; lra).
  assert (Hnp : 0 < n) by nra.
  set (C := c / N).
  assert (Hq : c / n - C = C * ((N - n) / n)) by (unfold C; field; lra).
  assert (Hr : Rabs ((N - n) / n) <= 303 / 100 * u).
  { unfold Rdiv. rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq n) by lra.
    apply Rmult_le_reg_r with n; [lra|]. rewrite Rmult_assoc, Rinv_l by lra. rewrite Rmult_1_r.
    rewrite Rabs_minus_sym. apply Rle_trans with (302 / 100 * u * N); [exact Hn|].
    assert (u * (u * N) <= / 1000000000000000 * (u * N)) by (apply Rmult_le_compat_r; nra).
    assert (303 / 100 * u * ((1 - 302 / 100 * u) * N) <= 303 / 100 * u * n) by (apply mul_le_l; lra).
    nra. }
  assert (Hd : Rabs (c / n - C) <= 303 / 100 * u * Rabs C).
  { rewrite Hq, Rabs_mult. rewrite (Rmult_comm (303 / 100 * u)). apply mul_le_l; [apply Rabs_pos | exact Hr]. }
  pose proof (fl_err (c / n)) as F.
  assert (Rabs (c / n) <= (1 + 303 / 100 * u) * Rabs C).
  { replace (c / n) with (C + (c / n - C)) by ring. pose proof (Rabs_triang C (c / n - C)). lra. }
  assert (u * Rabs (c / n) <= u * ((1 + 303 / 100 * u) * Rabs C)) by (apply mul_le_l; lra).
  assert (u * (u * Rabs C) <= / 1000000000000000 * (u * Rabs C)) by (apply Rmult_le_compat_r; [pose proof (Rabs_pos C); nra | lra]).
  replace (fl (c / n) - C) with ((fl (c / n) - c / n) + (c / n - C)) by ring.
  eapply Rle_trans; [apply Rabs_triang|]. nra.
Qed.

(* A rounded product of two normalized components, each within 4.1 u
   (relatively) + eta of the exact one, of magnitude <= 1. *)
Lemma qprod_err a A b B :
  Rabs (a - A) <= 41 / 10 * u * Rabs A + eta -> Rabs (b - B) <= 41 / 10 * u * Rabs B + eta ->
  Rabs A <= 1 -> Rabs B <= 1 ->
  Rabs (fl (a * b) - A * B) <= 93 / 10 * u * Rabs (A * B) + 5 * eta.
Proof.
  intros Ha Hb HA HB. pose proof u_small as Hu. pose proof eta_pos as He0.
  assert (He : eta <= / 1000000 * u) by (rewrite bpow_m53; unfold eta; simpl bpow; simpl IZR; lra).
  set (al := Rabs A) in *. set (be := Rabs B) in *.
  assert (Hal : 0 <= al) by apply Rabs_pos. assert (Hbe : 0 <= be) by apply Rabs_pos.
  set (da := Rabs (a - A)) in *. set (db := Rabs (b - B)) in *.
  assert (0 <= da) by apply Rabs_pos. assert (0 <= db) by apply Rabs_pos.
  set (e := 41 / 10 * u) in *.
  assert (He' : 0 < e <= / 100000000000000) by (unfold e; lra).
  assert (Hb1 : Rabs b <= (1 + e) * be + eta).
  { pose proof (Rabs_triang B (b - B)) as Tr. replace (B + (b - B)) with b in Tr by ring. fold be db in Tr.
    assert (e * be <= e * 1) by (apply mul_le_l; lra). nra. }
  assert (0 <= Rabs b) by apply Rabs_pos.
  assert (Hb2a : e * be <= e * 1) by (apply mul_le_l; lra).
  assert (Hb2 : Rabs b <= 2) by lra.
  assert (T1 : da * Rabs b <= (e * al + eta) * Rabs b) by (apply Rmult_le_compat_r; lra).
  assert (0 <= e * al) by (apply Rmult_le_pos; lra).
  assert (T2 : (e * al) * Rabs b <= (e * al) * ((1 + e) * be + eta)) by (apply mul_le_l; lra).
  assert (T3 : eta * Rabs b <= eta * 2) by (apply mul_le_l; lra).
  assert (T4 : (e * eta) * al <= (e * eta) * 1) by (apply mul_le_l; [apply Rmult_le_pos; lra | lra]).
  assert (T5 : al * db <= al * (e * be + eta)) by (apply mul_le_l; lra).
  assert (T6 : eta * al <= eta * 1) by (apply mul_le_l; lra).
  set (P := al * be) in *.
  assert (HP : 0 <= P) by (apply Rmult_le_pos; lra).
  assert (HP1 : P <= 1) by (unfold P; rewrite <- (Rmult_1_l 1); apply Rmult_le_compat; lra).
  assert (T7 : e * (e * P) <= / 100000000000000 * (e * P)) by (apply Rmult_le_compat_r; [apply Rmult_le_pos|]; lra).
  assert (T8 : e * eta <= / 100000000000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (D : Rabs (a * b - A * B) <= (2 * e + / 100000000000000 * e) * P + (3 + / 10000) * eta).
  { replace (a * b - A * B) with ((a - A) * b + A * (b - B)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult. fold da db al.
    assert (E1 : (e * al + eta) * Rabs b = (e * al) * Rabs b + eta * Rabs b) by ring.
    assert (E2 : (e * al) * ((1 + e) * be + eta) = e * P + e * (e * P) + (e * eta) * al) by (unfold P; ring).
    assert (E3 : al * (e * be + eta) = e * P + eta * al) by (unfold P; ring).
    lra. }
  pose proof (fl_err (a * b)) as F.
  assert (M : Rabs (a * b) <= (1 + / 10000) * P + 4 * eta).
  { replace (a * b) with (A * B + (a * b - A * B)) by ring. pose proof (Rabs_triang (A * B) (a * b - A * B)) as Tr2.
    rewrite (Rabs_mult A B) in Tr2. fold al be P in Tr2.
    assert ((2 * e + / 100000000000000 * e) * P <= / 10000 * P) by (apply Rmult_le_compat_r; lra). lra. }
  assert (M2 : u * Rabs (a * b) <= u * ((1 + / 10000) * P + 4 * eta)) by (apply mul_le_l; lra).
  assert (T9 : u * eta <= / 100000000000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (T10 : u * P <= e * P) by (apply Rmult_le_compat_r; unfold e; lra).
  replace (fl (a * b) - A * B) with ((fl (a * b) - a * b) + (a * b - A * B)) by ring.
  rewrite Rabs_mult. fold al be P.
  eapply Rle_trans; [apply Rabs_triang|].
  assert (T11 : e * P = 41 / 10 * (u * P)) by (unfold e; ring).
  assert (T12 : 0 <= u * P) by (apply Rmult_le_pos; lra).
  lra.
Qed.

(* One coordinate of vec(conj(qa) qb) as the code computes it: (p1 - p2) -
   (p3 - p4) of four rounded products, each within 9.3 u of its exact one
   + 5 eta, the exact products' magnitudes summing to at most 1. *)
Lemma qcomp_err p1 P1 p2 P2 p3 P3 p4 P4 :
  Rabs (p1 - P1) <= 93 / 10 * u * Rabs P1 + 5 * eta -> Rabs (p2 - P2) <= 93 / 10 * u * Rabs P2 + 5 * eta ->
  Rabs (p3 - P3) <= 93 / 10 * u * Rabs P3 + 5 * eta -> Rabs (p4 - P4) <= 93 / 10 * u * Rabs P4 + 5 * eta ->
  Rabs P1 + Rabs P2 + Rabs P3 + Rabs P4 <= 1 ->
  Rabs (fl (fl (p1 - p2) - fl (p3 - p4)) - ((P1 - P2) - (P3 - P4))) <= 1132 / 100 * u.
Proof.
  intros H1 H2 H3 H4 HT. pose proof u_small as Hu. pose proof eta_pos as He0.
  assert (He : eta <= / 1000000 * u) by (rewrite bpow_m53; unfold eta; simpl bpow; simpl IZR; lra).
  pose proof (Rabs_pos P1). pose proof (Rabs_pos P2). pose proof (Rabs_pos P3). pose proof (Rabs_pos P4).
  set (A1 := Rabs P1) in *. set (A2 := Rabs P2) in *. set (A3 := Rabs P3) in *. set (A4 := Rabs P4) in *.
  assert (Ec := step (p3 - p4) (P3 - P4) (A3 + A4) (93 / 10 * u * (A3 + A4) + 10 * eta)
                  ltac:(apply abs_diff_le; apply Rle_refl) ltac:(pose proof (abs_sub p3 P3 p4 P4 _ _ H3 H4); lra)).
  assert (Et := step (p1 - p2) (P1 - P2) (A1 + A2) (93 / 10 * u * (A1 + A2) + 10 * eta)
                  ltac:(apply abs_diff_le; apply Rle_refl) ltac:(pose proof (abs_sub p1 P1 p2 P2 _ _ H1 H2); lra)).
  assert (Q1 : u * (A3 + A4 + (93 / 10 * u * (A3 + A4) + 10 * eta)) <= u * (A3 + A4) + / 100000000 * u).
  { assert (u * (u * (A3 + A4)) <= / 1000000000000000 * u) by (apply Rle_trans with (u * (u * 1)); [apply mul_le_l; [lra | apply mul_le_l; lra] | rewrite Rmult_1_r; apply Rmult_le_compat_r; lra]).
    assert (u * eta <= / 1000000000000000 * eta) by (apply Rmult_le_compat_r; lra). lra. }
  assert (Q2 : u * (A1 + A2 + (93 / 10 * u * (A1 + A2) + 10 * eta)) <= u * (A1 + A2) + / 100000000 * u).
  { assert (u * (u * (A1 + A2)) <= / 1000000000000000 * u) by (apply Rle_trans with (u * (u * 1)); [apply mul_le_l; [lra | apply mul_le_l; lra] | rewrite Rmult_1_r; apply Rmult_le_compat_r; lra]).
    assert (u * eta <= / 1000000000000000 * eta) by (apply Rmult_le_compat_r; lra). lra. }
  set (Bc := 93 / 10 * u * (A3 + A4) + 10 * eta + (u * (A3 + A4) + / 100000000 * u) + eta).
  set (Bt := 93 / 10 * u * (A1 + A2) + 10 * eta + (u * (A1 + A2) + / 100000000 * u) + eta).
  assert (Ec' : Rabs (fl (p3 - p4) - (P3 - P4)) <= Bc) by (unfold Bc; lra).
  assert (Et' : Rabs (fl (p1 - p2) - (P1 - P2)) <= Bt) by (unfold Bt; lra).
  assert (Ef := step (fl (p1 - p2) - fl (p3 - p4)) ((P1 - P2) - (P3 - P4)) (A1 + A2 + A3 + A4) (Bt + Bc)
                  ltac:(pose proof (abs_diff_le (P1 - P2) (P3 - P4) (A1 + A2) (A3 + A4) ltac:(apply abs_diff_le; apply Rle_refl) ltac:(apply abs_diff_le; apply Rle_refl)); lra)
                  ltac:(apply abs_sub; assumption)).
  assert (0 <= u * A1) by (apply Rmult_le_pos; lra). assert (0 <= u * A2) by (apply Rmult_le_pos; lra).
  assert (0 <= u * A3) by (apply Rmult_le_pos; lra). assert (0 <= u * A4) by (apply Rmult_le_pos; lra).
  assert (Bt + Bc <= 1031 / 100 * u * (A1 + A2 + A3 + A4) + 23 * eta + / 10000000 * u) by (unfold Bt, Bc; lra).
  assert (0 <= u * (A1 + A2 + A3 + A4)) by (apply Rmult_le_pos; lra).
  assert (u * (A1 + A2 + A3 + A4) <= u * 1) by (apply mul_le_l; lra).
  assert (u * (Bt + Bc) <= / 100000000 * u).
  { apply Rle_trans with (u * (11 * / 1000000000000000)); [apply mul_le_l; [lra|] | lra].
    assert (1031 / 100 * u * (A1 + A2 + A3 + A4) <= 1031 / 100 * u * 1) by (apply mul_le_l; lra). lra. }
  assert (1031 / 100 * u * (A1 + A2 + A3 + A4) <= 1031 / 100 * (u * 1)) by (rewrite Rmult_assoc; apply mul_le_l; lra).
  lra.
Qed.

Lemma cs3 a0 a1 a2 w0 w1 w2 :
  a0 * w0 + a1 * w1 + a2 * w2 <= sqrt (a0 * a0 + a1 * a1 + a2 * a2) * sqrt (w0 * w0 + w1 * w1 + w2 * w2).
Proof. exact (ObbAllowances.cauchy_schwarz3 a0 a1 a2 w0 w1 w2). Qed.

(* The triangle inequality of the Euclidean norm of 3-vectors. *)
Lemma minkowski3 x0 x1 x2 y0 y1 y2 :
  sqrt ((x0 + y0) * (x0 + y0) + (x1 + y1) * (x1 + y1) + (x2 + y2) * (x2 + y2))
  <= sqrt (x0 * x0 + x1 * x1 + x2 * x2) + sqrt (y0 * y0 + y1 * y1 + y2 * y2).
Proof.
  set (X := x0 * x0 + x1 * x1 + x2 * x2). set (Y := y0 * y0 + y1 * y1 + y2 * y2).
  assert (0 <= X) by (unfold X; nra). assert (0 <= Y) by (unfold Y; nra).
  pose proof (sqrt_pos X). pose proof (sqrt_pos Y).
  rewrite <- (sqrt_square (sqrt X + sqrt Y)) by lra. apply sqrt_le_1_alt.
  pose proof (cs3 x0 x1 x2 y0 y1 y2). fold X Y in H3.
  pose proof (sqrt_sqrt X H). pose proof (sqrt_sqrt Y H0).
  unfold X, Y in *. nra.
Qed.

(* Each coordinate within m: the Euclidean norm within 1.7321 m. *)
Lemma norm_of_bounded e0 e1 e2 m :
  Rabs e0 <= m -> Rabs e1 <= m -> Rabs e2 <= m -> sqrt (e0 * e0 + e1 * e1 + e2 * e2) <= 17321 / 10000 * m.
Proof.
  intros H0 H1 H2. pose proof (Rabs_pos e0). assert (0 <= m) by lra.
  rewrite <- (sqrt_square (17321 / 10000 * m)) by lra. apply sqrt_le_1_alt.
  rewrite <- (abs_sq e0), <- (abs_sq e1), <- (abs_sq e2).
  pose proof (Rabs_pos e1). pose proof (Rabs_pos e2).
  assert (Rabs e0 * Rabs e0 <= m * m) by (apply Rmult_le_compat; lra).
  assert (Rabs e1 * Rabs e1 <= m * m) by (apply Rmult_le_compat; lra).
  assert (Rabs e2 * Rabs e2 <= m * m) by (apply Rmult_le_compat; lra).
  nra.
Qed.

(* The computed norm of a double vector (Allowances.v norm_c) is at least
   the exact norm less 3.04 u of it, above 2^-501. *)
Lemma norm_c_lower x y z :
  sqrt (x * x + y * y + z * z) <= (1 + 304 / 100 * u) * norm_c x y z + bpow radix2 (-501).
Proof.
  pose proof u_small. pose proof eta_pos.
  set (S := x * x + y * y + z * z). set (N := sqrt S).
  assert (HS0 : 0 <= S) by (unfold S; nra). assert (HN0 : 0 <= N) by apply sqrt_pos.
  assert (Hn0 : 0 <= norm_c x y z) by (unfold norm_c; apply fl_nonneg, sqrt_pos).
  assert (0 <= 304 / 100 * u * norm_c x y z) by (apply Rmult_le_pos; lra).
  pose proof (bpow_gt_0 radix2 (-501)).
  destruct (Rlt_or_le S (bpow radix2 (-1002))) as [Hs|Hs].
  - assert (N <= bpow radix2 (-501)).
    { unfold N. rewrite <- (sqrt_bpow2 (-501)). apply sqrt_le_1_alt. replace (2 * -501)%Z with (-1002)%Z by lia. lra. }
    lra.
  - pose proof (sumsq_lower x y z Hs) as L. fold S in L.
    set (s := fl (fl (fl (x * x) + fl (y * y)) + fl (z * z))) in *.
    assert (HN : bpow radix2 (-501) <= N)
      by (unfold N; rewrite <- (sqrt_bpow2 (-501)); apply sqrt_le_1_alt; exact Hs).
    assert (HeN : 1000000 * eta <= u * N) by (apply eta_norm; exact HN).
    assert (Hr : (1 - 201 / 100 * u) * N <= sqrt s).
    { unfold N. rewrite <- sqrt_scale by lra. apply sqrt_le_1_alt.
      apply Rle_trans with ((1 - 4 * u) * S); [apply Rmult_le_compat_r; nra | exact L]. }
    pose proof (fl_lower (sqrt s) (sqrt_pos s)) as F.
    unfold norm_c. fold s.
    assert ((1 - u) * ((1 - 201 / 100 * u) * N) <= (1 - u) * sqrt s) by (apply mul_le_l; lra).
    assert (K : (1 - 302 / 100 * u) * N <= fl (sqrt s)).
    { assert (u * (u * N) <= / 1000000000000000 * (u * N)) by (apply Rmult_le_compat_r; nra). nra. }
    assert (K2 : (1 + 304 / 100 * u) * ((1 - 302 / 100 * u) * N) <= (1 + 304 / 100 * u) * fl (sqrt s)) by (apply mul_le_l; lra).
    assert (u * (u * N) <= / 1000000000000000 * (u * N)) by (apply Rmult_le_compat_r; nra).
    nra.
Qed.

Lemma unit_component c S :
  0 < S -> c * c <= S -> Rabs (c / sqrt S) <= 1.
Proof.
  intros HS Hc. pose proof (sqrt_lt_R0 S HS) as HN.
  unfold Rdiv. rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq (sqrt S)) by lra.
  apply Rmult_le_reg_r with (sqrt S); [lra|]. rewrite Rmult_assoc, Rinv_l, Rmult_1_r, Rmult_1_l by lra.
  rewrite <- (sqrt_square (Rabs c)) by apply Rabs_pos. apply sqrt_le_1_alt. rewrite abs_sq. exact Hc.
Qed.

Lemma unit_sq c S : 0 < S -> (c / sqrt S) * (c / sqrt S) = c * c / S.
Proof.
  intros HS. pose proof (sqrt_lt_R0 S HS). pose proof (sqrt_sqrt S ltac:(lra)).
  replace (c / sqrt S * (c / sqrt S)) with (c * c / (sqrt S * sqrt S)) by (field; lra).
  rewrite H0. reflexivity.
Qed.

(* The sum of the magnitudes of the four products of one coordinate of
   vec(conj(A) B), A and B unit quaternions: at most 1 (2 |a b| <= a^2 + b^2). *)
Lemma four_products_le aw ax ay az bw bx by_ bz :
  aw * aw + ax * ax + ay * ay + az * az = 1 -> bw * bw + bx * bx + by_ * by_ + bz * bz = 1 ->
  Rabs (aw * bx) + Rabs (bw * ax) + Rabs (ay * bz) + Rabs (az * by_) <= 1.
Proof.
  intros HA HB. pose proof (two_ab aw bx). pose proof (two_ab bw ax). pose proof (two_ab ay bz). pose proof (two_ab az by_).
  lra.
Qed.

Definition vcomp a1 b1 a2 b2 a3 b3 a4 b4 := fl (fl (fl (a1 * b1) - fl (a2 * b2)) - fl (fl (a3 * b3) - fl (a4 * b4))).

(* allowance kQuaternionTurnRounding = 1e-14 *)
Definition kQuaternionTurnRounding := fl (/ 100000000000000).
Lemma kQuaternionTurnRounding_ge : 90 * u <= kQuaternionTurnRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.

(* quaternion_turn_rounding (Displacement::Displacement, motion_bounds.cpp):
   turn = round_up(2 |v|) + Upper{kQuaternionTurnRounding}, v = vec(conj(qa)
   qb) of the normalized doubles as the code computes it, is at least twice
   the norm of the exact vec(conj(A) B), A = a / |a|, B = b / |b|: the turn
   between the two poses' exact rotations (2 sin(theta / 2)). Each
   coordinate of v is within 11.32 u of the exact one (the normalisations
   4.1 u, the products 9.3 u, the three differences), the vector within
   19.61 u, its computed norm within 3.04 u + 2^-501: 2 |V| <= 2 |v|~ + 52 u,
   the allowance at least 90 u. *)
(* covers optimized/gauss6/ccd/motion_bounds.cpp "Displacement::Displacement(const Pose& a, const Pose& b)" sha256:79b4d579aa69d2b4 *)
(* covers optimized/gauss6/geometry/pose.cpp "Quat normalized(const Quat& q_in)" sha256:7d6163a1a0f15a70 *)
(* covers optimized/gauss6/geometry/pose.cpp "Quat rescaled(const Quat& q)" sha256:fb74734e83856b0e *)
Theorem quaternion_turn_rounding aw ax ay az bw bx by_ bz :
  let Sa := aw * aw + ax * ax + ay * ay + az * az in
  let Sb := bw * bw + bx * bx + by_ * by_ + bz * bz in
  bpow radix2 (-802) <= Sa -> bpow radix2 (-802) <= Sb ->
  let na := qnorm_c aw ax ay az in let nb := qnorm_c bw bx by_ bz in
  let aw' := fl (aw / na) in let ax' := fl (ax / na) in let ay' := fl (ay / na) in let az' := fl (az / na) in
  let bw' := fl (bw / nb) in let bx' := fl (bx / nb) in let by' := fl (by_ / nb) in let bz' := fl (bz / nb) in
  let v0 := vcomp aw' bx' bw' ax' ay' bz' az' by' in
  let v1 := vcomp aw' by' bw' ay' az' bx' ax' bz' in
  let v2 := vcomp aw' bz' bw' az' ax' by' ay' bx' in
  let Aw := aw / sqrt Sa in let Ax := ax / sqrt Sa in let Ay := ay / sqrt Sa in let Az := az / sqrt Sa in
  let Bw := bw / sqrt Sb in let Bx := bx / sqrt Sb in let By := by_ / sqrt Sb in let Bz := bz / sqrt Sb in
  let V0 := (Aw * Bx - Bw * Ax) - (Ay * Bz - Az * By) in
  let V1 := (Aw * By - Bw * Ay) - (Az * Bx - Ax * Bz) in
  let V2 := (Aw * Bz - Bw * Az) - (Ax * By - Ay * Bx) in
  2 * sqrt (V0 * V0 + V1 * V1 + V2 * V2)
    <= next_up (fl (next_up (fl (2 * norm_c v0 v1 v2)) + kQuaternionTurnRounding)).
Proof.
  intros Sa Sb HSa HSb na nb aw' ax' ay' az' bw' bx' by' bz' v0 v1 v2 Aw Ax Ay Az Bw Bx By Bz V0 V1 V2.
  pose proof u_small as Hu. pose proof eta_pos as He0.
  assert (He : eta <= / 1000000 * u) by (rewrite bpow_m53; unfold eta; simpl bpow; simpl IZR; lra).
  pose proof (bpow_gt_0 radix2 (-802)).
  assert (Sa0 : 0 < Sa) by lra. assert (Sb0 : 0 < Sb) by lra.
  assert (0 <= aw * aw) by nra. assert (0 <= ax * ax) by nra. assert (0 <= ay * ay) by nra. assert (0 <= az * az) by nra.
  assert (0 <= bw * bw) by nra. assert (0 <= bx * bx) by nra. assert (0 <= by_ * by_) by nra. assert (0 <= bz * bz) by nra.
  (* the exact unit quaternions *)
  assert (UA : Aw * Aw + Ax * Ax + Ay * Ay + Az * Az = 1).
  { unfold Aw, Ax, Ay, Az. rewrite !unit_sq by lra. unfold Sa in *. field. lra. }
  assert (UB : Bw * Bw + Bx * Bx + By * By + Bz * Bz = 1).
  { unfold Bw, Bx, By, Bz. rewrite !unit_sq by lra. unfold Sb in *. field. lra. }
  assert (BA : Rabs Aw <= 1 /\ Rabs Ax <= 1 /\ Rabs Ay <= 1 /\ Rabs Az <= 1).
  { unfold Aw, Ax, Ay, Az. repeat split; apply unit_component; [lra | unfold Sa; lra | lra | unfold Sa; lra | lra | unfold Sa; lra | lra | unfold Sa; lra]. }
  assert (BB : Rabs Bw <= 1 /\ Rabs Bx <= 1 /\ Rabs By <= 1 /\ Rabs Bz <= 1).
  { unfold Bw, Bx, By, Bz. repeat split; apply unit_component; [lra | unfold Sb; lra | lra | unfold Sb; lra | lra | unfold Sb; lra | lra | unfold Sb; lra]. }
  destruct BA as (BAw & BAx & BAy & BAz). destruct BB as (BBw & BBx & BBy & BBz).
  (* the normalized doubles *)
  assert (NA : forall c, Rabs (fl (c / na) - c / sqrt Sa) <= 41 / 10 * u * Rabs (c / sqrt Sa) + eta)
    by (intros c; apply normalize_err; exact HSa).
  assert (NB : forall c, Rabs (fl (c / nb) - c / sqrt Sb) <= 41 / 10 * u * Rabs (c / sqrt Sb) + eta)
    by (intros c; apply normalize_err; exact HSb).
  (* each coordinate *)
  assert (C : forall a1 A1 b1 B1 a2 A2 b2 B2 a3 A3 b3 B3 a4 A4 b4 B4,
     Rabs (a1 - A1) <= 41 / 10 * u * Rabs A1 + eta -> Rabs (b1 - B1) <= 41 / 10 * u * Rabs B1 + eta ->
     Rabs (a2 - A2) <= 41 / 10 * u * Rabs A2 + eta -> Rabs (b2 - B2) <= 41 / 10 * u * Rabs B2 + eta ->
     Rabs (a3 - A3) <= 41 / 10 * u * Rabs A3 + eta -> Rabs (b3 - B3) <= 41 / 10 * u * Rabs B3 + eta ->
     Rabs (a4 - A4) <= 41 / 10 * u * Rabs A4 + eta -> Rabs (b4 - B4) <= 41 / 10 * u * Rabs B4 + eta ->
     Rabs A1 <= 1 -> Rabs B1 <= 1 -> Rabs A2 <= 1 -> Rabs B2 <= 1 ->
     Rabs A3 <= 1 -> Rabs B3 <= 1 -> Rabs A4 <= 1 -> Rabs B4 <= 1 ->
     Rabs (A1 * B1) + Rabs (A2 * B2) + Rabs (A3 * B3) + Rabs (A4 * B4) <= 1 ->
     Rabs (vcomp a1 b1 a2 b2 a3 b3 a4 b4 - ((A1 * B1 - A2 * B2) - (A3 * B3 - A4 * B4))) <= 1132 / 100 * u
     /\ Rabs ((A1 * B1 - A2 * B2) - (A3 * B3 - A4 * B4)) <= 1).
  { intros. split.
    - apply qcomp_err; try apply qprod_err; assumption.
    - eapply Rle_trans; [apply abs_diff_le; apply abs_diff_le; apply Rle_refl|]. lra. }
  destruct (C aw' Aw bx' Bx bw' Bw ax' Ax ay' Ay bz' Bz az' Az by' By) as [E0 M0];
    try (apply NA || apply NB); try assumption.
  { pose proof (four_products_le Aw Ax Ay Az Bw Bx By Bz UA UB). lra. }
  destruct (C aw' Aw by' By bw' Bw ay' Ay az' Az bx' Bx ax' Ax bz' Bz) as [E1 M1];
    try (apply NA || apply NB); try assumption.
  { pose proof (four_products_le Aw Ay Az Ax Bw By Bz Bx ltac:(lra) ltac:(lra)). lra. }
  destruct (C aw' Aw bz' Bz bw' Bw az' Az ax' Ax by' By ay' Ay bx' Bx) as [E2 M2];
    try (apply NA || apply NB); try assumption.
  { pose proof (four_products_le Aw Az Ax Ay Bw Bz Bx By ltac:(lra) ltac:(lra)). lra. }
  fold v0 V0 in E0, M0. fold v1 V1 in E1, M1. fold v2 V2 in E2, M2.
  (* the vector: |V| <= |v| + |V - v| *)
  pose proof (norm_of_bounded (V0 - v0) (V1 - v1) (V2 - v2) (1132 / 100 * u)
                ltac:(rewrite Rabs_minus_sym; exact E0) ltac:(rewrite Rabs_minus_sym; exact E1)
                ltac:(rewrite Rabs_minus_sym; exact E2)) as Ed.
  pose proof (minkowski3 v0 v1 v2 (V0 - v0) (V1 - v1) (V2 - v2)) as Mk.
  replace (v0 + (V0 - v0)) with V0 in Mk by ring. replace (v1 + (V1 - v1)) with V1 in Mk by ring.
  replace (v2 + (V2 - v2)) with V2 in Mk by ring.
  pose proof (norm_c_lower v0 v1 v2) as Nl.
  (* the computed norm is at most 2 *)
  assert (Vb : forall v V, Rabs (v - V) <= 1132 / 100 * u -> Rabs V <= 1 -> v * v <= 11 / 10).
  { intros v V G1 G2. assert (Rabs v <= 1 + 1132 / 100 * u).
    { replace v with (V + (v - V)) by ring. pose proof (Rabs_triang V (v - V)). lra. }
    rewrite <- abs_sq. pose proof (Rabs_pos v).
    apply Rle_trans with ((1 + 1132 / 100 * u) * (1 + 1132 / 100 * u)); [apply Rmult_le_compat; lra | nra]. }
  pose proof (Vb v0 V0 E0 M0). pose proof (Vb v1 V1 E1 M1). pose proof (Vb v2 V2 E2 M2).
  pose proof (sumsq_upper v0 v1 v2) as Su.
  assert (Hn2 : norm_c v0 v1 v2 <= 2).
  { unfold norm_c. replace 2 with (bpow radix2 1) by (simpl; lra).
    apply fl_le_F; [apply generic_format_bpow; unfold FLT_exp; lia|].
    replace (bpow radix2 1) with 2 by (simpl; lra).
    rewrite <- (sqrt_square 2) by lra. apply sqrt_le_1_alt.
    assert ((1 + 4 * u) * (v0 * v0 + v1 * v1 + v2 * v2) <= (1 + 4 * u) * (33 / 10)) by (apply mul_le_l; lra).
    lra. }
  assert (Hn0 : 0 <= norm_c v0 v1 v2) by (unfold norm_c; apply fl_nonneg, sqrt_pos).
  assert (304 / 100 * u * norm_c v0 v1 v2 <= 304 / 100 * u * 2) by (apply mul_le_l; lra).
  assert (Hb : bpow radix2 (-501) <= / 1000000 * u).
  { rewrite bpow_m53. apply Rle_trans with (bpow radix2 (-20) * bpow radix2 (-53)).
    - rewrite <- bpow_plus. apply bpow_le. lia.
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra]. }
  (* the code's bound *)
  pose proof kQuaternionTurnRounding_ge as K.
  assert (U1 : 2 * norm_c v0 v1 v2 <= next_up (fl (2 * norm_c v0 v1 v2))) by (apply up_ge; lra).
  assert (U2 : next_up (fl (2 * norm_c v0 v1 v2)) + kQuaternionTurnRounding
               <= next_up (fl (next_up (fl (2 * norm_c v0 v1 v2)) + kQuaternionTurnRounding))) by (apply up_ge; lra).
  lra.
Qed.
Print Assumptions quaternion_turn_rounding.
