(* closest_point_on_triangle (geometry/distance.cpp) as the code computes it,
   whatever the face's shape: its computed separation from p, |p - q| as the
   callers compute it ((p - q).norm(): contacts.cpp feature_pair, held_beside),
   is at most p's exact distance from each edge of the face plus
   240 u M + 2^-529 (closest_upper) and at least p's exact distance from the
   face less 240 u M + 2^-529 (closest_lower), M the coordinates' magnitude.
   So two faces whose exact closest points of p are one point of an edge they
   share compute separations within generate_contacts' `tie` of each other
   (tie_closest): the premise of ContactTie.v's tie_shared_edge (that each
   face takes that edge's branch) is no longer needed.
   The code: a corner whose two edges' computed dot products point away from
   p (corner_nearest: it is as near p as any point of the face, to
   63 u M + 2^-530); otherwise the nearest, by the computed squared norm, of
   the three edges' points by the edge rule (ContactTie.v edge_rule) and the
   interior's combination when its computed weights are >= 0.
   Same model as Rounding.v (binary64, round to nearest, gradual underflow,
   finite results, no fused multiply-add); u = 2^-53, eta = 2^-1075. *)

From Coq Require Import Reals Psatz List.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances BoxPose ContactApart StopPose ContactTie.
Open Scope R_scope.

(* ---- Points of R^3 ---- *)

Record P3 := mk3 { cx : R; cy : R; cz : R }.

Definition fin (v : P3) := F (cx v) /\ F (cy v) /\ F (cz v).
Definition within M (v : P3) := Rabs (cx v) <= M /\ Rabs (cy v) <= M /\ Rabs (cz v) <= M.
(* |v - w|, exactly *)
Definition pdist (v w : P3) := norm3 (cx v - cx w) (cy v - cy w) (cz v - cz w).
(* the computed |p - q|: (p - q).norm() *)
Definition sep (p q : P3) := sep_c (cx p) (cy p) (cz p) (cx q) (cy q) (cz q).
(* the computed |p - q|^2: (p - q).squaredNorm(), whose root sep is *)
Definition ssq (p q : P3) :=
  fl (fl (fl (fl (cx p - cx q) * fl (cx p - cx q)) + fl (fl (cy p - cy q) * fl (cy p - cy q)))
      + fl (fl (cz p - cz q) * fl (cz p - cz q))).
Lemma sep_ssq p q : sep p q = fl (sqrt (ssq p q)).
Proof. reflexivity. Qed.

(* The points of the face (a, b, c): convex combinations of its corners. *)
Definition in_tri (a b c X : P3) := exists la lb lc, 0 <= la /\ 0 <= lb /\ 0 <= lc /\ la + lb + lc = 1 /\
  cx X = la * cx a + lb * cx b + lc * cx c /\ cy X = la * cy a + lb * cy b + lc * cy c /\
  cz X = la * cz a + lb * cz b + lc * cz c.

Lemma in_tri_bca a b c X : in_tri a b c X -> in_tri b a c X.
Proof. intros (la & lb & lc & H). exists lb, la, lc. lra. Qed.
Lemma in_tri_cab a b c X : in_tri a b c X -> in_tri c a b X.
Proof. intros (la & lb & lc & H). exists lc, la, lb. lra. Qed.

(* (t - s) . (p - r) as the code computes it (rounded differences, Eigen's dot). *)
Definition dotd (s t p r : P3) :=
  dot3 (fl (cx t - cx s)) (fl (cy t - cy s)) (fl (cz t - cz s)) (fl (cx p - cx r)) (fl (cy p - cy r)) (fl (cz p - cz r)).
(* The edge rule's e and -f for the edge from s to t (ContactTie.v edge_e, edge_f). *)
Definition eE (s t p : P3) := edge_e (cx s) (cy s) (cz s) (cx t) (cy t) (cz t) (cx p) (cy p) (cz p).
Definition eF (s t p : P3) := edge_f (cx s) (cy s) (cz s) (cx t) (cy t) (cz t) (cx p) (cy p) (cz p).
Definition rule (s t p q : P3) :=
  edge_rule (eE s t p) (eF s t p) (cx s) (cy s) (cz s) (cx t) (cy t) (cz t) (cx q) (cy q) (cz q).
(* The exact closest point of the segment from s to t to p. *)
Definition segpt (s t p : P3) : P3 :=
  let tau := seg_tau (cx s) (cy s) (cz s) (cx t) (cy t) (cz t) (cx p) (cy p) (cz p) in
  mk3 (cx s + tau * (cx t - cx s)) (cy s + tau * (cy t - cy s)) (cz s + tau * (cz t - cz s)).

(* ---- The code ---- *)

(* The interior's point: d1 .. d6 as the code names them, va, vb, vc >= 0 as
   computed, their sum finite, q = a + ab v + ac w at the computed weights. *)
Definition interior_pt (p a b c q : P3) : Prop :=
  let d1 := dotd a b p a in let d2 := dotd a c p a in let d3 := dotd a b p b in
  let d4 := dotd a c p b in let d5 := dotd a b p c in let d6 := dotd a c p c in
  let va := fl (fl (d3 * d6) - fl (d5 * d4)) in let vb := fl (fl (d5 * d2) - fl (d1 * d6)) in
  let vc := fl (fl (d1 * d4) - fl (d3 * d2)) in
  let S := fl (fl (va + vb) + vc) in let den := fl (/ S) in
  0 <= va /\ 0 <= vb /\ 0 <= vc /\ S < bpow radix2 1024 /\
  cx q = interior_c (cx a) (cx b) (cx c) (fl (vb * den)) (fl (vc * den)) /\
  cy q = interior_c (cy a) (cy b) (cy c) (fl (vb * den)) (fl (vc * den)) /\
  cz q = interior_c (cz a) (cz b) (cz c) (fl (vb * den)) (fl (vc * den)).

(* closest_point_on_triangle(p, a, b, c) returns q: corner a when d1 <= 0 and
   d2 <= 0; corner b when d3 >= 0 (eF a b p = -d3) and eb <= 0; corner c when
   d6 >= 0 and ec >= 0; otherwise one of the edges' points (edge_point) or the
   interior's, no farther by the computed squared norm than each edge's point
   (the code keeps the least, and takes the interior's only when less). *)
Definition closest_c (p a b c q : P3) : Prop :=
  (eE a b p <= 0 /\ eE a c p <= 0 /\ q = a) \/
  (eF a b p <= 0 /\ eE b c p <= 0 /\ q = b) \/
  (eF a c p <= 0 /\ eF b c p <= 0 /\ q = c) \/
  (exists qab qac qbc, rule a b p qab /\ rule a c p qac /\ rule b c p qbc /\
     (q = qab \/ q = qac \/ q = qbc \/ interior_pt p a b c q) /\
     ssq p q <= ssq p qab /\ ssq p q <= ssq p qac /\ ssq p q <= ssq p qbc).

(* ---- The computed separation against the exact distance ---- *)

(* norm3 grows with the magnitudes of its coordinates. *)
Lemma norm3_le_abs w0 w1 w2 d0 d1 d2 :
  Rabs w0 <= Rabs d0 -> Rabs w1 <= Rabs d1 -> Rabs w2 <= Rabs d2 -> norm3 w0 w1 w2 <= norm3 d0 d1 d2.
Proof.
  intros H0 H1 H2. unfold norm3. apply sqrt_le_1_alt.
  rewrite <- (abs_sq w0), <- (abs_sq w1), <- (abs_sq w2), <- (abs_sq d0), <- (abs_sq d1), <- (abs_sq d2).
  pose proof (Rabs_pos w0). pose proof (Rabs_pos w1). pose proof (Rabs_pos w2).
  assert (Rabs w0 * Rabs w0 <= Rabs d0 * Rabs d0) by (apply Rmult_le_compat; lra).
  assert (Rabs w1 * Rabs w1 <= Rabs d1 * Rabs d1) by (apply Rmult_le_compat; lra).
  assert (Rabs w2 * Rabs w2 <= Rabs d2 * Rabs d2) by (apply Rmult_le_compat; lra).
  lra.
Qed.

Lemma norm3_le_scaled k w0 w1 w2 d0 d1 d2 : 0 <= k ->
  Rabs w0 <= k * Rabs d0 -> Rabs w1 <= k * Rabs d1 -> Rabs w2 <= k * Rabs d2 ->
  norm3 w0 w1 w2 <= k * norm3 d0 d1 d2.
Proof.
  intros Hk H0 H1 H2. rewrite <- (Rabs_pos_eq k Hk) at 1. rewrite <- norm3_scale.
  apply norm3_le_abs; rewrite Rabs_mult, (Rabs_pos_eq k Hk); assumption.
Qed.

Lemma norm3_ge_scaled k w0 w1 w2 d0 d1 d2 : 0 <= k ->
  k * Rabs d0 <= Rabs w0 -> k * Rabs d1 <= Rabs w1 -> k * Rabs d2 <= Rabs w2 ->
  k * norm3 d0 d1 d2 <= norm3 w0 w1 w2.
Proof.
  intros Hk H0 H1 H2. rewrite <- (Rabs_pos_eq k Hk) at 1. rewrite <- norm3_scale.
  apply norm3_le_abs; rewrite Rabs_mult, (Rabs_pos_eq k Hk); assumption.
Qed.

(* One rounded difference of doubles: within u of the exact one, relatively. *)
Lemma sub_bounds x y : F x -> F y ->
  Rabs (fl (x - y)) <= (1 + u) * Rabs (x - y) /\ (1 - u) * Rabs (x - y) <= Rabs (fl (x - y)).
Proof.
  intros Fx Fy. pose proof (sub_rel x y Fx Fy) as H. pose proof (Rabs_pos (x - y)).
  set (d := x - y) in *. set (w := fl d) in *.
  pose proof (Rabs_triang (w - d) d) as T1. replace (w - d + d) with w in T1 by ring.
  pose proof (Rabs_triang_inv d w) as T2. rewrite Rabs_minus_sym in T2. lra.
Qed.

(* The computed separation of two doubles' points within 6 u and 2^-535 of
   their exact distance (ContactTie.v norm_c_upper, norm_c_lower). *)
Lemma sep_exact p q : fin p -> fin q ->
  sep p q <= (1 + 6 * u) * pdist p q + bpow radix2 (-535) /\
  (1 - 5 * u) * pdist p q - bpow radix2 (-535) <= sep p q.
Proof.
  intros (Fp0 & Fp1 & Fp2) (Fq0 & Fq1 & Fq2). pose proof u_small.
  destruct (sub_bounds _ _ Fp0 Fq0) as [U0 L0]. destruct (sub_bounds _ _ Fp1 Fq1) as [U1 L1].
  destruct (sub_bounds _ _ Fp2 Fq2) as [U2 L2].
  pose proof (norm3_le_scaled (1 + u) _ _ _ _ _ _ ltac:(lra) U0 U1 U2) as NU.
  pose proof (norm3_ge_scaled (1 - u) _ _ _ _ _ _ ltac:(lra) L0 L1 L2) as NL.
  unfold sep, sep_c, pdist.
  pose proof (norm_c_upper (fl (cx p - cx q)) (fl (cy p - cy q)) (fl (cz p - cz q))) as CU.
  pose proof (norm_c_lower (fl (cx p - cx q)) (fl (cy p - cy q)) (fl (cz p - cz q))) as CL.
  set (d := norm3 (cx p - cx q) (cy p - cy q) (cz p - cz q)) in *.
  set (n := norm3 (fl (cx p - cx q)) (fl (cy p - cy q)) (fl (cz p - cz q))) in *.
  assert (0 <= d) by apply norm3_nonneg.
  assert (0 <= u * d) by nra. assert (u * (u * d) <= / 1000000 * (u * d)) by (apply Rmult_le_compat_r; lra).
  split.
  - assert ((1 + 4 * u) * n <= (1 + 4 * u) * ((1 + u) * d)) by (apply Rmult_le_compat_l; lra). nra.
  - assert ((1 - 4 * u) * ((1 - u) * d) <= (1 - 4 * u) * n) by (apply Rmult_le_compat_l; lra). nra.
Qed.

Lemma pdist_le_4M p q M : within M p -> within M q -> pdist p q <= 4 * M.
Proof.
  intros (A0 & A1 & A2) (B0 & B1 & B2). unfold pdist. replace (4 * M) with (2 * (2 * M)) by ring.
  apply norm3_coords; apply abs_diff2; assumption.
Qed.

Lemma pdist_triangle p q X : pdist p X <= pdist p q + pdist q X.
Proof.
  unfold pdist. pose proof (norm3_triangle (cx p - cx q) (cy p - cy q) (cz p - cz q) (cx q - cx X) (cy q - cy X) (cz q - cz X)) as T.
  replace (cx p - cx q + (cx q - cx X)) with (cx p - cx X) in T by ring.
  replace (cy p - cy q + (cy q - cy X)) with (cy p - cy X) in T by ring.
  replace (cz p - cz q + (cz q - cz X)) with (cz p - cz X) in T by ring. exact T.
Qed.

Lemma in_tri_within a b c X M : within M a -> within M b -> within M c -> in_tri a b c X -> within M X.
Proof.
  intros (A0 & A1 & A2) (B0 & B1 & B2) (C0 & C1 & C2) (la & lb & lc & Ha & Hb & Hc & Hs & E0 & E1 & E2).
  assert (K : forall x y z, Rabs x <= M -> Rabs y <= M -> Rabs z <= M -> Rabs (la * x + lb * y + lc * z) <= M).
  { intros x y z Hx Hy Hz.
    assert (G : forall l v, 0 <= l -> Rabs v <= M -> Rabs (l * v) <= l * M)
      by (intros l v Hl Hv; rewrite Rabs_mult, (Rabs_pos_eq l) by lra; apply Rmult_le_compat_l; lra).
    pose proof (G la x Ha Hx). pose proof (G lb y Hb Hy). pose proof (G lc z Hc Hz).
    pose proof (Rabs_triang (la * x + lb * y) (lc * z)). pose proof (Rabs_triang (la * x) (lb * y)).
    assert (la * M + lb * M + lc * M = M) by (replace (la * M + lb * M + lc * M) with ((la + lb + lc) * M) by ring; rewrite Hs; ring).
    lra. }
  unfold within. rewrite E0, E1, E2. repeat split; apply K; assumption.
Qed.

(* ---- A corner ---- *)

(* The exact dot product of (t - s) and (p - s) is at most the computed one
   plus 31.2 u M |p - s| + 5.02 eta. *)
Lemma eE_exact s t p M : fin s -> fin t -> fin p -> within M s -> within M t ->
  (cx t - cx s) * (cx p - cx s) + (cy t - cy s) * (cy p - cy s) + (cz t - cz s) * (cz p - cz s)
  <= eE s t p + 312 / 10 * u * M * pdist p s + 502 / 100 * eta.
Proof.
  intros (Fs0 & Fs1 & Fs2) (Ft0 & Ft1 & Ft2) (Fp0 & Fp1 & Fp2) (S0 & S1 & S2) (T0 & T1 & T2).
  pose proof u_small.
  set (r := pdist p s).
  assert (H0 : Rabs (cx p - cx s) <= r) by apply coord_le_norm3.
  assert (H1 : Rabs (cy p - cy s) <= r) by apply coord1_le_norm3.
  assert (H2 : Rabs (cz p - cz s) <= r) by apply coord2_le_norm3.
  pose proof (diff_dot (cx s) (cy s) (cz s) (cx t) (cy t) (cz t) (cx p) (cy p) (cz p) (cx s) (cy s) (cz s) r
                Fs0 Fs1 Fs2 Ft0 Ft1 Ft2 Fp0 Fp1 Fp2 Fs0 Fs1 Fs2 H0 H1 H2) as D.
  unfold eE, edge_e. apply Rabs_le_inv in D.
  assert (Hs1 : Rabs (cx t - cx s) + Rabs (cy t - cy s) + Rabs (cz t - cz s) <= 6 * M)
    by (pose proof (abs_diff2 _ _ _ T0 S0); pose proof (abs_diff2 _ _ _ T1 S1); pose proof (abs_diff2 _ _ _ T2 S2); lra).
  assert (0 <= r) by apply norm3_nonneg.
  assert (r * (Rabs (cx t - cx s) + Rabs (cy t - cy s) + Rabs (cz t - cz s)) <= r * (6 * M)) by (apply Rmult_le_compat_l; lra).
  assert (0 <= u) by lra.
  assert (u * (r * (Rabs (cx t - cx s) + Rabs (cy t - cy s) + Rabs (cz t - cz s))) <= u * (r * (6 * M))) by (apply Rmult_le_compat_l; lra).
  nra.
Qed.

(* A corner o whose two edges' computed e = (t - o) . (p - o) are <= 0 is as
   near p as every point X of the face, to 63 u M + 2^-530: |p - X|^2 =
   |p - o|^2 - 2 (ly D1 + lz D2) + |ly (y - o) + lz (z - o)|^2, D1, D2 the
   exact dot products, each <= 31.2 u M |p - o| + 5.02 eta. *)
Theorem corner_nearest o y z p X M : fin o -> fin y -> fin z -> fin p ->
  within M o -> within M y -> within M z -> within M p ->
  eE o y p <= 0 -> eE o z p <= 0 -> in_tri o y z X ->
  pdist p o <= pdist p X + 63 * u * M + bpow radix2 (-530).
Proof.
  intros Fo Fy Fz Fp Mo My Mz Mp E1 E2 (lo & ly & lz & Hlo & Hly & Hlz & Hs & X0 & X1 & X2).
  pose proof u_small. pose proof eta_pos.
  assert (HM : 0 <= M) by (destruct Mo as (A & _); pose proof (Rabs_pos (cx o)); lra).
  pose proof (eE_exact o y p M Fo Fy Fp Mo My) as D1. pose proof (eE_exact o z p M Fo Fz Fp Mo Mz) as D2.
  set (r := pdist p o) in *. set (r' := pdist p X).
  assert (Hr : 0 <= r) by apply norm3_nonneg. assert (Hr' : 0 <= r') by apply norm3_nonneg.
  set (K := 312 / 10 * u * M * r + 502 / 100 * eta) in *.
  assert (HK : 0 <= K) by (unfold K; assert (0 <= u * M * r) by (apply Rmult_le_pos; nra); lra).
  set (D1e := (cx y - cx o) * (cx p - cx o) + (cy y - cy o) * (cy p - cy o) + (cz y - cz o) * (cz p - cz o)) in *.
  set (D2e := (cx z - cx o) * (cx p - cx o) + (cy z - cy o) * (cy p - cy o) + (cz z - cz o) * (cz p - cz o)) in *.
  set (P0 := cx p - cx o). set (P1 := cy p - cy o). set (P2 := cz p - cz o).
  set (V0 := ly * (cx y - cx o) + lz * (cx z - cx o)).
  set (V1 := ly * (cy y - cy o) + lz * (cy z - cy o)).
  set (V2 := ly * (cz y - cz o) + lz * (cz z - cz o)).
  assert (Hr2 : r * r = P0 * P0 + P1 * P1 + P2 * P2) by (unfold r, pdist, norm3; rewrite sqrt_sqrt by apply sq_nonneg3; reflexivity).
  assert (Hr'2 : r' * r' = (P0 - V0) * (P0 - V0) + (P1 - V1) * (P1 - V1) + (P2 - V2) * (P2 - V2)).
  { unfold r', pdist, norm3. rewrite sqrt_sqrt by apply sq_nonneg3.
    rewrite X0, X1, X2. replace lo with (1 - ly - lz) by lra. unfold P0, P1, P2, V0, V1, V2. ring. }
  assert (Hexp : r' * r' = r * r - 2 * (ly * D1e + lz * D2e) + (V0 * V0 + V1 * V1 + V2 * V2))
    by (rewrite Hr'2, Hr2; unfold D1e, D2e, V0, V1, V2, P0, P1, P2; ring).
  assert (D1K : D1e <= K) by (unfold K; lra). assert (D2K : D2e <= K) by (unfold K; lra).
  assert (ly * D1e <= ly * K) by (apply Rmult_le_compat_l; lra).
  assert (lz * D2e <= lz * K) by (apply Rmult_le_compat_l; lra).
  assert (0 <= V0 * V0 + V1 * V1 + V2 * V2) by apply sq_nonneg3.
  assert (HlK : ly * K + lz * K <= K) by nra.
  assert (Hlow : r * r - 2 * K <= r' * r') by lra.
  set (B := 63 * u * M + bpow radix2 (-530)).
  destruct (Rle_lt_dec r (r' + B)) as [Hle|Hgt]; [unfold B in *; lra|].
  exfalso.
  assert (Hb530 : 0 < bpow radix2 (-530)) by apply bpow_gt_0.
  assert (HB : 0 <= B) by (unfold B; assert (0 <= u * M) by nra; lra).
  assert (HrB : r' < r - B) by lra.
  assert (Hsq : r' * r' < (r - B) * (r - B)) by (apply Rmult_le_0_lt_compat; lra).
  assert (HBr : B * B <= B * r) by (apply Rmult_le_compat_l; lra).
  (* B r < 2 K: 63 u M r + 2^-530 r < 62.4 u M r + 10.04 eta *)
  assert (HBK : B * r < 2 * K) by nra.
  assert (HBd : B = 63 * u * M + bpow radix2 (-530)) by reflexivity.
  assert (HKd : K = 312 / 10 * u * M * r + 502 / 100 * eta) by reflexivity.
  assert (Hr530 : bpow radix2 (-530) < r) by (assert (0 <= 63 * u * M) by nra; lra).
  assert (H1060 : 1004 / 100 * eta < bpow radix2 (-530) * bpow radix2 (-530)).
  { rewrite <- bpow_plus. unfold eta. replace (-530 + -530)%Z with (15 + -1075)%Z by lia. rewrite bpow_plus.
    pose proof (bpow_gt_0 radix2 (-1075)). simpl (bpow radix2 15). lra. }
  assert (bpow radix2 (-530) * bpow radix2 (-530) <= bpow radix2 (-530) * r) by (apply Rmult_le_compat_l; lra).
  assert (0 <= u * M * r) by (apply Rmult_le_pos; nra).
  assert (EB : B * r = 63 * (u * M * r) + bpow radix2 (-530) * r) by (unfold B; ring).
  assert (EK : 2 * K = 624 / 10 * (u * M * r) + 1004 / 100 * eta) by (rewrite HKd; lra).
  lra.
Qed.
Print Assumptions corner_nearest.

(* e of the edge from t to s is -f of the edge from s to t: fl(s - t) =
   -fl(t - s), and a dot product with a negated vector is negated exactly. *)
Lemma eE_flip s t p : eE t s p = eF s t p.
Proof.
  unfold eE, eF, edge_e, edge_f, dot3.
  replace (cx s - cx t) with (- (cx t - cx s)) by ring. replace (cy s - cy t) with (- (cy t - cy s)) by ring.
  replace (cz s - cz t) with (- (cz t - cz s)) by ring. rewrite !fl_opp.
  replace (- fl (cx t - cx s) * fl (cx p - cx t)) with (- (fl (cx t - cx s) * fl (cx p - cx t))) by ring.
  replace (- fl (cy t - cy s) * fl (cy p - cy t)) with (- (fl (cy t - cy s) * fl (cy p - cy t))) by ring.
  replace (- fl (cz t - cz s) * fl (cz p - cz t)) with (- (fl (cz t - cz s) * fl (cz p - cz t))) by ring.
  rewrite !fl_opp.
  replace (- fl (fl (cx t - cx s) * fl (cx p - cx t)) + - fl (fl (cy t - cy s) * fl (cy p - cy t)))
    with (- (fl (fl (cx t - cx s) * fl (cx p - cx t)) + fl (fl (cy t - cy s) * fl (cy p - cy t)))) by ring.
  rewrite fl_opp.
  match goal with |- fl (- ?A + - ?B) = _ => replace (- A + - B) with (- (A + B)) by ring end.
  rewrite fl_opp. reflexivity.
Qed.

(* The corner branches' separation: at most every point's exact distance
   plus 87 u M + 2^-529. *)
Lemma corner_sep o y z p X M : fin o -> fin y -> fin z -> fin p ->
  within M o -> within M y -> within M z -> within M p ->
  eE o y p <= 0 -> eE o z p <= 0 -> in_tri o y z X ->
  sep p o <= pdist p X + 87 * u * M + bpow radix2 (-529).
Proof.
  intros Fo Fy Fz Fp Mo My Mz Mp E1 E2 HX. pose proof u_small.
  pose proof (corner_nearest o y z p X M Fo Fy Fz Fp Mo My Mz Mp E1 E2 HX) as C.
  destruct (sep_exact p o Fp Fo) as [S _].
  pose proof (pdist_le_4M p o M Mp Mo).
  assert (HM : 0 <= M) by (destruct Mo as (A & _); pose proof (Rabs_pos (cx o)); lra).
  assert (u * pdist p o <= u * (4 * M)) by (apply Rmult_le_compat_l; lra).
  assert (bpow radix2 (-530) + bpow radix2 (-535) <= bpow radix2 (-529)).
  { replace (-529)%Z with (1 + -530)%Z by lia. replace (-535)%Z with (-5 + -530)%Z by lia. rewrite !bpow_plus.
    pose proof (bpow_gt_0 radix2 (-530)). simpl (bpow radix2 1). simpl (bpow radix2 (-5)). lra. }
  lra.
Qed.

(* ---- The interior's point ---- *)

(* The weights' combination at v + w <= 1 + 8 u is within 16 u M of the face's
   point at the weights scaled to sum at most 1. *)
Lemma scaled_comb a b c v w M : 0 <= v -> 0 <= w -> 1 < v + w -> v + w <= 1 + 8 * u ->
  Rabs a <= M -> Rabs b <= M -> Rabs c <= M ->
  Rabs ((a + v * (b - a) + w * (c - a)) - (v / (v + w) * b + w / (v + w) * c)) <= 16 * u * M.
Proof.
  intros Hv Hw H1 Hs Ma Mb Mc. set (s := v + w) in *.
  assert (E : (a + v * (b - a) + w * (c - a)) - (v / s * b + w / s * c) = (s - 1) / s * (v * (b - a) + w * (c - a)))
    by (unfold s in *; field; lra).
  rewrite E, Rabs_mult. rewrite (Rabs_pos_eq ((s - 1) / s)) by (apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]).
  assert (Dba : Rabs (b - a) <= 2 * M) by (apply abs_diff2; assumption).
  assert (Dca : Rabs (c - a) <= 2 * M) by (apply abs_diff2; assumption).
  assert (HV : Rabs (v * (b - a) + w * (c - a)) <= s * (2 * M)).
  { eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult, (Rabs_pos_eq v), (Rabs_pos_eq w) by lra.
    assert (v * Rabs (b - a) <= v * (2 * M)) by (apply Rmult_le_compat_l; lra).
    assert (w * Rabs (c - a) <= w * (2 * M)) by (apply Rmult_le_compat_l; lra).
    assert (Es : s * (2 * M) = v * (2 * M) + w * (2 * M)) by (unfold s; ring). lra. }
  assert (0 <= (s - 1) / s) by (apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]).
  apply Rle_trans with ((s - 1) / s * (s * (2 * M))); [apply Rmult_le_compat_l; assumption|].
  replace ((s - 1) / s * (s * (2 * M))) with ((s - 1) * (2 * M)) by (field; lra).
  assert (0 <= M) by (pose proof (Rabs_pos a); lra).
  assert ((s - 1) * (2 * M) <= (8 * u) * (2 * M)) by (apply Rmult_le_compat_r; lra). lra.
Qed.

Lemma tri2 x y z e1 e2 : Rabs (x - y) <= e1 -> Rabs (y - z) <= e2 -> Rabs (x - z) <= e1 + e2.
Proof. intros. replace (x - z) with ((x - y) + (y - z)) by ring. eapply Rle_trans; [apply Rabs_triang | lra]. Qed.

(* The interior's computed point (weights v, w >= 0, v + w <= 1 + 8 u:
   ContactApart.v interior_weights) lies within 80 u M + 10 eta of a point of
   the face. *)
Lemma interior_near a b c v w q M : fin a -> fin b -> fin c -> within M a -> within M b -> within M c ->
  0 <= v -> 0 <= w -> v + w <= 1 + 8 * u ->
  cx q = interior_c (cx a) (cx b) (cx c) v w -> cy q = interior_c (cy a) (cy b) (cy c) v w ->
  cz q = interior_c (cz a) (cz b) (cz c) v w ->
  exists X, in_tri a b c X /\ pdist q X <= 80 * u * M + 10 * eta.
Proof.
  intros (Fa0 & Fa1 & Fa2) (Fb0 & Fb1 & Fb2) (Fc0 & Fc1 & Fc2) (A0 & A1 & A2) (B0 & B1 & B2) (C0 & C1 & C2)
    Hv Hw Hs Q0 Q1 Q2. pose proof u_small. pose proof eta_pos.
  pose proof (interior_err _ _ _ v w M Fa0 Fb0 Fc0 Hv Hw Hs A0 B0 C0) as I0.
  pose proof (interior_err _ _ _ v w M Fa1 Fb1 Fc1 Hv Hw Hs A1 B1 C1) as I1.
  pose proof (interior_err _ _ _ v w M Fa2 Fb2 Fc2 Hv Hw Hs A2 B2 C2) as I2.
  rewrite <- Q0 in I0. rewrite <- Q1 in I1. rewrite <- Q2 in I2.
  assert (HM : 0 <= M) by (pose proof (Rabs_pos (cx a)); lra).
  assert (0 <= u * M) by nra.
  destruct (Rle_lt_dec (v + w) 1) as [Hs1|Hs1].
  - exists (mk3 (cx a + v * (cx b - cx a) + w * (cx c - cx a)) (cy a + v * (cy b - cy a) + w * (cy c - cy a))
                (cz a + v * (cz b - cz a) + w * (cz c - cz a))).
    split.
    + exists (1 - v - w), v, w. simpl. repeat split; try lra; ring.
    + unfold pdist. simpl. apply Rle_trans with (2 * (24 * u * M + 5 * eta)); [apply norm3_coords; assumption | lra].
  - set (s := v + w) in *.
    exists (mk3 (v / s * cx b + w / s * cx c) (v / s * cy b + w / s * cy c) (v / s * cz b + w / s * cz c)).
    split.
    + exists 0, (v / s), (w / s). simpl.
      assert (0 <= v / s) by (apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]).
      assert (0 <= w / s) by (apply Rmult_le_pos; [lra | left; apply Rinv_0_lt_compat; lra]).
      assert (v / s + w / s = 1) by (unfold s in *; field; lra).
      repeat split; try lra; ring.
    + pose proof (scaled_comb _ _ _ v w M Hv Hw Hs1 Hs A0 B0 C0) as S0.
      pose proof (scaled_comb _ _ _ v w M Hv Hw Hs1 Hs A1 B1 C1) as S1.
      pose proof (scaled_comb _ _ _ v w M Hv Hw Hs1 Hs A2 B2 C2) as S2.
      fold s in S0, S1, S2.
      unfold pdist. simpl. apply Rle_trans with (2 * (40 * u * M + 5 * eta)); [|lra].
      apply norm3_coords.
      * apply Rle_trans with ((24 * u * M + 5 * eta) + 16 * u * M); [eapply tri2; eassumption | lra].
      * apply Rle_trans with ((24 * u * M + 5 * eta) + 16 * u * M); [eapply tri2; eassumption | lra].
      * apply Rle_trans with ((24 * u * M + 5 * eta) + 16 * u * M); [eapply tri2; eassumption | lra].
Qed.

(* ---- The edges ---- *)

Lemma segpt_in_tri_ab a b c p : in_tri a b c (segpt a b p).
Proof.
  pose proof (clamp01_unit (((cx b - cx a) * (cx p - cx a) + (cy b - cy a) * (cy p - cy a) + (cz b - cz a) * (cz p - cz a)) /
           ((cx b - cx a) * (cx b - cx a) + (cy b - cy a) * (cy b - cy a) + (cz b - cz a) * (cz b - cz a)))) as H.
  unfold segpt, seg_tau. set (t := clamp01 _) in *. exists (1 - t), t, 0. simpl. repeat split; try lra; ring.
Qed.
Lemma segpt_in_tri_ac a b c p : in_tri a b c (segpt a c p).
Proof.
  pose proof (clamp01_unit (((cx c - cx a) * (cx p - cx a) + (cy c - cy a) * (cy p - cy a) + (cz c - cz a) * (cz p - cz a)) /
           ((cx c - cx a) * (cx c - cx a) + (cy c - cy a) * (cy c - cy a) + (cz c - cz a) * (cz c - cz a)))) as H.
  unfold segpt, seg_tau. set (t := clamp01 _) in *. exists (1 - t), 0, t. simpl. repeat split; try lra; ring.
Qed.
Lemma segpt_in_tri_bc a b c p : in_tri a b c (segpt b c p).
Proof.
  pose proof (clamp01_unit (((cx c - cx b) * (cx p - cx b) + (cy c - cy b) * (cy p - cy b) + (cz c - cz b) * (cz p - cz b)) /
           ((cx c - cx b) * (cx c - cx b) + (cy c - cy b) * (cy c - cy b) + (cz c - cz b) * (cz c - cz b)))) as H.
  unfold segpt, seg_tau. set (t := clamp01 _) in *. exists 0, (1 - t), t. simpl. repeat split; try lra; ring.
Qed.

Lemma list9 s t p : fin s -> fin t -> fin p -> forall v, In v [cx s; cy s; cz s; cx t; cy t; cz t; cx p; cy p; cz p] -> F v.
Proof.
  intros (A0 & A1 & A2) (B0 & B1 & B2) (P0 & P1 & P2) v Hv. simpl in Hv.
  repeat (destruct Hv as [<-|Hv]; [assumption|]). destruct Hv.
Qed.
Lemma list9M s t p M : within M s -> within M t -> within M p ->
  forall v, In v [cx s; cy s; cz s; cx t; cy t; cz t; cx p; cy p; cz p] -> Rabs v <= M.
Proof.
  intros (A0 & A1 & A2) (B0 & B1 & B2) (P0 & P1 & P2) v Hv. simpl in Hv.
  repeat (destruct Hv as [<-|Hv]; [assumption|]). destruct Hv.
Qed.

(* An edge rule's point: its separation within 230 u M + 2^-531 of p's exact
   distance from the segment (ContactTie.v edge_rule_separation). *)
Lemma rule_sep s t p q M : fin s -> fin t -> fin p -> within M s -> within M t -> within M p ->
  rule s t p q -> Rabs (sep p q - pdist p (segpt s t p)) <= 230 * u * M + bpow radix2 (-531).
Proof.
  intros Fs Ft Fp Ms Mt Mp Hr.
  exact (edge_rule_separation _ _ _ _ _ _ _ _ _ _ _ _ M (list9 s t p Fs Ft Fp) (list9M s t p M Ms Mt Mp) Hr).
Qed.

Lemma rule_fin s t p q : fin s -> fin t -> rule s t p q -> fin q.
Proof.
  intros (A0 & A1 & A2) (B0 & B1 & B2) Hr. unfold fin.
  destruct Hr as [(_ & -> & -> & ->)|[(_ & -> & -> & ->)|(_ & _ & -> & -> & ->)]];
    unfold point_c; repeat split; try apply F_fl; assumption.
Qed.

(* A computed squared norm no greater gives a computed separation no greater. *)
Lemma sep_mono p q r : ssq p q <= ssq p r -> sep p q <= sep p r.
Proof. intros H. rewrite !sep_ssq. apply fl_le, sqrt_le_1_alt, H. Qed.

(* ---- The theorems ---- *)

Lemma bpow_529_sum : bpow radix2 (-531) <= bpow radix2 (-529) /\ bpow radix2 (-535) <= bpow radix2 (-531).
Proof. split; apply bpow_le; lia. Qed.

(* closest_point_on_triangle's computed separation is at most p's exact
   distance from each of the face's edges plus 240 u M + 2^-529. *)
(* covers optimized/gauss6/geometry/distance.cpp "Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c)" sha256:fdad0635e55c0607 *)
(* covers optimized/gauss6/geometry/distance.cpp "Vec3 edge_point(const Vec3& s, const Vec3& t, const Vec3& st, double e, double f)" sha256:d2f624d780071625 *)
Theorem closest_upper p a b c q M : fin p -> fin a -> fin b -> fin c ->
  within M p -> within M a -> within M b -> within M c -> closest_c p a b c q ->
  sep p q <= pdist p (segpt a b p) + 240 * u * M + bpow radix2 (-529) /\
  sep p q <= pdist p (segpt a c p) + 240 * u * M + bpow radix2 (-529) /\
  sep p q <= pdist p (segpt b c p) + 240 * u * M + bpow radix2 (-529).
Proof.
  intros Fp Fa Fb Fc Mp Ma Mb Mc H. pose proof u_small. pose proof bpow_529_sum.
  assert (HM : 0 <= M) by (destruct Ma as (A & _); pose proof (Rabs_pos (cx a)); lra).
  assert (0 <= u * M) by nra.
  pose proof (segpt_in_tri_ab a b c p). pose proof (segpt_in_tri_ac a b c p). pose proof (segpt_in_tri_bc a b c p).
  destruct H as [(E1 & E2 & ->)|[(E1 & E2 & ->)|[(E1 & E2 & ->)|(qab & qac & qbc & Rab & Rac & Rbc & _ & Sab & Sac & Sbc)]]].
  - pose proof (corner_sep a b c p (segpt a b p) M Fa Fb Fc Fp Ma Mb Mc Mp E1 E2 ltac:(assumption)).
    pose proof (corner_sep a b c p (segpt a c p) M Fa Fb Fc Fp Ma Mb Mc Mp E1 E2 ltac:(assumption)).
    pose proof (corner_sep a b c p (segpt b c p) M Fa Fb Fc Fp Ma Mb Mc Mp E1 E2 ltac:(assumption)).
    repeat split; lra.
  - rewrite <- eE_flip in E1.
    pose proof (corner_sep b a c p (segpt a b p) M Fb Fa Fc Fp Mb Ma Mc Mp E1 E2 ltac:(apply in_tri_bca; assumption)).
    pose proof (corner_sep b a c p (segpt a c p) M Fb Fa Fc Fp Mb Ma Mc Mp E1 E2 ltac:(apply in_tri_bca; assumption)).
    pose proof (corner_sep b a c p (segpt b c p) M Fb Fa Fc Fp Mb Ma Mc Mp E1 E2 ltac:(apply in_tri_bca; assumption)).
    repeat split; lra.
  - rewrite <- eE_flip in E1, E2.
    pose proof (corner_sep c a b p (segpt a b p) M Fc Fa Fb Fp Mc Ma Mb Mp E1 E2 ltac:(apply in_tri_cab; assumption)).
    pose proof (corner_sep c a b p (segpt a c p) M Fc Fa Fb Fp Mc Ma Mb Mp E1 E2 ltac:(apply in_tri_cab; assumption)).
    pose proof (corner_sep c a b p (segpt b c p) M Fc Fa Fb Fp Mc Ma Mb Mp E1 E2 ltac:(apply in_tri_cab; assumption)).
    repeat split; lra.
  - pose proof (sep_mono _ _ _ Sab). pose proof (sep_mono _ _ _ Sac). pose proof (sep_mono _ _ _ Sbc).
    pose proof (rule_sep a b p qab M Fa Fb Fp Ma Mb Mp Rab) as G1.
    pose proof (rule_sep a c p qac M Fa Fc Fp Ma Mc Mp Rac) as G2.
    pose proof (rule_sep b c p qbc M Fb Fc Fp Mb Mc Mp Rbc) as G3.
    apply Rabs_le_inv in G1. apply Rabs_le_inv in G2. apply Rabs_le_inv in G3.
    repeat split; lra.
Qed.
Print Assumptions closest_upper.

(* ... and at least p's exact distance from the face (from some point X of
   it) less 240 u M + 2^-529. *)
Theorem closest_lower p a b c q M : fin p -> fin a -> fin b -> fin c ->
  within M p -> within M a -> within M b -> within M c -> closest_c p a b c q ->
  exists X, in_tri a b c X /\ pdist p X <= sep p q + 240 * u * M + bpow radix2 (-529).
Proof.
  intros Fp Fa Fb Fc Mp Ma Mb Mc H. pose proof u_small. pose proof bpow_529_sum. pose proof eta_pos.
  assert (HM : 0 <= M) by (destruct Ma as (A & _); pose proof (Rabs_pos (cx a)); lra).
  assert (0 <= u * M) by nra.
  (* a point of the face: its separation *)
  assert (Hc : forall o, fin o -> within M o -> in_tri a b c o ->
                 exists X, in_tri a b c X /\ pdist p X <= sep p o + 240 * u * M + bpow radix2 (-529)).
  { intros o Fo Mo Ho. exists o. split; [exact Ho|].
    destruct (sep_exact p o Fp Fo) as [_ S]. pose proof (pdist_le_4M p o M Mp Mo).
    assert (u * pdist p o <= u * (4 * M)) by (apply Rmult_le_compat_l; lra). lra. }
  assert (Ta : in_tri a b c a) by (exists 1, 0, 0; repeat split; try lra; ring).
  assert (Tb : in_tri a b c b) by (exists 0, 1, 0; repeat split; try lra; ring).
  assert (Tc : in_tri a b c c) by (exists 0, 0, 1; repeat split; try lra; ring).
  assert (Hr : forall s t qe, fin s -> fin t -> within M s -> within M t -> rule s t p qe -> in_tri a b c (segpt s t p) ->
                 exists X, in_tri a b c X /\ pdist p X <= sep p qe + 240 * u * M + bpow radix2 (-529)).
  { intros s t qe Fs Ft Ms Mt R T. exists (segpt s t p). split; [exact T|].
    pose proof (rule_sep s t p qe M Fs Ft Fp Ms Mt Mp R) as G. apply Rabs_le_inv in G. lra. }
  destruct H as [(_ & _ & ->)|[(_ & _ & ->)|[(_ & _ & ->)|(qab & qac & qbc & Rab & Rac & Rbc & Hq & _)]]].
  - apply Hc; auto.
  - apply Hc; auto.
  - apply Hc; auto.
  - destruct Hq as [->|[->|[->|Hi]]].
    + apply (Hr a b); auto. apply segpt_in_tri_ab.
    + apply (Hr a c); auto. apply segpt_in_tri_ac.
    + apply (Hr b c); auto. apply segpt_in_tri_bc.
    + (* the interior: within 80 u M + 10 eta of a point of the face *)
      unfold interior_pt in Hi. cbv zeta in Hi.
      destruct Hi as (Ha & Hb & Hc' & HS & Q0 & Q1 & Q2).
      pose proof (interior_weights _ _ _ (F_fl _) (F_fl _) (F_fl _) Ha Hb Hc' HS) as W. cbv zeta in W.
      destruct W as (Hv & Hw & Hvw).
      destruct (interior_near a b c _ _ q M Fa Fb Fc Ma Mb Mc Hv Hw Hvw Q0 Q1 Q2) as (X & HX & Hd).
      exists X. split; [exact HX|].
      assert (Fq : fin q).
      { unfold fin. rewrite Q0, Q1, Q2. unfold interior_c. repeat split; apply F_fl. }
      destruct (sep_exact p q Fp Fq) as [_ S].
      pose proof (pdist_triangle p q X) as T.
      pose proof (in_tri_within a b c X M Ma Mb Mc HX) as MX.
      pose proof (pdist_le_4M p X M Mp MX).
      pose proof (pdist_triangle p X q) as T2.
      assert (pdist X q = pdist q X) by (unfold pdist, norm3; f_equal; ring).
      assert (Hpq : pdist p q <= 4 * M + 80 * u * M + 10 * eta) by lra.
      assert (u * pdist p q <= u * (4 * M + 80 * u * M + 10 * eta)) by (apply Rmult_le_compat_l; lra).
      assert (u * (u * M) <= / 1000000 * (u * M)) by (apply Rmult_le_compat_r; lra).
      assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
      assert (He : 1000 * eta <= bpow radix2 (-535)).
      { unfold eta. replace (-535)%Z with (540 + -1075)%Z by lia. rewrite (bpow_plus _ 540).
        pose proof (bpow_gt_0 radix2 (-1075)).
        assert (1000 <= bpow radix2 540) by (apply Rle_trans with (bpow radix2 10); [simpl; lra | apply bpow_le; lia]).
        nra. }
      assert (bpow radix2 (-535) * 2 <= bpow radix2 (-529)).
      { replace (-529)%Z with (6 + -535)%Z by lia. rewrite (bpow_plus _ 6). pose proof (bpow_gt_0 radix2 (-535)).
        simpl (bpow radix2 6). lra. }
      lra.
Qed.
Print Assumptions closest_lower.

(* ---- Two faces that share an edge ---- *)

Lemma segpt_flip s t p : pdist p (segpt t s p) = pdist p (segpt s t p).
Proof.
  destruct (seg_flip (cx s) (cy s) (cz s) (cx t) (cy t) (cz t) (cx p) (cy p) (cz p)) as (E0 & E1 & E2).
  cbv zeta in E0, E1, E2. unfold pdist, segpt. simpl. rewrite E0, E1, E2. reflexivity.
Qed.

(* (s, t) is an edge of the face (a, b, c), either way round. *)
Definition edge_of (a b c s t : P3) : Prop :=
  (s = a /\ t = b) \/ (s = a /\ t = c) \/ (s = b /\ t = c) \/ (s = b /\ t = a) \/ (s = c /\ t = a) \/ (s = c /\ t = b).

(* held_beside's `reach` (contacts.cpp): a face F = (a, b, c) at computed
   separation sep p q from p and a face G = (a', b', c') that has the edge from
   s to t, where F's exact distance from p is that edge's (every point X of F
   is at least as far from p as the edge's exact closest point: the edge is
   F's and G's shared edge, and p's closest point on F lies on it). Then G's
   computed separation is within fl(sep + tie): sep p r <= sep p q + 480 u M +
   2^-528 (closest_upper for G, closest_lower for F), under `tie` (at least
   9000 u scale and 2^-500). M <= 4 scale + 2^-490 as for ContactTie.v
   tie_shared_edge (argued there, not proved). *)
(* covers optimized/gauss6/contact/contacts.cpp "ContactStatus generate_contacts(const CcdBody* obstacles, int num_obstacles, const CcdBody& god, const Pose& X_WB," sha256:f7318906decf3db7 *)
(* covers optimized/gauss6/contact/contacts.cpp "bool held_beside(const Vec3& p, const Side<AtV>& V, int vf, int vc, const Side<AtW>& W, int face, const Vec3& nF," sha256:ffbaa960d7c4b290 *)
Theorem tie_closest p a b c q a' b' c' r s t M scale :
  fin p -> fin a -> fin b -> fin c -> fin a' -> fin b' -> fin c' ->
  within M p -> within M a -> within M b -> within M c -> within M a' -> within M b' -> within M c' ->
  0 <= scale -> M <= 4 * scale + bpow radix2 (-490) ->
  closest_c p a b c q -> closest_c p a' b' c' r -> edge_of a' b' c' s t ->
  (forall X, in_tri a b c X -> pdist p (segpt s t p) <= pdist p X) ->
  sep p r <= fl (sep p q + tie scale).
Proof.
  intros Fp Fa Fb Fc Fa' Fb' Fc' Mp Ma Mb Mc Ma' Mb' Mc' Hs HMs Hq Hr He Hmin.
  pose proof u_small. pose proof eta_pos.
  destruct (closest_upper p a' b' c' r M Fp Fa' Fb' Fc' Mp Ma' Mb' Mc' Hr) as (U1 & U2 & U3).
  assert (U : sep p r <= pdist p (segpt s t p) + 240 * u * M + bpow radix2 (-529)).
  { destruct He as [(-> & ->)|[(-> & ->)|[(-> & ->)|[(-> & ->)|[(-> & ->)|(-> & ->)]]]]];
      first [assumption | rewrite segpt_flip; assumption]. }
  destruct (closest_lower p a b c q M Fp Fa Fb Fc Mp Ma Mb Mc Hq) as (X & HX & L).
  pose proof (Hmin X HX).
  assert (HM0 : 0 <= M) by (destruct Ma as (A & _); pose proof (Rabs_pos (cx a)); lra).
  assert (Fr : F (sep p r)) by (unfold sep, sep_c, norm_c; apply F_fl).
  apply (tie_covers _ _ M scale Fr Hs HM0 HMs). lra.
Qed.
Print Assumptions tie_closest.
