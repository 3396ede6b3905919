(* The oriented boxes' allowances, proved in Flocq's binary64 model of
   Rounding.v (the code's operations in its order, each rounded to nearest:
   `fl`; finite results, gradual underflow, no fused multiply-add), over
   double axes that are orthonormal only to within rounding:
   - frame_check_sound: near_orthonormal (bvh.h), the check fit_obb and
     SweptObbFrame::pose make of every frame, proves both Gram matrices of
     the double axes within e = 2^-46 of the identity (kObbFrameTolerance);
   - obb_fit_rounding: fit_obb's box holds its points along its double axes,
     |q_k . (p - c)| <= half_k exactly (kObbFitRounding, kUnderflowFloor),
     and every half extent is at least 2^-1001;
   - obb_axis_rounding: |C| + kObbAxisRounding, as obb_separated computes it,
     bounds the exact |a_i . b_j|;
   - obb_separation_face: when obb_separated's test along one of the six
     face axes holds, the swept posed box and the
     obstacle's box (as sets over the reals, with the double axes) have no
     common point (kObbSeparationRounding).
   The nine cross axes a_i x b_j of obb_separated: ObbCrossAxes.v. *)
From Coq Require Import Reals Psatz List.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances.
Open Scope R_scope.

Record V := mkV { v0 : R; v1 : R; v2 : R }.
Definition vdot (a b : V) := v0 a * v0 b + v1 a * v1 b + v2 a * v2 b.
Definition vcross (a b : V) :=
  mkV (v1 a * v2 b - v2 a * v1 b) (v2 a * v0 b - v0 a * v2 b) (v0 a * v1 b - v1 a * v0 b).
Definition vnorm1 (a : V) := Rabs (v0 a) + Rabs (v1 a) + Rabs (v2 a).
Definition FV (a : V) := F (v0 a) /\ F (v1 a) /\ F (v2 a).
Definition comp (a : V) (m : nat) := match m with 0%nat => v0 a | 1%nat => v1 a | _ => v2 a end.
Definition kron (m n : nat) := if Nat.eqb m n then 1 else 0.
Definition rowgram (x y z : V) m n := comp x m * comp x n + comp y m * comp y n + comp z m * comp z n.

(* A frame of three double axes (the columns of a Mat3), orthonormal to
   within e: both Gram matrices, the columns' A^T A and the rows' A A^T,
   within e of the identity entrywise. *)
Definition ortho e (x y z : V) :=
  (forall m n : nat, (m < 3)%nat -> (n < 3)%nat -> Rabs (rowgram x y z m n - kron m n) <= e) /\
  Rabs (vdot x x - 1) <= e /\ Rabs (vdot y y - 1) <= e /\ Rabs (vdot z z - 1) <= e /\
  Rabs (vdot x y) <= e /\ Rabs (vdot x z) <= e /\ Rabs (vdot y z) <= e.

Lemma vdot_comm a b : vdot a b = vdot b a.
Proof. unfold vdot; ring. Qed.

Lemma ortho_cycle e x y z : ortho e x y z -> ortho e y z x.
Proof.
  intros (Hr & Hx & Hy & Hz & Hxy & Hxz & Hyz). repeat split; try assumption.
  - intros m n Hm Hn. replace (rowgram y z x m n) with (rowgram x y z m n) by (unfold rowgram; ring). auto.
  - rewrite vdot_comm; assumption.
  - rewrite vdot_comm; assumption.
Qed.
Lemma ortho_swap e x y z : ortho e x y z -> ortho e y x z.
Proof.
  intros (Hr & Hx & Hy & Hz & Hxy & Hxz & Hyz). repeat split; try assumption.
  - intros m n Hm Hn. replace (rowgram y x z m n) with (rowgram x y z m n) by (unfold rowgram; ring). auto.
  - rewrite vdot_comm; assumption.
Qed.

Lemma e_small e : 0 <= e <= bpow radix2 (-46) -> 0 <= e <= / 1000000000000.
Proof. intros [H0 H1]. split; [lra|]. apply Rle_trans with (1 := H1). simpl. lra. Qed.

(* Entries of a near-unit axis are at most 1.01 in magnitude. *)
Lemma comp_le e x : 0 <= e <= / 100 -> Rabs (vdot x x - 1) <= e ->
  Rabs (v0 x) <= 101 / 100 /\ Rabs (v1 x) <= 101 / 100 /\ Rabs (v2 x) <= 101 / 100.
Proof.
  intros He Hx. unfold vdot in Hx.
  assert (v0 x * v0 x + v1 x * v1 x + v2 x * v2 x <= 1 + e) by (unfold Rabs in Hx; destruct Rcase_abs; lra).
  assert (forall t, t * t <= 1 + e -> Rabs t <= 101 / 100).
  { intros t Ht. apply Rabs_le. split; nra. }
  repeat split; apply H0; nra.
Qed.

Lemma abs_both x y : Rabs x <= y -> - y <= x /\ x <= y.
Proof. intros H. split; [pose proof (Rle_abs (- x)); rewrite Rabs_Ropp in H0; lra | pose proof (Rle_abs x); lra]. Qed.

(* (a . b)^2 <= |a|^2 |b|^2 (Lagrange's identity). *)
Lemma cs_sq a b : vdot a b * vdot a b <= vdot a a * vdot b b.
Proof.
  unfold vdot.
  assert (E : (v0 a * v0 a + v1 a * v1 a + v2 a * v2 a) * (v0 b * v0 b + v1 b * v1 b + v2 b * v2 b)
     - (v0 a * v0 b + v1 a * v1 b + v2 a * v2 b) * (v0 a * v0 b + v1 a * v1 b + v2 a * v2 b)
     = (v1 a * v2 b - v2 a * v1 b) * (v1 a * v2 b - v2 a * v1 b) + (v2 a * v0 b - v0 a * v2 b) * (v2 a * v0 b - v0 a * v2 b)
       + (v0 a * v1 b - v1 a * v0 b) * (v0 a * v1 b - v1 a * v0 b)) by ring.
  pose proof (Rle_0_sqr (v1 a * v2 b - v2 a * v1 b)). pose proof (Rle_0_sqr (v2 a * v0 b - v0 a * v2 b)).
  pose proof (Rle_0_sqr (v0 a * v1 b - v1 a * v0 b)). unfold Rsqr in *. lra.
Qed.

(* |x| <= y from x^2 <= y^2, y >= 0. *)
Lemma abs_of_sq x y : 0 <= y -> x * x <= y * y -> Rabs x <= y.
Proof. intros. apply Rabs_le. split; nra. Qed.

Lemma vdot_self_pos a : 0 <= vdot a a.
Proof. unfold vdot. pose proof (Rle_0_sqr (v0 a)). pose proof (Rle_0_sqr (v1 a)). pose proof (Rle_0_sqr (v2 a)). unfold Rsqr in *. lra. Qed.

(* A vector a with |a|^2 <= 1 + e and a vector E with |E|^2 <= g^2: |a . E| <= (1 + e) g. *)
Lemma ball_le e a E g : 0 <= e <= / 100 -> 0 <= g -> vdot a a <= 1 + e -> vdot E E <= g * g ->
  Rabs (vdot a E) <= (1 + e) * g.
Proof.
  intros He Hg Ha HE. apply abs_of_sq; [nra|].
  pose proof (cs_sq a E). pose proof (vdot_self_pos E). pose proof (vdot_self_pos a).
  assert (vdot a a * vdot E E <= (1 + e) * (g * g)) by (apply Rmult_le_compat; lra).
  assert (0 <= e * (1 + e) * (g * g)) by (apply Rmult_le_pos; [nra | apply Rle_0_sqr]).
  assert ((1 + e) * (g * g) <= ((1 + e) * g) * ((1 + e) * g)) by nra.
  lra.
Qed.

(* A near-unit axis a and a vector E with |E|^2 <= g^2: |a . E| <= (1 + e) g. *)
Lemma unit_dot_ball e a E g : 0 <= e <= / 100 -> 0 <= g -> Rabs (vdot a a - 1) <= e -> vdot E E <= g * g ->
  Rabs (vdot a E) <= (1 + e) * g.
Proof. intros He Hg Ha HE. apply ball_le; try assumption. unfold Rabs in Ha; destruct Rcase_abs; lra. Qed.

(* Any vector w in a frame orthonormal to within e: w = sum_j (x_j . w) x_j + r,
   |r_m| <= e |w|_1 (the rows' Gram matrix). *)
Lemma decompose e x y z w : ortho e x y z -> forall m : nat, (m < 3)%nat ->
  Rabs (comp w m - (vdot x w * comp x m + vdot y w * comp y m + vdot z w * comp z m)) <= e * vnorm1 w.
Proof.
  intros [Hr _] m Hm.
  assert (Hm' : (m = 0 \/ m = 1 \/ m = 2)%nat) by lia.
  assert (K : forall g0 g1 g2 w0 w1 w2, Rabs g0 <= e -> Rabs g1 <= e -> Rabs g2 <= e ->
            Rabs (g0 * w0 + g1 * w1 + g2 * w2) <= e * (Rabs w0 + Rabs w1 + Rabs w2)).
  { intros. eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    rewrite !Rabs_mult. pose proof (Rabs_pos w0). pose proof (Rabs_pos w1). pose proof (Rabs_pos w2).
    pose proof (Rabs_pos g0). pose proof (Rabs_pos g1). pose proof (Rabs_pos g2). nra. }
  pose proof (Hr m 0%nat Hm ltac:(lia)) as H0. pose proof (Hr m 1%nat Hm ltac:(lia)) as H1.
  pose proof (Hr m 2%nat Hm ltac:(lia)) as H2.
  unfold vnorm1.
  destruct Hm' as [-> | [-> | ->]]; simpl in *; unfold kron in *; simpl in *.
  - replace (v0 w - (vdot x w * v0 x + vdot y w * v0 y + vdot z w * v0 z))
      with (- (rowgram x y z 0 0 - 1) * v0 w + - (rowgram x y z 0 1 - 0) * v1 w + - (rowgram x y z 0 2 - 0) * v2 w)
      by (unfold rowgram, vdot; simpl; ring).
    apply K; rewrite Rabs_Ropp; assumption.
  - replace (v1 w - (vdot x w * v1 x + vdot y w * v1 y + vdot z w * v1 z))
      with (- (rowgram x y z 1 0 - 0) * v0 w + - (rowgram x y z 1 1 - 1) * v1 w + - (rowgram x y z 1 2 - 0) * v2 w)
      by (unfold rowgram, vdot; simpl; ring).
    apply K; rewrite Rabs_Ropp; assumption.
  - replace (v2 w - (vdot x w * v2 x + vdot y w * v2 y + vdot z w * v2 z))
      with (- (rowgram x y z 2 0 - 0) * v0 w + - (rowgram x y z 2 1 - 0) * v1 w + - (rowgram x y z 2 2 - 1) * v2 w)
      by (unfold rowgram, vdot; simpl; ring).
    apply K; rewrite Rabs_Ropp; assumption.
Qed.

(* ---- The computed dot products, and the allowances' doubles ---- *)
Definition cdot (a b : V) := Allowances.dot3 (v0 a) (v1 a) (v2 a) (v0 b) (v1 b) (v2 b).
Definition vinf_le (a : V) B := Rabs (v0 a) <= B /\ Rabs (v1 a) <= B /\ Rabs (v2 a) <= B.

Lemma u_tiny : 0 < u < / 1000000000000000.
Proof. unfold u; lra. Qed.

Lemma cdot_err a b B : vinf_le b B ->
  Rabs (cdot a b - vdot a b) <= 302 / 100 * u * (vnorm1 a * B) + 502 / 100 * eta.
Proof.
  intros (H0 & H1 & H2). pose proof (dot3_err (v0 a) (v1 a) (v2 a) (v0 b) (v1 b) (v2 b)) as E.
  unfold cdot, vdot. eapply Rle_trans; [exact E|].
  pose proof u_tiny. rewrite !Rabs_mult.
  assert (Rabs (v0 a) * Rabs (v0 b) + Rabs (v1 a) * Rabs (v1 b) + Rabs (v2 a) * Rabs (v2 b) <= vnorm1 a * B).
  { unfold vnorm1. pose proof (Rabs_pos (v0 a)). pose proof (Rabs_pos (v1 a)). pose proof (Rabs_pos (v2 a)).
    pose proof (Rabs_pos (v0 b)). nra. }
  assert (0 <= 302 / 100 * u) by lra. nra.
Qed.

(* |a|_1 <= sqrt 3 (1 + e) <= 1.733 for |a|^2 <= 1 + e. *)
Lemma norm1_le e a : 0 <= e <= / 1000 -> vdot a a <= 1 + e -> vnorm1 a <= 1733 / 1000.
Proof.
  intros He H. unfold vnorm1, vdot in *.
  rewrite <- (abs_sq (v0 a)), <- (abs_sq (v1 a)), <- (abs_sq (v2 a)) in H.
  pose proof (Rabs_pos (v0 a)). pose proof (Rabs_pos (v1 a)). pose proof (Rabs_pos (v2 a)).
  set (x := Rabs (v0 a)) in *. set (y := Rabs (v1 a)) in *. set (z := Rabs (v2 a)) in *.
  pose proof (Rle_0_sqr (x - y)). pose proof (Rle_0_sqr (y - z)). pose proof (Rle_0_sqr (z - x)). unfold Rsqr in *.
  assert ((x + y + z) * (x + y + z) <= 3 * (x * x + y * y + z * z)) by lra.
  assert ((x + y + z) * (x + y + z) <= 1733 / 1000 * (1733 / 1000)) by lra.
  destruct (Rle_or_lt (x + y + z) (1733 / 1000)); [lra | nra].
Qed.

(* |a|_1 <= sqrt 3 (1 + e) for a near-unit axis. *)
Lemma norm1_unit e a : 0 <= e <= / 1000000000000 -> Rabs (vdot a a - 1) <= e -> vnorm1 a <= 1733 / 1000.
Proof. intros He Ha. apply (norm1_le e); [lra | unfold Rabs in Ha; destruct Rcase_abs; lra]. Qed.

(* eta against kUnderflowFloor and 2^-1000. *)
Lemma bpow_le_floor : bpow radix2 (-1000) <= / IZR (Z.pow 10 300).
Proof.
  replace (-1000)%Z with (- (1000))%Z by reflexivity.
  rewrite bpow_opp. apply Rinv_le_contravar; [apply IZR_lt; reflexivity|].
  simpl bpow. apply IZR_le. vm_compute. discriminate.
Qed.
Lemma kUnderflowFloor_ge : bpow radix2 (-1000) <= kUnderflowFloor.
Proof. unfold kUnderflowFloor. apply fl_ge_F; [apply generic_format_bpow; unfold fexp, FLT_exp; simpl; lia | apply bpow_le_floor]. Qed.
Lemma eta_1000 : 1000000 * eta <= u * bpow radix2 (-1000).
Proof. apply eta_rel. apply bpow_le. lia. Qed.

(* ---- kObbAxisRounding: |C| + kObbAxisRounding bounds the exact |a_i . b_j| ----
   obb_separated: C = a.axes^T b.axes in doubles (each entry the computed dot
   product of two axes), A = |C| + kObbAxisRounding rounded. For axes of
   squared length within e of 1, the exact |a_i . b_j| is at most A(i, j)
   (the dot's rounding is under 3.03 u, the allowance 9 u), and A(i, j) at
   most 1 + 10^-11. *)
(* allowance kObbAxisRounding = 1e-15 *)
Definition kObbAxisRounding := fl (/ 1000000000000000).
Lemma kObbAxisRounding_ge : 9 * u <= kObbAxisRounding.
Proof. apply fl_decimal_ge; pose proof bpow_m1000; unfold u; lra. Qed.
Lemma kObbAxisRounding_le : kObbAxisRounding <= 2 / 1000000000000000.
Proof.
  unfold kObbAxisRounding. pose proof (fl_upper (/ 1000000000000000) ltac:(lra)).
  pose proof eta_small. pose proof u_tiny. simpl in *. lra.
Qed.
Lemma eta_u : 1000000 * eta <= u.
Proof. replace u with (u * 1) by ring. apply eta_rel. simpl; lra. Qed.
Lemma prod_abs_le x y : Rabs (x * y) <= (x * x + y * y) / 2.
Proof.
  rewrite Rabs_mult. rewrite <- (abs_sq x), <- (abs_sq y). pose proof (Rle_0_sqr (Rabs x - Rabs y)). unfold Rsqr in *. lra.
Qed.

Lemma axis_entry_bounds e a b : 0 <= e <= / 1000000000000 ->
  Rabs (vdot a a - 1) <= e -> Rabs (vdot b b - 1) <= e ->
  Rabs (vdot a b) <= fl (Rabs (cdot a b) + kObbAxisRounding) /\
  fl (Rabs (cdot a b) + kObbAxisRounding) <= 1 + / 100000000000 /\
  Rabs (cdot a b - vdot a b) <= 4 * u.
Proof.
  intros He Ha Hb. pose proof (dot3_err (v0 a) (v1 a) (v2 a) (v0 b) (v1 b) (v2 b)) as E.
  fold (cdot a b) in E. fold (vdot a b) in E.
  pose proof (prod_abs_le (v0 a) (v0 b)). pose proof (prod_abs_le (v1 a) (v1 b)). pose proof (prod_abs_le (v2 a) (v2 b)).
  assert (vdot a a <= 1 + e) by (unfold Rabs in Ha; destruct Rcase_abs; lra).
  assert (vdot b b <= 1 + e) by (unfold Rabs in Hb; destruct Rcase_abs; lra).
  unfold vdot in H2, H3.
  set (T := Rabs (v0 a * v0 b) + Rabs (v1 a * v1 b) + Rabs (v2 a * v2 b)) in E.
  assert (HT : T <= 1 + e) by (unfold T; lra).
  pose proof u_tiny. pose proof eta_u. pose proof eta_pos.
  pose proof (Rabs_pos (v0 a * v0 b)). pose proof (Rabs_pos (v1 a * v1 b)). pose proof (Rabs_pos (v2 a * v2 b)).
  assert (HE : Rabs (cdot a b - vdot a b) <= 4 * u).
  { eapply Rle_trans; [exact E|]. assert (0 <= T) by (unfold T; lra). nra. }
  pose proof kObbAxisRounding_ge. pose proof kObbAxisRounding_le.
  assert (Fk : F kObbAxisRounding) by apply F_fl.
  assert (Fc : F (Rabs (cdot a b))) by (apply generic_format_abs, F_fl).
  pose proof (sum_lower _ _ Fc Fk (Rabs_pos _) ltac:(lra)) as Hl.
  pose proof (fl_upper (Rabs (cdot a b) + kObbAxisRounding) ltac:(pose proof (Rabs_pos (cdot a b)); lra)) as Hu.
  assert (HC : Rabs (vdot a b) <= 1 + e).
  { unfold vdot. eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|]. lra. }
  assert (Rabs (cdot a b) <= Rabs (vdot a b) + Rabs (cdot a b - vdot a b))
    by (replace (cdot a b) with (vdot a b + (cdot a b - vdot a b)) at 1 by ring; apply Rabs_triang).
  assert (Rabs (vdot a b) <= Rabs (cdot a b) + Rabs (cdot a b - vdot a b))
    by (rewrite (Rabs_minus_sym (cdot a b)); replace (vdot a b) with (cdot a b + (vdot a b - cdot a b)) at 1 by ring; apply Rabs_triang).
  assert (Rabs (cdot a b) <= 1 + e + 4 * u) by lra.
  split; [|split; [|exact HE]].
  - assert (Rabs (vdot a b) <= Rabs (cdot a b) + 4 * u) by lra.
    assert (u * (Rabs (cdot a b) + kObbAxisRounding) <= u * (102 / 100)) by (apply mul_le_l; lra).
    lra.
  - assert (u * (Rabs (cdot a b) + kObbAxisRounding) <= u * (102 / 100)) by (apply mul_le_l; pose proof (Rabs_pos (cdot a b)); lra).
    lra.
Qed.

(* covers optimized/gauss6/ccd/motion_bounds.h "GAUSS6_ALWAYS_INLINE bool obb_separated_as(const PosedObb& a, const Obb& b)" sha256:d562414b9fe2bde6 *)
Theorem obb_axis_rounding e a b : 0 <= e <= bpow radix2 (-46) ->
  Rabs (vdot a a - 1) <= e -> Rabs (vdot b b - 1) <= e ->
  Rabs (vdot a b) <= fl (Rabs (cdot a b) + kObbAxisRounding).
Proof. intros He Ha Hb. apply (axis_entry_bounds e); [apply e_small|..]; assumption. Qed.
Print Assumptions obb_axis_rounding.

(* ---- kObbFitRounding and kUnderflowFloor at fit_obb ----
   fit_obb (bvh.cpp), for a frame of double axes x, y, z (the identity or the
   covariance's eigenvectors; a frame not orthonormal to within
   kObbFrameTolerance is dropped: frame_check_sound below gives the exact
   Gram matrices within e = 2^-46 of the identity): every point's projections
   x_k = axes^T p computed (cdot), lo_k / hi_k their least / largest (each a
   computed projection of a point, so within 1.734 scale + 6 eta:
   projection_bound), scale the largest |coordinate| of the points, mid_k =
   0.5 (lo_k + hi_k) rounded, the centre c = axes mid (each coordinate the
   computed dot of a row with mid), half_k = 0.5 (hi_k - lo_k) +
   (kObbFitRounding scale + kUnderflowFloor), each operation rounded.
   Conclusion: every point p lies within half_k of c along each double axis,
   |q_k . (p - c)| <= half_k exactly: the box holds its points. The
   axes' defect moves q_k . c by up to 3 e |mid|_inf <= 5.21 e scale (7.4e-14
   scale), the roundings by under 40 u scale (4.4e-15 scale); kObbFitRounding
   covers both (1.27 times), kUnderflowFloor the underflow (about 30 eta).
   And half_k >= 2^-1000 (the floor), which obb_separated's theorems take. *)
(* allowance kObbFitRounding = 1e-13 *)
Definition kObbFitRounding := fl (/ 10000000000000).
Definition vsub (a b : V) := mkV (v0 a - v0 b) (v1 a - v1 b) (v2 a - v2 b).
Definition fit_mid l h := fl (/ 2 * fl (l + h)).
Definition fit_slack scale := fl (fl (kObbFitRounding * scale) + kUnderflowFloor).
Definition fit_half l h scale := fl (fl (/ 2 * fl (h - l)) + fit_slack scale).
Definition fit_centre (x y z : V) m0 m1 m2 :=
  mkV (Allowances.dot3 (v0 x) (v0 y) (v0 z) m0 m1 m2) (Allowances.dot3 (v1 x) (v1 y) (v1 z) m0 m1 m2)
      (Allowances.dot3 (v2 x) (v2 y) (v2 z) m0 m1 m2).

Lemma kObbFitRounding_ge : 99 / 100 * / 10000000000000 <= kObbFitRounding.
Proof. unfold kObbFitRounding. pose proof (fl_lower (/ 10000000000000) ltac:(lra)). pose proof eta_small. pose proof u_tiny. simpl in *. lra. Qed.

Lemma ortho_units e x y z : ortho e x y z -> 0 <= e <= / 1000000000000 ->
  vnorm1 x <= 1733 / 1000 /\ vnorm1 y <= 1733 / 1000 /\ vnorm1 z <= 1733 / 1000 /\
  vnorm1 (mkV (v0 x) (v0 y) (v0 z)) <= 1733 / 1000 /\ vnorm1 (mkV (v1 x) (v1 y) (v1 z)) <= 1733 / 1000 /\
  vnorm1 (mkV (v2 x) (v2 y) (v2 z)) <= 1733 / 1000.
Proof.
  intros (Hr & Hx & Hy & Hz & _) He.
  repeat split; try (eapply norm1_unit; eassumption).
  - apply (norm1_unit e); [exact He|]. pose proof (Hr 0%nat 0%nat ltac:(lia) ltac:(lia)). unfold rowgram, kron in H; simpl in H. exact H.
  - apply (norm1_unit e); [exact He|]. pose proof (Hr 1%nat 1%nat ltac:(lia) ltac:(lia)). unfold rowgram, kron in H; simpl in H. exact H.
  - apply (norm1_unit e); [exact He|]. pose proof (Hr 2%nat 2%nat ltac:(lia) ltac:(lia)). unfold rowgram, kron in H; simpl in H. exact H.
Qed.

(* Every computed projection of a point within scale on a near-unit axis. *)
Theorem projection_bound e q p scale : 0 <= e <= bpow radix2 (-46) -> Rabs (vdot q q - 1) <= e -> vinf_le p scale ->
  Rabs (cdot q p) <= 1734 / 1000 * scale + 6 * eta.
Proof.
  intros He Hq Hp. pose proof (e_small e He). pose proof (norm1_unit e q H Hq).
  pose proof (cdot_err q p scale Hp). destruct Hp as (P0 & P1 & P2).
  assert (0 <= scale) by (pose proof (Rabs_pos (v0 p)); lra).
  assert (Rabs (vdot q p) <= vnorm1 q * scale).
  { unfold vdot, vnorm1. eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    rewrite !Rabs_mult. pose proof (Rabs_pos (v0 q)). pose proof (Rabs_pos (v1 q)). pose proof (Rabs_pos (v2 q)). nra. }
  pose proof u_tiny. pose proof eta_pos.
  assert (vnorm1 q * scale <= 1733 / 1000 * scale) by (apply Rmult_le_compat_r; lra).
  assert (302 / 100 * u * (vnorm1 q * scale) <= 302 / 100 * u * (1733 / 1000 * scale)) by (apply mul_le_l; lra).
  assert (Rabs (cdot q p) <= Rabs (vdot q p) + Rabs (cdot q p - vdot q p)).
  { replace (cdot q p) with (vdot q p + (cdot q p - vdot q p)) at 1 by ring. apply Rabs_triang. }
  nra.
Qed.
Print Assumptions projection_bound.

Lemma mid_err l h P : F l -> F h -> Rabs l <= P -> Rabs h <= P ->
  Rabs (fit_mid l h - (l + h) / 2) <= 3 * u * P + eta.
Proof.
  intros Fl Fh Hl Hh. pose proof u_tiny. pose proof eta_pos. unfold fit_mid.
  pose proof (add_rel l h Fl Fh) as E1.
  assert (Rabs (l + h) <= 2 * P) by (eapply Rle_trans; [apply Rabs_triang | lra]).
  pose proof (fl_err (/ 2 * fl (l + h))) as E2.
  assert (Rabs (/ 2 * fl (l + h)) <= P + u * P).
  { replace (/ 2 * fl (l + h)) with (/ 2 * (l + h) + / 2 * (fl (l + h) - (l + h))) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult, Rabs_inv, Rabs_pos_eq by lra.
    assert (u * Rabs (l + h) <= u * (2 * P)) by (apply mul_le_l; lra). lra. }
  replace (fl (/ 2 * fl (l + h)) - (l + h) / 2)
    with ((fl (/ 2 * fl (l + h)) - / 2 * fl (l + h)) + / 2 * (fl (l + h) - (l + h))) by (field).
  eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq 2) by lra.
  assert (u * Rabs (l + h) <= u * (2 * P)) by (apply mul_le_l; lra).
  assert (u * Rabs (/ 2 * fl (l + h)) <= u * (P + u * P)) by (apply mul_le_l; lra).
  assert (0 <= P) by (pose proof (Rabs_pos l); lra).
  assert (0 <= u * P) by nra.
  assert (u * (u * P) <= / 1000000 * (u * P)) by (apply Rmult_le_compat_r; lra).
  lra.
Qed.

Lemma half_lower l h scale : F l -> F h -> l <= h -> 0 <= scale ->
  (1 - u) * (1 - u) * (1 - u) * ((h - l) / 2) + (1 - u) * (1 - u) * (1 - u) * (kObbFitRounding * scale)
    + (1 - u) * (1 - u) * kUnderflowFloor - 4 * eta <= fit_half l h scale.
Proof.
  intros Fl Fh Hlh Hs. pose proof u_tiny. pose proof eta_pos.
  assert (Hk0 : 0 <= kObbFitRounding) by (unfold kObbFitRounding; apply fl_nonneg; lra).
  assert (Hf0 : 0 <= kUnderflowFloor) by (pose proof kUnderflowFloor_ge; pose proof (bpow_ge_0 radix2 (-1000)); lra).
  unfold fit_half, fit_slack.
  pose proof (sub_rel h l Fh Fl) as E1. rewrite (Rabs_pos_eq (h - l)) in E1 by lra.
  assert (D1 : (1 - u) * (h - l) <= fl (h - l)) by (destruct (abs_both _ _ E1); lra).
  assert (0 <= fl (h - l)) by (apply fl_nonneg; lra).
  pose proof (fl_lower (/ 2 * fl (h - l)) ltac:(lra)) as D2.
  assert (0 <= fl (/ 2 * fl (h - l))) by (apply fl_nonneg; lra).
  pose proof (fl_lower (kObbFitRounding * scale) ltac:(nra)) as K1.
  assert (0 <= fl (kObbFitRounding * scale)) by (apply fl_nonneg; nra).
  pose proof (fl_lower (fl (kObbFitRounding * scale) + kUnderflowFloor) ltac:(lra)) as K2.
  assert (0 <= fl (fl (kObbFitRounding * scale) + kUnderflowFloor)) by (apply fl_nonneg; lra).
  pose proof (fl_lower (fl (/ 2 * fl (h - l)) + fl (fl (kObbFitRounding * scale) + kUnderflowFloor)) ltac:(lra)) as K3.
  set (a := fl (/ 2 * fl (h - l))) in *. set (b := fl (fl (kObbFitRounding * scale) + kUnderflowFloor)) in *.
  set (k := fl (kObbFitRounding * scale)) in *.
  assert (/ 2 * ((1 - u) * (h - l)) <= / 2 * fl (h - l)) by (apply mul_le_l; lra).
  assert ((1 - u) * (/ 2 * ((1 - u) * (h - l))) <= (1 - u) * (/ 2 * fl (h - l))) by (apply mul_le_l; lra).
  assert (A1 : (1 - u) * (1 - u) * ((h - l) / 2) - eta <= a) by lra.
  assert ((1 - u) * ((1 - u) * (kObbFitRounding * scale) - eta) <= (1 - u) * k) by (apply mul_le_l; lra).
  assert (B1 : (1 - u) * ((1 - u) * (kObbFitRounding * scale) - eta + kUnderflowFloor) - eta <= b) by lra.
  assert ((1 - u) * ((1 - u) * (1 - u) * ((h - l) / 2) - eta) <= (1 - u) * a) by (apply mul_le_l; lra).
  assert ((1 - u) * ((1 - u) * ((1 - u) * (kObbFitRounding * scale) - eta + kUnderflowFloor) - eta) <= (1 - u) * b) by (apply mul_le_l; lra).
  assert (0 <= u * eta) by (apply Rmult_le_pos; lra).
  assert (u * u * eta <= u * eta) by (assert (u * (u * eta) <= 1 * (u * eta)) by (apply Rmult_le_compat_r; lra); lra).
  lra.
Qed.

(* One axis q of the frame, its column of the Gram matrix (d0, d1, d2) within
   e: the point lies within fit_half of the centre along q. *)
Lemma fit_axis e x y z q d0 d1 d2 p l0 h0 l1 h1 l2 h2 lk hk scale :
  ortho e x y z -> 0 <= e <= bpow radix2 (-46) ->
  Rabs (vdot q q - 1) <= e ->
  Rabs (vdot q x - d0) <= e -> Rabs (vdot q y - d1) <= e -> Rabs (vdot q z - d2) <= e ->
  (forall t, In t [l0; h0; l1; h1; l2; h2; lk; hk] -> F t /\ Rabs t <= 1734 / 1000 * scale + 6 * eta) ->
  fit_mid lk hk = d0 * fit_mid l0 h0 + d1 * fit_mid l1 h1 + d2 * fit_mid l2 h2 ->
  vinf_le p scale -> lk <= cdot q p <= hk ->
  Rabs (vdot q (vsub p (fit_centre x y z (fit_mid l0 h0) (fit_mid l1 h1) (fit_mid l2 h2)))) <= fit_half lk hk scale.
Proof.
  intros Ho He Hq G0 G1 G2 HL Hmk Hp Hx.
  pose proof (e_small e He) as He'. pose proof u_tiny. pose proof eta_pos. pose proof eta_u.
  assert (Hs : 0 <= scale) by (destruct Hp as (P0 & _); pose proof (Rabs_pos (v0 p)); lra).
  set (P := 1734 / 1000 * scale + 6 * eta).
  assert (L : forall t, In t [l0; h0; l1; h1; l2; h2; lk; hk] -> F t /\ Rabs t <= P) by exact HL.
  destruct (L l0 ltac:(simpl; tauto)) as [Fl0 Al0]. destruct (L h0 ltac:(simpl; tauto)) as [Fh0 Ah0].
  destruct (L l1 ltac:(simpl; tauto)) as [Fl1 Al1]. destruct (L h1 ltac:(simpl; tauto)) as [Fh1 Ah1].
  destruct (L l2 ltac:(simpl; tauto)) as [Fl2 Al2]. destruct (L h2 ltac:(simpl; tauto)) as [Fh2 Ah2].
  destruct (L lk ltac:(simpl; tauto)) as [Flk Alk]. destruct (L hk ltac:(simpl; tauto)) as [Fhk Ahk].
  assert (HP : 0 <= P) by (pose proof (Rabs_pos l0); lra).
  (* the mids *)
  set (M := P + 3 * u * P + eta).
  assert (Mid : forall l h, F l -> F h -> Rabs l <= P -> Rabs h <= P -> Rabs (fit_mid l h) <= M).
  { intros l h Fl Fh Hl Hh. pose proof (mid_err l h P Fl Fh Hl Hh).
    assert (Rabs ((l + h) / 2) <= P) by (unfold Rdiv; rewrite Rabs_mult, Rabs_inv, (Rabs_pos_eq 2) by lra;
      pose proof (Rabs_triang l h); lra).
    replace (fit_mid l h) with ((l + h) / 2 + (fit_mid l h - (l + h) / 2)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. unfold M. lra. }
  set (m0 := fit_mid l0 h0) in *. set (m1 := fit_mid l1 h1) in *. set (m2 := fit_mid l2 h2) in *.
  pose proof (Mid l0 h0 Fl0 Fh0 Al0 Ah0) as M0. pose proof (Mid l1 h1 Fl1 Fh1 Al1 Ah1) as M1.
  pose proof (Mid l2 h2 Fl2 Fh2 Al2 Ah2) as M2. fold m0 m1 m2 in M0, M1, M2.
  assert (Hmv : vinf_le (mkV m0 m1 m2) M) by (repeat split; simpl; assumption).
  (* the centre against the exact axes times mid *)
  destruct (ortho_units e x y z Ho He') as (Nx & Ny & Nz & R0 & R1 & R2).
  set (Ec := 302 / 100 * u * (1733 / 1000 * M) + 502 / 100 * eta).
  assert (CE : forall r, vnorm1 r <= 1733 / 1000 -> Rabs (cdot r (mkV m0 m1 m2) - vdot r (mkV m0 m1 m2)) <= Ec).
  { intros r Hr. eapply Rle_trans; [apply (cdot_err r (mkV m0 m1 m2) M Hmv)|]. unfold Ec.
    assert (0 <= M) by (unfold M; nra).
    assert (vnorm1 r * M <= 1733 / 1000 * M) by (apply Rmult_le_compat_r; lra).
    assert (302 / 100 * u * (vnorm1 r * M) <= 302 / 100 * u * (1733 / 1000 * M)) by (apply mul_le_l; lra). lra. }
  pose proof (CE _ R0) as C0. pose proof (CE _ R1) as C1. pose proof (CE _ R2) as C2.
  set (c := fit_centre x y z m0 m1 m2).
  set (C := mkV (v0 x * m0 + v0 y * m1 + v0 z * m2) (v1 x * m0 + v1 y * m1 + v1 z * m2) (v2 x * m0 + v2 y * m1 + v2 z * m2)).
  assert (Hc : vdot q c - vdot q C = v0 q * (v0 c - v0 C) + v1 q * (v1 c - v1 C) + v2 q * (v2 c - v2 C)) by (unfold vdot; ring).
  assert (Ec0 : Rabs (v0 c - v0 C) <= Ec) by exact C0.
  assert (Ec1 : Rabs (v1 c - v1 C) <= Ec) by exact C1.
  assert (Ec2 : Rabs (v2 c - v2 C) <= Ec) by exact C2.
  assert (Nq : vnorm1 q <= 1733 / 1000) by (apply (norm1_unit e); assumption).
  assert (Dc : Rabs (vdot q c - vdot q C) <= 1733 / 1000 * Ec).
  { rewrite Hc. eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    rewrite !Rabs_mult. unfold vnorm1 in Nq.
    pose proof (Rabs_pos (v0 q)). pose proof (Rabs_pos (v1 q)). pose proof (Rabs_pos (v2 q)).
    assert (0 <= Ec) by (pose proof (Rabs_pos (v0 c - v0 C)); lra).
    assert (Rabs (v0 q) * Rabs (v0 c - v0 C) <= Rabs (v0 q) * Ec) by (apply mul_le_l; lra).
    assert (Rabs (v1 q) * Rabs (v1 c - v1 C) <= Rabs (v1 q) * Ec) by (apply mul_le_l; lra).
    assert (Rabs (v2 q) * Rabs (v2 c - v2 C) <= Rabs (v2 q) * Ec) by (apply mul_le_l; lra).
    nra. }
  (* the exact axes times mid, against mid_k: the Gram matrix *)
  assert (HC : vdot q C - fit_mid lk hk = (vdot q x - d0) * m0 + (vdot q y - d1) * m1 + (vdot q z - d2) * m2)
    by (rewrite Hmk; unfold vdot, C; simpl; ring).
  assert (DC : Rabs (vdot q C - fit_mid lk hk) <= 3 * e * M).
  { rewrite HC. eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    rewrite !Rabs_mult.
    pose proof (Rabs_pos (vdot q x - d0)). pose proof (Rabs_pos (vdot q y - d1)). pose proof (Rabs_pos (vdot q z - d2)).
    pose proof (Rabs_pos m0). pose proof (Rabs_pos m1). pose proof (Rabs_pos m2).
    assert (Rabs (vdot q x - d0) * Rabs m0 <= e * M) by (apply Rmult_le_compat; lra).
    assert (Rabs (vdot q y - d1) * Rabs m1 <= e * M) by (apply Rmult_le_compat; lra).
    assert (Rabs (vdot q z - d2) * Rabs m2 <= e * M) by (apply Rmult_le_compat; lra).
    lra. }
  (* the point's projection *)
  pose proof (cdot_err q p scale Hp) as Dp.
  assert (vnorm1 q * scale <= 1733 / 1000 * scale) by (apply Rmult_le_compat_r; lra).
  assert (302 / 100 * u * (vnorm1 q * scale) <= 302 / 100 * u * (1733 / 1000 * scale)) by (apply mul_le_l; lra).
  pose proof (mid_err lk hk P Flk Fhk Alk Ahk) as Dm.
  pose proof (half_lower lk hk scale Flk Fhk ltac:(lra) Hs) as Hh.
  (* assemble *)
  assert (E : vdot q (vsub p c) = (cdot q p - (lk + hk) / 2) - (cdot q p - vdot q p) + ((lk + hk) / 2 - fit_mid lk hk)
            - (vdot q c - vdot q C) - (vdot q C - fit_mid lk hk)) by (unfold vdot, vsub; simpl; field).
  assert (Dx : Rabs (cdot q p - (lk + hk) / 2) <= (hk - lk) / 2) by (apply Rabs_le; lra).
  rewrite E. rewrite Rabs_minus_sym in Dm.
  assert (Dsum : forall a b c' d f, Rabs (a - b + c' - d - f) <= Rabs a + Rabs b + Rabs c' + Rabs d + Rabs f).
  { intros. unfold Rabs; repeat destruct Rcase_abs; lra. }
  eapply Rle_trans; [apply Dsum|].
  (* the allowance's doubles *)
  pose proof kObbFitRounding_ge as Kf. pose proof kUnderflowFloor_ge as Ku. pose proof eta_1000 as Eb.
  assert (Hes : e * scale <= / 70368744177664 * scale) by (apply Rmult_le_compat_r; [lra | destruct He as [_ He2]; simpl in He2; lra]).
  assert (Hee : e * eta <= / 70368744177664 * eta) by (apply Rmult_le_compat_r; [lra | destruct He as [_ He2]; simpl in He2; lra]).
  assert (Hks : 99 / 100 * / 10000000000000 * scale <= kObbFitRounding * scale) by (apply Rmult_le_compat_r; lra).
  assert ((hk - lk) / 2 <= P) by (unfold Rabs in Alk, Ahk; destruct Rcase_abs in Alk; destruct Rcase_abs in Ahk; lra).
  assert (0 <= e * scale) by nra. assert (0 <= e * eta) by nra.
  assert (0 <= kObbFitRounding * scale) by lra.
  unfold Ec, M, P in *. set (B := bpow radix2 (-1000)) in *. unfold u in *. lra.
Qed.

(* ---- kObbSeparationRounding: the six face axes of obb_separated ----
   obb_separated_as (motion_bounds.h) on the posed, swept god box a (axes
   a_0..a_2, centre ca, half extents ha_i, half step hs, grow) and the
   obstacle's box b (axes b_0..b_2, centre cb, half extents hb_j), every
   number a double. The sets (exact, over the reals, with the double axes):
   the box of b holds Y when |b_j . (Y - cb)| <= hb_j for each j (what
   obb_fit_rounding proves of fit_obb's boxes); the swept set of a holds X
   when X - E - (1 + sigma) hs is in a's box (centre ca) for some |sigma| <= 1
   and |E| <= grow: the posed box moved along its step 2 hs and grown by grow
   in every direction (PosedObb). Both frames orthonormal to within e =
   2^-46 (both Gram matrices, frame_check_sound: fit_obb's and
   SweptObbFrame::pose's near_orthonormal). The code, per axis L = a_i (or
   b_j, the frames' roles exchanged): t_w = cb - (ca + hs) rounded per
   coordinate, tL = L . t_w computed, A = |C| + kObbAxisRounding rounded,
   reach = (h_L + A's row (column) . the other box's halves) + |L . hs|
   computed, g = grow + kObbSeparationRounding s rounded, s the largest of
   the halves, |t_w|, |ca|, |cb|, |hs| and grow (exact: a max of doubles), and
   the test |tL| > reach + g rounded. Conclusion: when the test holds, no
   point is in both sets. The exact argument: L . t = L . (X-part) - L .
   (Y-part) + L . E + sigma L . hs; a's own box projects within h_L, the
   other within sum_j |L . f_j| k_j + 16 e s (its axes expand any vector
   within e |w|_1 of its coordinates: decompose), E within (1 + e) grow. The
   roundings are under 48 u s + 17 eta; with the axes' 17 e s, under 2.6e-13 s
   in all, which kObbSeparationRounding s covers 38 times (s >= 2^-1000:
   every half extent is, by fit_obb's floor). *)
(* allowance kObbSeparationRounding = 1e-11 *)
Definition kObbSeparationRounding := fl (/ 100000000000).
Definition vadd (a b : V) := mkV (v0 a + v0 b) (v1 a + v1 b) (v2 a + v2 b).
Definition vscale k (a : V) := mkV (k * v0 a) (k * v1 a) (k * v2 a).
Definition in_box (f0 f1 f2 c : V) h0 h1 h2 (X : V) :=
  Rabs (vdot f0 (vsub X c)) <= h0 /\ Rabs (vdot f1 (vsub X c)) <= h1 /\ Rabs (vdot f2 (vsub X c)) <= h2.
Definition in_swept (a0 a1 a2 ca : V) h0 h1 h2 (hs : V) grow (X : V) :=
  exists sigma E, Rabs sigma <= 1 /\ vdot E E <= grow * grow /\
    in_box a0 a1 a2 ca h0 h1 h2 (vsub (vsub X E) (vscale (1 + sigma) hs)).
Definition tw_c (ca cb hs : V) :=
  mkV (fl (v0 cb - fl (v0 ca + v0 hs))) (fl (v1 cb - fl (v1 ca + v1 hs))) (fl (v2 cb - fl (v2 ca + v2 hs))).
Definition axis_entry (a b : V) := fl (Rabs (cdot a b) + kObbAxisRounding).
Definition sep_slack grow s := fl (grow + fl (kObbSeparationRounding * s)).
Definition face_reach h (L f0 f1 f2 : V) k0 k1 k2 (hs : V) :=
  fl (fl (h + Allowances.dot3 (axis_entry L f0) (axis_entry L f1) (axis_entry L f2) k0 k1 k2) + Rabs (cdot L hs)).

Lemma cdot_comm a b : cdot a b = cdot b a.
Proof. unfold cdot, Allowances.dot3. rewrite (Rmult_comm (v0 a)), (Rmult_comm (v1 a)), (Rmult_comm (v2 a)). reflexivity. Qed.

Lemma kSep_ge : 99 / 100 * / 100000000000 <= kObbSeparationRounding.
Proof. unfold kObbSeparationRounding. pose proof (fl_lower (/ 100000000000) ltac:(lra)). pose proof eta_small. pose proof u_tiny. simpl in *. lra. Qed.
Lemma kSep_scaled s : 0 <= s ->
  kObbSeparationRounding <= / 10000000000 /\ 0 <= kObbSeparationRounding * s /\
  kObbSeparationRounding * s <= / 10000000000 * s /\ 99 / 100 * / 100000000000 * s <= kObbSeparationRounding * s.
Proof.
  intros Hs. pose proof kSep_ge.
  assert (K : kObbSeparationRounding <= / 10000000000).
  { unfold kObbSeparationRounding. pose proof (fl_upper (/ 100000000000) ltac:(lra)). pose proof eta_small. pose proof u_tiny. simpl in *. lra. }
  split; [exact K|]. split; [apply Rmult_le_pos; lra|]. split; apply Rmult_le_compat_r; lra.
Qed.

Lemma add_lin x y B : F x -> F y -> Rabs (x + y) <= B -> Rabs (fl (x + y) - (x + y)) <= u * B.
Proof. intros. eapply Rle_trans; [apply add_rel; assumption|]. apply mul_le_l; [unfold u; lra | assumption]. Qed.
Lemma sub_lin x y B : F x -> F y -> Rabs (x - y) <= B -> Rabs (fl (x - y) - (x - y)) <= u * B.
Proof. intros. eapply Rle_trans; [apply sub_rel; assumption|]. apply mul_le_l; [unfold u; lra | assumption]. Qed.
Lemma cdot_unit a b B : vnorm1 a <= 1733 / 1000 -> vinf_le b B ->
  Rabs (cdot a b - vdot a b) <= 524 / 100 * (u * B) + 502 / 100 * eta.
Proof.
  intros Ha Hb. pose proof (cdot_err a b B Hb). destruct Hb as (B0 & _).
  assert (0 <= B) by (pose proof (Rabs_pos (v0 b)); lra). pose proof u_tiny.
  assert (vnorm1 a * B <= 1733 / 1000 * B) by (apply Rmult_le_compat_r; lra).
  assert (302 / 100 * u * (vnorm1 a * B) <= 302 / 100 * u * (1733 / 1000 * B)) by (apply mul_le_l; lra).
  assert (0 <= u * B) by (apply Rmult_le_pos; lra).
  lra.
Qed.
Lemma dot_unit a w W : vnorm1 a <= 1733 / 1000 -> vinf_le w W -> Rabs (vdot a w) <= 1733 / 1000 * W.
Proof.
  intros Ha (W0 & W1 & W2). unfold vdot, vnorm1 in *.
  eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
  rewrite !Rabs_mult. pose proof (Rabs_pos (v0 a)). pose proof (Rabs_pos (v1 a)). pose proof (Rabs_pos (v2 a)).
  assert (0 <= W) by (pose proof (Rabs_pos (v0 w)); lra). nra.
Qed.

(* The other box's projection on L: within sum_j |L . f_j| k_j + 16 e s. *)
Lemma other_projection e f0 f1 f2 L w k0 k1 k2 s : ortho e f0 f1 f2 -> 0 <= e <= / 1000000000000 ->
  vnorm1 L <= 1733 / 1000 -> k0 <= s -> k1 <= s -> k2 <= s ->
  Rabs (vdot f0 w) <= k0 -> Rabs (vdot f1 w) <= k1 -> Rabs (vdot f2 w) <= k2 ->
  Rabs (vdot L w) <= Rabs (vdot L f0) * k0 + Rabs (vdot L f1) * k1 + Rabs (vdot L f2) * k2 + 16 * (e * s).
Proof.
  intros Ho He HL H0 H1 H2 W0 W1 W2.
  pose proof (decompose e f0 f1 f2 w Ho 0%nat ltac:(lia)) as D0.
  pose proof (decompose e f0 f1 f2 w Ho 1%nat ltac:(lia)) as D1.
  pose proof (decompose e f0 f1 f2 w Ho 2%nat ltac:(lia)) as D2. simpl in D0, D1, D2.
  destruct Ho as (Hr & Hx & Hy & Hz & _).
  assert (He' : 0 <= e <= / 100) by lra.
  destruct (comp_le e f0 He' Hx) as (A0 & A1 & A2). destruct (comp_le e f1 He' Hy) as (B0 & B1 & B2).
  destruct (comp_le e f2 He' Hz) as (C0 & C1 & C2).
  set (z0 := vdot f0 w) in *. set (z1 := vdot f1 w) in *. set (z2 := vdot f2 w) in *.
  set (r0 := v0 w - (z0 * v0 f0 + z1 * v0 f1 + z2 * v0 f2)) in *.
  set (r1 := v1 w - (z0 * v1 f0 + z1 * v1 f1 + z2 * v1 f2)) in *.
  set (r2 := v2 w - (z0 * v2 f0 + z1 * v2 f1 + z2 * v2 f2)) in *.
  assert (Hk : 0 <= k0 /\ 0 <= k1 /\ 0 <= k2) by (pose proof (Rabs_pos z0); pose proof (Rabs_pos z1); pose proof (Rabs_pos z2); lra).
  (* |w|_1 <= 9.1 s *)
  assert (Pm : forall a b c, Rabs a <= 101 / 100 -> Rabs b <= 101 / 100 -> Rabs c <= 101 / 100 ->
            Rabs (z0 * a + z1 * b + z2 * c) <= 101 / 100 * (k0 + k1 + k2)).
  { intros a b c Ha Hb Hc. eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
    rewrite !Rabs_mult. pose proof (Rabs_pos z0). pose proof (Rabs_pos z1). pose proof (Rabs_pos z2).
    pose proof (Rabs_pos a). pose proof (Rabs_pos b). pose proof (Rabs_pos c).
    assert (Rabs z0 * Rabs a <= k0 * (101 / 100)) by (apply Rmult_le_compat; lra).
    assert (Rabs z1 * Rabs b <= k1 * (101 / 100)) by (apply Rmult_le_compat; lra).
    assert (Rabs z2 * Rabs c <= k2 * (101 / 100)) by (apply Rmult_le_compat; lra). lra. }
  pose proof (Pm _ _ _ A0 B0 C0) as P0. pose proof (Pm _ _ _ A1 B1 C1) as P1. pose proof (Pm _ _ _ A2 B2 C2) as P2.
  set (n := vnorm1 w) in *.
  assert (Hn : n <= 3 * (101 / 100 * (k0 + k1 + k2)) + 3 * (e * n)).
  { unfold n, vnorm1.
    assert (Rabs (v0 w) <= Rabs (z0 * v0 f0 + z1 * v0 f1 + z2 * v0 f2) + Rabs r0)
      by (unfold r0; replace (v0 w) with ((z0 * v0 f0 + z1 * v0 f1 + z2 * v0 f2) + r0) at 1 by (unfold r0; ring); apply Rabs_triang).
    assert (Rabs (v1 w) <= Rabs (z0 * v1 f0 + z1 * v1 f1 + z2 * v1 f2) + Rabs r1)
      by (unfold r1; replace (v1 w) with ((z0 * v1 f0 + z1 * v1 f1 + z2 * v1 f2) + r1) at 1 by (unfold r1; ring); apply Rabs_triang).
    assert (Rabs (v2 w) <= Rabs (z0 * v2 f0 + z1 * v2 f1 + z2 * v2 f2) + Rabs r2)
      by (unfold r2; replace (v2 w) with ((z0 * v2 f0 + z1 * v2 f1 + z2 * v2 f2) + r2) at 1 by (unfold r2; ring); apply Rabs_triang).
    fold n in D0, D1, D2. unfold n, vnorm1 in D0, D1, D2. lra. }
  assert (0 <= n) by (unfold n, vnorm1; pose proof (Rabs_pos (v0 w)); pose proof (Rabs_pos (v1 w)); pose proof (Rabs_pos (v2 w)); lra).
  assert (Hn' : n <= 92 / 10 * s).
  { assert (e * n <= / 1000000000000 * n) by (apply Rmult_le_compat_r; lra). lra. }
  (* L . w = sum_j z_j (L . f_j) + L . r *)
  assert (E : vdot L w = z0 * vdot L f0 + z1 * vdot L f1 + z2 * vdot L f2 + (v0 L * r0 + v1 L * r1 + v2 L * r2))
    by (unfold r0, r1, r2, vdot; ring).
  rewrite E.
  assert (Rr : Rabs (v0 L * r0 + v1 L * r1 + v2 L * r2) <= 1733 / 1000 * (e * n)).
  { apply (dot_unit L (mkV r0 r1 r2)); [exact HL | repeat split; simpl; assumption]. }
  assert (e * n <= e * (92 / 10 * s)) by (apply mul_le_l; lra).
  assert (Rabs (z0 * vdot L f0) <= Rabs (vdot L f0) * k0)
    by (rewrite Rabs_mult, Rmult_comm; apply mul_le_l; [apply Rabs_pos | exact W0]).
  assert (Rabs (z1 * vdot L f1) <= Rabs (vdot L f1) * k1)
    by (rewrite Rabs_mult, Rmult_comm; apply mul_le_l; [apply Rabs_pos | exact W1]).
  assert (Rabs (z2 * vdot L f2) <= Rabs (vdot L f2) * k2)
    by (rewrite Rabs_mult, Rmult_comm; apply mul_le_l; [apply Rabs_pos | exact W2]).
  eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
  eapply Rle_trans; [apply Rplus_le_compat_r, Rplus_le_compat_r, Rabs_triang|].
  assert (0 <= e * s) by (apply Rmult_le_pos; lra). lra.
Qed.

(* t_w = cb - (ca + hs) per coordinate, projected on a near-unit axis and
   computed: within 14 u s + 5.02 eta of the exact projection of cb - ca - hs. *)
Lemma tw_err (L ca cb hs : V) s : vnorm1 L <= 1733 / 1000 -> FV ca -> FV cb -> FV hs ->
  vinf_le ca s -> vinf_le cb s -> vinf_le hs s -> vinf_le (tw_c ca cb hs) s ->
  Rabs (cdot L (tw_c ca cb hs) - vdot L (vsub (vsub cb ca) hs)) <= 14 * (u * s) + 502 / 100 * eta.
Proof.
  intros NL Fca Fcb Fhs Hca Hcb Hhs Htw.
  pose proof u_tiny. pose proof eta_pos.
  assert (Hs : 0 <= s) by (destruct Hca as (C0 & _); pose proof (Rabs_pos (v0 ca)); lra).
  assert (Tm : forall c b d, F c -> F b -> F d -> Rabs c <= s -> Rabs b <= s -> Rabs d <= s ->
            Rabs (fl (b - fl (c + d)) - (b - c - d)) <= 501 / 100 * (u * s)).
  { intros c b d Fc Fb Fd Hc Hb Hd.
    assert (S1 : Rabs (c + d) <= 2 * s) by (eapply Rle_trans; [apply Rabs_triang | lra]).
    pose proof (add_lin c d (2 * s) Fc Fd S1) as E1.
    assert (Rabs (fl (c + d)) <= 2 * s + u * (2 * s))
      by (replace (fl (c + d)) with ((c + d) + (fl (c + d) - (c + d))) by ring; eapply Rle_trans; [apply Rabs_triang | lra]).
    assert (S3 : Rabs (b - fl (c + d)) <= 3 * s + u * (2 * s))
      by (eapply Rle_trans; [apply Rabs_triang|]; rewrite Rabs_Ropp; lra).
    pose proof (sub_lin b (fl (c + d)) _ Fb (F_fl _) S3) as E2.
    replace (fl (b - fl (c + d)) - (b - c - d)) with ((fl (b - fl (c + d)) - (b - fl (c + d))) - (fl (c + d) - (c + d))) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_Ropp.
    assert (0 <= u * s) by (apply Rmult_le_pos; lra).
    assert (u * (3 * s + u * (2 * s)) <= 301 / 100 * (u * s)) by (unfold u in *; lra). lra. }
  destruct Fca as (Fa0 & Fa1 & Fa2). destruct Fcb as (Fb0 & Fb1 & Fb2). destruct Fhs as (Fs0 & Fs1 & Fs2).
  destruct Hca as (Ca0 & Ca1 & Ca2). destruct Hcb as (Cb0 & Cb1 & Cb2). destruct Hhs as (Hs0 & Hs1 & Hs2).
  pose proof (Tm _ _ _ Fa0 Fb0 Fs0 Ca0 Cb0 Hs0) as T0. pose proof (Tm _ _ _ Fa1 Fb1 Fs1 Ca1 Cb1 Hs1) as T1.
  pose proof (Tm _ _ _ Fa2 Fb2 Fs2 Ca2 Cb2 Hs2) as T2.
  set (t := vsub (vsub cb ca) hs). set (tw := tw_c ca cb hs) in *.
  assert (Dtw : Rabs (vdot L tw - vdot L t) <= 1733 / 1000 * (501 / 100 * (u * s))).
  { replace (vdot L tw - vdot L t) with (vdot L (vsub tw t)) by (unfold vdot, vsub; simpl; ring).
    apply dot_unit; [exact NL | repeat split; unfold tw, t, tw_c, vsub; simpl; assumption]. }
  pose proof (cdot_unit L tw s NL Htw) as Dta.
  replace (cdot L tw - vdot L t) with ((cdot L tw - vdot L tw) + (vdot L tw - vdot L t)) by ring.
  assert (0 <= u * s) by (apply Rmult_le_pos; lra).
  eapply Rle_trans; [apply Rabs_triang|]. lra.
Qed.

(* The rounding half of a face axis: the exact bound of |L . t| (h, the
   other box's sum, the axes' 16 e s, (1 + e) grow, |L . hs|) against the
   test the code computes. *)
Lemma face_round e (L f0 f1 f2 ca cb hs : V) h k0 k1 k2 grow s :
  FV L -> FV ca -> FV cb -> FV hs -> F h -> F k0 -> F k1 -> F k2 -> F grow -> F s ->
  ortho e f0 f1 f2 -> 0 <= e <= bpow radix2 (-46) -> Rabs (vdot L L - 1) <= e ->
  0 <= h <= s -> 0 <= k0 <= s -> 0 <= k1 <= s -> 0 <= k2 <= s -> 0 <= grow <= s ->
  vinf_le ca s -> vinf_le cb s -> vinf_le hs s -> vinf_le (tw_c ca cb hs) s -> bpow radix2 (-1001) <= s ->
  Rabs (cdot L (tw_c ca cb hs)) > fl (face_reach h L f0 f1 f2 k0 k1 k2 hs + sep_slack grow s) ->
  h + Rabs (vdot L f0) * k0 + Rabs (vdot L f1) * k1 + Rabs (vdot L f2) * k2 + 16 * (e * s) + (1 + e) * grow
    + Rabs (vdot L hs) < Rabs (vdot L (vsub (vsub cb ca) hs)).
Proof.
  intros FL Fca Fcb Fhs Fh Fk0 Fk1 Fk2 Fg Fs Ho He HL Hh Hk0 Hk1 Hk2 Hg Hca Hcb Hhs Htw Hs1 T.
  pose proof (e_small e He) as He'. pose proof u_tiny. pose proof eta_pos. pose proof eta_u.
  pose proof (eta_rel s ltac:(apply Rle_trans with (2 := Hs1); apply bpow_le; lia)) as Eta.
  assert (NL : vnorm1 L <= 1733 / 1000) by (apply (norm1_unit e); assumption).
  destruct Ho as (Hr & Hf0 & Hf1 & Hf2 & _).
  destruct (axis_entry_bounds e L f0 He' HL Hf0) as (A0 & A0' & _).
  destruct (axis_entry_bounds e L f1 He' HL Hf1) as (A1 & A1' & _).
  destruct (axis_entry_bounds e L f2 He' HL Hf2) as (A2 & A2' & _).
  fold (axis_entry L f0) in A0, A0'. fold (axis_entry L f1) in A1, A1'. fold (axis_entry L f2) in A2, A2'.
  set (a0 := axis_entry L f0) in *. set (a1 := axis_entry L f1) in *. set (a2 := axis_entry L f2) in *.
  (* t_w against the exact t *)
  pose proof (tw_err L ca cb hs s NL Fca Fcb Fhs Hca Hcb Hhs Htw) as Dt.
  set (t := vsub (vsub cb ca) hs) in *. set (tw := tw_c ca cb hs) in *.
  (* the reach *)
  set (S := Allowances.dot3 a0 a1 a2 k0 k1 k2).
  pose proof (dot3_err a0 a1 a2 k0 k1 k2) as DS. fold S in DS.
  assert (0 <= a0) by (pose proof (Rabs_pos (vdot L f0)); lra).
  assert (0 <= a1) by (pose proof (Rabs_pos (vdot L f1)); lra).
  assert (0 <= a2) by (pose proof (Rabs_pos (vdot L f2)); lra).
  rewrite !Rabs_mult, (Rabs_pos_eq a0), (Rabs_pos_eq a1), (Rabs_pos_eq a2), (Rabs_pos_eq k0), (Rabs_pos_eq k1), (Rabs_pos_eq k2) in DS by lra.
  assert (a0 * k0 <= (1 + / 100000000000) * s) by (apply Rmult_le_compat; lra).
  assert (a1 * k1 <= (1 + / 100000000000) * s) by (apply Rmult_le_compat; lra).
  assert (a2 * k2 <= (1 + / 100000000000) * s) by (apply Rmult_le_compat; lra).
  assert (Rabs (vdot L f0) * k0 <= a0 * k0) by (apply Rmult_le_compat_r; lra).
  assert (Rabs (vdot L f1) * k1 <= a1 * k1) by (apply Rmult_le_compat_r; lra).
  assert (Rabs (vdot L f2) * k2 <= a2 * k2) by (apply Rmult_le_compat_r; lra).
  assert (0 <= a0 * k0) by (apply Rmult_le_pos; lra). assert (0 <= a1 * k1) by (apply Rmult_le_pos; lra).
  assert (0 <= a2 * k2) by (apply Rmult_le_pos; lra).
  set (W := a0 * k0 + a1 * k1 + a2 * k2) in *.
  assert (HW : W <= 301 / 100 * s /\ 0 <= W) by (unfold W; lra).
  assert (HW' : Rabs (vdot L f0) * k0 + Rabs (vdot L f1) * k1 + Rabs (vdot L f2) * k2 <= W) by (unfold W; lra).
  assert (u * W <= u * (301 / 100 * s)) by (apply mul_le_l; unfold W; lra).
  destruct (abs_both _ _ DS) as [DS1 DS2].
  assert (SL : W - 302 / 100 * (u * (301 / 100 * s)) - 502 / 100 * eta <= S) by lra.
  assert (SU : S <= W + 302 / 100 * (u * (301 / 100 * s)) + 502 / 100 * eta) by lra.
  assert (0 <= u * s) by (apply Rmult_le_pos; lra).
  assert (Hus : u * (301 / 100 * s) = 301 / 100 * (u * s)) by ring.
  assert (FS : F S) by apply F_fl.
  assert (R1 : Rabs (h + S) <= 5 * s) by (apply Rabs_le; split; unfold u in *; lra).
  pose proof (add_lin h S _ Fh FS R1) as E1.
  set (r1 := fl (h + S)) in *.
  set (d := Rabs (cdot L hs)).
  pose proof (cdot_unit L hs s NL Hhs) as Dd.
  assert (Hd : Rabs (vdot L hs) <= 1733 / 1000 * s) by (apply dot_unit; assumption).
  assert (Dd' : Rabs (d - Rabs (vdot L hs)) <= 524 / 100 * (u * s) + 502 / 100 * eta)
    by (unfold d; eapply Rle_trans; [apply Rabs_triang_inv2 | exact Dd]).
  assert (Fd : F d) by (apply generic_format_abs, F_fl).
  assert (R2 : Rabs (r1 + d) <= 8 * s).
  { apply Rabs_le. assert (0 <= d) by apply Rabs_pos.
    destruct (abs_both _ _ E1). destruct (abs_both _ _ Dd'). unfold u in *; split; lra. }
  pose proof (add_lin r1 d _ (F_fl _) Fd R2) as E2.
  set (reach := fl (r1 + d)) in *.
  (* the slack g *)
  pose proof kSep_ge as Ks.
  destruct (kSep_scaled s ltac:(lra)) as (Ks' & Ks0 & Kss & Ksl).
  pose proof (fl_err (kObbSeparationRounding * s)) as E3. rewrite (Rabs_pos_eq (kObbSeparationRounding * s)) in E3 by lra.
  assert (u * (kObbSeparationRounding * s) <= u * s) by (apply mul_le_l; lra).
  set (ks := fl (kObbSeparationRounding * s)) in *.
  assert (R3 : Rabs (grow + ks) <= 2 * s) by (apply Rabs_le; destruct (abs_both _ _ E3); unfold u in *; split; lra).
  pose proof (add_lin grow ks _ Fg (F_fl _) R3) as E4.
  set (g := fl (grow + ks)) in *.
  assert (R4 : Rabs (reach + g) <= 11 * s).
  { apply Rabs_le. destruct (abs_both _ _ E2). destruct (abs_both _ _ E4). destruct (abs_both _ _ E3).
    destruct (abs_both _ _ E1). destruct (abs_both _ _ Dd'). assert (0 <= d) by apply Rabs_pos. unfold u in *; split; lra. }
  pose proof (add_lin reach g _ (F_fl _) (F_fl _) R4) as E5.
  unfold face_reach, sep_slack in T. fold a0 a1 a2 S r1 d reach ks g in T.
  (* the axes' terms *)
  assert (Hes : e * s <= / 70368744177664 * s) by (apply Rmult_le_compat_r; [lra | destruct He as [_ He2]; simpl in He2; lra]).
  assert (Heg : e * grow <= e * s) by (apply mul_le_l; lra).
  assert (0 <= e * grow) by (apply Rmult_le_pos; lra).
  (* |L . t| from |cdot L tw| *)
  assert (Lt : Rabs (cdot L tw) <= Rabs (vdot L t) + (14 * (u * s) + 502 / 100 * eta)).
  { replace (cdot L tw) with (vdot L t + (cdot L tw - vdot L t)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. lra. }
  destruct (abs_both _ _ E1). destruct (abs_both _ _ E2). destruct (abs_both _ _ E3). destruct (abs_both _ _ E4).
  destruct (abs_both _ _ E5). destruct (abs_both _ _ Dd'). assert (0 <= d) by apply Rabs_pos.
  unfold u in *; lra.
Qed.

(* The exact half: a common point X of the two sets bounds |L . t|. *)
Lemma face_exact e (L f0 f1 f2 wown woth E hs t : V) h k0 k1 k2 grow s sigma :
  ortho e f0 f1 f2 -> 0 <= e <= / 1000000000000 -> Rabs (vdot L L - 1) <= e -> vnorm1 L <= 1733 / 1000 ->
  Rabs (vdot L wown) <= h -> Rabs (vdot f0 woth) <= k0 -> Rabs (vdot f1 woth) <= k1 -> Rabs (vdot f2 woth) <= k2 ->
  k0 <= s -> k1 <= s -> k2 <= s -> 0 <= grow -> vdot E E <= grow * grow -> Rabs sigma <= 1 ->
  Rabs (vdot L t) <= Rabs (vdot L wown) + Rabs (vdot L woth) + Rabs (vdot L E) + Rabs sigma * Rabs (vdot L hs) ->
  Rabs (vdot L t) <= h + Rabs (vdot L f0) * k0 + Rabs (vdot L f1) * k1 + Rabs (vdot L f2) * k2 + 16 * (e * s)
    + (1 + e) * grow + Rabs (vdot L hs).
Proof.
  intros Ho He HL NL Hw W0 W1 W2 K0 K1 K2 Hg HE Hs Ht.
  pose proof (other_projection e f0 f1 f2 L woth k0 k1 k2 s Ho He NL K0 K1 K2 W0 W1 W2).
  pose proof (unit_dot_ball e L E grow ltac:(lra) Hg HL HE).
  assert (Rabs sigma * Rabs (vdot L hs) <= 1 * Rabs (vdot L hs)) by (apply Rmult_le_compat_r; [apply Rabs_pos | exact Hs]).
  lra.
Qed.

Lemma abs4 a b c d : Rabs (a - b + c + d) <= Rabs a + Rabs b + Rabs c + Rabs d.
Proof. unfold Rabs; repeat destruct Rcase_abs; lra. Qed.

Lemma vdot_sub a x y : vdot a (vsub x y) = vdot a x - vdot a y.
Proof. unfold vdot, vsub; simpl; ring. Qed.
Lemma vdot_scale a k x : vdot a (vscale k x) = k * vdot a x.
Proof. unfold vdot, vscale; simpl; ring. Qed.

(* The magnitude hypotheses of the two theorems: s the code's max. *)
Definition obb_sizes (ca cb hs : V) ha0 ha1 ha2 hb0 hb1 hb2 grow s :=
  0 <= ha0 <= s /\ 0 <= ha1 <= s /\ 0 <= ha2 <= s /\ 0 <= hb0 <= s /\ 0 <= hb1 <= s /\ 0 <= hb2 <= s /\
  0 <= grow <= s /\ vinf_le ca s /\ vinf_le cb s /\ vinf_le hs s /\ vinf_le (tw_c ca cb hs) s /\
  bpow radix2 (-1001) <= s.

(* One face axis L of either box, the roles as parameters: L with its half
   extent hL and the part wown of the common point in L's own box, the other
   box's axes f_j with half extents k_j and the part woth in its box, and
   the sweep's terms E, sigma (for either box's L, t = cb - ca - hs is
   +-(wown - woth) + E + sigma hs). *)
Lemma face_separates e (L f0 f1 f2 ca cb hs wown woth E : V) hL k0 k1 k2 grow s sigma :
  FV L -> FV ca -> FV cb -> FV hs -> F hL -> F k0 -> F k1 -> F k2 -> F grow -> F s ->
  ortho e f0 f1 f2 -> 0 <= e <= bpow radix2 (-46) -> Rabs (vdot L L - 1) <= e ->
  0 <= hL <= s -> 0 <= k0 <= s -> 0 <= k1 <= s -> 0 <= k2 <= s -> 0 <= grow <= s ->
  vinf_le ca s -> vinf_le cb s -> vinf_le hs s -> vinf_le (tw_c ca cb hs) s -> bpow radix2 (-1001) <= s ->
  Rabs (cdot L (tw_c ca cb hs)) > fl (face_reach hL L f0 f1 f2 k0 k1 k2 hs + sep_slack grow s) ->
  Rabs (vdot L wown) <= hL -> Rabs (vdot f0 woth) <= k0 -> Rabs (vdot f1 woth) <= k1 -> Rabs (vdot f2 woth) <= k2 ->
  vdot E E <= grow * grow -> Rabs sigma <= 1 ->
  Rabs (vdot L (vsub (vsub cb ca) hs)) <=
    Rabs (vdot L wown) + Rabs (vdot L woth) + Rabs (vdot L E) + Rabs sigma * Rabs (vdot L hs) ->
  False.
Proof.
  intros FL Fca Fcb Fhs Fh Fk0 Fk1 Fk2 Fg Fs Ho He HLu Hh Hk0 Hk1 Hk2 Hg Hca Hcb Hhs Htw Hs1 T Wown W0 W1 W2 HE Hsg Ht.
  pose proof (e_small e He) as He'.
  assert (NL : vnorm1 L <= 1733 / 1000) by (apply (norm1_unit e); assumption).
  pose proof (face_round e L f0 f1 f2 ca cb hs hL k0 k1 k2 grow s FL Fca Fcb Fhs Fh Fk0 Fk1 Fk2 Fg Fs
                Ho He HLu Hh Hk0 Hk1 Hk2 Hg Hca Hcb Hhs Htw Hs1 T) as R.
  pose proof (face_exact e L f0 f1 f2 wown woth E hs (vsub (vsub cb ca) hs) hL k0 k1 k2 grow s sigma Ho He' HLu NL
                Wown W0 W1 W2 ltac:(lra) ltac:(lra) ltac:(lra) ltac:(lra) HE Hsg Ht).
  lra.
Qed.

(* An axis L of a frame f (hL its half extent) and a point w of the box:
   what face_separates asks of L. *)
Lemma face_role e (L f0 f1 f2 w : V) hL h0 h1 h2 s : ortho e f0 f1 f2 -> FV f0 -> FV f1 -> FV f2 ->
  F h0 -> F h1 -> F h2 -> 0 <= h0 <= s -> 0 <= h1 <= s -> 0 <= h2 <= s ->
  Rabs (vdot f0 w) <= h0 -> Rabs (vdot f1 w) <= h1 -> Rabs (vdot f2 w) <= h2 ->
  (L = f0 /\ hL = h0) \/ (L = f1 /\ hL = h1) \/ (L = f2 /\ hL = h2) ->
  Rabs (vdot L L - 1) <= e /\ Rabs (vdot L w) <= hL /\ FV L /\ 0 <= hL <= s /\ F hL.
Proof.
  intros (_ & U0 & U1 & U2 & _) F0 F1 F2 G0 G1 G2 H0 H1 H2 W0 W1 W2 HL.
  destruct HL as [[-> ->] | [[-> ->] | [-> ->]]]; tauto.
Qed.

(* The six face axes: L = a_i (hL = ha_i) with reach's row of A = |C| +
   kObbAxisRounding, or L = b_j (hL = hb_j) with its column (A(i, j) computed
   from C(i, j) = a_i . b_j). *)
(* covers optimized/gauss6/ccd/motion_bounds.h "GAUSS6_ALWAYS_INLINE bool obb_separated_as(const PosedObb& a, const Obb& b)" sha256:d562414b9fe2bde6 *)
Theorem obb_separation_face e (a0 a1 a2 b0 b1 b2 ca cb hs L : V) ha0 ha1 ha2 hb0 hb1 hb2 hL grow s :
  (forall v, In v [a0; a1; a2; b0; b1; b2; ca; cb; hs] -> FV v) ->
  (forall x, In x [ha0; ha1; ha2; hb0; hb1; hb2; grow; s] -> F x) ->
  ortho e a0 a1 a2 -> ortho e b0 b1 b2 -> 0 <= e <= bpow radix2 (-46) ->
  obb_sizes ca cb hs ha0 ha1 ha2 hb0 hb1 hb2 grow s ->
  ((L = a0 /\ hL = ha0) \/ (L = a1 /\ hL = ha1) \/ (L = a2 /\ hL = ha2)) /\
    Rabs (cdot L (tw_c ca cb hs)) > fl (face_reach hL L b0 b1 b2 hb0 hb1 hb2 hs + sep_slack grow s)
  \/ ((L = b0 /\ hL = hb0) \/ (L = b1 /\ hL = hb1) \/ (L = b2 /\ hL = hb2)) /\
    Rabs (cdot L (tw_c ca cb hs)) >
      fl (fl (fl (hL + Allowances.dot3 (axis_entry a0 L) (axis_entry a1 L) (axis_entry a2 L) ha0 ha1 ha2)
              + Rabs (cdot L hs)) + sep_slack grow s) ->
  forall X, ~ (in_swept a0 a1 a2 ca ha0 ha1 ha2 hs grow X /\ in_box b0 b1 b2 cb hb0 hb1 hb2 X).
Proof.
  intros HV HF Hoa Hob He Hz HLT X [(sigma & E & Hsg & HE & Ha) Hb].
  destruct Hz as (Z0 & Z1 & Z2 & Z3 & Z4 & Z5 & Zg & Zca & Zcb & Zhs & Ztw & Zs).
  assert (Fv : forall v, In v [a0; a1; a2; b0; b1; b2] -> FV v) by (intros v Hv; apply HV; simpl in *; tauto).
  assert (G : forall x, In x [ha0; ha1; ha2; hb0; hb1; hb2] -> F x) by (intros x Hx; apply HF; simpl in *; tauto).
  finite_of G ha0 as G0. finite_of G ha1 as G1.
  finite_of G ha2 as G2. finite_of G hb0 as G3.
  finite_of G hb1 as G4. finite_of G hb2 as G5.
  set (t := vsub (vsub cb ca) hs).
  set (wa := vsub (vsub (vsub X E) (vscale (1 + sigma) hs)) ca) in *.
  set (wb := vsub X cb) in *.
  assert (Ht : vdot L t = vdot L wa - vdot L wb + vdot L E + sigma * vdot L hs)
    by (unfold t, wa, wb, vdot, vsub, vscale; simpl; ring).
  assert (Ht' : forall p q, (p = wa /\ q = wb \/ p = wb /\ q = wa) ->
            Rabs (vdot L t) <= Rabs (vdot L p) + Rabs (vdot L q) + Rabs (vdot L E) + Rabs sigma * Rabs (vdot L hs)).
  { intros p q Hpq. rewrite Ht. eapply Rle_trans; [apply abs4|]. rewrite Rabs_mult.
    destruct Hpq as [[-> ->] | [-> ->]]; lra. }
  destruct Ha as (Ha0 & Ha1 & Ha2). destruct Hb as (Hb0 & Hb1 & Hb2).
  destruct HLT as [[HL T] | [HL T]].
  - (* L = a_i: L's own part wa, the other box b *)
    destruct (face_role e L a0 a1 a2 wa hL ha0 ha1 ha2 s Hoa (Fv a0 ltac:(simpl; tauto)) (Fv a1 ltac:(simpl; tauto))
                (Fv a2 ltac:(simpl; tauto)) G0 G1 G2 Z0 Z1 Z2 Ha0 Ha1 Ha2 HL) as (HLu & HLw & FL & Hh & Fh).
    apply (face_separates e L b0 b1 b2 ca cb hs wa wb E hL hb0 hb1 hb2 grow s sigma); try assumption;
      try (apply HV; simpl; tauto); try (apply HF; simpl; tauto).
    apply Ht'; tauto.
  - (* L = b_j: L's own part wb, the other box a; A's column, C(i, j) = a_i . L *)
    unfold axis_entry in T. rewrite (cdot_comm a0 L), (cdot_comm a1 L), (cdot_comm a2 L) in T.
    fold (axis_entry L a0) (axis_entry L a1) (axis_entry L a2) in T.
    fold (face_reach hL L a0 a1 a2 ha0 ha1 ha2 hs) in T.
    destruct (face_role e L b0 b1 b2 wb hL hb0 hb1 hb2 s Hob (Fv b0 ltac:(simpl; tauto)) (Fv b1 ltac:(simpl; tauto))
                (Fv b2 ltac:(simpl; tauto)) G3 G4 G5 Z3 Z4 Z5 Hb0 Hb1 Hb2 HL) as (HLu & HLw & FL & Hh & Fh).
    apply (face_separates e L a0 a1 a2 ca cb hs wb wa E hL ha0 ha1 ha2 grow s sigma); try assumption;
      try (apply HV; simpl; tauto); try (apply HF; simpl; tauto).
    apply Ht'; tauto.
Qed.
Print Assumptions obb_separation_face.

(* Every half extent fit_obb computes is at least 2^-1001 (kUnderflowFloor). *)
Lemma fit_half_floor l h scale : F l -> F h -> l <= h -> 0 <= scale -> bpow radix2 (-1001) <= fit_half l h scale.
Proof.
  intros Fl Fh Hlh Hs.
  assert (Hb : bpow radix2 (-1000) = 2 * bpow radix2 (-1001))
    by (replace (-1000)%Z with (1 + -1001)%Z by lia; rewrite bpow_plus; simpl; lra).
  pose proof kUnderflowFloor_ge. pose proof eta_1000. pose proof u_tiny. pose proof eta_pos.
  pose proof (bpow_gt_0 radix2 (-1001)).
  assert (0 <= kObbFitRounding * scale) by (apply Rmult_le_pos; [unfold kObbFitRounding; apply fl_nonneg; lra | lra]).
  pose proof (half_lower l h scale Fl Fh Hlh Hs) as H5.
  assert (0 <= (1 - u) * (1 - u) * (1 - u) * ((h - l) / 2)) by (apply Rmult_le_pos; [nra | lra]).
  assert (0 <= (1 - u) * (1 - u) * (1 - u) * (kObbFitRounding * scale)) by (apply Rmult_le_pos; [nra | lra]).
  assert ((1 - u) * (1 - u) * bpow radix2 (-1000) <= (1 - u) * (1 - u) * kUnderflowFloor) by (apply mul_le_l; nra).
  unfold u in *. lra.
Qed.

(* covers optimized/gauss6/geometry/bvh.cpp "Obb fit_obb(const Vec3* points, int num_points)" sha256:e8643d5fb8f792eb *)
Theorem obb_fit_rounding e x y z p l0 h0 l1 h1 l2 h2 scale :
  ortho e x y z -> 0 <= e <= bpow radix2 (-46) ->
  (forall t, In t [l0; h0; l1; h1; l2; h2] -> F t /\ Rabs t <= 1734 / 1000 * scale + 6 * eta) ->
  vinf_le p scale ->
  l0 <= cdot x p <= h0 -> l1 <= cdot y p <= h1 -> l2 <= cdot z p <= h2 ->
  let c := fit_centre x y z (fit_mid l0 h0) (fit_mid l1 h1) (fit_mid l2 h2) in
  in_box x y z c (fit_half l0 h0 scale) (fit_half l1 h1 scale) (fit_half l2 h2 scale) p /\
  bpow radix2 (-1001) <= fit_half l0 h0 scale /\ bpow radix2 (-1001) <= fit_half l1 h1 scale /\
  bpow radix2 (-1001) <= fit_half l2 h2 scale.
Proof.
  intros Ho He HL Hp Hx Hy Hz c.
  pose proof Ho as (Hr & Ux & Uy & Uz & Gxy & Gxz & Gyz).
  assert (Z : forall t, Rabs (t - 0) = Rabs t) by (intros; f_equal; ring).
  assert (HL' : forall a b, In a [l0; h0; l1; h1; l2; h2] -> In b [l0; h0; l1; h1; l2; h2] ->
            forall t, In t [l0; h0; l1; h1; l2; h2; a; b] -> F t /\ Rabs t <= 1734 / 1000 * scale + 6 * eta).
  { intros a b Ha Hb t Ht. simpl in Ht.
    destruct Ht as [<-|[<-|[<-|[<-|[<-|[<-|[<-|[<-|[]]]]]]]]]; apply HL; simpl; tauto. }
  split; [|split; [|split]].
  - unfold in_box. split; [|split].
    + apply (fit_axis e x y z x 1 0 0 p l0 h0 l1 h1 l2 h2 l0 h0 scale Ho He Ux); try rewrite Z; try assumption.
      * apply HL'; simpl; tauto.
      * ring.
    + apply (fit_axis e x y z y 0 1 0 p l0 h0 l1 h1 l2 h2 l1 h1 scale Ho He Uy); try rewrite Z; try assumption.
      * rewrite vdot_comm; exact Gxy.
      * apply HL'; simpl; tauto.
      * ring.
    + apply (fit_axis e x y z z 0 0 1 p l0 h0 l1 h1 l2 h2 l2 h2 scale Ho He Uz); try rewrite Z; try assumption.
      * rewrite vdot_comm; exact Gxz.
      * rewrite vdot_comm; exact Gyz.
      * apply HL'; simpl; tauto.
      * ring.
  - assert (Hs : 0 <= scale) by (destruct Hp as (P0 & _); pose proof (Rabs_pos (v0 p)); lra).
    destruct (HL l0 ltac:(simpl; tauto)) as [Fl _]. destruct (HL h0 ltac:(simpl; tauto)) as [Fh _].
    apply fit_half_floor; try assumption; lra.
  - assert (Hs : 0 <= scale) by (destruct Hp as (P0 & _); pose proof (Rabs_pos (v0 p)); lra).
    destruct (HL l1 ltac:(simpl; tauto)) as [Fl _]. destruct (HL h1 ltac:(simpl; tauto)) as [Fh _].
    apply fit_half_floor; try assumption; lra.
  - assert (Hs : 0 <= scale) by (destruct Hp as (P0 & _); pose proof (Rabs_pos (v0 p)); lra).
    destruct (HL l2 ltac:(simpl; tauto)) as [Fl _]. destruct (HL h2 ltac:(simpl; tauto)) as [Fh _].
    apply fit_half_floor; try assumption; lra.
Qed.
Print Assumptions obb_fit_rounding.

(* ---- The frame check (near_orthonormal, bvh.h): kObbFrameTolerance ----
   Every entry of m^T m (columns' dots) and m m^T (rows' dots), computed,
   less the identity's entry, rounded, at most kObbFrameTolerance = 1e-14 in
   magnitude, proves both exact Gram matrices within 2^-46 (1.42e-14) of the
   identity: ortho (2^-46). The dots' rounding is under 3.1 u. *)
(* allowance kObbFrameTolerance = 1e-14 *)
Definition kObbFrameTolerance := fl (/ 100000000000000).
Definition passes (a b : V) d := Rabs (fl (cdot a b - d)) <= kObbFrameTolerance.

Lemma tol_le : kObbFrameTolerance <= 10000001 / 10000000 * / 100000000000000.
Proof. unfold kObbFrameTolerance. pose proof (fl_upper (/ 100000000000000) ltac:(lra)). pose proof eta_small. pose proof u_tiny. simpl in *. lra. Qed.

Lemma passes_near a b d : passes a b d -> Rabs (cdot a b - d) <= 10000003 / 10000000 * / 100000000000000.
Proof.
  unfold passes. intros H. pose proof tol_le. pose proof (fl_err (cdot a b - d)). pose proof u_tiny. pose proof eta_u.
  pose proof eta_pos.
  assert (Rabs (cdot a b - d) <= Rabs (fl (cdot a b - d)) + Rabs (fl (cdot a b - d) - (cdot a b - d))).
  { replace (cdot a b - d) with (fl (cdot a b - d) - (fl (cdot a b - d) - (cdot a b - d))) at 1 by ring.
    unfold Rminus at 1. eapply Rle_trans; [apply Rabs_triang|]. rewrite Rabs_Ropp. lra. }
  assert (u * Rabs (cdot a b - d) <= / 1000000000000000 * Rabs (cdot a b - d)) by (apply Rmult_le_compat_r; [apply Rabs_pos | lra]).
  assert (eta <= / 1000000000000000000000) by (unfold u in *; lra).
  lra.
Qed.

Lemma diag_sound a : passes a a 1 -> Rabs (vdot a a - 1) <= bpow radix2 (-46).
Proof.
  intros H. pose proof (passes_near a a 1 H) as N.
  pose proof (dot3_err (v0 a) (v1 a) (v2 a) (v0 a) (v1 a) (v2 a)) as E. cbv zeta in E.
  rewrite (Rabs_pos_eq (v0 a * v0 a)), (Rabs_pos_eq (v1 a * v1 a)), (Rabs_pos_eq (v2 a * v2 a)) in E by apply Rle_0_sqr.
  fold (cdot a a) (vdot a a) in E.
  pose proof u_tiny. pose proof eta_u. pose proof eta_pos.
  assert (vdot a a <= 2) by (unfold Rabs in N, E; destruct Rcase_abs in N; destruct Rcase_abs in E; unfold u in *; nra).
  assert (0 <= vdot a a) by (unfold vdot; nra).
  assert (u * vdot a a <= u * 2) by (apply mul_le_l; lra).
  replace (vdot a a - 1) with ((cdot a a - 1) - (cdot a a - vdot a a)) by ring.
  eapply Rle_trans; [apply abs_diff_le; [exact N | exact E]|]. simpl. unfold u in *. lra.
Qed.

Lemma offdiag_sound a b : Rabs (vdot a a - 1) <= bpow radix2 (-46) -> Rabs (vdot b b - 1) <= bpow radix2 (-46) ->
  passes a b 0 -> Rabs (vdot a b) <= bpow radix2 (-46).
Proof.
  intros Ha Hb H. pose proof (passes_near a b 0 H) as N. rewrite Rminus_0_r in N.
  pose proof (dot3_err (v0 a) (v1 a) (v2 a) (v0 b) (v1 b) (v2 b)) as E. cbv zeta in E. fold (cdot a b) (vdot a b) in E.
  pose proof (prod_abs_le (v0 a) (v0 b)). pose proof (prod_abs_le (v1 a) (v1 b)). pose proof (prod_abs_le (v2 a) (v2 b)).
  simpl in Ha, Hb.
  assert (vdot a a <= 2) by (unfold Rabs in Ha; destruct Rcase_abs in Ha; lra).
  assert (vdot b b <= 2) by (unfold Rabs in Hb; destruct Rcase_abs in Hb; lra).
  unfold vdot in *.
  set (T := Rabs (v0 a * v0 b) + Rabs (v1 a * v1 b) + Rabs (v2 a * v2 b)) in E.
  assert (T <= 2) by (unfold T; lra). pose proof u_tiny. pose proof eta_u. pose proof eta_pos.
  assert (0 <= T) by (unfold T; pose proof (Rabs_pos (v0 a * v0 b)); pose proof (Rabs_pos (v1 a * v1 b)); pose proof (Rabs_pos (v2 a * v2 b)); lra).
  assert (u * T <= u * 2) by (apply mul_le_l; lra).
  replace (v0 a * v0 b + v1 a * v1 b + v2 a * v2 b) with (cdot a b - (cdot a b - (v0 a * v0 b + v1 a * v1 b + v2 a * v2 b))) by ring.
  eapply Rle_trans; [apply abs_diff_le; [exact N | exact E]|]. simpl. unfold u in *. lra.
Qed.

Definition row (x y z : V) (m : nat) := mkV (comp x m) (comp y m) (comp z m).

(* covers optimized/gauss6/geometry/bvh.h "inline bool near_orthonormal(const Mat3& m, double tolerance = kObbFrameTolerance)" sha256:c6604e12f978af7d *)
(* covers optimized/gauss6/ccd/motion_bounds.h "PosedObb pose_checked(const Obb& b, bool check_frame) const" sha256:3c631a4b53f4d403 *)
(* covers optimized/gauss6/geometry/bvh.cpp "Obb fit_obb(const Vec3* points, int num_points)" sha256:e8643d5fb8f792eb *)
Theorem frame_check_sound x y z :
  passes x x 1 -> passes y y 1 -> passes z z 1 -> passes x y 0 -> passes x z 0 -> passes y z 0 ->
  let r0 := row x y z 0 in let r1 := row x y z 1 in let r2 := row x y z 2 in
  passes r0 r0 1 -> passes r1 r1 1 -> passes r2 r2 1 -> passes r0 r1 0 -> passes r0 r2 0 -> passes r1 r2 0 ->
  ortho (bpow radix2 (-46)) x y z.
Proof.
  intros Pxx Pyy Pzz Pxy Pxz Pyz r0 r1 r2 P00 P11 P22 P01 P02 P12.
  pose proof (diag_sound _ Pxx). pose proof (diag_sound _ Pyy). pose proof (diag_sound _ Pzz).
  pose proof (diag_sound _ P00) as D0. pose proof (diag_sound _ P11) as D1. pose proof (diag_sound _ P22) as D2.
  pose proof (offdiag_sound _ _ D0 D1 P01) as O01. pose proof (offdiag_sound _ _ D0 D2 P02) as O02.
  pose proof (offdiag_sound _ _ D1 D2 P12) as O12.
  split; [|repeat split; try assumption; apply offdiag_sound; assumption].
  intros m n Hm Hn.
  assert (G : forall i j, rowgram x y z i j = vdot (row x y z i) (row x y z j)) by (intros; unfold rowgram, vdot, row; simpl; ring).
  rewrite G.
  assert (Hm' : (m = 0 \/ m = 1 \/ m = 2)%nat) by lia. assert (Hn' : (n = 0 \/ n = 1 \/ n = 2)%nat) by lia.
  destruct Hm' as [-> | [-> | ->]]; destruct Hn' as [-> | [-> | ->]]; unfold kron; simpl Nat.eqb; cbv iota;
    fold r0 r1 r2; try rewrite Rminus_0_r; try assumption; rewrite vdot_comm; assumption.
Qed.
Print Assumptions frame_check_sound.
