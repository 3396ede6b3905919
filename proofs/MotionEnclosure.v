(* The enclosure of the Cayley motion by enclose_motion
   (optimized/gauss6/ccd/motion.cpp), proved in Flocq: for every u of the
   parameter interval the code is given, the exact motion's position
   p(u) = p0 + u dp and rotation R(u) = C(u g) R0 (Cayley.v's algebra,
   METHOD.md section 4) lie in the computed MotionEnclosure, each operation
   being Rounding.v's outward-rounded interval operation, in the code's order;
   and every entry of R(u) lies within R_rad of R_mid, the form swept_box
   takes (ObbAllowances.v `swept_box_encloses`), so that the swept box holds
   every pose of the exact motion over the sub-interval
   (`swept_box_motion`). Same model as Rounding.v (finite results, gradual
   underflow).

   The code's algebra: C(u g) = I + alpha(u) [g]x + beta(u) [g]x^2 with
   alpha = 2u / (1 + u^2 s), beta = 2u^2 / (1 + u^2 s), s = |g|^2. beta
   increases with u >= 0 and alpha increases while u^2 s <= 1 and decreases
   after it, so over [u0, u1] each lies between its values at the ends, but
   for alpha's maximum 1 / sqrt(s) inside, which the code caps by
   min(2 u1, 1 / sqrt(s_lo)) (alpha <= 2u and alpha <= 1 / sqrt(s)). R(u)
   is a rotation (Cayley.v `cayley_orthogonal`, R0 one), so each entry is in
   [-1, 1]: the code's clamp keeps it. *)

From Coq Require Import Reals Psatz List Arith.
Import ListNotations.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances Cayley ObbAllowances.
Open Scope R_scope.

(* ---- next_up and next_down move a value by little: the bounds that show
   the divisors' lower ends positive. ---- *)
Lemma abs_le_hi x y e : Rabs (x - y) <= e -> x <= y + e.
Proof. intros H; pose proof (Rle_abs (x - y)); lra. Qed.

Lemma next_up_le r : next_up r <= r + 4 * u * Rabs r + 2 * kTiny.
Proof.
  unfold next_up, widening.
  assert (HU : kUlp = 2 * u) by (unfold kUlp, u; simpl; lra).
  rewrite HU. assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  pose proof eta_pos as He.
  assert (Hek : 1000 * eta <= kTiny).
  { unfold eta, kTiny. apply Rle_trans with (bpow radix2 10 * bpow radix2 (-1075)).
    - apply Rmult_le_compat_r; [apply bpow_ge_0 | simpl; lra].
    - rewrite <- bpow_plus. apply bpow_le. lia. }
  assert (Hk : 0 < kTiny) by apply bpow_gt_0.
  pose proof (Rabs_pos r) as Hr. set (X := Rabs r) in *.
  set (c := 1 + u).
  assert (Hc : 1 <= c <= 1 + / 1000000) by (unfold c; lra).
  set (z := X * (2 * u)).
  assert (Hz : 0 <= z) by (unfold z; apply Rmult_le_pos; lra).
  set (a := fl z).
  assert (Ha1 : a <= c * z + eta) by (apply fl_upper; exact Hz).
  assert (Ha0 : 0 <= a) by (apply fl_nonneg; exact Hz).
  set (w := fl (a + kTiny)).
  assert (Hw1 : w <= c * (a + kTiny) + eta) by (apply fl_upper; lra).
  assert (Hw0 : 0 <= w) by (apply fl_nonneg; lra).
  assert (Hn : Rabs (fl (r + w) - (r + w)) <= u * Rabs (r + w) + eta) by apply fl_err.
  assert (Hrw : Rabs (r + w) <= X + w)
    by (eapply Rle_trans; [apply Rabs_triang | rewrite (Rabs_pos_eq w) by lra; unfold X; lra]).
  assert (Hn2 : u * Rabs (r + w) <= u * (X + w)) by (apply Rmult_le_compat_l; lra).
  assert (Hn1 : fl (r + w) <= r + w + u * (X + w) + eta) by (pose proof (abs_le_hi _ _ _ Hn); lra).
  (* (1 + u) w <= c (c (c z + eta) + c kTiny) + c eta *)
  assert (W1 : c * w <= c * (c * (a + kTiny) + eta)) by (apply Rmult_le_compat_l; lra).
  assert (W2 : c * (c * a) <= c * (c * (c * z + eta))) by (apply Rmult_le_compat_l; [lra | apply Rmult_le_compat_l; lra]).
  assert (C3 : c * (c * c) <= 3 / 2) by nra.
  assert (Z1 : c * (c * (c * z)) <= 3 / 2 * z)
    by (replace (c * (c * (c * z))) with ((c * (c * c)) * z) by ring; apply Rmult_le_compat_r; lra).
  assert (C2 : c * c <= 2) by nra.
  assert (E1 : c * (c * eta) <= 2 * eta)
    by (replace (c * (c * eta)) with ((c * c) * eta) by ring; apply Rmult_le_compat_r; lra).
  assert (K1 : c * (c * kTiny) <= (1 + / 100000) * kTiny)
    by (replace (c * (c * kTiny)) with ((c * c) * kTiny) by ring; apply Rmult_le_compat_r; nra).
  assert (E2 : c * eta <= 2 * eta) by (apply Rmult_le_compat_r; lra).
  assert (UZ : u * X * 2 = z) by (unfold z; ring).
  assert (Wb : c * w <= 3 / 2 * z + 4 * eta + (1 + / 100000) * kTiny).
  { replace (c * (c * (a + kTiny) + eta)) with (c * (c * a) + c * (c * kTiny) + c * eta) in W1 by ring.
    replace (c * (c * (c * z + eta))) with (c * (c * (c * z)) + c * (c * eta)) in W2 by ring. lra. }
  assert (Hcw : u * w + w = c * w) by (unfold c; ring).
  lra.
Qed.

Lemma next_down_ge r : r - 4 * u * Rabs r - 2 * kTiny <= next_down r.
Proof.
  unfold next_down. pose proof (next_up_le (- r)) as H. rewrite Rabs_Ropp in H. lra.
Qed.

Lemma kTiny_small : 2 * kTiny <= / 1000000000000.
Proof.
  unfold kTiny. apply Rle_trans with (2 * bpow radix2 (-60)).
  - apply Rmult_le_compat_l; [lra | apply bpow_le; lia].
  - simpl. lra.
Qed.

(* A double doubled is a double (2 v in the code is exact). *)
Lemma F_twice v : F v -> F (2 * v).
Proof.
  intros Fv. apply generic_format_FLT.
  destruct (FLT_format_generic radix2 (-1074) 53 v Fv) as [[m e] H1 H2 H3].
  apply (FLT_spec radix2 (-1074) 53 _ (Float radix2 m (e + 1))); simpl in *; try lia.
  rewrite H1. unfold F2R; simpl. rewrite bpow_plus.
  replace (bpow radix2 1) with 2 by (simpl; lra). ring.
Qed.
Lemma fl_twice v : F v -> fl (2 * v) = 2 * v.
Proof. intros; apply fl_F, F_twice; assumption. Qed.

Lemma F_one : F 1.
Proof. replace 1 with (bpow radix2 0) by reflexivity. apply generic_format_bpow. unfold FLT_exp; lia. Qed.
Lemma F_quarter : F (- / 4).
Proof.
  apply F_opp. replace (/ 4) with (bpow radix2 (-2)) by (simpl; lra).
  apply generic_format_bpow. unfold FLT_exp; lia.
Qed.

(* ---- The code's intervals ---- *)
Definition ipoint x := {| lo := x; hi := x |}.

(* enclose_motion's den_at(v) = 1 + v^2 s, alpha_at(v) = 2 v / den_at(v),
   beta_at(v) = 2 v^2 / den_at(v) (sqr(point(v)) * s: Interval products). *)
Definition den_at s v := iadd (ipoint 1) (imul (isqr (ipoint v)) s).
Definition alpha_at s v := idiv (ipoint (fl (2 * v))) (den_at s v).
Definition beta_at s v := idiv (iscale 2 (isqr (ipoint v))) (den_at s v).

(* The exact alpha(u), beta(u) for s = |g|^2. *)
Definition alpha S t := 2 * t / (1 + t * t * S).
Definition beta S t := 2 * (t * t) / (1 + t * t * S).

(* make_ccd_motion's check on the enclosure of |g|^2 (motion.h,
   kMaxGibbsSquared = 1e4, and the lower end at least -1/8): what keeps the
   denominators' lower ends positive. *)
Definition kMaxGibbsSquared := 10000.

Lemma sqr_point_bounds v : 0 <= v <= 1 ->
  - (2 * kTiny) <= lo (isqr (ipoint v)) <= 1 /\ 0 <= hi (isqr (ipoint v)) <= 2.
Proof.
  intros Hv. unfold isqr; simpl. destruct (Rle_dec 0 v) as [_|N]; [|lra]. simpl.
  assert (H0 : 0 <= fl (v * v)) by (apply fl_nonneg; nra).
  assert (H1 : fl (v * v) <= 1) by (apply fl_le_F; [exact F_one | nra]).
  pose proof (next_down_ge (fl (v * v))) as D. pose proof (next_up_le (fl (v * v))) as U.
  pose proof (next_down_le_F _ (F_fl (v * v))). pose proof (next_up_ge_F _ (F_fl (v * v))).
  rewrite Rabs_pos_eq in D, U by lra. pose proof kTiny_small.
  assert (0 < u < / 1000000) by (unfold u; lra). nra.
Qed.

Lemma corner_ge x y : - (2 * kTiny) <= x <= 2 -> - / 8 <= y <= kMaxGibbsSquared -> - / 4 <= x * y.
Proof.
  intros Hx Hy. pose proof kTiny_small. unfold kMaxGibbsSquared in Hy.
  destruct (Rle_or_lt 0 x); destruct (Rle_or_lt 0 y); nra.
Qed.

(* The lower end of den_at(v) is positive. *)
Lemma den_lo_pos s S v : 0 <= v <= 1 -> holds s S -> - / 8 <= lo s -> hi s <= kMaxGibbsSquared ->
  0 < lo (den_at s v).
Proof.
  intros Hv HS Hl Hh. destruct (sqr_point_bounds v Hv) as [[A1 A2] [B1 B2]].
  unfold den_at. remember (isqr (ipoint v)) as A eqn:EA. clear EA.
  unfold iadd, imul, ipoint; cbn [lo hi]. rewrite fl_min4.
  unfold holds in HS.
  set (m := min4 (lo A * lo s) (lo A * hi s) (hi A * lo s) (hi A * hi s)).
  assert (0 < kTiny) by apply bpow_gt_0.
  assert (Hm : - / 4 <= m).
  { unfold m, min4, Rmin. repeat destruct Rle_dec; apply corner_ge; lra. }
  assert (Hf : - / 4 <= fl m) by (apply fl_ge_F; [exact F_quarter | exact Hm]).
  pose proof (next_down_ge (fl m)) as D. pose proof kTiny_small.
  assert (Hu : 0 < u < / 1000000) by (unfold u; lra).
  assert (Hd : - / 4 - / 1000 <= next_down (fl m)) by (unfold Rabs in D; destruct Rcase_abs in D; nra).
  set (z := fl (1 + next_down (fl m))).
  assert (Hz : 7 / 10 <= z).
  { unfold z. pose proof (fl_lower (1 + next_down (fl m)) ltac:(lra)). pose proof eta_small.
    assert (0 < bpow radix2 (-1022) <= 1) by (split; [apply bpow_gt_0 | apply (bpow_le radix2 _ 0); lia]). nra. }
  pose proof (next_down_ge z) as D2. rewrite Rabs_pos_eq in D2 by lra.
  assert (u * z <= / 1000000 * z) by (apply Rmult_le_compat_r; lra). lra.
Qed.

(* ---- alpha and beta over an interval of u ---- *)
Lemma div_le_div x y p q : 0 < p -> 0 < q -> x * q <= y * p -> x / p <= y / q.
Proof.
  intros Hp Hq H. unfold Rdiv.
  replace (x * / p) with ((x * q) * / (p * q)) by (field; lra).
  replace (y * / q) with ((y * p) * / (p * q)) by (field; lra).
  apply Rmult_le_compat_r; [left; apply Rinv_0_lt_compat; nra | exact H].
Qed.

Lemma alpha_mono S a b : 0 <= S -> 0 <= a <= b -> a * b * S <= 1 -> alpha S a <= alpha S b.
Proof. intros HS Hab H. unfold alpha. apply div_le_div; nra. Qed.
Lemma alpha_anti S a b : 0 <= S -> 0 <= a <= b -> 1 <= a * b * S -> alpha S b <= alpha S a.
Proof. intros HS Hab H. unfold alpha. apply div_le_div; nra. Qed.
Lemma alpha_le_twice S t : 0 <= S -> 0 <= t -> alpha S t <= 2 * t.
Proof.
  intros HS Ht. unfold alpha. replace (2 * t) with (2 * t / 1) at 2 by field.
  assert (X : 0 <= t * t * S) by (apply Rmult_le_pos; nra).
  assert (0 <= t * (t * t * S)) by (apply Rmult_le_pos; lra).
  apply div_le_div; lra.
Qed.
Lemma alpha_le_peak S t : 0 < S -> 0 <= t -> alpha S t <= 1 / sqrt S.
Proof.
  intros HS Ht. pose proof (sqrt_lt_R0 S HS) as Q. pose proof (sqrt_sqrt S ltac:(lra)) as E.
  unfold alpha. apply div_le_div; [nra | exact Q |].
  assert (E2 : t * t * S = (t * sqrt S) * (t * sqrt S))
    by (replace S with (sqrt S * sqrt S) at 1 by exact E; ring).
  rewrite E2. set (k := t * sqrt S).
  assert (0 <= (k - 1) * (k - 1)) by apply Rle_0_sqr. replace (2 * t * sqrt S) with (2 * k) by (unfold k; ring).
  lra.
Qed.
Lemma beta_mono S a b : 0 <= S -> 0 <= a <= b -> beta S a <= beta S b.
Proof. intros HS Hab. unfold beta. apply div_le_div; nra. Qed.

(* The ends' enclosures. *)
Lemma alpha_at_encloses s S v : F v -> 0 <= v <= 1 -> holds s S -> - / 8 <= lo s -> hi s <= kMaxGibbsSquared ->
  holds (alpha_at s v) (alpha S v).
Proof.
  intros Fv Hv HS Hl Hh. unfold alpha_at, alpha.
  apply interval_div_positive_encloses; [eapply den_lo_pos; eassumption | |].
  - rewrite fl_twice by exact Fv. apply interval_point_encloses.
  - apply interval_add_encloses; [apply interval_point_encloses|].
    apply interval_mul_encloses; [apply interval_sqr_encloses, interval_point_encloses | exact HS].
Qed.
Lemma beta_at_encloses s S v : 0 <= v <= 1 -> holds s S -> - / 8 <= lo s -> hi s <= kMaxGibbsSquared ->
  holds (beta_at s v) (beta S v).
Proof.
  intros Hv HS Hl Hh. unfold beta_at, beta.
  apply interval_div_positive_encloses; [eapply den_lo_pos; eassumption | |].
  - apply interval_scale_encloses, interval_sqr_encloses, interval_point_encloses.
  - apply interval_add_encloses; [apply interval_point_encloses|].
    apply interval_mul_encloses; [apply interval_sqr_encloses, interval_point_encloses | exact HS].
Qed.

(* enclose_motion's alpha over [u0, u1]: the hull of the ends; when neither
   increasing ((sqr(point(u1)) * s).hi < 1) nor decreasing
   ((sqr(point(u0)) * s).lo > 1), its upper end raised to the cap
   min(2 u1, Upper{1} / sqrt(Lower{s.lo})) (the latter only when s.lo > 0). *)
Definition alpha_enc s u0 u1 :=
  let a := ihull (alpha_at s u0) (alpha_at s u1) in
  if Rlt_dec (hi (imul (isqr (ipoint u1)) s)) 1 then a
  else if Rlt_dec 1 (lo (imul (isqr (ipoint u0)) s)) then a
  else let cap := if Rlt_dec 0 (lo s)
                  then Rmin (fl (2 * u1)) (next_up (fl (1 / next_down (fl (sqrt (lo s))))))
                  else fl (2 * u1) in
       {| lo := lo a; hi := Rmax (hi a) cap |}.
(* beta over [u0, u1]: the hull of the ends. *)
Definition beta_enc s u0 u1 := ihull (beta_at s u0) (beta_at s u1).

Lemma F_pos_ge x : F x -> 0 < x -> bpow radix2 (-1074) <= x.
Proof.
  intros Fx Hx. apply (generic_format_ge_bpow radix2 fexp); [intros e; unfold FLT_exp; lia | exact Hx | exact Fx].
Qed.

Lemma prod_le a b c S : 0 <= a <= c -> 0 <= b <= c -> 0 <= S -> a * b * S <= c * c * S.
Proof. intros. apply Rmult_le_compat_r; [lra|]. apply Rmult_le_compat; lra. Qed.

Lemma alpha_beta_encloses s S u0 u1 t :
  F u0 -> F u1 -> F (lo s) -> 0 <= u0 -> u1 <= 1 -> u0 <= t <= u1 -> holds s S -> 0 <= S ->
  - / 8 <= lo s -> hi s <= kMaxGibbsSquared ->
  holds (alpha_enc s u0 u1) (alpha S t) /\ holds (beta_enc s u0 u1) (beta S t).
Proof.
  intros F0 F1 Fs H0 H1 Ht HS S0 Hl Hh.
  assert (A0 := alpha_at_encloses s S u0 F0 ltac:(lra) HS Hl Hh).
  assert (A1 := alpha_at_encloses s S u1 F1 ltac:(lra) HS Hl Hh).
  split.
  2: { pose proof (beta_at_encloses s S u0 ltac:(lra) HS Hl Hh).
       pose proof (beta_at_encloses s S u1 ltac:(lra) HS Hl Hh).
       pose proof (beta_mono S u0 t S0 ltac:(lra)). pose proof (beta_mono S t u1 S0 ltac:(lra)).
       unfold beta_enc, holds, ihull in *; cbn [lo hi] in *.
       pose proof (Rmin_l (lo (beta_at s u0)) (lo (beta_at s u1))).
       pose proof (Rmax_r (hi (beta_at s u0)) (hi (beta_at s u1))). lra. }
  assert (E1 : holds (imul (isqr (ipoint u1)) s) (u1 * u1 * S))
    by (apply interval_mul_encloses; [apply interval_sqr_encloses, interval_point_encloses | exact HS]).
  assert (E0 : holds (imul (isqr (ipoint u0)) s) (u0 * u0 * S))
    by (apply interval_mul_encloses; [apply interval_sqr_encloses, interval_point_encloses | exact HS]).
  unfold holds in A0, A1.
  pose proof (Rmin_l (lo (alpha_at s u0)) (lo (alpha_at s u1))).
  pose proof (Rmin_r (lo (alpha_at s u0)) (lo (alpha_at s u1))).
  pose proof (Rmax_l (hi (alpha_at s u0)) (hi (alpha_at s u1))).
  pose proof (Rmax_r (hi (alpha_at s u0)) (hi (alpha_at s u1))).
  unfold alpha_enc. destruct (Rlt_dec (hi (imul (isqr (ipoint u1)) s)) 1) as [Inc|Inc].
  { unfold holds in E1.
    pose proof (prod_le u0 t u1 S ltac:(lra) ltac:(lra) S0). pose proof (prod_le t u1 u1 S ltac:(lra) ltac:(lra) S0).
    pose proof (alpha_mono S u0 t S0 ltac:(lra) ltac:(lra)). pose proof (alpha_mono S t u1 S0 ltac:(lra) ltac:(lra)).
    unfold holds, ihull; cbn [lo hi]. lra. }
  destruct (Rlt_dec 1 (lo (imul (isqr (ipoint u0)) s))) as [Dec|Dec].
  { unfold holds in E0.
    pose proof (prod_le u0 u0 u0 S ltac:(lra) ltac:(lra) S0).
    assert (u0 * u0 * S <= u0 * t * S) by (apply Rmult_le_compat_r; [lra | apply Rmult_le_compat_l; lra]).
    assert (u0 * t * S <= t * u1 * S) by (apply Rmult_le_compat_r; [lra | apply Rmult_le_compat; lra]).
    pose proof (alpha_anti S u0 t S0 ltac:(lra) ltac:(lra)). pose proof (alpha_anti S t u1 S0 ltac:(lra) ltac:(lra)).
    unfold holds, ihull; cbn [lo hi]. lra. }
  (* the lower end: alpha is least at an end *)
  assert (L : Rmin (lo (alpha_at s u0)) (lo (alpha_at s u1)) <= alpha S t).
  { destruct (Rle_or_lt (u0 * t * S) 1).
    - pose proof (alpha_mono S u0 t S0 ltac:(lra) H5). lra.
    - assert (u0 * t * S <= t * u1 * S) by (apply Rmult_le_compat_r; [lra | rewrite Rmult_comm; apply Rmult_le_compat_l; lra]).
      assert (H8 : 1 <= t * u1 * S) by lra. pose proof (alpha_anti S t u1 S0 ltac:(lra) H8). lra. }
  (* the upper end: the cap *)
  pose proof (alpha_le_twice S t S0 ltac:(lra)) as T2.
  assert (Cap : alpha S t <= (if Rlt_dec 0 (lo s)
                              then Rmin (fl (2 * u1)) (next_up (fl (1 / next_down (fl (sqrt (lo s))))))
                              else fl (2 * u1))).
  { rewrite fl_twice by exact F1. destruct (Rlt_dec 0 (lo s)) as [P|P]; [|lra].
    apply Rmin_glb; [lra|].
    unfold holds in HS.
    assert (Hb : 0 < next_down (fl (sqrt (lo s)))).
    { pose proof (F_pos_ge _ Fs P) as B.
      assert (Bs : bpow radix2 (-537) <= sqrt (lo s)).
      { rewrite <- sqrt_bpow2. apply sqrt_le_1_alt. replace (2 * -537)%Z with (-1074)%Z by lia. exact B. }
      assert (Bf : bpow radix2 (-537) <= fl (sqrt (lo s)))
        by (apply fl_ge_F; [apply generic_format_bpow; unfold FLT_exp; lia | exact Bs]).
      pose proof (next_down_ge (fl (sqrt (lo s)))) as D.
      rewrite Rabs_pos_eq in D by (pose proof (bpow_gt_0 radix2 (-537)); lra).
      assert (0 < u < / 1000000) by (unfold u; lra).
      assert (2 * kTiny < / 2 * bpow radix2 (-537)).
      { unfold kTiny. replace (2 * bpow radix2 (-600)) with (bpow radix2 (-599)) by
          (replace (-599)%Z with (1 + -600)%Z by lia; rewrite bpow_plus; simpl; lra).
        replace (/ 2 * bpow radix2 (-537)) with (bpow radix2 (-538)) by
          (replace (-537)%Z with (1 + -538)%Z by lia; rewrite bpow_plus; simpl; lra).
        apply bpow_lt. lia. }
      assert (u * fl (sqrt (lo s)) <= / 1000000 * fl (sqrt (lo s)))
        by (apply Rmult_le_compat_r; [pose proof (bpow_gt_0 radix2 (-537)) |]; lra).
      pose proof (bpow_gt_0 radix2 (-537)). lra. }
    eapply Rle_trans; [apply (alpha_le_peak S t ltac:(lra) ltac:(lra))|].
    apply upper_div; [lra|]. split; [exact Hb|].
    apply lower_sqrt; lra. }
  unfold holds, ihull; cbn [lo hi]. pose proof (Rmax_r (Rmax (hi (alpha_at s u0)) (hi (alpha_at s u1)))
    (if Rlt_dec 0 (lo s) then Rmin (fl (2 * u1)) (next_up (fl (1 / next_down (fl (sqrt (lo s)))))) else fl (2 * u1))).
  lra.
Qed.

(* ---- Matrices entry by entry (row i, column j, from 0 as the code
   indexes R[3 i + j]) ---- *)
Definition ent (A : M3) (i j : nat) : R :=
  match i, j with
  | O, O => e11 A | O, S O => e12 A | O, _ => e13 A
  | S O, O => e21 A | S O, S O => e22 A | S O, _ => e23 A
  | _, O => e31 A | _, S O => e32 A | _, _ => e33 A end.
Definition coord (v : V3) (i : nat) : R := match i with O => x1 v | S O => x2 v | _ => x3 v end.

Lemma ent_mmul A B i j :
  ent (mmul A B) i j = ent A i 0 * ent B 0 j + ent A i 1 * ent B 1 j + ent A i 2 * ent B 2 j.
Proof. destruct A, B; destruct i as [|[|i]]; destruct j as [|[|j]]; reflexivity. Qed.

(* C(t g) entry by entry: delta_ij + alpha(t) [g]x_ij + beta(t) ([g]x^2)_ij,
   the diagonal's 1 added last, as the code does. *)
Lemma cayley_entry g t i j : (i < 3)%nat -> (j < 3)%nat ->
  ent (cayley (vscale t g)) i j =
  (let x := alpha (dot g g) t * ent (K g) i j + beta (dot g g) t * ent (mmul (K g) (K g)) i j in
   if Nat.eqb i j then 1 + x else x).
Proof.
  intros Hi Hj.
  assert (E : Dh (vscale t g) = 1 + t * t * dot g g) by (destruct g; unfold Dh, dot, vscale; simpl; ring).
  assert (P0 : 0 < 1 + t * t * dot g g) by (rewrite <- E; apply Dh_pos).
  unfold cayley. rewrite E. unfold alpha, beta. revert P0. generalize (dot g g). intros S P0.
  set (D := 1 + t * t * S). destruct g as [a b c].
  destruct i as [|[|[|i]]]; [| | |lia]; destruct j as [|[|[|j]]]; try lia;
    cbv zeta; cbn [Nat.eqb ent madd mscale mmul K I3 vscale e11 e12 e13 e21 e22 e23 e31 e32 e33 x1 x2 x3];
    unfold Rdiv; ring.
Qed.

(* Every entry of a rotation times a rotation is in [-1, 1]: its column is
   C applied to R0's, of norm 1 (Cayley.v cayley_dot). *)
Definition col (A : M3) (j : nat) := v3 (ent A 0 j) (ent A 1 j) (ent A 2 j).
Lemma col_mmul A B j : col (mmul A B) j = mvec A (col B j).
Proof. destruct A, B; destruct j as [|[|j]]; unfold col, mvec; simpl; apply v3_eq; ring. Qed.
Lemma dot_col A j : dot (col A j) (col A j) = ent (mmul (mtr A) A) j j.
Proof. destruct A; destruct j as [|[|j]]; unfold col, dot, mmul, mtr; simpl; ring. Qed.

Lemma rotation_entry_bound h R0 i j : mmul (mtr R0) R0 = I3 -> (j < 3)%nat ->
  - 1 <= ent (mmul (cayley h) R0) i j <= 1.
Proof.
  intros O Hj.
  assert (N : dot (col (mmul (cayley h) R0) j) (col (mmul (cayley h) R0) j) = 1).
  { rewrite col_mmul, cayley_dot, dot_col, O. destruct j as [|[|[|j]]]; [reflexivity.. | lia]. }
  unfold col, dot in N; cbn [x1 x2 x3] in N.
  set (a := ent (mmul (cayley h) R0) 0 j) in *. set (b := ent (mmul (cayley h) R0) 1 j) in *.
  set (c := ent (mmul (cayley h) R0) 2 j) in *.
  assert (E : ent (mmul (cayley h) R0) i j = a \/ ent (mmul (cayley h) R0) i j = b \/
              ent (mmul (cayley h) R0) i j = c)
    by (destruct i as [|[|[|i]]]; [left | right; left | right; right | right; right]; reflexivity).
  assert (0 <= a * a) by apply Rle_0_sqr. assert (0 <= b * b) by apply Rle_0_sqr.
  assert (0 <= c * c) by apply Rle_0_sqr.
  destruct E as [E|[E|E]]; rewrite E; nra.
Qed.

(* ---- make_ccd_motion's CcdMotion, as intervals: p0, dp, g (index i),
   R0 and K2 = [g]x^2 (row i, column j), g2 = |g|^2 ---- *)
Record IMotion := {
  mp0 : nat -> Interval; mdp : nat -> Interval; mg : nat -> Interval;
  mR0 : nat -> nat -> Interval; mg2 : Interval; mK2 : nat -> nat -> Interval }.

(* enclose_motion's K = {zero, -g[2], g[1], g[2], zero, -g[0], -g[1], g[0], zero}. *)
Definition iK (g : nat -> Interval) (i j : nat) : Interval :=
  match i, j with
  | O, S O => ineg (g 2%nat) | O, S (S O) => g 1%nat
  | S O, O => g 2%nat | S O, S (S O) => ineg (g O)
  | S (S O), O => ineg (g 1%nat) | S (S O), S O => g O
  | _, _ => ipoint 0 end.
(* C[3 i + j] = alpha * K + beta * K2, and Interval::point(1) + that on the diagonal. *)
Definition iC a b m i j :=
  let c := iadd (imul a (iK (mg m) i j)) (imul b (mK2 m i j)) in
  if Nat.eqb i j then iadd (ipoint 1) c else c.
(* e = C[3 i] * R0[j] + C[3 i + 1] * R0[3 + j] + C[3 i + 2] * R0[6 + j]. *)
Definition iRe a b m i j :=
  iadd (iadd (imul (iC a b m i 0) (mR0 m 0 j)) (imul (iC a b m i 1) (mR0 m 1 j))) (imul (iC a b m i 2) (mR0 m 2 j)).
(* r = {max(e.lo, -1), min(e.hi, 1)}; mid = 0.5 r.lo + 0.5 r.hi;
   R_rad = next_up(max(r.hi - mid, mid - r.lo)); R_abs = |mid| (exact). *)
Definition clamp1 I := {| lo := Rmax (lo I) (-1); hi := Rmin (hi I) 1 |}.
Definition rmid I := fl (fl (/ 2 * lo I) + fl (/ 2 * hi I)).
Definition rrad I := next_up (Rmax (fl (hi I - rmid I)) (fl (rmid I - lo I))).
(* p[i] = m.p0[i] + u * m.dp[i] (Interval products and sums). *)
Definition ipos m U i := iadd (mp0 m i) (imul U (mdp m i)).

Lemma iK_encloses mg g i j : (i < 3)%nat -> (j < 3)%nat ->
  (forall k, (k < 3)%nat -> holds (mg k) (coord g k)) -> holds (iK mg i j) (ent (K g) i j).
Proof.
  intros Hi Hj H.
  pose proof (H 0%nat ltac:(lia)) as G0. pose proof (H 1%nat ltac:(lia)) as G1.
  pose proof (H 2%nat ltac:(lia)) as G2.
  destruct g as [a b c]; cbn [coord x1 x2 x3] in G0, G1, G2.
  destruct i as [|[|[|i]]]; [| | |lia]; destruct j as [|[|[|j]]]; try lia;
    cbn [iK ent K e11 e12 e13 e21 e22 e23 e31 e32 e33 x1 x2 x3];
    first [ exact (interval_point_encloses 0) | apply interval_neg_encloses; assumption | assumption ].
Qed.

Lemma coord_pos p0 dp t i : coord (vadd p0 (vscale t dp)) i = coord p0 i + t * coord dp i.
Proof. destruct i as [|[|i]]; reflexivity. Qed.

(* The CcdMotion m holds the exact motion's data: p0, dp, g (index i), R0
   (a rotation) and [g]x^2 (row i, column j), |g|^2. make_ccd_motion_encloses
   proves it of make_ccd_motion's. *)
Definition motion_data m p0 dp g R0 : Prop :=
  (forall i, (i < 3)%nat -> holds (mp0 m i) (coord p0 i) /\ holds (mdp m i) (coord dp i) /\
                            holds (mg m i) (coord g i)) /\
  (forall i j, (i < 3)%nat -> (j < 3)%nat ->
     holds (mR0 m i j) (ent R0 i j) /\ holds (mK2 m i j) (ent (mmul (K g) (K g)) i j)) /\
  holds (mg2 m) (dot g g) /\ mmul (mtr R0) R0 = I3.

(* ---- The theorem ----
   enclose_motion_encloses (motion.cpp, enclose_motion): the exact motion
   p(t) = p0 + t dp, R(t) = C(t g) R0 with R0 a rotation, its CcdMotion m
   enclosing p0, dp, g, R0, |g|^2 and [g]x^2 (make_ccd_motion: each an
   interval operation of Rounding.v on the input doubles), and the parameter
   interval [u0, u1] of doubles in [0, 1]: for every t in it, p_i(t) lies in
   p[i], and R(t)_ij in the clamped R[3 i + j], within R_rad of R_mid.
   Hypotheses on magnitudes: -1/8 <= g2.lo and g2.hi <= kMaxGibbsSquared,
   make_ccd_motion's check (motion.cpp); 0 <= u0 <= u1 <= 1, the callers'
   sub-intervals of the motion's [0, 1]. *)
(* covers optimized/gauss6/ccd/motion.cpp "void enclose_motion(const CcdMotion& m, Interval u, MotionEnclosure* out)" sha256:99ad7aece5205dfe *)
Theorem enclose_motion_encloses m p0 dp g R0 u0 u1 t :
  motion_data m p0 dp g R0 ->
  F (lo (mg2 m)) -> - / 8 <= lo (mg2 m) -> hi (mg2 m) <= kMaxGibbsSquared ->
  F u0 -> F u1 -> 0 <= u0 -> u1 <= 1 -> u0 <= t <= u1 ->
  let a := alpha_enc (mg2 m) u0 u1 in
  let b := beta_enc (mg2 m) u0 u1 in
  let Rt := mmul (cayley (vscale t g)) R0 in
  (forall i, (i < 3)%nat -> holds (ipos m {| lo := u0; hi := u1 |} i) (coord (vadd p0 (vscale t dp)) i)) /\
  (forall i j, (i < 3)%nat -> (j < 3)%nat ->
     let r := clamp1 (iRe a b m i j) in
     holds r (ent Rt i j) /\ Rabs (ent Rt i j - rmid r) <= rrad r /\ 0 <= rrad r).
Proof.
  intros [Hv [HM [Hs O]]] Fs Hl Hh F0 F1 H0 H1 Ht a b Rt. split.
  - intros i Hi. destruct (Hv i Hi) as [A [B _]]. rewrite coord_pos. unfold ipos.
    apply interval_add_encloses; [exact A|].
    apply interval_mul_encloses; [unfold holds; simpl; lra | exact B].
  - intros i j Hi Hj r.
    assert (S0 : 0 <= dot g g) by (unfold dot; nra).
    destruct (alpha_beta_encloses (mg2 m) (dot g g) u0 u1 t F0 F1 Fs H0 H1 Ht Hs S0 Hl Hh) as [Ha Hb].
    fold a b in Ha, Hb.
    assert (HC : forall k, (k < 3)%nat -> holds (iC a b m i k) (ent (cayley (vscale t g)) i k)).
    { intros k Hk. rewrite (cayley_entry g t i k Hi Hk). unfold iC. cbv zeta.
      assert (Hx : holds (iadd (imul a (iK (mg m) i k)) (imul b (mK2 m i k)))
                     (alpha (dot g g) t * ent (K g) i k + beta (dot g g) t * ent (mmul (K g) (K g)) i k)).
      { apply interval_add_encloses; apply interval_mul_encloses; try assumption.
        - apply iK_encloses; try assumption. intros l Hl'. apply (Hv l Hl').
        - apply (HM i k Hi Hk). }
      destruct (Nat.eqb i k); [apply interval_add_encloses; [apply interval_point_encloses|]|]; exact Hx. }
    assert (He : holds (iRe a b m i j) (ent Rt i j)).
    { unfold Rt. rewrite ent_mmul. unfold iRe.
      apply interval_add_encloses; [apply interval_add_encloses|]; apply interval_mul_encloses;
        first [ apply HC; lia | apply (proj1 (HM 0%nat j ltac:(lia) Hj))
              | apply (proj1 (HM 1%nat j ltac:(lia) Hj)) | apply (proj1 (HM 2%nat j ltac:(lia) Hj)) ]. }
    assert (B : - 1 <= ent Rt i j <= 1) by exact (rotation_entry_bound (vscale t g) R0 i j O Hj).
    assert (Hr : holds r (ent Rt i j)).
    { unfold holds in He |- *. unfold r, clamp1; cbn [lo hi].
      split; [apply Rmax_lub | apply Rmin_glb]; lra. }
    split; [exact Hr|].
    exact (half_extent (lo r) (hi r) (rmid r) (ent Rt i j) Hr).
Qed.
Print Assumptions enclose_motion_encloses.

(* ---- make_ccd_motion: the CcdMotion encloses the exact motion of the input
   doubles ---- *)

(* A matrix whose columns are orthonormal has its entries in [-1, 1]. *)
Lemma orth_entry_bound A i j : mmul (mtr A) A = I3 -> (j < 3)%nat -> - 1 <= ent A i j <= 1.
Proof.
  intros O Hj.
  assert (N : dot (col A j) (col A j) = 1)
    by (rewrite dot_col, O; destruct j as [|[|[|j]]]; [reflexivity.. | lia]).
  unfold col, dot in N; cbn [x1 x2 x3] in N.
  set (a := ent A 0 j) in *. set (b := ent A 1 j) in *. set (c := ent A 2 j) in *.
  assert (E : ent A i j = a \/ ent A i j = b \/ ent A i j = c)
    by (destruct i as [|[|[|i]]]; [left | right; left | right; right | right; right]; reflexivity).
  assert (0 <= a * a) by apply Rle_0_sqr. assert (0 <= b * b) by apply Rle_0_sqr.
  assert (0 <= c * c) by apply Rle_0_sqr.
  destruct E as [E|[E|E]]; rewrite E; nra.
Qed.

(* R(q) = N(q) / |q|^2 is a rotation (Cayley.v's rational form). *)
Lemma Rq_orthogonal q : 0 < qn2 q -> mmul (mtr (Rq q)) (Rq q) = I3.
Proof.
  intros P. assert (HN : mmul (mtr (Nq q)) (Nq q) = mscale (qn2 q * qn2 q) I3).
  { destruct q as [w x y z]. unfold Nq, qn2, mmul, mtr, mscale, I3; cbn. apply m3_eq; ring. }
  unfold Rq. rewrite mtr_scale, mmul_scale, HN. unfold mscale, I3; cbn.
  apply m3_eq; field; lra.
Qed.

(* rational_rotation (motion.cpp): n = ww + xx + yy + zz, the nine e[k] as
   Interval sums, differences and scalings of the squares and products, each
   div_positive by n and clamped to [-1, 1]. *)
Definition rr_entry (w x y z : R) (i j : nat) : Interval :=
  let W := ipoint w in let X := ipoint x in let Y := ipoint y in let Z := ipoint z in
  let ww := isqr W in let xx := isqr X in let yy := isqr Y in let zz := isqr Z in
  let xy := imul X Y in let xz := imul X Z in let yz := imul Y Z in
  let wx := imul W X in let wy := imul W Y in let wz := imul W Z in
  match i, j with
  | O, O => isub (isub (iadd ww xx) yy) zz
  | O, S O => iscale 2 (isub xy wz) | O, _ => iscale 2 (iadd xz wy)
  | S O, O => iscale 2 (iadd xy wz) | S O, S O => isub (iadd (isub ww xx) yy) zz
  | S O, _ => iscale 2 (isub yz wx)
  | _, O => iscale 2 (isub xz wy) | _, S O => iscale 2 (iadd yz wx)
  | _, _ => iadd (isub (isub ww xx) yy) zz end.
Definition rr_norm (w x y z : R) :=
  iadd (iadd (iadd (isqr (ipoint w)) (isqr (ipoint x))) (isqr (ipoint y))) (isqr (ipoint z)).
Definition rational_rotation_int w x y z i j := clamp1 (idiv (rr_entry w x y z i j) (rr_norm w x y z)).

Lemma rational_rotation_encloses w x y z i j : 0 < lo (rr_norm w x y z) -> (j < 3)%nat ->
  holds (rational_rotation_int w x y z i j) (ent (Rq (q4 w x y z)) i j).
Proof.
  intros P Hj.
  assert (Hn : holds (rr_norm w x y z) (qn2 (q4 w x y z))).
  { unfold rr_norm, qn2; cbn [qw qx qy qz].
    repeat apply interval_add_encloses; apply interval_sqr_encloses, interval_point_encloses. }
  assert (Q : 0 < qn2 (q4 w x y z)) by (unfold holds in Hn; lra).
  assert (He : holds (idiv (rr_entry w x y z i j) (rr_norm w x y z)) (ent (Rq (q4 w x y z)) i j)).
  { replace (ent (Rq (q4 w x y z)) i j) with (ent (Nq (q4 w x y z)) i j / qn2 (q4 w x y z))
      by (destruct i as [|[|i]]; destruct j as [|[|j]]; unfold Rq, mscale; cbn; unfold Rdiv; ring).
    apply interval_div_positive_encloses; [exact P | | exact Hn].
    pose proof (interval_point_encloses w) as W. pose proof (interval_point_encloses x) as X.
    pose proof (interval_point_encloses y) as Y. pose proof (interval_point_encloses z) as Z.
    destruct i as [|[|i]]; destruct j as [|[|j]]; unfold rr_entry, Nq; cbv zeta; cbn [ent e11 e12 e13 e21 e22 e23 e31 e32 e33 qw qx qy qz];
      repeat first [ apply interval_add_encloses | apply interval_sub_encloses | apply interval_scale_encloses
                   | apply interval_mul_encloses | apply interval_sqr_encloses | exact (interval_point_encloses _) ]. }
  pose proof (orth_entry_bound (Rq (q4 w x y z)) i j (Rq_orthogonal _ Q) Hj) as B.
  unfold rational_rotation_int, clamp1, holds in *; cbn [lo hi].
  split; [apply Rmax_lub | apply Rmin_glb]; lra.
Qed.

(* make_ccd_motion's qr = q1 conj(q0) (hamilton on point intervals, conj's
   components negated exactly), negated when the double qr's scalar part is
   < 0 (flip), g = div_positive(r_k, r_w), g2 = sqr(g0) + sqr(g1) + sqr(g2),
   K2 = sqr(g_i) - g2 on the diagonal, g_i * g_j off it. *)
Definition hamilton_w (a b : nat -> Interval) :=
  isub (isub (isub (imul (a 0%nat) (b 0%nat)) (imul (a 1%nat) (b 1%nat))) (imul (a 2%nat) (b 2%nat))) (imul (a 3%nat) (b 3%nat)).
Definition hamilton_x (a b : nat -> Interval) :=
  isub (iadd (iadd (imul (a 0%nat) (b 1%nat)) (imul (a 1%nat) (b 0%nat))) (imul (a 2%nat) (b 3%nat))) (imul (a 3%nat) (b 2%nat)).
Definition hamilton_y (a b : nat -> Interval) :=
  iadd (iadd (isub (imul (a 0%nat) (b 2%nat)) (imul (a 1%nat) (b 3%nat))) (imul (a 2%nat) (b 0%nat))) (imul (a 3%nat) (b 1%nat)).
Definition hamilton_z (a b : nat -> Interval) :=
  iadd (isub (iadd (imul (a 0%nat) (b 3%nat)) (imul (a 1%nat) (b 2%nat))) (imul (a 2%nat) (b 1%nat))) (imul (a 3%nat) (b 0%nat)).
Definition qpoints (q : Q4) (k : nat) : Interval :=
  match k with O => ipoint (qw q) | S O => ipoint (qx q) | S (S O) => ipoint (qy q) | _ => ipoint (qz q) end.
Definition qconj_points (q : Q4) (k : nat) : Interval :=
  match k with O => ipoint (qw q) | S O => ineg (ipoint (qx q)) | S (S O) => ineg (ipoint (qy q)) | _ => ineg (ipoint (qz q)) end.
Definition flip_if (f : bool) I := if f then ineg I else I.
Definition rw_int f q1 q0 := flip_if f (hamilton_w (qpoints q1) (qconj_points q0)).
Definition gibbs_int f q1 q0 (k : nat) : Interval :=
  let rw := rw_int f q1 q0 in
  match k with
  | O => idiv (flip_if f (hamilton_x (qpoints q1) (qconj_points q0))) rw
  | S O => idiv (flip_if f (hamilton_y (qpoints q1) (qconj_points q0))) rw
  | _ => idiv (flip_if f (hamilton_z (qpoints q1) (qconj_points q0))) rw end.
Definition g2_int (gi : nat -> Interval) := iadd (iadd (isqr (gi 0%nat)) (isqr (gi 1%nat))) (isqr (gi 2%nat)).
Definition K2_int (gi : nat -> Interval) (i j : nat) : Interval :=
  if Nat.eqb i j then isub (isqr (gi i)) (g2_int gi) else imul (gi i) (gi j).
Definition p_int (p : V3) (k : nat) := ipoint (coord p k).
Definition dp_int (p0 p1 : V3) (k : nat) := isub (ipoint (coord p1 k)) (ipoint (coord p0 k)).

(* The CcdMotion make_ccd_motion builds from (p0, q0), (p1, q1). *)
Definition ccd_motion (p0 p1 : V3) (q0 q1 : Q4) (f : bool) : IMotion :=
  let gi := gibbs_int f q1 q0 in
  {| mp0 := p_int p0; mdp := dp_int p0 p1; mg := gi;
     mR0 := rational_rotation_int (qw q0) (qx q0) (qy q0) (qz q0);
     mg2 := g2_int gi; mK2 := K2_int gi |}.

Lemma hamilton_encloses q1 q0 :
  let r := qmul q1 (qconj q0) in
  holds (hamilton_w (qpoints q1) (qconj_points q0)) (qw r) /\
  holds (hamilton_x (qpoints q1) (qconj_points q0)) (qx r) /\
  holds (hamilton_y (qpoints q1) (qconj_points q0)) (qy r) /\
  holds (hamilton_z (qpoints q1) (qconj_points q0)) (qz r).
Proof.
  destruct q1 as [a b c d], q0 as [e f g h]. cbv zeta.
  unfold qmul, qconj, hamilton_w, hamilton_x, hamilton_y, hamilton_z, qpoints, qconj_points;
    cbn [qw qx qy qz].
  repeat split;
    repeat first [ apply interval_add_encloses | apply interval_sub_encloses | apply interval_mul_encloses
                 | apply interval_neg_encloses | exact (interval_point_encloses _) ].
Qed.

(* make_ccd_motion_encloses (motion.cpp, make_ccd_motion with rational_rotation
   and hamilton): for the input doubles, once the code's checks pass (n.lo > 0
   in rational_rotation, r_w.lo > 0 after the sign choice), the CcdMotion
   encloses p0, dp = p1 - p0, g = vec(qr) / scalar(qr) of qr = q1 conj(q0)
   (Cayley.v gibbs: the sign choice cancels in the quotient), R0 = R(q0)
   (Cayley.v Rq, a rotation), |g|^2 and [g]x^2: the hypotheses of
   enclose_motion_encloses but the magnitudes of g2, which make_ccd_motion
   checks after. *)
Lemma holds_eq I x y : holds I x -> x = y -> holds I y.
Proof. intros H E; subst; exact H. Qed.

Lemma flip_encloses f I x : holds I x -> holds (flip_if f I) (if f then - x else x).
Proof. destruct f; simpl; [apply interval_neg_encloses | exact (fun H => H)]. Qed.

Lemma make_ccd_motion_encloses p0 p1 q0 q1 f :
  0 < lo (rr_norm (qw q0) (qx q0) (qy q0) (qz q0)) -> 0 < lo (rw_int f q1 q0) ->
  let m := ccd_motion p0 p1 q0 q1 f in
  let g := gibbs (qmul q1 (qconj q0)) in
  motion_data m p0 (vsub p1 p0) g (Rq q0).
Proof.
  intros Pn Pw m g. unfold motion_data.
  destruct (hamilton_encloses q1 q0) as [Hw [Hx [Hy Hz]]].
  set (r := qmul q1 (qconj q0)) in *.
  assert (Hg : forall k, (k < 3)%nat -> holds (gibbs_int f q1 q0 k) (coord g k)).
  { intros k Hk. unfold g, gibbs.
    assert (Hw' := flip_encloses f _ _ Hw). fold (rw_int f q1 q0) in Hw'.
    assert (E : forall v, (if f then - v else v) / (if f then - qw r else qw r) = v / qw r).
    { intros v. assert (H : qw r <> 0).
      { intros Z. unfold holds in Hw'.
        destruct f; [change (if true then - qw r else qw r) with (- qw r) in Hw'
                    | change (if false then - qw r else qw r) with (qw r) in Hw']; lra. }
      destruct f; [change ((- v) / (- qw r) = v / qw r); field; exact H | reflexivity]. }
    destruct k as [|[|[|k]]]; [| | |lia]; unfold gibbs_int; cbv zeta; cbn [coord x1 x2 x3]; rewrite <- E;
      (apply interval_div_positive_encloses; [exact Pw | apply flip_encloses; assumption | exact Hw']). }
  assert (Hg2 : holds (g2_int (gibbs_int f q1 q0)) (dot g g)).
  { unfold g2_int, dot.
    pose proof (Hg 0%nat ltac:(lia)); pose proof (Hg 1%nat ltac:(lia)); pose proof (Hg 2%nat ltac:(lia)).
    repeat apply interval_add_encloses; apply interval_sqr_encloses; assumption. }
  assert (Q0 : 0 < qn2 q0).
  { assert (Hn : holds (rr_norm (qw q0) (qx q0) (qy q0) (qz q0)) (qn2 q0)).
    { unfold rr_norm, qn2.
      repeat apply interval_add_encloses; apply interval_sqr_encloses, interval_point_encloses. }
    unfold holds in Hn; lra. }
  split; [|split; [|split]].
  - intros i Hi. split; [|split].
    + unfold m, ccd_motion, p_int; cbn [mp0]. apply interval_point_encloses.
    + unfold m, ccd_motion, dp_int; cbn [mdp].
      replace (coord (vsub p1 p0) i) with (coord p1 i - coord p0 i) by (destruct i as [|[|i]]; reflexivity).
      apply interval_sub_encloses; apply interval_point_encloses.
    + exact (Hg i Hi).
  - intros i j Hi Hj. split.
    + unfold m, ccd_motion; cbn [mR0]. destruct q0 as [w x y z].
      exact (rational_rotation_encloses w x y z i j Pn Hj).
    + unfold m, ccd_motion; cbn [mK2]. unfold K2_int.
      pose proof (Hg 0%nat ltac:(lia)) as G0; pose proof (Hg 1%nat ltac:(lia)) as G1;
        pose proof (Hg 2%nat ltac:(lia)) as G2.
      revert Hg2 G0 G1 G2. generalize (gibbs_int f q1 q0). intros gi Hg2 G0 G1 G2.
      destruct g as [a b c]; unfold dot in Hg2; cbn [coord x1 x2 x3] in Hg2, G0, G1, G2.
      destruct i as [|[|[|i]]]; [| | |lia]; destruct j as [|[|[|j]]]; try lia;
        cbn [Nat.eqb ent mmul K e11 e12 e13 e21 e22 e23 e31 e32 e33 x1 x2 x3];
        (eapply holds_eq;
         [ first [ apply interval_sub_encloses; [apply interval_sqr_encloses; eassumption | exact Hg2]
                 | apply interval_mul_encloses; eassumption ]
         | ring ]).
  - unfold m, ccd_motion; cbn [mg2]. exact Hg2.
  - exact (Rq_orthogonal q0 Q0).
Qed.

(* enclose_exact_motion (motion.cpp, make_ccd_motion then enclose_motion):
   for poses of doubles (p0, q0), (p1, q1), once make_ccd_motion's checks
   pass (rational_rotation's n.lo > 0, r_w.lo > 0 after the sign choice f,
   -1/8 <= g2.lo and g2.hi <= kMaxGibbsSquared), and a parameter interval
   [u0, u1] of doubles in [0, 1]: for every t in it, the exact motion of
   METHOD.md section 4, p(t) = p0 + t (p1 - p0) and R(t) = C(t g) R(q0) with
   g = vec(qr) / scalar(qr), qr = q1 conj(q0), lies in enclose_motion's
   MotionEnclosure (p[i], R[3 i + j], within R_rad of R_mid). *)
(* covers optimized/gauss6/ccd/motion.cpp "MotionStatus make_ccd_motion(const Pose& x0, const Pose& x1, CcdMotion* m)" sha256:3eec2b3670094b94 *)
(* covers optimized/gauss6/ccd/motion.cpp "bool rational_rotation(const Quat& q, IMat3* R)" sha256:14679c6ba59f52b0 *)
(* covers optimized/gauss6/ccd/motion.cpp "IQuat hamilton(const IQuat& a, const IQuat& b)" sha256:20776425dffe3f5f *)
(* covers optimized/gauss6/ccd/motion.cpp "void enclose_motion(const CcdMotion& m, Interval u, MotionEnclosure* out)" sha256:99ad7aece5205dfe *)
Theorem enclose_exact_motion p0 p1 q0 q1 f u0 u1 t :
  0 < lo (rr_norm (qw q0) (qx q0) (qy q0) (qz q0)) -> 0 < lo (rw_int f q1 q0) ->
  let m := ccd_motion p0 p1 q0 q1 f in
  - / 8 <= lo (mg2 m) -> hi (mg2 m) <= kMaxGibbsSquared ->
  F u0 -> F u1 -> 0 <= u0 -> u1 <= 1 -> u0 <= t <= u1 ->
  let g := gibbs (qmul q1 (qconj q0)) in
  let a := alpha_enc (mg2 m) u0 u1 in
  let b := beta_enc (mg2 m) u0 u1 in
  let Rt := mmul (cayley (vscale t g)) (Rq q0) in
  (forall i, (i < 3)%nat ->
     holds (ipos m {| lo := u0; hi := u1 |} i) (coord (vadd p0 (vscale t (vsub p1 p0))) i)) /\
  (forall i j, (i < 3)%nat -> (j < 3)%nat ->
     let r := clamp1 (iRe a b m i j) in
     holds r (ent Rt i j) /\ Rabs (ent Rt i j - rmid r) <= rrad r /\ 0 <= rrad r).
Proof.
  intros Pn Pw m Hl Hh F0 F1 H0 H1 Ht g a b Rt.
  assert (Fs : F (lo (mg2 m)))
    by (unfold m, ccd_motion, g2_int, iadd; cbn [mg2 lo]; unfold next_down, next_up; apply F_opp, F_fl).
  exact (enclose_motion_encloses m p0 (vsub p1 p0) g (Rq q0) u0 u1 t (make_ccd_motion_encloses p0 p1 q0 q1 f Pn Pw)
           Fs Hl Hh F0 F1 H0 H1 Ht).
Qed.
Print Assumptions enclose_exact_motion.

(* ---- Chained with ObbAllowances.v swept_box_encloses ----
   swept_box_motion (motion_bounds.cpp swept_box over enclose_motion's
   MotionEnclosure): under the hypotheses of enclose_motion_encloses, for
   every t of [u0, u1] and every body point r of the body box [lo, hi]
   (doubles), the world coordinate i of the exact motion's point
   p(t) + R(t) r lies in swept_box's world interval, computed as the code
   computes it from R_mid, R_rad (row i) and p[i]: the swept box holds every
   pose of the exact motion over the sub-interval. *)
(* covers optimized/gauss6/ccd/motion.cpp "void enclose_motion(const CcdMotion& m, Interval u, MotionEnclosure* out)" sha256:99ad7aece5205dfe *)
(* covers optimized/gauss6/ccd/motion_bounds.cpp "Aabb swept_box(const MotionEnclosure& e, const Aabb& body)" sha256:17e777d36e576019 *)
Theorem swept_box_motion m p0 dp g R0 u0 u1 t i lo0 lo1 lo2 hi0 hi1 hi2 r0 r1 r2 :
  motion_data m p0 dp g R0 ->
  F (lo (mg2 m)) -> - / 8 <= lo (mg2 m) -> hi (mg2 m) <= kMaxGibbsSquared ->
  F u0 -> F u1 -> 0 <= u0 -> u1 <= 1 -> u0 <= t <= u1 -> (i < 3)%nat ->
  (forall x, In x [lo0; lo1; lo2; hi0; hi1; hi2] -> F x) ->
  lo0 <= r0 <= hi0 -> lo1 <= r1 <= hi1 -> lo2 <= r2 <= hi2 ->
  let a := alpha_enc (mg2 m) u0 u1 in
  let b := beta_enc (mg2 m) u0 u1 in
  let Rt := mmul (cayley (vscale t g)) R0 in
  let m0 := rmid (clamp1 (iRe a b m i 0)) in
  let m1 := rmid (clamp1 (iRe a b m i 1)) in
  let m2 := rmid (clamp1 (iRe a b m i 2)) in
  let q0 := rrad (clamp1 (iRe a b m i 0)) in
  let q1 := rrad (clamp1 (iRe a b m i 1)) in
  let q2 := rrad (clamp1 (iRe a b m i 2)) in
  let p := ipos m {| lo := u0; hi := u1 |} i in
  holds (swept_world m0 m1 m2 q0 q1 q2 lo0 lo1 lo2 hi0 hi1 hi2 (lo p) (hi p)) (coord (vadd p0 (vscale t dp)) i + (ent Rt i 0 * r0 + ent Rt i 1 * r1 + ent Rt i 2 * r2)).
Proof.
  intros Hd Fs Hl Hh F0 F1 H0 H1 Ht Hi HF Hr0 Hr1 Hr2 a b Rt m0 m1 m2 q0 q1 q2 p.
  destruct (enclose_motion_encloses m p0 dp g R0 u0 u1 t Hd Fs Hl Hh F0 F1 H0 H1 Ht) as [Hp HR].
  destruct (HR i 0%nat Hi ltac:(lia)) as [_ [E0 G0]]. destruct (HR i 1%nat Hi ltac:(lia)) as [_ [E1 G1]].
  destruct (HR i 2%nat Hi ltac:(lia)) as [_ [E2 G2]].
  pose proof (Hp i Hi) as HP. fold p in HP. unfold holds in HP.
  assert (HF' : forall x, In x [m0; m1; m2; q0; q1; q2; lo0; lo1; lo2; hi0; hi1; hi2] -> F x).
  { intros x Hx. simpl in Hx.
    repeat (destruct Hx as [<-|Hx]; [first [apply HF; simpl; tauto | apply F_fl | unfold rrad, next_up; apply F_fl] |]).
    destruct Hx. }
  exact (swept_box_encloses m0 m1 m2 q0 q1 q2 lo0 lo1 lo2 hi0 hi1 hi2 (ent Rt i 0) (ent Rt i 1) (ent Rt i 2)
           r0 r1 r2 (lo p) (hi p) (coord (vadd p0 (vscale t dp)) i) HF' G0 G1 G2 E0 E1 E2 Hr0 Hr1 Hr2 HP).
Qed.
Print Assumptions swept_box_motion.
