(* Outward rounding of optimized/gauss6/numeric/rounding.h, proved in Flocq:
   binary64 (53-bit significand, least subnormal 2^-1074), round to nearest
   even, as SSE2 computes on x86-64. Each theorem speaks for one function of
   rounding.h and says that its result encloses the exact result of the same
   operation on the reals its operands stand for.

   Model and hypotheses, shared by every theorem:
   - A double is a real of the format `F` (Flocq's FLT, no exponent cap), an
     operation its exact real result rounded by `fl`: the IEEE result whenever
     it is finite. Overflow (a result past DBL_MAX, rounded to an infinity) is
     outside the model; next_up's clamp r' = max(r, -DBL_MAX) and the
     comparisons' falseness on NaN, which rounding.h argues for infinities and
     NaNs, are argued there, not here.
   - Gradual underflow: the model rounds subnormal results to nearest; a
     thread that flushes them to zero (FTZ/DAZ) is outside these theorems
     (rounding.h's comment argues the 2^-600 widening covers it).
   - No fused multiply-add contraction of `|r| 2^-52 + 2^-600`: the theorem
     `next_up_ge_fma` covers the contracted form too. *)

From Coq Require Import Reals Psatz.
From Flocq Require Import Core.
Open Scope R_scope.

Notation fexp := (FLT_exp (-1074) 53).
Global Instance prec_53_gt_0 : Prec_gt_0 53. Proof. unfold Prec_gt_0; lia. Qed.
Definition fl (x : R) : R := round radix2 fexp ZnearestE x.
Notation F := (generic_format radix2 fexp).

(* rounding.h, next_up: kUlp = 0x1p-52, kTiny = 0x1p-600;
   return r + (std::abs(r) * kUlp + kTiny), on a finite r (the clamp is the
   identity there). next_down(x) = -next_up(-x). *)
Definition kUlp := bpow radix2 (-52).
Definition kTiny := bpow radix2 (-600).
Definition widening (r : R) : R := fl (fl (Rabs r * kUlp) + kTiny).
Definition next_up (r : R) : R := fl (r + widening r).
Definition next_down (r : R) : R := - next_up (- r).

(* lia over Z.max: split every max into its two cases. *)
Ltac zmax := unfold FLT_exp in *; repeat match goal with
  | |- context [Z.max ?a ?b] => destruct (Z.max_spec a b) as [[? ->]|[? ->]] end; lia.

Lemma F_fl x : F (fl x).
Proof. apply generic_format_round; auto with typeclass_instances. Qed.

Lemma fl_le x y : x <= y -> fl x <= fl y.
Proof. apply round_le; auto with typeclass_instances. Qed.

Lemma fl_ge_F x y : F x -> x <= y -> x <= fl y.
Proof. apply round_ge_generic; auto with typeclass_instances. Qed.

Lemma fl_le_F x y : F y -> x <= y -> fl x <= y.
Proof. apply round_le_generic; auto with typeclass_instances. Qed.

Lemma fl_F x : F x -> fl x = x.
Proof. apply round_generic; auto with typeclass_instances. Qed.

Lemma fl_opp x : fl (- x) = - fl x.
Proof. apply round_NE_opp. Qed.

Lemma F_opp x : F x -> F (- x).
Proof. apply generic_format_opp. Qed.

Lemma fl_nonneg x : 0 <= x -> 0 <= fl x.
Proof. intros H; apply fl_ge_F; [apply generic_format_0 | exact H]. Qed.

Lemma F_ulp r : F (ulp radix2 fexp r).
Proof.
  destruct (Req_dec r 0) as [->|Hr].
  - rewrite ulp_FLT_0 by exact prec_53_gt_0.
    apply generic_format_bpow; zmax.
  - rewrite ulp_neq_0 by exact Hr. apply generic_format_bpow.
    unfold cexp. destruct (mag radix2 r) as [e He]; simpl. zmax.
Qed.

(* The widening t is at least one ulp of r. *)
Lemma widening_ge_ulp r : ulp radix2 fexp r <= widening r.
Proof.
  unfold widening.
  destruct (Rle_or_lt (bpow radix2 (-1074 + 53 - 1)) (Rabs r)) as [Hn|Hs].
  - assert (Hu : ulp radix2 fexp r <= Rabs r * kUlp)
      by (apply ulp_FLT_le; exact Hn).
    apply fl_ge_F; [apply F_ulp|].
    assert (ulp radix2 fexp r <= fl (Rabs r * kUlp)) by (apply fl_ge_F; [apply F_ulp | exact Hu]).
    assert (0 < kTiny) by apply bpow_gt_0. lra.
  - assert (Hu : ulp radix2 fexp r = bpow radix2 (-1074)).
    { apply ulp_FLT_small; [exact prec_53_gt_0|].
      eapply Rlt_le_trans; [exact Hs | apply bpow_le; lia]. }
    rewrite Hu. apply fl_ge_F; [apply generic_format_bpow; zmax|].
    assert (0 <= fl (Rabs r * kUlp))
      by (apply fl_nonneg, Rmult_le_pos; [apply Rabs_pos | apply bpow_ge_0]).
    assert (bpow radix2 (-1074) <= kTiny) by (apply bpow_le; lia). lra.
Qed.

(* Core: a float r plus anything of at least one ulp of r rounds to at least
   the float after r. *)
Lemma plus_ulp_ge_succ r t :
  F r -> ulp radix2 fexp r <= t -> succ radix2 fexp r <= fl (r + t).
Proof.
  intros Fr Ht. apply fl_ge_F.
  - apply generic_format_succ; auto with typeclass_instances.
  - eapply Rle_trans; [apply succ_le_plus_ulp; auto with typeclass_instances | lra].
Qed.

(* next_up_ge (rounding.h, next_up): for every real x, the double
   next_up(fl x) is >= x, fl x being the double nearest x. *)
(* covers optimized/gauss6/numeric/rounding.h "double next_up(double x)" sha256:f7f39b665daf7c8b *)
Theorem next_up_ge x : x <= next_up (fl x).
Proof.
  unfold next_up. eapply Rle_trans.
  - apply (succ_round_ge_id radix2 fexp ZnearestE x).
  - apply plus_ulp_ge_succ; [apply F_fl | apply widening_ge_ulp].
Qed.

(* next_down_le (rounding.h, next_down): next_down(fl x) <= x. *)
(* covers optimized/gauss6/numeric/rounding.h "double next_down(double x)" sha256:073c1384ed8f3ceb *)
Theorem next_down_le x : next_down (fl x) <= x.
Proof.
  unfold next_down. rewrite <- fl_opp. pose proof (next_up_ge (- x)). lra.
Qed.

(* A double entering as its own bound: next_up r >= r, next_down r <= r. *)
Lemma next_up_ge_F r : F r -> r <= next_up r.
Proof. intros Fr. rewrite <- (fl_F r Fr) at 2. apply next_up_ge. Qed.
Lemma next_down_le_F r : F r -> next_down r <= r.
Proof. intros Fr. rewrite <- (fl_F r Fr) at 1. apply next_down_le. Qed.

(* next_up_ge_fma (rounding.h, next_up, contracted): if a compiler
   fuses the product that made r = fl x with the sum "+ t" (one rounding of
   x + t), or the widening's own product and sum, the result is still >= x. *)
(* covers optimized/gauss6/numeric/rounding.h "double next_up(double x)" sha256:f7f39b665daf7c8b *)
Theorem next_up_ge_fma x :
  let r := fl x in
  let t1 := widening r in
  let t2 := fl (Rabs r * kUlp + kTiny) in
  x <= fl (x + t1) /\ x <= fl (r + t2) /\ x <= fl (x + t2).
Proof.
  intros r t1 t2.
  assert (Hu1 : ulp radix2 fexp r <= t1) by apply widening_ge_ulp.
  assert (Hu2 : ulp radix2 fexp r <= t2).
  { unfold t2. destruct (Rle_or_lt (bpow radix2 (-1074 + 53 - 1)) (Rabs r)) as [Hn|Hs].
    - assert (ulp radix2 fexp r <= Rabs r * kUlp)
        by (apply ulp_FLT_le; exact Hn).
      apply fl_ge_F; [apply F_ulp|]. assert (0 < kTiny) by apply bpow_gt_0. lra.
    - assert (Hu : ulp radix2 fexp r = bpow radix2 (-1074)).
      { apply ulp_FLT_small; [exact prec_53_gt_0|].
        eapply Rlt_le_trans; [exact Hs | apply bpow_le; lia]. }
      rewrite Hu. apply fl_ge_F; [apply generic_format_bpow; zmax|].
      assert (0 <= Rabs r * kUlp) by (apply Rmult_le_pos; [apply Rabs_pos | apply bpow_ge_0]).
      assert (bpow radix2 (-1074) <= kTiny) by (apply bpow_le; lia). lra. }
  (* fused with the product that made r: x + t versus the float after r *)
  assert (Hfused : forall t, ulp radix2 fexp r <= t -> x <= fl (x + t)).
  { intros t Ht. destruct (Rle_or_lt x r) as [Hle|Hgt].
    - (* x <= r: x + t >= r - ulp/2 + ulp >= r, and r is a float >= x *)
      assert (Hh' : Rabs (r - x) <= / 2 * ulp radix2 fexp r).
      { unfold r, fl. apply error_le_half_ulp_round; auto with typeclass_instances. }
      assert (r <= x + t) by (rewrite Rabs_pos_eq in Hh' by lra; assert (0 <= ulp radix2 fexp r) by apply ulp_ge_0; lra).
      eapply Rle_trans; [exact Hle | apply fl_ge_F; [apply F_fl | assumption]].
    - assert (succ radix2 fexp r <= x + t).
      { eapply Rle_trans; [apply succ_le_plus_ulp; auto with typeclass_instances | lra]. }
      eapply Rle_trans; [apply (succ_round_ge_id radix2 fexp ZnearestE x)|].
      apply fl_ge_F; [apply generic_format_succ; [auto with typeclass_instances | apply F_fl] | assumption]. }
  split; [apply Hfused; exact Hu1|]. split; [|apply Hfused; exact Hu2].
  eapply Rle_trans; [apply (succ_round_ge_id radix2 fexp ZnearestE x)|].
  apply plus_ulp_ge_succ; [apply F_fl | exact Hu2].
Qed.

(* The double result of an exact operation, moved outward: the two facts every
   theorem below rests on. *)
Lemma up_ge x y : x <= y -> x <= next_up (fl y).
Proof. intros H; eapply Rle_trans; [exact H | apply next_up_ge]. Qed.
Lemma down_le x y : y <= x -> next_down (fl y) <= x.
Proof. intros H; eapply Rle_trans; [apply next_down_le | exact H]. Qed.

(* Rounding commutes with min and max (it is monotone), so the min / max of
   rounded corner values is the rounded min / max of the exact ones. *)
Lemma fl_min a b : Rmin (fl a) (fl b) = fl (Rmin a b).
Proof.
  unfold Rmin; destruct (Rle_dec a b) as [H|H]; destruct (Rle_dec (fl a) (fl b)) as [H'|H'];
    try reflexivity.
  - exfalso; apply H', fl_le, H.
  - apply Rle_antisym; [exact H' | apply fl_le; lra].
Qed.
Lemma fl_max a b : Rmax (fl a) (fl b) = fl (Rmax a b).
Proof.
  unfold Rmax; destruct (Rle_dec a b) as [H|H]; destruct (Rle_dec (fl a) (fl b)) as [H'|H'];
    try reflexivity.
  - exfalso; apply H', fl_le, H.
  - apply Rle_antisym; [apply fl_le; lra | exact H'].
Qed.

Definition min4 a b c d := Rmin (Rmin a b) (Rmin c d).
Definition max4 a b c d := Rmax (Rmax a b) (Rmax c d).
Lemma fl_min4 a b c d : min4 (fl a) (fl b) (fl c) (fl d) = fl (min4 a b c d).
Proof. unfold min4; rewrite !fl_min; reflexivity. Qed.
Lemma fl_max4 a b c d : max4 (fl a) (fl b) (fl c) (fl d) = fl (max4 a b c d).
Proof. unfold max4; rewrite !fl_max; reflexivity. Qed.
Lemma min4_le a b c d z : a <= z \/ b <= z \/ c <= z \/ d <= z -> min4 a b c d <= z.
Proof.
  unfold min4, Rmin; intros H; repeat destruct Rle_dec; lra.
Qed.
Lemma max4_ge a b c d z : z <= a \/ z <= b \/ z <= c \/ z <= d -> z <= max4 a b c d.
Proof.
  unfold max4, Rmax; intros H; repeat destruct Rle_dec; lra.
Qed.

(* A product of x in [al, ah] and y in [bl, bh] is at least one corner product
   and at most one (it is bilinear). *)
Lemma product_corners al ah bl bh x y :
  al <= x <= ah -> bl <= y <= bh ->
  (al * bl <= x * y \/ al * bh <= x * y \/ ah * bl <= x * y \/ ah * bh <= x * y) /\
  (x * y <= al * bl \/ x * y <= al * bh \/ x * y <= ah * bl \/ x * y <= ah * bh).
Proof.
  intros Hx Hy.
  destruct (Rle_or_lt 0 y) as [Y|Y]; destruct (Rle_or_lt 0 al) as [A|A];
    destruct (Rle_or_lt 0 ah) as [B|B]; split; nra.
Qed.

(* ---- Interval (rounding.h): a pair lo <= hi of doubles, holding x when
   lo <= x <= hi. ---- *)
Record Interval := { lo : R; hi : R }.
Definition holds (I : Interval) (x : R) := lo I <= x <= hi I.

(* operator+(Interval, Interval) *)
Definition iadd I J := {| lo := next_down (fl (lo I + lo J)); hi := next_up (fl (hi I + hi J)) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval operator+(Interval a, Interval b)" sha256:75cee5110dc23935 *)
Theorem interval_add_encloses I J x y : holds I x -> holds J y -> holds (iadd I J) (x + y).
Proof. unfold holds; simpl; intros; split; [apply down_le | apply up_ge]; lra. Qed.

(* operator-(Interval, Interval) *)
Definition isub I J := {| lo := next_down (fl (lo I - hi J)); hi := next_up (fl (hi I - lo J)) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval operator-(Interval a, Interval b)" sha256:9864ba0a2e8b49d1 *)
Theorem interval_sub_encloses I J x y : holds I x -> holds J y -> holds (isub I J) (x - y).
Proof. unfold holds; simpl; intros; split; [apply down_le | apply up_ge]; lra. Qed.

(* operator-(Interval): {-hi, -lo}, exact (negating a double is exact). *)
Definition ineg I := {| lo := - hi I; hi := - lo I |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval operator-(Interval a)" sha256:c8d557b635f019ad *)
Theorem interval_neg_encloses I x : holds I x -> holds (ineg I) (- x).
Proof. unfold holds; simpl; intros; lra. Qed.
Lemma interval_neg_exact I : F (lo I) -> F (hi I) -> F (lo (ineg I)) /\ F (hi (ineg I)).
Proof. simpl; intros; split; apply F_opp; assumption. Qed.

(* operator*(Interval, Interval): the min / max of the four rounded corner
   products p1..p4, moved outward. *)
Definition imul I J :=
  {| lo := next_down (min4 (fl (lo I * lo J)) (fl (lo I * hi J)) (fl (hi I * lo J)) (fl (hi I * hi J)));
     hi := next_up (max4 (fl (lo I * lo J)) (fl (lo I * hi J)) (fl (hi I * lo J)) (fl (hi I * hi J))) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval operator*(Interval a, Interval b)" sha256:3f3f93e6ecd32c67 *)
Theorem interval_mul_encloses I J x y : holds I x -> holds J y -> holds (imul I J) (x * y).
Proof.
  unfold holds, imul; simpl; intros Hx Hy.
  destruct (product_corners _ _ _ _ _ _ Hx Hy) as [L U].
  rewrite fl_min4, fl_max4; split; [apply down_le, min4_le | apply up_ge, max4_ge]; assumption.
Qed.

(* operator*(double s, Interval): min / max of s lo and s hi, moved outward. *)
Definition iscale s I :=
  {| lo := next_down (Rmin (fl (s * lo I)) (fl (s * hi I)));
     hi := next_up (Rmax (fl (s * lo I)) (fl (s * hi I))) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval operator*(double s, Interval a)" sha256:772f29f9ea65e0b5 *)
Theorem interval_scale_encloses s I x : holds I x -> holds (iscale s I) (s * x).
Proof.
  unfold holds, iscale; simpl; intros Hx. rewrite fl_min, fl_max.
  split; [apply down_le | apply up_ge].
  - destruct (Rle_or_lt 0 s); [eapply Rle_trans; [apply Rmin_l|] | eapply Rle_trans; [apply Rmin_r|]]; nra.
  - destruct (Rle_or_lt 0 s); [eapply Rle_trans; [|apply Rmax_r] | eapply Rle_trans; [|apply Rmax_l]]; nra.
Qed.

(* div_positive(Interval a, Interval b), the caller guaranteeing b.lo > 0:
   min / max of the four rounded corner quotients, moved outward. *)
Definition idiv I J :=
  {| lo := next_down (min4 (fl (lo I / lo J)) (fl (lo I / hi J)) (fl (hi I / lo J)) (fl (hi I / hi J)));
     hi := next_up (max4 (fl (lo I / lo J)) (fl (lo I / hi J)) (fl (hi I / lo J)) (fl (hi I / hi J))) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval div_positive(Interval a, Interval b)" sha256:1a34809825b530c2 *)
Theorem interval_div_positive_encloses I J x y :
  0 < lo J -> holds I x -> holds J y -> holds (idiv I J) (x / y).
Proof.
  unfold holds, idiv; simpl; intros P Hx Hy.
  assert (Hr : / hi J <= / y <= / lo J)
    by (split; apply Rinv_le_contravar; lra).
  destruct (product_corners _ _ _ _ _ _ Hx Hr) as [L U].
  unfold Rdiv in *. rewrite fl_min4, fl_max4.
  split; [apply down_le, min4_le | apply up_ge, max4_ge]; lra.
Qed.

(* sqr(Interval): three cases on the signs of lo and hi; the mixed case's
   lower end is the exact 0. *)
Definition isqr I :=
  if Rle_dec 0 (lo I) then {| lo := next_down (fl (lo I * lo I)); hi := next_up (fl (hi I * hi I)) |}
  else if Rle_dec (hi I) 0 then {| lo := next_down (fl (hi I * hi I)); hi := next_up (fl (lo I * lo I)) |}
  else {| lo := 0; hi := next_up (fl (Rmax (- lo I) (hi I) * Rmax (- lo I) (hi I))) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval sqr(Interval a)" sha256:0738a9253ed1e9ba *)
Theorem interval_sqr_encloses I x : holds I x -> holds (isqr I) (x * x).
Proof.
  unfold holds, isqr; intros Hx.
  destruct (Rle_dec 0 (lo I)); [|destruct (Rle_dec (hi I) 0)]; simpl;
    (split; [try apply down_le | apply up_ge]); try nra.
  pose proof (Rmax_l (- lo I) (hi I)); pose proof (Rmax_r (- lo I) (hi I)). nra.
Qed.

(* hull(Interval, Interval): exact min / max. *)
Definition ihull I J := {| lo := Rmin (lo I) (lo J); hi := Rmax (hi I) (hi J) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval hull(Interval a, Interval b)" sha256:efa4509bb8adc7a9 *)
Theorem interval_hull_encloses I J x : holds I x \/ holds J x -> holds (ihull I J) x.
Proof.
  unfold holds, ihull; simpl; intros H.
  pose proof (Rmin_l (lo I) (lo J)); pose proof (Rmin_r (lo I) (lo J));
  pose proof (Rmax_l (hi I) (hi J)); pose proof (Rmax_r (hi I) (hi J)); lra.
Qed.

(* Interval::point(x): the double x holds itself. *)
(* covers optimized/gauss6/numeric/rounding.h "static Interval point(double x)" sha256:545ba5673b13aaef *)
Theorem interval_point_encloses x : holds {| lo := x; hi := x |} x.
Proof. unfold holds; simpl; lra. Qed.

(* ---- Upper / Lower (rounding.h): a double u with x <= u for the exact real
   x it stands for; a double l with l <= x. ---- *)

(* round_up(x) / round_down(x): a value within its last rounding of x. *)
(* covers optimized/gauss6/numeric/rounding.h "Upper round_up(double x)" sha256:bad8791bfbed5152 *)
Theorem round_up_bounds x : x <= next_up (fl x).
Proof. apply next_up_ge. Qed.
(* covers optimized/gauss6/numeric/rounding.h "Lower round_down(double x)" sha256:4f93442ea04e06c7 *)
Theorem round_down_bounds x : next_down (fl x) <= x.
Proof. apply next_down_le. Qed.

(* operator+(Upper, Upper) and operator-(Upper, Lower) *)
(* covers optimized/gauss6/numeric/rounding.h "Upper operator+(Upper a, Upper b)" sha256:9b65569393f5d5ca *)
Theorem upper_add x y a b : x <= a -> y <= b -> x + y <= next_up (fl (a + b)).
Proof. intros; apply up_ge; lra. Qed.
(* covers optimized/gauss6/numeric/rounding.h "Upper operator-(Upper a, Lower b)" sha256:72a5f1bc466a3d4f *)
Theorem upper_sub x y a b : x <= a -> b <= y -> x - y <= next_up (fl (a - b)).
Proof. intros; apply up_ge; lra. Qed.
(* operator*(Upper, Upper), of nonnegative reals *)
(* covers optimized/gauss6/numeric/rounding.h "Upper operator*(Upper a, Upper b)" sha256:4911751a1879188b *)
Theorem upper_mul x y a b : 0 <= x <= a -> 0 <= y <= b -> x * y <= next_up (fl (a * b)).
Proof. intros; apply up_ge; nra. Qed.
(* operator*(double s, Upper), s >= 0 *)
(* covers optimized/gauss6/numeric/rounding.h "Upper operator*(double s, Upper a)" sha256:f644b35d800c0055 *)
Theorem upper_scale s x a : 0 <= s -> x <= a -> s * x <= next_up (fl (s * a)).
Proof. intros; apply up_ge; nra. Qed.
(* operator/(Upper, Lower): a nonnegative real over a positive one. The
   Lower's double b must itself be > 0 (a Lower of a positive real may be 0
   or below): the sites guarantee it (proofs/README.md). *)
(* covers optimized/gauss6/numeric/rounding.h "Upper operator/(Upper a, Lower b)" sha256:eaf3d64f67bdbf7f *)
Theorem upper_div x y a b : 0 <= x <= a -> 0 < b <= y -> x / y <= next_up (fl (a / b)).
Proof.
  intros Hx Hy; apply up_ge. unfold Rdiv.
  assert (/ y <= / b) by (apply Rinv_le_contravar; lra).
  assert (0 < / y) by (apply Rinv_0_lt_compat; lra). nra.
Qed.
(* operator/(Upper, double s), s > 0 *)
(* covers optimized/gauss6/numeric/rounding.h "Upper operator/(Upper a, double s)" sha256:b3c6d35922a660e1 *)
Theorem upper_div_scalar x a s : x <= a -> 0 < s -> x / s <= next_up (fl (a / s)).
Proof.
  intros; apply up_ge; unfold Rdiv.
  assert (0 < / s) by (apply Rinv_0_lt_compat; lra). nra.
Qed.
(* sqr(Upper), of a nonnegative real *)
(* covers optimized/gauss6/numeric/rounding.h "Upper sqr(Upper a)" sha256:2131f3f0fb191df5 *)
Theorem upper_sqr x a : 0 <= x <= a -> x * x <= next_up (fl (a * a)).
Proof. intros; apply up_ge; nra. Qed.
(* sqrt(Upper), of a nonnegative real *)
(* covers optimized/gauss6/numeric/rounding.h "Upper sqrt(Upper a)" sha256:cce2cae9470dd236 *)
Theorem upper_sqrt x a : 0 <= x <= a -> sqrt x <= next_up (fl (sqrt a)).
Proof. intros; apply up_ge, sqrt_le_1_alt; lra. Qed.
(* max(Upper, Upper), min(Upper, Upper): exact *)
(* covers optimized/gauss6/numeric/rounding.h "Upper max(Upper a, Upper b)" sha256:5553571db6d61a7e *)
Theorem upper_max x y a b : x <= a -> y <= b -> Rmax x y <= Rmax a b.
Proof. intros; apply Rmax_lub; [eapply Rle_trans; [|apply Rmax_l] | eapply Rle_trans; [|apply Rmax_r]]; eassumption. Qed.
(* covers optimized/gauss6/numeric/rounding.h "Upper min(Upper a, Upper b)" sha256:0516ea767307c6f4 *)
Theorem upper_min x y a b : x <= a -> y <= b -> Rmin x y <= Rmin a b.
Proof. intros; apply Rmin_glb; [eapply Rle_trans; [apply Rmin_l|] | eapply Rle_trans; [apply Rmin_r|]]; eassumption. Qed.

(* operator+(Lower, Lower) and operator-(Lower, Upper) *)
(* covers optimized/gauss6/numeric/rounding.h "Lower operator+(Lower a, Lower b)" sha256:9c6fde7cd2f35cf1 *)
Theorem lower_add x y a b : a <= x -> b <= y -> next_down (fl (a + b)) <= x + y.
Proof. intros; apply down_le; lra. Qed.
(* covers optimized/gauss6/numeric/rounding.h "Lower operator-(Lower a, Upper b)" sha256:0f44c8ff9fb6d6a1 *)
Theorem lower_sub x y a b : a <= x -> y <= b -> next_down (fl (a - b)) <= x - y.
Proof. intros; apply down_le; lra. Qed.
(* operator/(Lower, Upper): a nonnegative real over a positive one (the
   Upper's double is then positive too). *)
(* covers optimized/gauss6/numeric/rounding.h "Lower operator/(Lower a, Upper b)" sha256:db5f15e3da44f8a0 *)
Theorem lower_div x y a b : a <= x -> 0 <= x -> 0 < y <= b -> next_down (fl (a / b)) <= x / y.
Proof.
  intros Ha Hx Hy; apply down_le. unfold Rdiv.
  assert (/ b <= / y) by (apply Rinv_le_contravar; lra).
  assert (0 < / b) by (apply Rinv_0_lt_compat; lra).
  assert (0 < / y) by (apply Rinv_0_lt_compat; lra). nra.
Qed.
(* sqr(Lower): the Lower's double a must be >= 0 (a Lower of a nonnegative
   real may be negative, and then a * a may exceed x * x): the one site,
   excludes in ccd/bisection.h, enters a distance m >= 0. *)
(* covers optimized/gauss6/numeric/rounding.h "Lower sqr(Lower a)" sha256:852741653cf3b95a *)
Theorem lower_sqr x a : 0 <= a <= x -> next_down (fl (a * a)) <= x * x.
Proof. intros; apply down_le; nra. Qed.
(* sqrt(Lower) of a nonnegative real (a negative double a gives NaN in IEEE,
   which fails safe; over the reals sqrt is monotone on all of R). *)
(* covers optimized/gauss6/numeric/rounding.h "Lower sqrt(Lower a)" sha256:a105fc859c7040bb *)
Theorem lower_sqrt x a : a <= x -> next_down (fl (sqrt a)) <= sqrt x.
Proof.
  intros; apply down_le. destruct (Rle_or_lt a 0).
  - rewrite sqrt_neg_0 by lra. apply sqrt_pos.
  - apply sqrt_le_1_alt; lra.
Qed.
(* operator>(Lower, Upper): proves the exact order. *)
(* covers optimized/gauss6/numeric/rounding.h "bool operator>(Lower a, Upper b)" sha256:70fdb8d7f0fd530c *)
Theorem lower_gt_upper x y a b : a <= x -> y <= b -> a > b -> x > y.
Proof. intros; lra. Qed.

(* widen(Interval a, Upper e): [lo - e, hi + e], e >= 0, rounded outward. *)
Definition iwiden I e := {| lo := next_down (fl (lo I - e)); hi := next_up (fl (hi I + e)) |}.
(* covers optimized/gauss6/numeric/rounding.h "Interval widen(Interval a, Upper e)" sha256:af31ca9120c0c9e1 *)
Theorem interval_widen_encloses I e E x :
  0 <= E <= e -> lo I - E <= x <= hi I + E -> holds (iwiden I e) x.
Proof. unfold holds, iwiden; simpl; intros; split; [apply down_le | apply up_ge]; lra. Qed.

(* magnitude(Interval): max(|lo|, |hi|), exact. *)
(* covers optimized/gauss6/numeric/rounding.h "Upper magnitude(Interval a)" sha256:8b1e8d73539e3617 *)
Theorem magnitude_bounds I x : holds I x -> Rabs x <= Rmax (Rabs (lo I)) (Rabs (hi I)).
Proof.
  unfold holds; intros H. pose proof (Rmax_l (Rabs (lo I)) (Rabs (hi I))).
  pose proof (Rmax_r (Rabs (lo I)) (Rabs (hi I))).
  unfold Rabs in *; repeat destruct Rcase_abs; lra.
Qed.

(* distance_from(Interval a, double x): max(Upper{hi} - Lower{x}, Upper{x} - Lower{lo}). *)
(* covers optimized/gauss6/numeric/rounding.h "Upper distance_from(Interval a, double x)" sha256:35e8cf51074b7db7 *)
Theorem distance_from_bounds I x y :
  holds I y -> Rabs (y - x) <= Rmax (next_up (fl (hi I - x))) (next_up (fl (x - lo I))).
Proof.
  unfold holds; intros H.
  assert (y - x <= next_up (fl (hi I - x))) by (apply up_ge; lra).
  assert (x - y <= next_up (fl (x - lo I))) by (apply up_ge; lra).
  pose proof (Rmax_l (next_up (fl (hi I - x))) (next_up (fl (x - lo I)))).
  pose proof (Rmax_r (next_up (fl (hi I - x))) (next_up (fl (x - lo I)))).
  unfold Rabs; destruct Rcase_abs; lra.
Qed.

(* norm_upper(IVec3): s2 = 0, then s2 = s2 + sqr(magnitude(c)) for each
   coordinate, then sqrt(s2), every step rounded up. *)
Definition mag I := Rmax (Rabs (lo I)) (Rabs (hi I)).
Definition norm_upper I0 I1 I2 :=
  let s0 := next_up (fl (0 + next_up (fl (mag I0 * mag I0)))) in
  let s1 := next_up (fl (s0 + next_up (fl (mag I1 * mag I1)))) in
  let s2 := next_up (fl (s1 + next_up (fl (mag I2 * mag I2)))) in
  next_up (fl (sqrt s2)).
(* covers optimized/gauss6/numeric/rounding.h "Upper norm_upper(const IVec3& v)" sha256:dca29cba64a96a85 *)
Theorem norm_upper_bounds I0 I1 I2 x0 x1 x2 :
  holds I0 x0 -> holds I1 x1 -> holds I2 x2 ->
  sqrt (x0 * x0 + x1 * x1 + x2 * x2) <= norm_upper I0 I1 I2.
Proof.
  intros H0 H1 H2. unfold norm_upper.
  pose proof (magnitude_bounds _ _ H0); pose proof (magnitude_bounds _ _ H1);
  pose proof (magnitude_bounds _ _ H2). fold (mag I0) (mag I1) (mag I2) in *.
  assert (E : forall x I, Rabs x <= mag I -> x * x <= next_up (fl (mag I * mag I))).
  { intros x I Hm. replace (x * x) with (Rabs x * Rabs x)
      by (rewrite <- Rabs_mult; apply Rabs_pos_eq; nra).
    apply upper_sqr; split; [apply Rabs_pos | exact Hm]. }
  pose proof (E _ _ H); pose proof (E _ _ H3); pose proof (E _ _ H4).
  apply up_ge, sqrt_le_1_alt.
  apply up_ge. eapply Rplus_le_compat; [|eassumption].
  apply up_ge. eapply Rplus_le_compat; [|eassumption].
  apply up_ge. lra.
Qed.

(* The theorems, each answered by tools/check_proofs.sh. *)
Print Assumptions next_up_ge.
Print Assumptions next_down_le.
Print Assumptions next_up_ge_fma.
Print Assumptions interval_add_encloses.
Print Assumptions interval_sub_encloses.
Print Assumptions interval_neg_encloses.
Print Assumptions interval_mul_encloses.
Print Assumptions interval_scale_encloses.
Print Assumptions interval_div_positive_encloses.
Print Assumptions interval_sqr_encloses.
Print Assumptions interval_hull_encloses.
Print Assumptions interval_point_encloses.
Print Assumptions round_up_bounds.
Print Assumptions round_down_bounds.
Print Assumptions upper_add.
Print Assumptions upper_sub.
Print Assumptions upper_mul.
Print Assumptions upper_scale.
Print Assumptions upper_div.
Print Assumptions upper_div_scalar.
Print Assumptions upper_sqr.
Print Assumptions upper_sqrt.
Print Assumptions upper_max.
Print Assumptions upper_min.
Print Assumptions lower_add.
Print Assumptions lower_sub.
Print Assumptions lower_div.
Print Assumptions lower_sqr.
Print Assumptions lower_sqrt.
Print Assumptions lower_gt_upper.
Print Assumptions interval_widen_encloses.
Print Assumptions magnitude_bounds.
Print Assumptions distance_from_bounds.
Print Assumptions norm_upper_bounds.
