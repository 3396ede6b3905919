(* The nine cross axes a_i x b_j of obb_separated (motion_bounds.h), in
   Flocq's binary64 model of Rounding.v (the code's operations in its order,
   each rounded to nearest: `fl`; finite results, gradual underflow, no fused
   multiply-add), over double axes orthonormal only to within e = 2^-46 (both
   Gram matrices: frame_check_sound, ObbSeparation.v), with the sets and the
   magnitude hypotheses of the face axes' theorems there.

   The code's test along a_i x b_j, for (i, i1, i2) and (j, j1, j2) cyclic,
   C = a^T b and A = |C| + kObbAxisRounding computed, ta = a^T t_w, da =
   a^T hs computed:
     |ta[i2] C(i1, j) - ta[i1] C(i2, j)| >
       ((ha[i1] A(i2, j) + ha[i2] A(i1, j)) + (hb[j1] A(i, j2) + hb[j2] A(i, j1))
        + |da[i2] C(i1, j) - da[i1] C(i2, j)|) + (grow + kObbSeparationRounding s),
   every operation rounded. The axis the proof uses is not the cross product
   itself but L = c1 a_i2 - c2 a_i1, c1 = a_i1 . b_j, c2 = a_i2 . b_j exact (for
   an exactly orthonormal right-handed frame, a_i x b_j): L . t is what the
   code's dist computes, whatever the frames' handedness, and
   - the posed box projects within |c1| ha_i2 + |c2| ha_i1 on L, exactly;
   - L . b_j = 0 exactly, and L . b_j1, L . b_j2 are the 2 x 2 minors of C of
     rows i1, i2, which Binet-Cauchy writes (a_i1 x a_i2) . (b_j x b_m): within
     11 e of |a_i . b_j2| and |a_i . b_j1| (minor_bound), so the obstacle's box
     projects within (|a_i . b_j2| + 11 e) hb_j1 + (|a_i . b_j1| + 11 e) hb_j2
     + 16 e s (other_projection), and A(i, j) >= |a_i . b_j| (obb_axis_rounding);
   - |L|^2 <= 1 + 8 e, so the grow ball projects within (1 + 8 e) grow.
   The roundings are under 140 u s + 60 eta; with the axes' 46 e s, under
   6.8e-13 s, which kObbSeparationRounding s (1e-11 s) covers 14 times. *)
From Coq Require Import Reals Psatz List.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances ObbSeparation.
Open Scope R_scope.

Lemma vnorm1_pos a : 0 <= vnorm1 a.
Proof. unfold vnorm1. pose proof (Rabs_pos (v0 a)). pose proof (Rabs_pos (v1 a)). pose proof (Rabs_pos (v2 a)). lra. Qed.

(* ---- The frames' algebra ---- *)

Lemma term_le g a b e : Rabs g <= e -> g * a * b <= e * (Rabs a * Rabs b).
Proof.
  intros H. pose proof (Rle_abs (g * a * b)) as H0. rewrite !Rabs_mult in H0.
  assert (Rabs g * Rabs a * Rabs b <= e * (Rabs a * Rabs b))
    by (rewrite Rmult_assoc; apply Rmult_le_compat_r; [apply Rmult_le_pos; apply Rabs_pos | exact H]).
  lra.
Qed.

(* sum_k (f_k . w)^2 = w^T (F F^T) w <= |w|^2 + e |w|_1^2 (the rows' Gram matrix). *)
Lemma gram_sum e f0 f1 f2 w : ortho e f0 f1 f2 ->
  vdot f0 w * vdot f0 w + vdot f1 w * vdot f1 w + vdot f2 w * vdot f2 w <= vdot w w + e * (vnorm1 w * vnorm1 w).
Proof.
  intros [Hr _].
  assert (T : forall m n, (m < 3)%nat -> (n < 3)%nat ->
     (rowgram f0 f1 f2 m n - kron m n) * comp w m * comp w n <= e * (Rabs (comp w m) * Rabs (comp w n)))
    by (intros; apply term_le; auto).
  pose proof (T 0%nat 0%nat ltac:(lia) ltac:(lia)). pose proof (T 0%nat 1%nat ltac:(lia) ltac:(lia)).
  pose proof (T 0%nat 2%nat ltac:(lia) ltac:(lia)). pose proof (T 1%nat 0%nat ltac:(lia) ltac:(lia)).
  pose proof (T 1%nat 1%nat ltac:(lia) ltac:(lia)). pose proof (T 1%nat 2%nat ltac:(lia) ltac:(lia)).
  pose proof (T 2%nat 0%nat ltac:(lia) ltac:(lia)). pose proof (T 2%nat 1%nat ltac:(lia) ltac:(lia)).
  pose proof (T 2%nat 2%nat ltac:(lia) ltac:(lia)).
  pose (t := fun m n => (rowgram f0 f1 f2 m n - kron m n) * comp w m * comp w n).
  pose (q := fun m n => Rabs (comp w m) * Rabs (comp w n)).
  assert (Id : vdot f0 w * vdot f0 w + vdot f1 w * vdot f1 w + vdot f2 w * vdot f2 w =
    vdot w w + (t 0%nat 0%nat + t 0%nat 1%nat + t 0%nat 2%nat + t 1%nat 0%nat + t 1%nat 1%nat + t 1%nat 2%nat + t 2%nat 0%nat + t 2%nat 1%nat + t 2%nat 2%nat))
    by (unfold t, vdot, rowgram, kron, comp; simpl; ring).
  assert (N : vnorm1 w * vnorm1 w = (q 0%nat 0%nat + q 0%nat 1%nat + q 0%nat 2%nat + q 1%nat 0%nat + q 1%nat 1%nat + q 1%nat 2%nat + q 2%nat 0%nat + q 2%nat 1%nat + q 2%nat 2%nat))
    by (unfold q, vnorm1, comp; simpl; ring).
  rewrite Id, N. unfold t, q. cbv beta. lra.
Qed.

(* L = c1 y - c2 x. *)
Definition vlin c1 (y : V) c2 (x : V) :=
  mkV (c1 * v0 y - c2 * v0 x) (c1 * v1 y - c2 * v1 x) (c1 * v2 y - c2 * v2 x).
Lemma vdot_lin c1 y c2 x P : vdot (vlin c1 y c2 x) P = c1 * vdot y P - c2 * vdot x P.
Proof. unfold vdot, vlin; simpl; ring. Qed.

(* |L|^2 <= 1 + 8 e for L = (x . w) y - (y . w) x, (z, x, y) a frame, w a near-unit axis. *)
Lemma lin_len e x y z w : ortho e z x y -> 0 <= e <= / 1000000000000 -> Rabs (vdot w w - 1) <= e ->
  vdot (vlin (vdot x w) y (vdot y w) x) (vlin (vdot x w) y (vdot y w) x) <= 1 + 8 * e.
Proof.
  intros Ho He Hw.
  pose proof (gram_sum e z x y w Ho) as G.
  pose proof Ho as (_ & Uz & Ux & Uy & _ & _ & Gxy).
  assert (Nw : vnorm1 w <= 1733 / 1000) by (apply (norm1_unit e); assumption).
  pose proof (vnorm1_pos w).
  set (c1 := vdot x w) in *. set (c2 := vdot y w) in *.
  assert (Id : vdot (vlin c1 y c2 x) (vlin c1 y c2 x) = c1 * c1 * vdot y y + c2 * c2 * vdot x x - 2 * (c1 * c2) * vdot x y)
    by (unfold vdot, vlin; simpl; ring).
  rewrite Id.
  assert (S : c1 * c1 + c2 * c2 <= 1 + 5 * e).
  { assert (0 <= vdot z w * vdot z w) by nra.
    assert (vnorm1 w * vnorm1 w <= 1733 / 1000 * (1733 / 1000)) by (apply Rmult_le_compat; lra).
    assert (e * (vnorm1 w * vnorm1 w) <= e * (1733 / 1000 * (1733 / 1000))) by (apply mul_le_l; lra).
    assert (vdot w w <= 1 + e) by (unfold Rabs in Hw; destruct Rcase_abs; lra). lra. }
  assert (c1 * c1 * vdot y y <= c1 * c1 * (1 + e)) by (apply mul_le_l; [nra | unfold Rabs in Uy; destruct Rcase_abs; lra]).
  assert (c2 * c2 * vdot x x <= c2 * c2 * (1 + e)) by (apply mul_le_l; [nra | unfold Rabs in Ux; destruct Rcase_abs; lra]).
  assert (Rabs (2 * (c1 * c2) * vdot x y) <= (c1 * c1 + c2 * c2) * e).
  { rewrite Rabs_mult, (Rabs_mult 2), (Rabs_pos_eq 2) by lra. pose proof (prod_abs_le c1 c2).
    assert (Rabs (c1 * c2) * Rabs (vdot x y) <= (c1 * c1 + c2 * c2) / 2 * e)
      by (apply Rmult_le_compat; [apply Rabs_pos | apply Rabs_pos | assumption | assumption]).
    lra. }
  pose proof (Rle_abs (- (2 * (c1 * c2) * vdot x y))) as Hn. rewrite Rabs_Ropp in Hn.
  assert ((c1 * c1 + c2 * c2) * (1 + 2 * e) <= (1 + 5 * e) * (1 + 2 * e)) by (apply Rmult_le_compat_r; lra).
  assert (e * e <= / 1000000000000 * e) by nra.
  lra.
Qed.

Lemma lagrange a b : vdot (vcross a b) (vcross a b) = vdot a a * vdot b b - vdot a b * vdot a b.
Proof. unfold vdot, vcross; simpl; ring. Qed.
Lemma binet_cauchy x y p q : vdot x p * vdot y q - vdot y p * vdot x q = vdot (vcross x y) (vcross p q).
Proof. unfold vdot, vcross; simpl; ring. Qed.
Lemma cross_perp a b : vdot (vcross a b) a = 0 /\ vdot (vcross a b) b = 0.
Proof. unfold vdot, vcross; simpl; split; ring. Qed.

(* The cross product of two near-unit axes: |a x b|_1 <= 1.733 and
   |(a x b) . c| <= 1 + 2 e for a third. *)
Lemma cross_unit e a b c : 0 <= e <= / 1000000000000 ->
  Rabs (vdot a a - 1) <= e -> Rabs (vdot b b - 1) <= e -> Rabs (vdot c c - 1) <= e ->
  vnorm1 (vcross a b) <= 1733 / 1000 /\ Rabs (vdot (vcross a b) c) <= 1 + 2 * e.
Proof.
  intros He Ha Hb Hc.
  assert (vdot a a <= 1 + e) by (unfold Rabs in Ha; destruct Rcase_abs; lra).
  assert (vdot b b <= 1 + e) by (unfold Rabs in Hb; destruct Rcase_abs; lra).
  assert (vdot c c <= 1 + e) by (unfold Rabs in Hc; destruct Rcase_abs; lra).
  pose proof (vdot_self_pos a). pose proof (vdot_self_pos b). pose proof (vdot_self_pos c).
  pose proof (vdot_self_pos (vcross a b)).
  assert (P : vdot (vcross a b) (vcross a b) <= (1 + e) * (1 + e)).
  { rewrite lagrange. assert (0 <= vdot a b * vdot a b) by nra.
    assert (vdot a a * vdot b b <= (1 + e) * (1 + e)) by (apply Rmult_le_compat; lra). lra. }
  split.
  - apply (norm1_le (3 * e)); [lra | nra].
  - apply abs_of_sq; [lra|]. pose proof (cs_sq (vcross a b) c).
    assert (vdot (vcross a b) (vcross a b) * vdot c c <= (1 + e) * (1 + e) * (1 + e)) by (apply Rmult_le_compat; lra).
    assert ((1 + e) * (1 + e) * (1 + e) <= (1 + 2 * e) * (1 + 2 * e)) by nra.
    lra.
Qed.

(* P . w against its part along a frame (f0, f1, f2): the rest within
   |P|_1 e |w|_1 (decompose). *)
Lemma resid_dot e (f0 f1 f2 P w : V) : ortho e f0 f1 f2 -> vnorm1 P <= 1733 / 1000 -> vnorm1 w <= 1733 / 1000 -> 0 <= e ->
  Rabs (vdot P w - (vdot f0 w * vdot P f0 + vdot f1 w * vdot P f1 + vdot f2 w * vdot P f2)) <= 1733 / 1000 * (e * (1733 / 1000)).
Proof.
  intros Ho HP Hw He.
  pose proof (decompose e f0 f1 f2 w Ho 0%nat ltac:(lia)) as D0.
  pose proof (decompose e f0 f1 f2 w Ho 1%nat ltac:(lia)) as D1.
  pose proof (decompose e f0 f1 f2 w Ho 2%nat ltac:(lia)) as D2. simpl in D0, D1, D2.
  set (r := mkV (v0 w - (vdot f0 w * v0 f0 + vdot f1 w * v0 f1 + vdot f2 w * v0 f2))
                (v1 w - (vdot f0 w * v1 f0 + vdot f1 w * v1 f1 + vdot f2 w * v1 f2))
                (v2 w - (vdot f0 w * v2 f0 + vdot f1 w * v2 f1 + vdot f2 w * v2 f2))).
  replace (vdot P w - (vdot f0 w * vdot P f0 + vdot f1 w * vdot P f1 + vdot f2 w * vdot P f2)) with (vdot P r)
    by (unfold r, vdot; simpl; ring).
  apply dot_unit; [exact HP|].
  assert (e * vnorm1 w <= e * (1733 / 1000)) by (apply mul_le_l; lra).
  unfold vinf_le, r; simpl. repeat split; lra.
Qed.

(* The 2 x 2 minor of C = A^T B of rows x, y and columns p, q is within 11 e
   of |z . r|, (z, x, y) and (r, p, q) frames orthonormal to within e (for
   exact rotations, the cofactor is +-C(z, r)): Binet-Cauchy writes it
   (x x y) . (p x q); x x y is +-z up to e, p x q +-r. *)
Lemma minor_bound e x y z p q r : ortho e z x y -> ortho e r p q -> 0 <= e <= / 1000000000000 ->
  Rabs (vdot x p * vdot y q - vdot y p * vdot x q) <= Rabs (vdot z r) + 11 * e.
Proof.
  intros Ha Hb He.
  pose proof Ha as (_ & Uz & Ux & Uy & _). pose proof Hb as (_ & Ur & Up & Uq & _).
  rewrite binet_cauchy.
  destruct (cross_unit e x y z He Ux Uy Uz) as [NP Pz].
  destruct (cross_unit e p q r He Up Uq Ur) as [NQ Qr].
  destruct (cross_perp x y) as [Px Py]. destruct (cross_perp p q) as [Qp Qq].
  set (P := vcross x y) in *. set (Q := vcross p q) in *.
  assert (Nz : vnorm1 z <= 1733 / 1000) by (apply (norm1_unit e); assumption).
  pose proof (resid_dot e z x y P Q Ha NP NQ ltac:(lra)) as R1.
  rewrite Px, Py, !Rmult_0_r, !Rplus_0_r in R1.
  pose proof (resid_dot e r p q Q z Hb NQ Nz ltac:(lra)) as R2.
  rewrite Qp, Qq, !Rmult_0_r, !Rplus_0_r in R2.
  assert (Hrz : Rabs (vdot r z) <= 1 + e).
  { apply abs_of_sq; [lra|]. pose proof (cs_sq r z).
    assert (vdot r r <= 1 + e) by (unfold Rabs in Ur; destruct Rcase_abs; lra).
    assert (vdot z z <= 1 + e) by (unfold Rabs in Uz; destruct Rcase_abs; lra).
    pose proof (vdot_self_pos r). pose proof (vdot_self_pos z).
    assert (vdot r r * vdot z z <= (1 + e) * (1 + e)) by (apply Rmult_le_compat; lra). lra. }
  set (a := Rabs (vdot z Q)) in *. set (b := Rabs (vdot r z)) in *.
  assert (Ha' : 0 <= a) by apply Rabs_pos. assert (Hb' : 0 <= b) by apply Rabs_pos.
  assert (S1 : Rabs (vdot P Q) <= a * (1 + 2 * e) + 1733 / 1000 * (e * (1733 / 1000))).
  { replace (vdot P Q) with (vdot z Q * vdot P z + (vdot P Q - vdot z Q * vdot P z)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_mult.
    assert (a * Rabs (vdot P z) <= a * (1 + 2 * e)) by (apply mul_le_l; lra). unfold a in *. lra. }
  assert (S2 : a <= b * (1 + 2 * e) + 1733 / 1000 * (e * (1733 / 1000))).
  { unfold a. rewrite vdot_comm.
    replace (vdot Q z) with (vdot r z * vdot Q r + (vdot Q z - vdot r z * vdot Q r)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_mult.
    assert (b * Rabs (vdot Q r) <= b * (1 + 2 * e)) by (apply mul_le_l; lra). unfold b in *. lra. }
  assert (a * (1 + 2 * e) <= (b * (1 + 2 * e) + 1733 / 1000 * (e * (1733 / 1000))) * (1 + 2 * e))
    by (apply Rmult_le_compat_r; lra).
  assert (b * (e * e) <= (1 + e) * (e * e)) by (apply Rmult_le_compat_r; [apply Rmult_le_pos; lra | lra]).
  assert (b * e <= (1 + e) * e) by (apply Rmult_le_compat_r; lra).
  assert (e * e <= / 1000000000000 * e) by nra.
  assert (e * (e * e) <= 1 * (e * e)) by (apply Rmult_le_compat_r; [apply Rmult_le_pos; lra | lra]).
  rewrite (vdot_comm z r). fold b. lra.
Qed.

(* ---- The code's computation ---- *)

(* ta[i2] C(i1, j) - ta[i1] C(i2, j) (or da's), x = a_i1, y = a_i2, p = t_w (hs). *)
Definition cross_c (x y p bj : V) := fl (fl (cdot y p * cdot x bj) - fl (cdot x p * cdot y bj)).
(* (ra + rb) + |da[i2] C(i1, j) - da[i1] C(i2, j)|, z = a_i, hx = ha[i1], hy = ha[i2],
   hb1 = hb[j1], hb2 = hb[j2]. *)
Definition cross_reach (x y z bj bj1 bj2 : V) hx hy hb1 hb2 (hs : V) :=
  fl (fl (fl (fl (hx * axis_entry y bj) + fl (hy * axis_entry x bj))
          + fl (fl (hb1 * axis_entry z bj2) + fl (hb2 * axis_entry z bj1)))
      + Rabs (cross_c x y hs bj)).

Lemma fl_near z S : Rabs z <= S -> Rabs (fl z - z) <= u * S + eta.
Proof. intros H. pose proof (fl_err z). assert (u * Rabs z <= u * S) by (apply mul_le_l; [unfold u; lra | exact H]). lra. Qed.

Lemma abs5 a b c d f : Rabs (a + b - c + d - f) <= Rabs a + Rabs b + Rabs c + Rabs d + Rabs f.
Proof. unfold Rabs; repeat destruct Rcase_abs; lra. Qed.

(* The computed ta[i2] C(i1, j) - ta[i1] C(i2, j) against the exact
   c1 (y . P) - c2 (x . P), the projections within D of the exact ones. *)
Lemma cross_c_err e x y p bj (P : V) D M :
  0 <= e <= / 1000000000000 -> Rabs (vdot x x - 1) <= e -> Rabs (vdot y y - 1) <= e -> Rabs (vdot bj bj - 1) <= e ->
  Rabs (cdot x p - vdot x P) <= D -> Rabs (cdot y p - vdot y P) <= D ->
  Rabs (vdot x P) <= M -> Rabs (vdot y P) <= M -> 0 <= D <= M ->
  Rabs (cross_c x y p bj - (vdot x bj * vdot y P - vdot y bj * vdot x P)) <= 21 / 10 * D + 17 * (u * M) + 3 * eta.
Proof.
  intros He Hx Hy Hb HDx HDy HMx HMy HD.
  destruct (axis_entry_bounds e x bj He Hx Hb) as (A1 & A1' & E1).
  destruct (axis_entry_bounds e y bj He Hy Hb) as (A2 & A2' & E2).
  pose proof u_tiny. pose proof eta_pos. pose proof eta_u.
  unfold cross_c.
  set (Cx := cdot x bj) in *. set (Cy := cdot y bj) in *. set (X' := cdot x p) in *. set (Y' := cdot y p) in *.
  set (c1 := vdot x bj) in *. set (c2 := vdot y bj) in *. set (XP := vdot x P) in *. set (YP := vdot y P) in *.
  assert (HCx : Rabs Cx <= 102 / 100)
    by (replace Cx with (c1 + (Cx - c1)) by ring; eapply Rle_trans; [apply Rabs_triang|]; unfold u in *; lra).
  assert (HCy : Rabs Cy <= 102 / 100)
    by (replace Cy with (c2 + (Cy - c2)) by ring; eapply Rle_trans; [apply Rabs_triang|]; unfold u in *; lra).
  assert (HX : Rabs X' <= 2 * M)
    by (replace X' with (XP + (X' - XP)) by ring; eapply Rle_trans; [apply Rabs_triang|]; lra).
  assert (HY : Rabs Y' <= 2 * M)
    by (replace Y' with (YP + (Y' - YP)) by ring; eapply Rle_trans; [apply Rabs_triang|]; lra).
  assert (P1 : Rabs (Y' * Cx - c1 * YP) <= D * (102 / 100) + M * (4 * u)).
  { replace (Y' * Cx - c1 * YP) with ((Y' - YP) * Cx + YP * (Cx - c1)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult.
    apply Rplus_le_compat; apply Rmult_le_compat; try apply Rabs_pos; lra. }
  assert (P2 : Rabs (X' * Cy - c2 * XP) <= D * (102 / 100) + M * (4 * u)).
  { replace (X' * Cy - c2 * XP) with ((X' - XP) * Cy + XP * (Cy - c2)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult.
    apply Rplus_le_compat; apply Rmult_le_compat; try apply Rabs_pos; lra. }
  assert (B1 : Rabs (Y' * Cx) <= 204 / 100 * M)
    by (rewrite Rabs_mult; replace (204 / 100 * M) with (2 * M * (102 / 100)) by lra;
        apply Rmult_le_compat; try apply Rabs_pos; lra).
  assert (B2 : Rabs (X' * Cy) <= 204 / 100 * M)
    by (rewrite Rabs_mult; replace (204 / 100 * M) with (2 * M * (102 / 100)) by lra;
        apply Rmult_le_compat; try apply Rabs_pos; lra).
  pose proof (fl_near _ _ B1) as F1. pose proof (fl_near _ _ B2) as F2.
  assert (0 <= u * M) by (apply Rmult_le_pos; lra).
  assert (B3 : Rabs (fl (Y' * Cx) - fl (X' * Cy)) <= 41 / 10 * M + 2 * eta).
  { replace (fl (Y' * Cx) - fl (X' * Cy)) with ((fl (Y' * Cx) - Y' * Cx) + Y' * Cx - (fl (X' * Cy) - X' * Cy) + 0 - X' * Cy) by ring.
    eapply Rle_trans; [apply abs5|]. rewrite Rabs_R0. unfold u in *. lra. }
  pose proof (sub_rel _ _ (F_fl (Y' * Cx)) (F_fl (X' * Cy))) as F3.
  assert (u * Rabs (fl (Y' * Cx) - fl (X' * Cy)) <= u * (41 / 10 * M + 2 * eta)) by (apply mul_le_l; lra).
  assert (u * eta <= eta) by (replace eta with (1 * eta) at 2 by ring; apply Rmult_le_compat_r; lra).
  replace (fl (fl (Y' * Cx) - fl (X' * Cy)) - (c1 * YP - c2 * XP))
    with ((fl (fl (Y' * Cx) - fl (X' * Cy)) - (fl (Y' * Cx) - fl (X' * Cy))) + (fl (Y' * Cx) - Y' * Cx)
          - (fl (X' * Cy) - X' * Cy) + (Y' * Cx - c1 * YP) - (X' * Cy - c2 * XP)) by ring.
  eapply Rle_trans; [apply abs5|].
  assert (M * (4 * u) = 4 * (u * M)) by ring.
  unfold u in *. lra.
Qed.

(* ---- The exact half ---- *)

(* A common point of the two sets bounds |L . t| along L = c1 y - c2 x. *)
Lemma cross_exact e (x y z bj bj1 bj2 wown woth E hs t : V) hx hy hb0 hb1 hb2 grow s sigma :
  ortho e z x y -> ortho e bj bj1 bj2 -> 0 <= e <= / 1000000000000 ->
  let L := vlin (vdot x bj) y (vdot y bj) x in
  Rabs (vdot x wown) <= hx -> Rabs (vdot y wown) <= hy ->
  Rabs (vdot bj woth) <= hb0 -> Rabs (vdot bj1 woth) <= hb1 -> Rabs (vdot bj2 woth) <= hb2 ->
  hb0 <= s -> 0 <= hb1 <= s -> 0 <= hb2 <= s -> 0 <= grow <= s -> vdot E E <= grow * grow -> Rabs sigma <= 1 ->
  Rabs (vdot L t) <= Rabs (vdot L wown) + Rabs (vdot L woth) + Rabs (vdot L E) + Rabs sigma * Rabs (vdot L hs) ->
  Rabs (vdot L t) <= Rabs (vdot x bj) * hy + Rabs (vdot y bj) * hx + (Rabs (vdot z bj2) + 11 * e) * hb1
    + (Rabs (vdot z bj1) + 11 * e) * hb2 + 38 * (e * s) + grow + Rabs (vdot L hs).
Proof.
  intros Ha Hb He L Wx Wy W0 W1 W2 K0 K1 K2 Hg HE Hsg Ht.
  pose proof Hb as (_ & Ubj & _).
  pose proof (lin_len e x y z bj Ha He Ubj) as LL. fold L in LL.
  assert (NL : vnorm1 L <= 1733 / 1000) by (apply (norm1_le (8 * e)); [lra | exact LL]).
  (* the posed box *)
  assert (Own : Rabs (vdot L wown) <= Rabs (vdot x bj) * hy + Rabs (vdot y bj) * hx).
  { unfold L. rewrite vdot_lin. eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_Ropp, !Rabs_mult.
    apply Rplus_le_compat; apply mul_le_l; try apply Rabs_pos; assumption. }
  (* the obstacle's box *)
  pose proof (other_projection e bj bj1 bj2 L woth hb0 hb1 hb2 s Hb He NL K0 ltac:(lra) ltac:(lra) W0 W1 W2) as Oth.
  assert (Z0 : vdot L bj = 0) by (unfold L; rewrite vdot_lin; ring).
  assert (M1 : Rabs (vdot L bj1) <= Rabs (vdot z bj2) + 11 * e).
  { unfold L. rewrite vdot_lin. apply minor_bound; [exact Ha | apply ortho_cycle, ortho_cycle, Hb | exact He]. }
  assert (M2 : Rabs (vdot L bj2) <= Rabs (vdot z bj1) + 11 * e).
  { unfold L. rewrite vdot_lin. apply minor_bound; [exact Ha | apply ortho_swap, Hb | exact He]. }
  rewrite Z0, Rabs_R0, Rmult_0_l in Oth.
  assert (Rabs (vdot L bj1) * hb1 <= (Rabs (vdot z bj2) + 11 * e) * hb1) by (apply Rmult_le_compat_r; lra).
  assert (Rabs (vdot L bj2) * hb2 <= (Rabs (vdot z bj1) + 11 * e) * hb2) by (apply Rmult_le_compat_r; lra).
  (* the grow ball *)
  pose proof (ball_le (8 * e) L E grow ltac:(lra) ltac:(lra) LL HE) as Bl.
  assert (e * grow <= e * s) by (apply mul_le_l; lra).
  assert (0 <= e * s) by (apply Rmult_le_pos; lra).
  assert (Rabs sigma * Rabs (vdot L hs) <= 1 * Rabs (vdot L hs)) by (apply Rmult_le_compat_r; [apply Rabs_pos | exact Hsg]).
  lra.
Qed.

(* The rounding half: the test as the code computes it, against the exact
   bound of cross_exact. *)
Lemma cross_round e (x y z bj bj1 bj2 ca cb hs : V) hx hy hb1 hb2 grow s :
  FV x -> FV y -> FV ca -> FV cb -> FV hs -> F hx -> F hy -> F hb1 -> F hb2 -> F grow -> F s ->
  ortho e z x y -> ortho e bj bj1 bj2 -> 0 <= e <= bpow radix2 (-46) ->
  0 <= hx <= s -> 0 <= hy <= s -> 0 <= hb1 <= s -> 0 <= hb2 <= s -> 0 <= grow <= s ->
  vinf_le ca s -> vinf_le cb s -> vinf_le hs s -> vinf_le (tw_c ca cb hs) s -> bpow radix2 (-1001) <= s ->
  let L := vlin (vdot x bj) y (vdot y bj) x in
  Rabs (cross_c x y (tw_c ca cb hs) bj) > fl (cross_reach x y z bj bj1 bj2 hx hy hb1 hb2 hs + sep_slack grow s) ->
  Rabs (vdot x bj) * hy + Rabs (vdot y bj) * hx + (Rabs (vdot z bj2) + 11 * e) * hb1
    + (Rabs (vdot z bj1) + 11 * e) * hb2 + 38 * (e * s) + grow + Rabs (vdot L hs)
    < Rabs (vdot L (vsub (vsub cb ca) hs)).
Proof.
  intros Fx Fy Fca Fcb Fhs Fhx Fhy Fh1 Fh2 Fg Fs Ha Hb He Hx Hy H1 H2 Hg Hca Hcb Hhs Htw Hs1 L T.
  pose proof (e_small e He) as He'. pose proof u_tiny. pose proof eta_pos. pose proof eta_u.
  pose proof (eta_rel s ltac:(apply Rle_trans with (2 := Hs1); apply bpow_le; lia)) as Eta.
  pose proof (bpow_gt_0 radix2 (-1001)).
  pose proof Ha as (_ & Uz & Ux & Uy & _). pose proof Hb as (_ & Ubj & Ubj1 & Ubj2 & _).
  assert (Nx : vnorm1 x <= 1733 / 1000) by (apply (norm1_unit e); assumption).
  assert (Ny : vnorm1 y <= 1733 / 1000) by (apply (norm1_unit e); assumption).
  assert (0 <= u * s) by (apply Rmult_le_pos; lra).
  set (t := vsub (vsub cb ca) hs). set (tw := tw_c ca cb hs) in *.
  (* dist against |L . t| *)
  pose proof (tw_err x ca cb hs s Nx Fca Fcb Fhs Hca Hcb Hhs Htw) as Dx.
  pose proof (tw_err y ca cb hs s Ny Fca Fcb Fhs Hca Hcb Hhs Htw) as Dy. fold t tw in Dx, Dy.
  assert (Mx : Rabs (vdot x t) <= 174 / 100 * s).
  { pose proof (dot_unit x tw s Nx Htw). pose proof (cdot_unit x tw s Nx Htw).
    replace (vdot x t) with (vdot x tw - (cdot x tw - vdot x t) + (cdot x tw - vdot x tw)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    rewrite Rabs_Ropp. unfold u in *. lra. }
  assert (My : Rabs (vdot y t) <= 174 / 100 * s).
  { pose proof (dot_unit y tw s Ny Htw). pose proof (cdot_unit y tw s Ny Htw).
    replace (vdot y t) with (vdot y tw - (cdot y tw - vdot y t) + (cdot y tw - vdot y tw)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    rewrite Rabs_Ropp. unfold u in *. lra. }
  pose proof (cross_c_err e x y tw bj t (14 * (u * s) + 502 / 100 * eta) (174 / 100 * s) He' Ux Uy Ubj Dx Dy Mx My
                ltac:(unfold u in *; lra)) as Et.
  (* the sweep's term *)
  pose proof (cdot_unit x hs s Nx Hhs) as Dhx. pose proof (cdot_unit y hs s Ny Hhs) as Dhy.
  pose proof (dot_unit x hs s Nx Hhs) as Mhx. pose proof (dot_unit y hs s Ny Hhs) as Mhy.
  pose proof (cross_c_err e x y hs bj hs (524 / 100 * (u * s) + 502 / 100 * eta) (1733 / 1000 * s) He' Ux Uy Ubj
                Dhx Dhy Mhx Mhy ltac:(unfold u in *; lra)) as Eh.
  assert (HL : forall P, vdot L P = vdot x bj * vdot y P - vdot y bj * vdot x P) by (intros; unfold L; apply vdot_lin).
  rewrite <- HL in Et, Eh.
  (* the axis entries *)
  destruct (axis_entry_bounds e x bj He' Ux Ubj) as (Ax & Ax' & _).
  destruct (axis_entry_bounds e y bj He' Uy Ubj) as (Ay & Ay' & _).
  destruct (axis_entry_bounds e z bj1 He' Uz Ubj1) as (Az1 & Az1' & _).
  destruct (axis_entry_bounds e z bj2 He' Uz Ubj2) as (Az2 & Az2' & _).
  fold (axis_entry x bj) in Ax, Ax'. fold (axis_entry y bj) in Ay, Ay'.
  fold (axis_entry z bj1) in Az1, Az1'. fold (axis_entry z bj2) in Az2, Az2'.
  set (ax := axis_entry x bj) in *. set (ay := axis_entry y bj) in *.
  set (az1 := axis_entry z bj1) in *. set (az2 := axis_entry z bj2) in *.
  assert (0 <= ax) by (pose proof (Rabs_pos (vdot x bj)); lra).
  assert (0 <= ay) by (pose proof (Rabs_pos (vdot y bj)); lra).
  assert (0 <= az1) by (pose proof (Rabs_pos (vdot z bj1)); lra).
  assert (0 <= az2) by (pose proof (Rabs_pos (vdot z bj2)); lra).
  assert (Pb : forall h a, 0 <= h <= s -> 0 <= a <= 1 + / 100000000000 -> 0 <= h * a <= 101 / 100 * s).
  { intros h a Hh Ha0. split; [apply Rmult_le_pos; lra|].
    replace (101 / 100 * s) with (s * (101 / 100)) by lra. apply Rmult_le_compat; lra. }
  assert (Ab : forall z, 0 <= z <= 101 / 100 * s -> Rabs z <= 101 / 100 * s) by (intros; apply Rabs_le; lra).
  pose proof (Pb hx ay Hx ltac:(lra)) as Q1. pose proof (Pb hy ax Hy ltac:(lra)) as Q2.
  pose proof (Pb hb1 az2 H1 ltac:(lra)) as Q3. pose proof (Pb hb2 az1 H2 ltac:(lra)) as Q4.
  pose proof (fl_near _ _ (Ab _ Q1)) as R1. pose proof (fl_near _ _ (Ab _ Q2)) as R2.
  pose proof (fl_near _ _ (Ab _ Q3)) as R3. pose proof (fl_near _ _ (Ab _ Q4)) as R4.
  destruct (abs_both _ _ R1). destruct (abs_both _ _ R2). destruct (abs_both _ _ R3). destruct (abs_both _ _ R4).
  set (q1 := fl (hx * ay)) in *. set (q2 := fl (hy * ax)) in *. set (q3 := fl (hb1 * az2)) in *. set (q4 := fl (hb2 * az1)) in *.
  assert (Ra : Rabs (q1 + q2) <= 203 / 100 * s) by (apply Rabs_le; unfold u in *; lra).
  assert (Rb : Rabs (q3 + q4) <= 203 / 100 * s) by (apply Rabs_le; unfold u in *; lra).
  pose proof (fl_near _ _ Ra) as R5. pose proof (fl_near _ _ Rb) as R6.
  destruct (abs_both _ _ R5). destruct (abs_both _ _ R6).
  set (ra := fl (q1 + q2)) in *. set (rb := fl (q3 + q4)) in *.
  assert (Rr : Rabs (ra + rb) <= 407 / 100 * s) by (apply Rabs_le; unfold u in *; lra).
  pose proof (fl_near _ _ Rr) as R7. destruct (abs_both _ _ R7).
  set (r := fl (ra + rb)) in *.
  set (d := Rabs (cross_c x y hs bj)) in *.
  assert (HLhs : Rabs (vdot L hs) <= 36 / 10 * s).
  { rewrite HL. eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_Ropp, !Rabs_mult.
    assert (Rabs (vdot x bj) * Rabs (vdot y hs) <= 101 / 100 * (1733 / 1000 * s))
      by (apply Rmult_le_compat; try apply Rabs_pos; lra).
    assert (Rabs (vdot y bj) * Rabs (vdot x hs) <= 101 / 100 * (1733 / 1000 * s))
      by (apply Rmult_le_compat; try apply Rabs_pos; lra).
    lra. }
  assert (Dd : Rabs (d - Rabs (vdot L hs)) <= 21 / 10 * (524 / 100 * (u * s) + 502 / 100 * eta) + 17 * (u * (1733 / 1000 * s)) + 3 * eta)
    by (unfold d; eapply Rle_trans; [apply Rabs_triang_inv2 | exact Eh]).
  destruct (abs_both _ _ Dd). assert (0 <= d) by apply Rabs_pos.
  assert (Rd : Rabs (r + d) <= 8 * s) by (apply Rabs_le; unfold u in *; lra).
  pose proof (fl_near _ _ Rd) as R8. destruct (abs_both _ _ R8).
  set (reach := fl (r + d)) in *.
  (* the slack g *)
  pose proof kSep_ge as Ks.
  destruct (kSep_scaled s ltac:(lra)) as (Ks' & Ks0 & Kss & Ksl).
  assert (Rk : Rabs (kObbSeparationRounding * s) <= s) by (apply Rabs_le; lra).
  pose proof (fl_near _ _ Rk) as R9. destruct (abs_both _ _ R9).
  set (ks := fl (kObbSeparationRounding * s)) in *.
  assert (Rg : Rabs (grow + ks) <= 2 * s) by (apply Rabs_le; unfold u in *; lra).
  pose proof (fl_near _ _ Rg) as R10. destruct (abs_both _ _ R10).
  set (g := fl (grow + ks)) in *.
  assert (Rt : Rabs (reach + g) <= 11 * s) by (apply Rabs_le; unfold u in *; lra).
  pose proof (fl_near _ _ Rt) as R11. destruct (abs_both _ _ R11).
  unfold cross_reach, sep_slack in T. fold ax ay az1 az2 q1 q2 q3 q4 ra rb r d reach ks g in T.
  (* the exact side *)
  assert (hy * Rabs (vdot x bj) <= hy * ax) by (apply mul_le_l; lra).
  assert (hx * Rabs (vdot y bj) <= hx * ay) by (apply mul_le_l; lra).
  assert (hb1 * Rabs (vdot z bj2) <= hb1 * az2) by (apply mul_le_l; lra).
  assert (hb2 * Rabs (vdot z bj1) <= hb2 * az1) by (apply mul_le_l; lra).
  assert (Hes : e * s <= / 70368744177664 * s) by (apply Rmult_le_compat_r; [lra | destruct He as [_ He2]; simpl in He2; lra]).
  assert (e * hb1 <= e * s) by (apply mul_le_l; lra). assert (e * hb2 <= e * s) by (apply mul_le_l; lra).
  assert (0 <= e * hb1) by (apply Rmult_le_pos; lra). assert (0 <= e * hb2) by (apply Rmult_le_pos; lra).
  destruct (abs_both _ _ Et).
  assert (Lt : Rabs (cross_c x y tw bj) <= Rabs (vdot L t) + (21 / 10 * (14 * (u * s) + 502 / 100 * eta) + 17 * (u * (174 / 100 * s)) + 3 * eta)).
  { replace (cross_c x y tw bj) with (vdot L t + (cross_c x y tw bj - vdot L t)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. lra. }
  unfold u in *. lra.
Qed.

(* The nine axes' frames: (z, x, y) = (a_i, a_i1, a_i2) with the half
   extents, for i = 0, 1, 2 (the code's i1 = (i + 1) % 3, i2 = (i + 2) % 3). *)
Definition rot3 (p : V * V * V * R * R * R) (a0 a1 a2 : V) h0 h1 h2 :=
  p = (a0, a1, a2, h0, h1, h2) \/ p = (a1, a2, a0, h1, h2, h0) \/ p = (a2, a0, a1, h2, h0, h1).

Lemma cross_core e (x y z bj bj1 bj2 ca cb hs E X : V) hx hy hb0 hb1 hb2 grow s sigma :
  FV x -> FV y -> FV ca -> FV cb -> FV hs -> F hx -> F hy -> F hb1 -> F hb2 -> F grow -> F s ->
  ortho e z x y -> ortho e bj bj1 bj2 -> 0 <= e <= bpow radix2 (-46) ->
  0 <= hx <= s -> 0 <= hy <= s -> 0 <= hb0 <= s -> 0 <= hb1 <= s -> 0 <= hb2 <= s -> 0 <= grow <= s ->
  vinf_le ca s -> vinf_le cb s -> vinf_le hs s -> vinf_le (tw_c ca cb hs) s -> bpow radix2 (-1001) <= s ->
  Rabs (cross_c x y (tw_c ca cb hs) bj) > fl (cross_reach x y z bj bj1 bj2 hx hy hb1 hb2 hs + sep_slack grow s) ->
  Rabs sigma <= 1 -> vdot E E <= grow * grow ->
  Rabs (vdot x (vsub (vsub (vsub X E) (vscale (1 + sigma) hs)) ca)) <= hx ->
  Rabs (vdot y (vsub (vsub (vsub X E) (vscale (1 + sigma) hs)) ca)) <= hy ->
  Rabs (vdot bj (vsub X cb)) <= hb0 -> Rabs (vdot bj1 (vsub X cb)) <= hb1 -> Rabs (vdot bj2 (vsub X cb)) <= hb2 ->
  False.
Proof.
  intros Fx Fy Fca Fcb Fhs Fhx Fhy Fh1 Fh2 Fg Fs Ha Hb He Hx Hy H0 H1 H2 Hg Hca Hcb Hhs Htw Hs1 T Hsg HE Wx Wy W0 W1 W2.
  pose proof (cross_round e x y z bj bj1 bj2 ca cb hs hx hy hb1 hb2 grow s Fx Fy Fca Fcb Fhs Fhx Fhy Fh1 Fh2 Fg Fs
                Ha Hb He Hx Hy H1 H2 Hg Hca Hcb Hhs Htw Hs1 T) as R.
  set (L := vlin (vdot x bj) y (vdot y bj) x) in *.
  set (t := vsub (vsub cb ca) hs) in *.
  set (wown := vsub (vsub (vsub X E) (vscale (1 + sigma) hs)) ca) in *.
  set (woth := vsub X cb) in *.
  assert (Ht : vdot L t = vdot L wown - vdot L woth + vdot L E + sigma * vdot L hs)
    by (unfold t, wown, woth, vdot, vsub, vscale; simpl; ring).
  assert (Ht' : Rabs (vdot L t) <= Rabs (vdot L wown) + Rabs (vdot L woth) + Rabs (vdot L E) + Rabs sigma * Rabs (vdot L hs)).
  { rewrite Ht. eapply Rle_trans; [apply abs4|]. rewrite Rabs_mult. lra. }
  pose proof (cross_exact e x y z bj bj1 bj2 wown woth E hs t hx hy hb0 hb1 hb2 grow s sigma Ha Hb (e_small e He)
                Wx Wy W0 W1 W2 ltac:(lra) H1 H2 Hg HE Hsg Ht').
  fold L in H. lra.
Qed.

(* covers optimized/gauss6/ccd/motion_bounds.h "GAUSS6_ALWAYS_INLINE bool obb_separated_as(const PosedObb& a, const Obb& b)" sha256:d562414b9fe2bde6 *)
Theorem obb_separation_cross e (a0 a1 a2 b0 b1 b2 ca cb hs z x y bj bj1 bj2 : V)
    ha0 ha1 ha2 hb0 hb1 hb2 hz hx hy hbj hbj1 hbj2 grow s :
  (forall v, In v [a0; a1; a2; b0; b1; b2; ca; cb; hs] -> FV v) ->
  (forall r, In r [ha0; ha1; ha2; hb0; hb1; hb2; grow; s] -> F r) ->
  ortho e a0 a1 a2 -> ortho e b0 b1 b2 -> 0 <= e <= bpow radix2 (-46) ->
  obb_sizes ca cb hs ha0 ha1 ha2 hb0 hb1 hb2 grow s ->
  rot3 (z, x, y, hz, hx, hy) a0 a1 a2 ha0 ha1 ha2 ->
  rot3 (bj, bj1, bj2, hbj, hbj1, hbj2) b0 b1 b2 hb0 hb1 hb2 ->
  Rabs (cross_c x y (tw_c ca cb hs) bj) > fl (cross_reach x y z bj bj1 bj2 hx hy hbj1 hbj2 hs + sep_slack grow s) ->
  forall X, ~ (in_swept a0 a1 a2 ca ha0 ha1 ha2 hs grow X /\ in_box b0 b1 b2 cb hb0 hb1 hb2 X).
Proof.
  intros HV HF Hoa Hob He Hz Ra Rb T X [(sigma & E & Hsg & HE & (Wa0 & Wa1 & Wa2)) (Wb0 & Wb1 & Wb2)].
  destruct Hz as (Z0 & Z1 & Z2 & Z3 & Z4 & Z5 & Zg & Zca & Zcb & Zhs & Ztw & Zs).
  assert (Fa0 : FV a0) by (apply HV; simpl; tauto). assert (Fa1 : FV a1) by (apply HV; simpl; tauto).
  assert (Fa2 : FV a2) by (apply HV; simpl; tauto). assert (Fca : FV ca) by (apply HV; simpl; tauto).
  assert (Fcb : FV cb) by (apply HV; simpl; tauto). assert (Fhs : FV hs) by (apply HV; simpl; tauto).
  finite_of HF ha0 as G0. finite_of HF ha1 as G1.
  finite_of HF ha2 as G2. finite_of HF hb0 as G3.
  finite_of HF hb1 as G4. finite_of HF hb2 as G5.
  finite_of HF grow as Gg. finite_of HF s as Gs.
  pose proof (ortho_cycle _ _ _ _ Hoa) as Hoa1. pose proof (ortho_cycle _ _ _ _ Hoa1) as Hoa2.
  pose proof (ortho_cycle _ _ _ _ Hob) as Hob1. pose proof (ortho_cycle _ _ _ _ Hob1) as Hob2.
  apply (cross_core e x y z bj bj1 bj2 ca cb hs E X hx hy hbj hbj1 hbj2 grow s sigma); try assumption;
    destruct Ra as [Ra | [Ra | Ra]]; injection Ra; intros; subst;
    destruct Rb as [Rb | [Rb | Rb]]; injection Rb; intros; subst; assumption.
Qed.
Print Assumptions obb_separation_cross.
