(* kBoxPoseRounding (optimized/gauss6/numeric/error_allowances.h) at its site,
   posed_body_box (contact/contacts.cpp), which generate_contacts uses as the
   world box of a god body box at a double pose: the box it computes holds
   every double vertex of the body box posed as generate_contacts poses it
   (world(v) = G + R v in doubles). Same model as Rounding.v (binary64, round
   to nearest, gradual underflow, finite results, no fused multiply-add: the
   build targets x86-64 without FMA, so nothing is contracted). Per world coordinate: G the
   pose's coordinate, R0, R1, R2 the row of the double rotation matrix. *)

From Coq Require Import Reals Psatz List.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances.
Open Scope R_scope.

(* allowance kBoxPoseRounding = 1e-12 *)
Definition kBoxPoseRounding := fl (/ 1000000000000).

Lemma u_small : 0 < u < / 1000000.
Proof. unfold u; lra. Qed.

(* X (1 - u)^2 <= Y gives X <= 2 Y and X <= Y + 2 u X. *)
Lemma shrink2 X Y : 0 <= X -> (1 - u) * ((1 - u) * X) <= Y -> X <= 2 * Y /\ X <= Y + 2 * u * X.
Proof.
  intros HX H. pose proof u_small.
  assert (E : (1 - u) * ((1 - u) * X) = X - 2 * u * X + u * (u * X)) by ring.
  assert (0 <= u * X) by (apply Rmult_le_pos; lra).
  assert (u * (u * X) <= / 1000000 * (u * X)) by (apply Rmult_le_compat_r; lra).
  assert (u * X <= / 1000000 * X) by (apply Rmult_le_compat_r; lra).
  assert (0 <= u * (u * X)) by (apply Rmult_le_pos; lra).
  split; lra.
Qed.

(* A vertex's coordinate v in [lo, hi] lies within half + 8 u (|mid| + half) +
   8 eta of the box's computed mid = 0.5 (lo + hi), with half = 0.5 (hi - lo)
   computed (the two sums round, the halvings round where they underflow). *)
Lemma vertex_mid lo hi v : F lo -> F hi -> lo <= v <= hi ->
  let mid := fl (/ 2 * fl (lo + hi)) in let half := fl (/ 2 * fl (hi - lo)) in
  Rabs (v - mid) <= half + 8 * u * (Rabs mid + half) + 8 * eta.
Proof.
  intros Flo Fhi Hv mid half. pose proof u_small as Hu. pose proof eta_pos.
  set (s := fl (lo + hi)). set (d := fl (hi - lo)).
  pose proof (add_rel lo hi Flo Fhi) as Hs. fold s in Hs.
  pose proof (sub_rel hi lo Fhi Flo) as Hd. fold d in Hd. rewrite (Rabs_pos_eq (hi - lo)) in Hd by lra.
  pose proof (fl_err (/ 2 * s)) as Hm. change (fl (/ 2 * s)) with mid in Hm.
  pose proof (fl_err (/ 2 * d)) as Hh. change (fl (/ 2 * d)) with half in Hh.
  assert (Hd0 : 0 <= d) by (apply fl_nonneg; lra).
  rewrite (Rabs_pos_eq (/ 2 * d)) in Hh by lra.
  rewrite Rabs_mult, (Rabs_pos_eq (/ 2)) in Hm by lra.
  (* X = (hi - lo) / 2 <= half (1 + 4 u) + 2 eta *)
  set (X := (hi - lo) / 2).
  assert (HX0 : 0 <= X) by (unfold X; lra).
  assert (HdX : (1 - u) * (2 * X) <= d) by (unfold X; unfold Rabs in Hd; destruct Rcase_abs; lra).
  assert (Hhd : (1 - u) * (/ 2 * d) <= half + eta) by (unfold Rabs in Hh; destruct Rcase_abs; lra).
  assert (HX1 : (1 - u) * ((1 - u) * X) <= half + eta).
  { assert ((1 - u) * ((1 - u) * X) <= (1 - u) * (/ 2 * d)) by (apply mul_le_l; lra). lra. }
  destruct (shrink2 X (half + eta) HX0 HX1) as [HX2 HX3].
  assert (HX4 : u * X <= u * (2 * (half + eta))) by (apply mul_le_l; lra).
  (* Y = |lo + hi| / 2 and |s| / 2 are at most 2.1 (|mid| + eta) *)
  set (Y := Rabs (lo + hi) / 2).
  assert (HY0 : 0 <= Y) by (unfold Y; pose proof (Rabs_pos (lo + hi)); lra).
  assert (Hs1 : (1 - u) * (2 * Y) <= Rabs s).
  { unfold Y. pose proof (Rabs_triang_inv (lo + hi) (lo + hi - s)).
    replace (lo + hi - (lo + hi - s)) with s in H0 by ring. rewrite Rabs_minus_sym in H0. lra. }
  assert (Hs2 : Rabs s <= (1 + u) * (2 * Y)).
  { unfold Y. replace s with ((s - (lo + hi)) + (lo + hi)) by ring.
    eapply Rle_trans; [apply Rabs_triang|]. lra. }
  assert (Hm1 : (1 - u) * (/ 2 * Rabs s) <= Rabs mid + eta).
  { pose proof (Rabs_triang_inv (/ 2 * s) (/ 2 * s - mid)).
    replace (/ 2 * s - (/ 2 * s - mid)) with mid in H0 by ring. rewrite Rabs_minus_sym in H0.
    rewrite Rabs_mult, (Rabs_pos_eq (/ 2)) in H0 by lra. lra. }
  assert (HY1 : (1 - u) * ((1 - u) * Y) <= Rabs mid + eta).
  { assert ((1 - u) * ((1 - u) * Y) <= (1 - u) * (/ 2 * Rabs s)) by (apply mul_le_l; lra). lra. }
  pose proof (Rabs_pos mid). pose proof (Rabs_pos s).
  destruct (shrink2 Y (Rabs mid + eta) HY0 HY1) as [HY2 _].
  assert (HS2 : / 2 * Rabs s <= 21 / 10 * (Rabs mid + eta)).
  { assert (u * (2 * Y) <= u * (2 * (2 * (Rabs mid + eta)))) by (apply mul_le_l; lra).
    assert (u * (Rabs mid + eta) <= / 1000000 * (Rabs mid + eta)) by (apply Rmult_le_compat_r; lra). lra. }
  assert (u * Y <= u * (2 * (Rabs mid + eta))) by (apply mul_le_l; lra).
  assert (u * (/ 2 * Rabs s) <= u * (21 / 10 * (Rabs mid + eta))) by (apply mul_le_l; lra).
  (* the three steps: v to (lo + hi) / 2, to s / 2, to mid *)
  assert (E1 : Rabs (v - (lo + hi) / 2) <= X) by (unfold X; unfold Rabs; destruct Rcase_abs; lra).
  assert (E2 : Rabs ((lo + hi) / 2 - / 2 * s) <= u * Y).
  { unfold Y. replace ((lo + hi) / 2 - / 2 * s) with (/ 2 * ((lo + hi) - s)) by field.
    rewrite Rabs_mult, (Rabs_pos_eq (/ 2)) by lra. rewrite Rabs_minus_sym. lra. }
  replace (v - mid) with ((v - (lo + hi) / 2) + ((lo + hi) / 2 - / 2 * s) + (/ 2 * s - mid)) by ring.
  eapply Rle_trans; [apply Rabs_triang|].
  eapply Rle_trans; [apply Rplus_le_compat; [apply Rabs_triang | rewrite Rabs_minus_sym; exact Hm]|].
  assert (Hh0 : 0 <= half) by (change half with (fl (/ 2 * d)); apply fl_nonneg; lra).
  assert (0 <= u * half) by (apply Rmult_le_pos; lra).
  assert (0 <= u * Rabs mid) by (apply Rmult_le_pos; lra).
  assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (0 <= u * eta) by (apply Rmult_le_pos; lra).
  lra.
Qed.

(* The box's ends, fl(fl(c - h) - slack) and fl(fl(c + h) + slack), hold a
   double x when |x - c| + u (|c| + h) <= h + slack (c - h and c + h round
   within u |c -+ h|; the second roundings move past no double). *)
Lemma box_ends c h x slack : F c -> F h -> F x -> 0 <= h ->
  Rabs (x - c) + u * (Rabs c + h) <= h + slack ->
  fl (fl (c - h) - slack) <= x <= fl (fl (c + h) + slack).
Proof.
  intros Fc Fh Fx Hh H. pose proof u_small.
  pose proof (sub_rel c h Fc Fh) as E1. pose proof (add_rel c h Fc Fh) as E2.
  assert (u * Rabs (c - h) <= u * (Rabs c + h))
    by (apply mul_le_l; [lra | pose proof (Rabs_triang c (- h)); rewrite Rabs_Ropp, (Rabs_pos_eq h) in H1 by lra; exact H1]).
  assert (u * Rabs (c + h) <= u * (Rabs c + h))
    by (apply mul_le_l; [lra | pose proof (Rabs_triang c h); rewrite (Rabs_pos_eq h) in H2 by lra; exact H2]).
  apply Rabs_le_inv in E1. apply Rabs_le_inv in E2.
  pose proof (Rle_abs (x - c)). pose proof (Rle_abs (c - x)). rewrite Rabs_minus_sym in H4.
  split; [apply fl_le_F | apply fl_ge_F]; try assumption; lra.
Qed.

(* A dot product's terms |a_j b_j| of magnitudes. *)
Lemma abs3 a0 a1 a2 b0 b1 b2 :
  Rabs (a0 * b0) + Rabs (a1 * b1) + Rabs (a2 * b2) = Rabs a0 * Rabs b0 + Rabs a1 * Rabs b1 + Rabs a2 * Rabs b2.
Proof. rewrite !Rabs_mult. reflexivity. Qed.

(* One term of the exact difference: |R (v - m)| <= |R| e + 8 u |R| (|m| + e) + 16 eta. *)
Lemma term_bound R v m e : Rabs R <= 2 -> Rabs (v - m) <= e + 8 * u * (Rabs m + e) + 8 * eta ->
  Rabs (R * v - R * m) <= Rabs R * e + 8 * u * (Rabs R * Rabs m + Rabs R * e) + 16 * eta /\
  Rabs R * Rabs v <= Rabs R * Rabs m + (Rabs R * e + 8 * u * (Rabs R * Rabs m + Rabs R * e) + 16 * eta).
Proof.
  intros HR H. pose proof (Rabs_pos R). pose proof eta_pos.
  assert (K : Rabs R * Rabs (v - m) <= Rabs R * (e + 8 * u * (Rabs m + e) + 8 * eta)) by (apply mul_le_l; lra).
  assert (Rabs R * eta <= 2 * eta) by (apply Rmult_le_compat_r; lra).
  assert (Rabs v <= Rabs m + Rabs (v - m))
    by (replace v with (m + (v - m)) at 1 by ring; apply Rabs_triang).
  assert (Rabs R * Rabs v <= Rabs R * (Rabs m + Rabs (v - m))) by (apply mul_le_l; lra).
  replace (R * v - R * m) with (R * (v - m)) by ring. rewrite Rabs_mult.
  split; nra.
Qed.

Lemma dot3_nonneg a0 a1 a2 b0 b1 b2 : 0 <= a0 -> 0 <= a1 -> 0 <= a2 -> 0 <= b0 -> 0 <= b1 -> 0 <= b2 ->
  0 <= dot3 a0 a1 a2 b0 b1 b2.
Proof.
  intros. unfold dot3. apply fl_nonneg. apply Rplus_le_le_0_compat; [apply fl_nonneg, Rplus_le_le_0_compat|];
  apply fl_nonneg; nra.
Qed.

Lemma sum3_abs a0 a1 a2 b0 b1 b2 :
  Rabs (a0 * b0 + a1 * b1 + a2 * b2) <= Rabs a0 * Rabs b0 + Rabs a1 * Rabs b1 + Rabs a2 * Rabs b2.
Proof.
  rewrite <- abs3. pose proof (Rabs_triang (a0 * b0 + a1 * b1) (a2 * b2)).
  pose proof (Rabs_triang (a0 * b0) (a1 * b1)). lra.
Qed.
Lemma one_minus_u z : (1 - u) * z = z - u * z.
Proof. ring. Qed.

(* ---- kBoxPoseRounding ----
   posed_body_box (contact/contacts.cpp), per world coordinate: mid_j =
   0.5 (lo_j + hi_j), half_j = 0.5 (hi_j - lo_j), c = G + R mid, h = |R| half,
   reach = (|G| + |R| |mid|) + h, slack = kBoxPoseRounding reach +
   kUnderflowFloor, the box [(c - h) - slack, (c + h) + slack]; the vertex
   posed as generate_contacts' world(v) does, x = G + R v; each product of a
   row by a vector summed left to right (dot3; any order of the three terms:
   the statement is symmetric in them). Hypotheses: the doubles of the pose
   and the box (R a double matrix with entries at most 2 in magnitude:
   rotation_matrix's, within 30 u of a rotation's, PoseAllowances.v
   pose_rounding), the vertex within the body box (triangle_box and the BVH's
   node boxes are the min / max of their vertices). No magnitude hypothesis:
   the roundings are relative to W = |G| + |R| (|mid| + half), under 23 u W
   + 66 2^-1075 in all, and the slack is at least 8000 u W + 1e-300 / 4;
   the former slack, relative to |c| + h, missed a vertex where G and R mid
   cancel and h is small. *)
(* covers optimized/gauss6/contact/contacts.cpp "Aabb posed_body_box(const Mat3& R, const Mat3& absR, const Vec3& G, const Aabb& box)" sha256:4685d2d3a07ebaab *)
Theorem box_pose_encloses G R0 R1 R2 lo0 lo1 lo2 hi0 hi1 hi2 v0 v1 v2 :
  (forall y, In y [G; R0; R1; R2; lo0; lo1; lo2; hi0; hi1; hi2] -> F y) ->
  Rabs R0 <= 2 -> Rabs R1 <= 2 -> Rabs R2 <= 2 ->
  lo0 <= v0 <= hi0 -> lo1 <= v1 <= hi1 -> lo2 <= v2 <= hi2 ->
  let m0 := fl (/ 2 * fl (lo0 + hi0)) in let m1 := fl (/ 2 * fl (lo1 + hi1)) in
  let m2 := fl (/ 2 * fl (lo2 + hi2)) in
  let e0 := fl (/ 2 * fl (hi0 - lo0)) in let e1 := fl (/ 2 * fl (hi1 - lo1)) in
  let e2 := fl (/ 2 * fl (hi2 - lo2)) in
  let c := fl (G + dot3 R0 R1 R2 m0 m1 m2) in
  let h := dot3 (Rabs R0) (Rabs R1) (Rabs R2) e0 e1 e2 in
  let reach := fl (fl (Rabs G + dot3 (Rabs R0) (Rabs R1) (Rabs R2) (Rabs m0) (Rabs m1) (Rabs m2)) + h) in
  let slack := fl (fl (kBoxPoseRounding * reach) + kUnderflowFloor) in
  let x := fl (G + dot3 R0 R1 R2 v0 v1 v2) in
  fl (fl (c - h) - slack) <= x <= fl (fl (c + h) + slack).
Proof.
  intros HF HR0 HR1 HR2 Hv0 Hv1 Hv2 m0 m1 m2 e0 e1 e2 c h reach slack x.
  pose proof u_small as Hu. pose proof eta_pos.
  finite_of HF G as FG. finite_of HF R0 as FR0. finite_of HF R1 as FR1. finite_of HF R2 as FR2.
  finite_of HF lo0 as Flo0. finite_of HF lo1 as Flo1. finite_of HF lo2 as Flo2.
  finite_of HF hi0 as Fhi0. finite_of HF hi1 as Fhi1. finite_of HF hi2 as Fhi2.
  pose proof (vertex_mid lo0 hi0 v0 Flo0 Fhi0 Hv0) as D0. pose proof (vertex_mid lo1 hi1 v1 Flo1 Fhi1 Hv1) as D1.
  pose proof (vertex_mid lo2 hi2 v2 Flo2 Fhi2 Hv2) as D2. simpl in D0, D1, D2.
  change (fl (/ 2 * fl (lo0 + hi0))) with m0 in D0. change (fl (/ 2 * fl (hi0 - lo0))) with e0 in D0.
  change (fl (/ 2 * fl (lo1 + hi1))) with m1 in D1. change (fl (/ 2 * fl (hi1 - lo1))) with e1 in D1.
  change (fl (/ 2 * fl (lo2 + hi2))) with m2 in D2. change (fl (/ 2 * fl (hi2 - lo2))) with e2 in D2.
  assert (He0 : 0 <= e0) by (apply fl_nonneg; apply Rmult_le_pos; [lra | apply fl_nonneg; lra]).
  assert (He1 : 0 <= e1) by (apply fl_nonneg; apply Rmult_le_pos; [lra | apply fl_nonneg; lra]).
  assert (He2 : 0 <= e2) by (apply fl_nonneg; apply Rmult_le_pos; [lra | apply fl_nonneg; lra]).
  destruct (term_bound R0 v0 m0 e0 HR0 D0) as [T0 V0]. destruct (term_bound R1 v1 m1 e1 HR1 D1) as [T1 V1].
  destruct (term_bound R2 v2 m2 e2 HR2 D2) as [T2 V2].
  set (M := Rabs R0 * Rabs m0 + Rabs R1 * Rabs m1 + Rabs R2 * Rabs m2).
  set (E := Rabs R0 * e0 + Rabs R1 * e1 + Rabs R2 * e2).
  set (V := Rabs R0 * Rabs v0 + Rabs R1 * Rabs v1 + Rabs R2 * Rabs v2).
  pose proof (Rabs_pos R0) as A0. pose proof (Rabs_pos R1) as A1. pose proof (Rabs_pos R2) as A2.
  assert (HM : 0 <= M) by (unfold M; repeat apply Rplus_le_le_0_compat; apply Rmult_le_pos; apply Rabs_pos).
  assert (HE : 0 <= E) by (unfold E; repeat apply Rplus_le_le_0_compat; apply Rmult_le_pos; assumption).
  assert (HV : 0 <= V) by (unfold V; repeat apply Rplus_le_le_0_compat; apply Rmult_le_pos; apply Rabs_pos).
  pose proof (Rabs_pos G) as AG.
  (* the exact difference of the vertex and the centre, and V *)
  assert (X1 : Rabs ((R0 * v0 + R1 * v1 + R2 * v2) - (R0 * m0 + R1 * m1 + R2 * m2)) <= E + 8 * u * (M + E) + 48 * eta).
  { replace ((R0 * v0 + R1 * v1 + R2 * v2) - (R0 * m0 + R1 * m1 + R2 * m2))
      with ((R0 * v0 - R0 * m0) + (R1 * v1 - R1 * m1) + (R2 * v2 - R2 * m2)) by ring.
    eapply Rle_trans; [apply Rabs_triang|].
    pose proof (Rabs_triang (R0 * v0 - R0 * m0) (R1 * v1 - R1 * m1)). unfold M, E. lra. }
  assert (XV : V <= M + E + 8 * u * (M + E) + 48 * eta) by (unfold V, M, E; lra).
  assert (SV : Rabs (R0 * v0 + R1 * v1 + R2 * v2) <= V) by (unfold V; apply sum3_abs).
  assert (SM : Rabs (R0 * m0 + R1 * m1 + R2 * m2) <= M) by (unfold M; apply sum3_abs).
  (* the three dot products *)
  pose proof (dot3_err R0 R1 R2 v0 v1 v2) as Pv. simpl in Pv. rewrite abs3 in Pv. fold V in Pv.
  pose proof (dot3_err R0 R1 R2 m0 m1 m2) as Pm. simpl in Pm. rewrite abs3 in Pm. fold M in Pm.
  pose proof (dot3_err (Rabs R0) (Rabs R1) (Rabs R2) e0 e1 e2) as Ph. simpl in Ph. rewrite abs3 in Ph.
  rewrite !Rabs_Rabsolu, (Rabs_pos_eq e0), (Rabs_pos_eq e1), (Rabs_pos_eq e2) in Ph by lra.
  change (dot3 (Rabs R0) (Rabs R1) (Rabs R2) e0 e1 e2) with h in Ph. fold E in Ph.
  pose proof (dot3_err (Rabs R0) (Rabs R1) (Rabs R2) (Rabs m0) (Rabs m1) (Rabs m2)) as Pa. simpl in Pa.
  rewrite abs3 in Pa. rewrite !Rabs_Rabsolu in Pa. fold M in Pa.
  assert (Hh : 0 <= h) by (apply dot3_nonneg; try apply Rabs_pos; lra).
  set (PV := dot3 R0 R1 R2 v0 v1 v2) in *. set (PM := dot3 R0 R1 R2 m0 m1 m2) in *.
  set (PA := dot3 (Rabs R0) (Rabs R1) (Rabs R2) (Rabs m0) (Rabs m1) (Rabs m2)) in *.
  assert (HPA : 0 <= PA) by (apply dot3_nonneg; apply Rabs_pos).
  (* the sums with G *)
  pose proof (add_rel G PV FG (F_fl _)) as Gv. change (fl (G + PV)) with x in Gv.
  pose proof (add_rel G PM FG (F_fl _)) as Gm. change (fl (G + PM)) with c in Gm.
  assert (BV : Rabs (G + PV) <= Rabs G + V + (302 / 100 * u * V + 502 / 100 * eta)).
  { replace (G + PV) with (G + (PV - (R0 * v0 + R1 * v1 + R2 * v2)) + (R0 * v0 + R1 * v1 + R2 * v2)) by ring.
    pose proof (Rabs_triang (G + (PV - (R0 * v0 + R1 * v1 + R2 * v2))) (R0 * v0 + R1 * v1 + R2 * v2)).
    pose proof (Rabs_triang G (PV - (R0 * v0 + R1 * v1 + R2 * v2))). lra. }
  assert (BM : Rabs (G + PM) <= Rabs G + M + (302 / 100 * u * M + 502 / 100 * eta)).
  { replace (G + PM) with (G + (PM - (R0 * m0 + R1 * m1 + R2 * m2)) + (R0 * m0 + R1 * m1 + R2 * m2)) by ring.
    pose proof (Rabs_triang (G + (PM - (R0 * m0 + R1 * m1 + R2 * m2))) (R0 * m0 + R1 * m1 + R2 * m2)).
    pose proof (Rabs_triang G (PM - (R0 * m0 + R1 * m1 + R2 * m2))). lra. }
  assert (UGv : u * Rabs (G + PV) <= u * (Rabs G + V + (302 / 100 * u * V + 502 / 100 * eta))) by (apply mul_le_l; lra).
  assert (UGm : u * Rabs (G + PM) <= u * (Rabs G + M + (302 / 100 * u * M + 502 / 100 * eta))) by (apply mul_le_l; lra).
  apply Rabs_le_inv in Pv. apply Rabs_le_inv in Pm. apply Rabs_le_inv in Ph. apply Rabs_le_inv in Pa.
  apply Rabs_le_inv in X1. apply Rabs_le_inv in Gv. apply Rabs_le_inv in Gm.
  assert (u * V <= u * (M + E + 8 * u * (M + E) + 48 * eta)) by (apply mul_le_l; lra).
  assert (0 <= u * M) by (apply Rmult_le_pos; lra). assert (0 <= u * E) by (apply Rmult_le_pos; lra).
  assert (0 <= u * V) by (apply Rmult_le_pos; lra).
  assert (0 <= u * eta) by (apply Rmult_le_pos; lra).
  assert (u * (u * M) <= / 1000000 * (u * M)) by (apply Rmult_le_compat_r; lra).
  assert (u * (u * E) <= / 1000000 * (u * E)) by (apply Rmult_le_compat_r; lra).
  assert (u * (u * V) <= / 1000000 * (u * V)) by (apply Rmult_le_compat_r; lra).
  assert (u * (u * eta) <= / 1000000 * (u * eta)) by (apply Rmult_le_compat_r; lra).
  assert (u * eta <= / 1000000 * eta) by (apply Rmult_le_compat_r; lra).
  assert (u * M <= / 1000000 * M) by (apply Rmult_le_compat_r; lra).
  assert (u * E <= / 1000000 * E) by (apply Rmult_le_compat_r; lra).
  assert (0 <= u * Rabs G) by (apply Rmult_le_pos; lra).
  assert (u * Rabs G <= / 1000000 * Rabs G) by (apply Rmult_le_compat_r; lra).
  (* |x - c| <= h + 21 u W + 65 eta, W = |G| + M + E *)
  assert (XC : Rabs (x - c) <= h + 21 * u * (Rabs G + M + E) + 65 * eta).
  { apply Rabs_le. split; lra. }
  (* u (|c| + h) *)
  assert (CH : u * (Rabs c + h) <= 11 / 10 * u * (Rabs G + M + E) + eta).
  { pose proof (Rabs_le_inv G _ (Rle_refl _)) as GG. pose proof (Rabs_le_inv _ _ SM) as SM'.
    assert (Rabs c <= 101 / 100 * (Rabs G + M) + 6 * eta) by (apply Rabs_le; split; lra).
    assert (h <= 101 / 100 * E + 6 * eta) by lra.
    assert (u * (Rabs c + h) <= u * (101 / 100 * (Rabs G + M) + 6 * eta + (101 / 100 * E + 6 * eta))) by (apply mul_le_l; lra).
    lra. }
  (* the slack: reach >= 0.9 W - 11 eta *)
  assert (FPA : F PA) by apply F_fl. assert (Fh : F h) by apply F_fl.
  assert (FaG : F (Rabs G)) by (apply generic_format_abs; exact FG).
  pose proof (sum_lower (Rabs G) PA FaG FPA AG HPA) as S1.
  assert (HGA : 0 <= fl (Rabs G + PA)) by (apply fl_nonneg; lra).
  pose proof (sum_lower _ h (F_fl _) Fh HGA Hh) as S2. change (fl (fl (Rabs G + PA) + h)) with reach in S2.
  rewrite one_minus_u in S1 by lra. rewrite one_minus_u in S2 by lra.
  assert (Zs1 : u * (Rabs G + PA) <= / 1000000 * (Rabs G + PA)) by (apply Rmult_le_compat_r; lra).
  assert (Zs2 : u * (fl (Rabs G + PA) + h) <= / 1000000 * (fl (Rabs G + PA) + h)) by (apply Rmult_le_compat_r; lra).
  assert (Q1 : 999999 / 1000000 * (Rabs G + PA) <= fl (Rabs G + PA)) by lra.
  assert (Q2 : 999999 / 1000000 * (fl (Rabs G + PA) + h) <= reach) by lra.
  assert (Q3 : 99 / 100 * M - 6 * eta <= PA) by (unfold M in *; lra).
  assert (Q4 : 99 / 100 * E - 6 * eta <= h) by (unfold E in *; lra).
  assert (RW : 9 / 10 * (Rabs G + M + E) - 11 * eta <= reach) by lra.
  assert (Hk : (1 - u) * / 1000000000000 - eta <= kBoxPoseRounding) by (apply fl_lower; lra).
  assert (Hsmall : 100 * eta <= / IZR (Z.pow 10 300) * / 2).
  { pose proof eta_small. assert (bpow radix2 (-1022) <= / IZR (Z.pow 10 300) * / 20000) by (simpl; lra). lra. }
  assert (Htiny : / IZR (Z.pow 10 300) <= / 1000000000000000000000000) by (simpl; lra).
  assert (Hk1 : kBoxPoseRounding <= 1).
  { unfold kBoxPoseRounding. pose proof (fl_err (/ 1000000000000)) as K. apply Rabs_le_inv in K.
    rewrite (Rabs_pos_eq (/ 1000000000000)) in K by lra. lra. }
  assert (Hk9 : 9000 * u <= kBoxPoseRounding) by (unfold u in *; lra).
  assert (Hk0 : 0 <= kBoxPoseRounding) by (unfold u in *; lra).
  assert (Hr : 0 <= reach) by (apply fl_nonneg; lra).
  assert (Hkr : 0 <= kBoxPoseRounding * reach) by (apply Rmult_le_pos; assumption).
  pose proof (fl_lower (kBoxPoseRounding * reach) Hkr) as S3. rewrite one_minus_u in S3 by lra.
  assert (Hf : (1 - u) * / IZR (Z.pow 10 300) - eta <= kUnderflowFloor)
    by (apply fl_lower; apply Rlt_le, Rinv_0_lt_compat; apply IZR_lt; reflexivity).
  assert (Hf0 : 0 <= kUnderflowFloor) by (apply fl_nonneg; apply Rlt_le, Rinv_0_lt_compat; apply IZR_lt; reflexivity).
  assert (Hkf : 0 <= fl (kBoxPoseRounding * reach)) by (apply fl_nonneg; assumption).
  pose proof (sum_lower (fl (kBoxPoseRounding * reach)) kUnderflowFloor (F_fl _) (F_fl _) Hkf Hf0) as S4.
  change (fl (fl (kBoxPoseRounding * reach) + kUnderflowFloor)) with slack in S4.
  rewrite one_minus_u in S4 by lra.
  assert (W0 : 0 <= Rabs G + M + E) by lra.
  assert (K1 : kBoxPoseRounding * (9 / 10 * (Rabs G + M + E) - 11 * eta) <= kBoxPoseRounding * reach)
    by (apply mul_le_l; lra).
  assert (K2 : 9000 * u * (Rabs G + M + E) <= kBoxPoseRounding * (Rabs G + M + E))
    by (apply Rmult_le_compat_r; lra).
  assert (K3 : kBoxPoseRounding * eta <= eta) by (rewrite <- (Rmult_1_l eta) at 2; apply Rmult_le_compat_r; lra).
  assert (K4 : u * (kBoxPoseRounding * reach) <= / 1000000 * (kBoxPoseRounding * reach)) by (apply Rmult_le_compat_r; lra).
  assert (K5 : u * (fl (kBoxPoseRounding * reach) + kUnderflowFloor) <= / 1000000 * (fl (kBoxPoseRounding * reach) + kUnderflowFloor))
    by (apply Rmult_le_compat_r; lra).
  assert (K6 : u * / IZR (Z.pow 10 300) <= / 1000000 * / IZR (Z.pow 10 300))
    by (apply Rmult_le_compat_r; [apply Rlt_le, Rinv_0_lt_compat; apply IZR_lt; reflexivity | lra]).
  set (TEN := / IZR (Z.pow 10 300)) in *.
  assert (L1 : 8100 * u * (Rabs G + M + E) - 11 * eta <= kBoxPoseRounding * reach) by lra.
  assert (L2 : 999999 / 1000000 * (kBoxPoseRounding * reach) - eta <= fl (kBoxPoseRounding * reach)) by lra.
  assert (L3 : 999999 / 1000000 * TEN - eta <= kUnderflowFloor) by lra.
  assert (L4 : 999999 / 1000000 * (fl (kBoxPoseRounding * reach) + kUnderflowFloor) <= slack) by lra.
  assert (SL : 8000 * u * (Rabs G + M + E) + TEN * / 4 <= slack) by lra.
  apply box_ends; try apply F_fl; try lra.
Qed.

Print Assumptions box_pose_encloses.
