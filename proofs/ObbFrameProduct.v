(* The posed boxes' frame check made once per frame (SweptObbFrame::pose,
   motion_bounds.h), proved in Flocq's binary64 model of Rounding.v (each
   operation rounded to nearest: `fl`; finite results, gradual underflow, no
   fused multiply-add), over the frame check near_orthonormal (bvh.h) with its
   tolerance as a parameter:
   - posed_frame_check: a rotation R (columns k0 k1 k2) that passes the check
     at kObbRotationTight = 2^-50 and a node's axes A (columns a0 a1 a2) that
     pass it at kObbAxesTight = 2^-49 make the posed axes M = R A, each entry
     the sum of the three products R(i, l) A(l, j) rounded in any of the six
     orders (Eigen's 3 x 3 product), pass it at kObbFrameTolerance: the code's
     near_orthonormal(R A) is true, so pose() skipping it decides the same;
   - posed_frame_ortho: then both exact Gram matrices of M are within 2^-46
     of the identity (frame_check_sound), the hypothesis of the 15-axis tests.
   The budget, in units of u = 2^-53: the tight checks put the exact Gram
   matrices of R within 11.03 u and of A within 19.03 u of the identity; the
   exact product R A's within 11.03 + 3 (1 + 11.03 u) 19.03 <= 68.2 u (a near
   orthonormal frame's Gram defect e moves the dot of x's and y's images by
   e |x|_1 |y|_1 <= 3 e (1 + ..)); each entry's rounding, at most 3.021 u,
   moves M's by 2 sqrt 3 3.021 u + .. <= 10.5 u: 78.7 u; the check's own dot
   and subtraction add 3.03 u: 81.8 u, under kObbFrameTolerance = 1e-14 =
   90.07 u. *)
From Coq Require Import Reals Psatz.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances ObbSeparation.
Open Scope R_scope.

(* allowance kObbAxesTight = 0x1p-49 *)
Definition kObbAxesTight := bpow radix2 (-49).
(* allowance kObbRotationTight = 0x1p-50 *)
Definition kObbRotationTight := bpow radix2 (-50).

Lemma axes_tight_u : kObbAxesTight = 16 * u.
Proof. unfold kObbAxesTight, u. simpl. lra. Qed.
Lemma rotation_tight_u : kObbRotationTight = 8 * u.
Proof. unfold kObbRotationTight, u. simpl. lra. Qed.

(* near_orthonormal's test of one Gram entry at tolerance t, and of a frame
   (columns x y z): the six distinct entries of each Gram matrix. *)
Definition passes_at t (a b : V) d := Rabs (fl (cdot a b - d)) <= t.
Definition frame_passes t (x y z : V) :=
  passes_at t x x 1 /\ passes_at t y y 1 /\ passes_at t z z 1 /\
  passes_at t x y 0 /\ passes_at t x z 0 /\ passes_at t y z 0 /\
  passes_at t (row x y z 0) (row x y z 0) 1 /\ passes_at t (row x y z 1) (row x y z 1) 1 /\
  passes_at t (row x y z 2) (row x y z 2) 1 /\ passes_at t (row x y z 0) (row x y z 1) 0 /\
  passes_at t (row x y z 0) (row x y z 2) 0 /\ passes_at t (row x y z 1) (row x y z 2) 0.

Definition col3 (x y z : V) (j : nat) := match j with 0%nat => x | 1%nat => y | _ => z end.

Lemma u_facts : 0 < u /\ u <= / 1000000000000000 /\ u * u <= / 1000000000000000 * u /\ 1000000 * eta <= u /\ 0 < eta.
Proof.
  pose proof u_tiny. pose proof eta_u. pose proof eta_pos.
  split; [lra|]. split; [lra|]. split; [apply Rmult_le_compat_r; lra|]. split; lra.
Qed.

Lemma kron_refl j : kron j j = 1.
Proof. unfold kron. rewrite Nat.eqb_refl. reflexivity. Qed.

Lemma idx3 (i : nat) : (i < 3)%nat -> i = 0%nat \/ i = 1%nat \/ i = 2%nat.
Proof. intros; lia. Qed.

(* ---- A tight check's exact Gram entries ---- *)
Lemma near_k k a b d : 0 <= k <= 100 -> passes_at (k * u) a b d -> Rabs (cdot a b - d) <= (k + / 1000) * u.
Proof.
  intros Hk H. unfold passes_at in H. set (x := cdot a b - d) in *.
  destruct u_facts as (Hu & Hu15 & Huu & He & He0).
  pose proof (fl_err x) as F.
  assert (A : Rabs x <= Rabs (fl x) + Rabs (fl x - x)).
  { replace x with (fl x - (fl x - x)) at 1 by ring. apply abs_diff_le; lra. }
  assert (Hku : k * u <= 100 * u) by (apply Rmult_le_compat_r; lra).
  assert (u * Rabs x <= / 1000000000000000 * Rabs x) by (apply Rmult_le_compat_r; [apply Rabs_pos | lra]).
  assert (B : Rabs x <= 102 * u) by lra.
  assert (u * Rabs x <= u * (102 * u)) by (apply mul_le_l; lra).
  lra.
Qed.

Lemma diag_k k a : 0 <= k <= 100 -> passes_at (k * u) a a 1 -> Rabs (vdot a a - 1) <= (k + 303 / 100) * u.
Proof.
  intros Hk H. pose proof (near_k k a a 1 Hk H) as N.
  pose proof (dot3_err (v0 a) (v1 a) (v2 a) (v0 a) (v1 a) (v2 a)) as E. cbv zeta in E.
  rewrite (Rabs_pos_eq (v0 a * v0 a)), (Rabs_pos_eq (v1 a * v1 a)), (Rabs_pos_eq (v2 a * v2 a)) in E by apply Rle_0_sqr.
  fold (cdot a a) (vdot a a) in E.
  destruct u_facts as (Hu & Hu15 & Huu & He & He0).
  pose proof (vdot_self_pos a).
  set (T := vdot a a) in *.
  destruct (abs_both _ _ N). destruct (abs_both _ _ E).
  assert (Hku : k * u <= 100 * u) by (apply Rmult_le_compat_r; lra).
  assert (u * T <= / 1000000000000000 * T) by (apply Rmult_le_compat_r; lra).
  assert (T <= 2) by lra.
  assert (u * T <= u * 2) by (apply mul_le_l; lra).
  assert (T <= 1 + 107 * u) by lra.
  assert (u * T <= u * (1 + 107 * u)) by (apply mul_le_l; lra).
  apply Rabs_le. split; lra.
Qed.

Lemma offdiag_k k a b : 0 <= k <= 100 ->
  Rabs (vdot a a - 1) <= (k + 303 / 100) * u -> Rabs (vdot b b - 1) <= (k + 303 / 100) * u ->
  passes_at (k * u) a b 0 -> Rabs (vdot a b) <= (k + 303 / 100) * u.
Proof.
  intros Hk Ha Hb H. pose proof (near_k k a b 0 Hk H) as N. rewrite Rminus_0_r in N.
  pose proof (dot3_err (v0 a) (v1 a) (v2 a) (v0 b) (v1 b) (v2 b)) as E. cbv zeta in E. fold (cdot a b) (vdot a b) in E.
  pose proof (prod_abs_le (v0 a) (v0 b)). pose proof (prod_abs_le (v1 a) (v1 b)). pose proof (prod_abs_le (v2 a) (v2 b)).
  destruct u_facts as (Hu & Hu15 & Huu & He & He0).
  assert (Hku : k * u <= 100 * u) by (apply Rmult_le_compat_r; lra).
  destruct (abs_both _ _ Ha). destruct (abs_both _ _ Hb).
  unfold vdot in *.
  set (T := Rabs (v0 a * v0 b) + Rabs (v1 a * v1 b) + Rabs (v2 a * v2 b)) in E.
  assert (T <= 1 + 104 * u) by (unfold T; lra).
  assert (0 <= T) by (unfold T; pose proof (Rabs_pos (v0 a * v0 b)); pose proof (Rabs_pos (v1 a * v1 b));
                      pose proof (Rabs_pos (v2 a * v2 b)); lra).
  assert (u * T <= u * (1 + 104 * u)) by (apply mul_le_l; lra).
  replace (v0 a * v0 b + v1 a * v1 b + v2 a * v2 b) with (cdot a b - (cdot a b - (v0 a * v0 b + v1 a * v1 b + v2 a * v2 b))) by ring.
  eapply Rle_trans; [apply abs_diff_le; [exact N | exact E]|]. lra.
Qed.

(* A frame that passes the check at k u (k <= 100) has both exact Gram
   matrices within (k + 3.03) u of the identity (frame_check_sound's argument
   at a tolerance of k u). *)
Lemma ortho_k k x y z : 0 <= k <= 100 -> frame_passes (k * u) x y z -> ortho ((k + 303 / 100) * u) x y z.
Proof.
  intros Hk (Pxx & Pyy & Pzz & Pxy & Pxz & Pyz & P00 & P11 & P22 & P01 & P02 & P12).
  pose proof (diag_k k _ Hk Pxx). pose proof (diag_k k _ Hk Pyy). pose proof (diag_k k _ Hk Pzz).
  pose proof (diag_k k _ Hk P00) as D0. pose proof (diag_k k _ Hk P11) as D1. pose proof (diag_k k _ Hk P22) as D2.
  pose proof (offdiag_k k _ _ Hk D0 D1 P01) as O01. pose proof (offdiag_k k _ _ Hk D0 D2 P02) as O02.
  pose proof (offdiag_k k _ _ Hk D1 D2 P12) as O12.
  split; [|repeat split; try assumption; apply (offdiag_k k); assumption].
  intros m n Hm Hn.
  assert (G : forall i j, rowgram x y z i j = vdot (row x y z i) (row x y z j)) by (intros; unfold rowgram, vdot, row; simpl; ring).
  rewrite G.
  destruct (idx3 m Hm) as [-> | [-> | ->]]; destruct (idx3 n Hn) as [-> | [-> | ->]]; unfold kron; simpl Nat.eqb; cbv iota;
    try rewrite Rminus_0_r; try assumption; rewrite vdot_comm; assumption.
Qed.

Lemma ortho_cols e x y z : ortho e x y z -> forall j l, (j < 3)%nat -> (l < 3)%nat ->
  Rabs (vdot (col3 x y z j) (col3 x y z l) - kron j l) <= e.
Proof.
  intros (_ & Hx & Hy & Hz & Hxy & Hxz & Hyz) j l Hj Hl.
  destruct (idx3 j Hj) as [-> | [-> | ->]]; destruct (idx3 l Hl) as [-> | [-> | ->]]; unfold kron; simpl;
    try rewrite Rminus_0_r; try assumption; rewrite vdot_comm; assumption.
Qed.

Lemma ortho_rows e x y z : ortho e x y z -> forall i l, (i < 3)%nat -> (l < 3)%nat ->
  Rabs (vdot (row x y z i) (row x y z l) - kron i l) <= e.
Proof.
  intros (Hr & _) i l Hi Hl.
  replace (vdot (row x y z i) (row x y z l)) with (rowgram x y z i l) by (unfold rowgram, vdot, row; simpl; ring).
  auto.
Qed.

(* ---- The exact product ---- *)
Lemma K3 e g0 g1 g2 w0 w1 w2 : Rabs g0 <= e -> Rabs g1 <= e -> Rabs g2 <= e ->
  Rabs (g0 * w0 + g1 * w1 + g2 * w2) <= e * (Rabs w0 + Rabs w1 + Rabs w2).
Proof.
  intros. eapply Rle_trans; [apply Rabs_triang|]. eapply Rle_trans; [apply Rplus_le_compat_r, Rabs_triang|].
  rewrite !Rabs_mult. pose proof (Rabs_pos w0). pose proof (Rabs_pos w1). pose proof (Rabs_pos w2).
  pose proof (Rabs_pos g0). pose proof (Rabs_pos g1). pose proof (Rabs_pos g2). nra.
Qed.

Lemma n1_sq x : vnorm1 x * vnorm1 x <= 3 * vdot x x.
Proof.
  unfold vnorm1, vdot. rewrite <- (abs_sq (v0 x)), <- (abs_sq (v1 x)), <- (abs_sq (v2 x)).
  pose proof (Rle_0_sqr (Rabs (v0 x) - Rabs (v1 x))). pose proof (Rle_0_sqr (Rabs (v0 x) - Rabs (v2 x))).
  pose proof (Rle_0_sqr (Rabs (v1 x) - Rabs (v2 x))). unfold Rsqr in *. nra.
Qed.

Lemma n1_pos x : 0 <= vnorm1 x.
Proof. unfold vnorm1. pose proof (Rabs_pos (v0 x)). pose proof (Rabs_pos (v1 x)). pose proof (Rabs_pos (v2 x)). lra. Qed.

Lemma n1_prod e x y : Rabs (vdot x x - 1) <= e -> Rabs (vdot y y - 1) <= e -> vnorm1 x * vnorm1 y <= 3 * (1 + e).
Proof.
  intros Hx Hy. pose proof (n1_sq x). pose proof (n1_sq y). destruct (abs_both _ _ Hx). destruct (abs_both _ _ Hy).
  pose proof (Rle_0_sqr (vnorm1 x - vnorm1 y)). unfold Rsqr in *. nra.
Qed.

(* x's image in a frame b (its columns b0 b1 b2): x0 b0 + x1 b1 + x2 b2. *)
Definition lin (x b0 b1 b2 : V) :=
  mkV (v0 x * v0 b0 + v1 x * v0 b1 + v2 x * v0 b2) (v0 x * v1 b0 + v1 x * v1 b1 + v2 x * v1 b2)
      (v0 x * v2 b0 + v1 x * v2 b1 + v2 x * v2 b2).

(* In a frame whose columns' Gram matrix is within e of the identity, the
   images' dot is within e |x|_1 |y|_1 of x . y. *)
Lemma lin_gram e b0 b1 b2 x y :
  (forall j l, (j < 3)%nat -> (l < 3)%nat -> Rabs (vdot (col3 b0 b1 b2 j) (col3 b0 b1 b2 l) - kron j l) <= e) ->
  Rabs (vdot (lin x b0 b1 b2) (lin y b0 b1 b2) - vdot x y) <= e * (vnorm1 x * vnorm1 y).
Proof.
  intros G.
  set (g := fun j l => vdot (col3 b0 b1 b2 j) (col3 b0 b1 b2 l) - kron j l).
  assert (Hg : forall j l, (j < 3)%nat -> (l < 3)%nat -> Rabs (g j l) <= e) by (intros; apply G; assumption).
  replace (vdot (lin x b0 b1 b2) (lin y b0 b1 b2) - vdot x y) with
    ((g 0%nat 0%nat * v0 y + g 0%nat 1%nat * v1 y + g 0%nat 2%nat * v2 y) * v0 x +
     (g 1%nat 0%nat * v0 y + g 1%nat 1%nat * v1 y + g 1%nat 2%nat * v2 y) * v1 x +
     (g 2%nat 0%nat * v0 y + g 2%nat 1%nat * v1 y + g 2%nat 2%nat * v2 y) * v2 x)
    by (unfold g, lin, vdot, kron; simpl; ring).
  assert (I : forall j, (j < 3)%nat -> Rabs (g j 0%nat * v0 y + g j 1%nat * v1 y + g j 2%nat * v2 y) <= e * vnorm1 y).
  { intros j Hj. apply K3; apply Hg; lia. }
  replace (e * (vnorm1 x * vnorm1 y)) with ((e * vnorm1 y) * vnorm1 x) by ring.
  apply K3; apply I; lia.
Qed.

(* ---- The rounded product ---- *)
(* One entry of Eigen's product, the three products' sum rounded in any order
   (a product commutes exactly: fl (a b) = fl (b a)). *)
Definition dot3_any (m : R) (r a : V) :=
  m = dot3 (v0 r) (v1 r) (v2 r) (v0 a) (v1 a) (v2 a) \/ m = dot3 (v0 r) (v2 r) (v1 r) (v0 a) (v2 a) (v1 a) \/
  m = dot3 (v1 r) (v0 r) (v2 r) (v1 a) (v0 a) (v2 a) \/ m = dot3 (v1 r) (v2 r) (v0 r) (v1 a) (v2 a) (v0 a) \/
  m = dot3 (v2 r) (v0 r) (v1 r) (v2 a) (v0 a) (v1 a) \/ m = dot3 (v2 r) (v1 r) (v0 r) (v2 a) (v1 a) (v0 a).

Lemma dot3_any_err m r a : dot3_any m r a ->
  Rabs (m - vdot r a) <= 302 / 100 * u * (Rabs (v0 r * v0 a) + Rabs (v1 r * v1 a) + Rabs (v2 r * v2 a)) + 502 / 100 * eta.
Proof.
  unfold vdot.
  intros [-> | [-> | [-> | [-> | [-> | ->]]]]];
    match goal with |- Rabs (dot3 ?a0 ?a1 ?a2 ?b0 ?b1 ?b2 - _) <= _ =>
      pose proof (dot3_err a0 a1 a2 b0 b1 b2) as E; cbv zeta in E end;
    match type of E with Rabs (?d - ?s) <= ?B =>
      match goal with |- Rabs (_ - ?s') <= ?B' =>
        replace s' with s by ring; replace B' with B by ring; exact E end end.
Qed.

(* Computed vectors m, n within dl of p, q per coordinate. *)
Lemma round_gram dl p q m n :
  Rabs (v0 m - v0 p) <= dl -> Rabs (v1 m - v1 p) <= dl -> Rabs (v2 m - v2 p) <= dl ->
  Rabs (v0 n - v0 q) <= dl -> Rabs (v1 n - v1 q) <= dl -> Rabs (v2 n - v2 q) <= dl ->
  Rabs (vdot m n - vdot p q) <= dl * (vnorm1 p + vnorm1 q) + 3 * (dl * dl).
Proof.
  intros M0 M1 M2 N0 N1 N2.
  replace (vdot m n - vdot p q) with
    (((v0 m - v0 p) * v0 q + (v1 m - v1 p) * v1 q + (v2 m - v2 p) * v2 q) +
     ((v0 n - v0 q) * v0 p + (v1 n - v1 q) * v1 p + (v2 n - v2 q) * v2 p) +
     ((v0 m - v0 p) * (v0 n - v0 q) + (v1 m - v1 p) * (v1 n - v1 q) + (v2 m - v2 p) * (v2 n - v2 q)))
    by (unfold vdot; ring).
  pose proof (K3 dl _ _ _ (v0 q) (v1 q) (v2 q) M0 M1 M2) as A.
  pose proof (K3 dl _ _ _ (v0 p) (v1 p) (v2 p) N0 N1 N2) as B.
  pose proof (K3 dl _ _ _ (v0 n - v0 q) (v1 n - v1 q) (v2 n - v2 q) M0 M1 M2) as C.
  assert (0 <= dl) by (pose proof (Rabs_pos (v0 m - v0 p)); lra).
  assert (dl * (Rabs (v0 n - v0 q) + Rabs (v1 n - v1 q) + Rabs (v2 n - v2 q)) <= dl * (3 * dl)) by (apply mul_le_l; lra).
  unfold vnorm1.
  eapply Rle_trans; [apply abs_sum_le; [apply abs_sum_le; [exact A | exact B] | exact C]|]. lra.
Qed.

(* The check's last step: a pair whose exact dot is within 78.7 u of d, of
   vectors of squared norm at most 1 + 78.7 u, passes at kObbFrameTolerance. *)
Lemma pass_final m n d : Rabs (vdot m n - d) <= 787 / 10 * u -> vdot m m <= 1 + 787 / 10 * u -> vdot n n <= 1 + 787 / 10 * u ->
  passes m n d.
Proof.
  intros H Hm Hn. unfold passes.
  pose proof (dot3_err (v0 m) (v1 m) (v2 m) (v0 n) (v1 n) (v2 n)) as E. cbv zeta in E. fold (cdot m n) (vdot m n) in E.
  pose proof (prod_abs_le (v0 m) (v0 n)). pose proof (prod_abs_le (v1 m) (v1 n)). pose proof (prod_abs_le (v2 m) (v2 n)).
  destruct u_facts as (Hu & Hu15 & Huu & He & He0).
  unfold vdot in Hm, Hn.
  set (T := Rabs (v0 m * v0 n) + Rabs (v1 m * v1 n) + Rabs (v2 m * v2 n)) in E.
  assert (T <= 1 + 787 / 10 * u) by (unfold T; lra).
  assert (0 <= T) by (unfold T; pose proof (Rabs_pos (v0 m * v0 n)); pose proof (Rabs_pos (v1 m * v1 n));
                      pose proof (Rabs_pos (v2 m * v2 n)); lra).
  assert (u * T <= u * (1 + 787 / 10 * u)) by (apply mul_le_l; lra).
  set (x := cdot m n - d).
  assert (X : Rabs x <= 8174 / 100 * u).
  { unfold x. replace (cdot m n - d) with ((cdot m n - vdot m n) + (vdot m n - d)) by ring.
    eapply Rle_trans; [apply abs_sum_le; [exact E | exact H]|]. lra. }
  pose proof (fl_err x) as F.
  assert (u * Rabs x <= u * (8174 / 100 * u)) by (apply mul_le_l; lra).
  assert (Y : Rabs (fl x) <= 8175 / 100 * u).
  { replace (fl x) with ((fl x - x) + x) by ring. eapply Rle_trans; [apply abs_sum_le; [exact F | exact X]|]. lra. }
  pose proof (fl_lower (/ 100000000000000) ltac:(lra)) as L. fold kObbFrameTolerance in L.
  assert (90 * u <= / 100000000000000) by (unfold u; lra).
  assert (u * / 100000000000000 <= / 1000000000000000 * / 100000000000000) by (apply Rmult_le_compat_r; lra).
  lra.
Qed.

(* ---- The theorem ---- *)
(* covers optimized/gauss6/geometry/bvh.h "inline bool near_orthonormal(const Mat3& m, double tolerance = kObbFrameTolerance)" sha256:c6604e12f978af7d *)
(* covers optimized/gauss6/ccd/motion_bounds.h "PosedObb pose_checked(const Obb& b, bool check_frame) const" sha256:3c631a4b53f4d403 *)
(* covers optimized/gauss6/ccd/motion_bounds.h "void set_rotation(const Mat3& rotation)" sha256:ff21ca623727066b *)
(* covers optimized/gauss6/geometry/bvh.cpp "int build(int index, int begin, int end)" sha256:9b7104992da41868 *)
Theorem posed_frame_check k0 k1 k2 a0 a1 a2 c0 c1 c2 :
  frame_passes kObbRotationTight k0 k1 k2 -> frame_passes kObbAxesTight a0 a1 a2 ->
  (forall i j, (i < 3)%nat -> (j < 3)%nat -> dot3_any (comp (col3 c0 c1 c2 j) i) (row k0 k1 k2 i) (col3 a0 a1 a2 j)) ->
  frame_passes kObbFrameTolerance c0 c1 c2.
Proof.
  intros PR PA HM.
  rewrite rotation_tight_u in PR. rewrite axes_tight_u in PA.
  pose proof (ortho_k 8 _ _ _ ltac:(lra) PR) as OR. pose proof (ortho_k 16 _ _ _ ltac:(lra) PA) as OA.
  destruct u_facts as (Hu & Hu15 & Huu & He & He0).
  set (eR := (8 + 303 / 100) * u) in OR. set (eA := (16 + 303 / 100) * u) in OA.
  assert (HeR : 0 <= eR) by (unfold eR; lra). assert (HeA : 0 <= eA) by (unfold eA; lra).
  assert (eR * eA <= 400 * (u * u)) by (unfold eR, eA; nra).
  pose proof (ortho_cols _ _ _ _ OR) as CR. pose proof (ortho_rows _ _ _ _ OR) as RR.
  pose proof (ortho_cols _ _ _ _ OA) as CA. pose proof (ortho_rows _ _ _ _ OA) as RA.
  assert (CAd : forall j, (j < 3)%nat -> Rabs (vdot (col3 a0 a1 a2 j) (col3 a0 a1 a2 j) - 1) <= eA)
    by (intros j Hj; rewrite <- (kron_refl j); apply CA; assumption).
  assert (RRd : forall i, (i < 3)%nat -> Rabs (vdot (row k0 k1 k2 i) (row k0 k1 k2 i) - 1) <= eR)
    by (intros i Hi; rewrite <- (kron_refl i); apply RR; assumption).
  set (p := fun j => lin (col3 a0 a1 a2 j) k0 k1 k2).
  set (q := fun i => lin (row k0 k1 k2 i) (row a0 a1 a2 0) (row a0 a1 a2 1) (row a0 a1 a2 2)).
  set (P := fun i j => vdot (row k0 k1 k2 i) (col3 a0 a1 a2 j)).
  assert (Pp : forall i j, (i < 3)%nat -> (j < 3)%nat -> comp (p j) i = P i j).
  { intros i j Hi Hj. unfold p, P.
    destruct (idx3 i Hi) as [-> | [-> | ->]]; destruct (idx3 j Hj) as [-> | [-> | ->]]; simpl; unfold vdot; simpl; ring. }
  assert (Pq : forall i j, (i < 3)%nat -> (j < 3)%nat -> comp (q i) j = P i j).
  { intros i j Hi Hj. unfold q, P.
    destruct (idx3 i Hi) as [-> | [-> | ->]]; destruct (idx3 j Hj) as [-> | [-> | ->]]; simpl; unfold vdot; simpl; ring. }
  (* each entry's rounding *)
  assert (D : forall i j, (i < 3)%nat -> (j < 3)%nat -> Rabs (comp (col3 c0 c1 c2 j) i - P i j) <= 3021 / 1000 * u).
  { intros i j Hi Hj. pose proof (dot3_any_err _ _ _ (HM i j Hi Hj)) as E. fold (P i j) in E.
    set (r := row k0 k1 k2 i) in E. set (a := col3 a0 a1 a2 j) in E.
    pose proof (RRd i Hi) as Rr. pose proof (CAd j Hj) as Ra. fold r in Rr. fold a in Ra.
    destruct (abs_both _ _ Rr). destruct (abs_both _ _ Ra).
    pose proof (prod_abs_le (v0 r) (v0 a)). pose proof (prod_abs_le (v1 r) (v1 a)). pose proof (prod_abs_le (v2 r) (v2 a)).
    unfold vdot in *.
    set (T := Rabs (v0 r * v0 a) + Rabs (v1 r * v1 a) + Rabs (v2 r * v2 a)) in E.
    assert (T <= 1 + 20 * u) by (unfold T, eR, eA in *; lra).
    assert (u * T <= u * (1 + 20 * u)) by (apply mul_le_l; lra).
    lra. }
  (* the exact product's Gram matrices *)
  assert (Gp : forall j l, (j < 3)%nat -> (l < 3)%nat -> Rabs (vdot (p j) (p l) - kron j l) <= 682 / 10 * u).
  { intros j l Hj Hl. unfold p.
    pose proof (lin_gram eR k0 k1 k2 (col3 a0 a1 a2 j) (col3 a0 a1 a2 l) CR) as L.
    pose proof (n1_prod eA _ _ (CAd j Hj) (CAd l Hl)) as N.
    assert (eR * (vnorm1 (col3 a0 a1 a2 j) * vnorm1 (col3 a0 a1 a2 l)) <= eR * (3 * (1 + eA))) by (apply mul_le_l; lra).
    pose proof (CA j l Hj Hl) as Cjl.
    replace (vdot (lin (col3 a0 a1 a2 j) k0 k1 k2) (lin (col3 a0 a1 a2 l) k0 k1 k2) - kron j l)
      with ((vdot (lin (col3 a0 a1 a2 j) k0 k1 k2) (lin (col3 a0 a1 a2 l) k0 k1 k2) - vdot (col3 a0 a1 a2 j) (col3 a0 a1 a2 l))
            + (vdot (col3 a0 a1 a2 j) (col3 a0 a1 a2 l) - kron j l)) by ring.
    eapply Rle_trans; [apply abs_sum_le; [exact L | exact Cjl]|]. unfold eR, eA in *. lra. }
  assert (SA : forall j l, (j < 3)%nat -> (l < 3)%nat ->
     Rabs (vdot (col3 (row a0 a1 a2 0) (row a0 a1 a2 1) (row a0 a1 a2 2) j)
                (col3 (row a0 a1 a2 0) (row a0 a1 a2 1) (row a0 a1 a2 2) l) - kron j l) <= eA).
  { intros j l Hj Hl.
    replace (col3 (row a0 a1 a2 0) (row a0 a1 a2 1) (row a0 a1 a2 2) j) with (row a0 a1 a2 j)
      by (destruct (idx3 j Hj) as [-> | [-> | ->]]; reflexivity).
    replace (col3 (row a0 a1 a2 0) (row a0 a1 a2 1) (row a0 a1 a2 2) l) with (row a0 a1 a2 l)
      by (destruct (idx3 l Hl) as [-> | [-> | ->]]; reflexivity).
    apply RA; assumption. }
  assert (Gq : forall i l, (i < 3)%nat -> (l < 3)%nat -> Rabs (vdot (q i) (q l) - kron i l) <= 682 / 10 * u).
  { intros i l Hi Hl. unfold q.
    pose proof (lin_gram eA _ _ _ (row k0 k1 k2 i) (row k0 k1 k2 l) SA) as L.
    pose proof (n1_prod eR _ _ (RRd i Hi) (RRd l Hl)) as N.
    assert (eA * (vnorm1 (row k0 k1 k2 i) * vnorm1 (row k0 k1 k2 l)) <= eA * (3 * (1 + eR))) by (apply mul_le_l; lra).
    pose proof (RR i l Hi Hl) as Ril.
    match goal with |- Rabs (?g - kron i l) <= _ =>
      replace (g - kron i l) with ((g - vdot (row k0 k1 k2 i) (row k0 k1 k2 l)) + (vdot (row k0 k1 k2 i) (row k0 k1 k2 l) - kron i l)) by ring end.
    eapply Rle_trans; [apply abs_sum_le; [exact L | exact Ril]|]. unfold eR, eA in *. lra. }
  (* |p|_1 and |q|_1 under 1.7321 *)
  assert (N1 : forall w, Rabs (vdot w w - 1) <= 682 / 10 * u -> vnorm1 w <= 17321 / 10000).
  { intros w Hw. pose proof (n1_sq w). pose proof (n1_pos w). destruct (abs_both _ _ Hw). nra. }
  (* the rounded product's Gram matrices *)
  assert (Fin : forall m n p' q' d, Rabs (vdot p' q' - d) <= 682 / 10 * u -> vnorm1 p' <= 17321 / 10000 -> vnorm1 q' <= 17321 / 10000 ->
            (forall i, (i < 3)%nat -> Rabs (comp m i - comp p' i) <= 3021 / 1000 * u) ->
            (forall i, (i < 3)%nat -> Rabs (comp n i - comp q' i) <= 3021 / 1000 * u) ->
            Rabs (vdot m n - d) <= 787 / 10 * u).
  { intros m n p' q' d Hd Hp' Hq' Mi Ni.
    pose proof (Mi 0%nat ltac:(lia)) as M0. pose proof (Mi 1%nat ltac:(lia)) as M1. pose proof (Mi 2%nat ltac:(lia)) as M2.
    pose proof (Ni 0%nat ltac:(lia)) as N0. pose proof (Ni 1%nat ltac:(lia)) as N1'. pose proof (Ni 2%nat ltac:(lia)) as N2.
    simpl in M0, M1, M2, N0, N1', N2.
    pose proof (round_gram _ _ _ _ _ M0 M1 M2 N0 N1' N2) as Rg.
    assert (3021 / 1000 * u * (vnorm1 p' + vnorm1 q') <= 3021 / 1000 * u * (2 * (17321 / 10000))) by (apply mul_le_l; lra).
    replace (vdot m n - d) with ((vdot m n - vdot p' q') + (vdot p' q' - d)) by ring.
    eapply Rle_trans; [apply abs_sum_le; [exact Rg | exact Hd]|]. lra. }
  assert (Gc : forall j l, (j < 3)%nat -> (l < 3)%nat -> Rabs (vdot (col3 c0 c1 c2 j) (col3 c0 c1 c2 l) - kron j l) <= 787 / 10 * u).
  { intros j l Hj Hl.
    pose proof (Gp j j Hj Hj) as Pj. pose proof (Gp l l Hl Hl) as Pl. rewrite kron_refl in Pj, Pl.
    apply (Fin _ _ (p j) (p l)); [apply Gp; assumption | apply N1; exact Pj | apply N1; exact Pl | |];
      intros i Hi; rewrite Pp by assumption; apply D; assumption. }
  assert (Gr : forall i l, (i < 3)%nat -> (l < 3)%nat -> Rabs (vdot (row c0 c1 c2 i) (row c0 c1 c2 l) - kron i l) <= 787 / 10 * u).
  { assert (RC : forall i j, (j < 3)%nat -> comp (row c0 c1 c2 i) j = comp (col3 c0 c1 c2 j) i)
      by (intros i' j' Hj'; destruct (idx3 j' Hj') as [-> | [-> | ->]]; reflexivity).
    intros i l Hi Hl.
    pose proof (Gq i i Hi Hi) as Qi. pose proof (Gq l l Hl Hl) as Ql. rewrite kron_refl in Qi, Ql.
    apply (Fin _ _ (q i) (q l)); [apply Gq; assumption | apply N1; exact Qi | apply N1; exact Ql | |];
      intros j Hj; rewrite Pq by assumption; rewrite RC by assumption; apply D; assumption. }
  assert (Pc : forall j l, (j < 3)%nat -> (l < 3)%nat -> passes (col3 c0 c1 c2 j) (col3 c0 c1 c2 l) (kron j l)).
  { intros j l Hj Hl. apply pass_final; [apply Gc; assumption | |];
      [pose proof (Gc j j Hj Hj) as G | pose proof (Gc l l Hl Hl) as G]; rewrite kron_refl in G;
      destruct (abs_both _ _ G); lra. }
  assert (Pr : forall i l, (i < 3)%nat -> (l < 3)%nat -> passes (row c0 c1 c2 i) (row c0 c1 c2 l) (kron i l)).
  { intros i l Hi Hl. apply pass_final; [apply Gr; assumption | |];
      [pose proof (Gr i i Hi Hi) as G | pose proof (Gr l l Hl Hl) as G]; rewrite kron_refl in G;
      destruct (abs_both _ _ G); lra. }
  unfold frame_passes.
  repeat split;
    [ apply (Pc 0%nat 0%nat) | apply (Pc 1%nat 1%nat) | apply (Pc 2%nat 2%nat) | apply (Pc 0%nat 1%nat)
    | apply (Pc 0%nat 2%nat) | apply (Pc 1%nat 2%nat) | apply (Pr 0%nat 0%nat) | apply (Pr 1%nat 1%nat)
    | apply (Pr 2%nat 2%nat) | apply (Pr 0%nat 1%nat) | apply (Pr 0%nat 2%nat) | apply (Pr 1%nat 2%nat) ]; lia.
Qed.
Print Assumptions posed_frame_check.

(* The posed axes' both exact Gram matrices within 2^-46 of the identity: the
   hypothesis `ortho` of obb_separation_face (ObbSeparation.v) and
   obb_separation_cross (ObbCrossAxes.v), for the boxes whose check pose()
   skips. *)
Theorem posed_frame_ortho k0 k1 k2 a0 a1 a2 c0 c1 c2 :
  frame_passes kObbRotationTight k0 k1 k2 -> frame_passes kObbAxesTight a0 a1 a2 ->
  (forall i j, (i < 3)%nat -> (j < 3)%nat -> dot3_any (comp (col3 c0 c1 c2 j) i) (row k0 k1 k2 i) (col3 a0 a1 a2 j)) ->
  ortho (bpow radix2 (-46)) c0 c1 c2.
Proof.
  intros PR PA HM.
  destruct (posed_frame_check _ _ _ _ _ _ _ _ _ PR PA HM) as (P1 & P2 & P3 & P4 & P5 & P6 & P7 & P8 & P9 & P10 & P11 & P12).
  apply frame_check_sound; assumption.
Qed.
Print Assumptions posed_frame_ortho.
