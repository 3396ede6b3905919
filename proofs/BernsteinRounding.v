(* The rounding half of the Bernstein certificate of
   optimized/gauss6/numeric/bernstein.h, proved in Flocq (the model of
   Rounding.v: binary64, round to nearest even, finite results, gradual
   underflow, no fused multiply-add): the weights that BernsteinBasis computes
   in doubles, the sums S~_i and T~_i of positive_on, and the floor of
   LowerCoefficients::set, evaluated as the code evaluates them (the same
   operations in the same order, each rounded by `fl`), make positive_on's
   test S~_i - (kBernsteinRounding T~_i + floor) > 0 a proof that the exact
   S_i = sum_j lo_j w_ij is > 0 (bernstein_rounding); with
   bernstein_certificate (Bernstein.v) a proof that every polynomial of the
   coefficient box is > 0 on [u0, u1] (bernstein_certificate_doubles).
   Hypotheses: degree N <= 6 (the code's static_assert), 0 <= u0, u1 <= 1
   (valid_window in ccd.cpp checks 0 <= u_begin <= u_end <= 1 on every query,
   and the filter's sub-intervals are midpoint splits of that window). No
   hypothesis on the coefficients lo_j: any reals (the model has no overflow;
   an infinite or NaN sum makes the comparison false, bernstein.h).
   Proved: |S~_i - S_i| <= g(2N + 6) T_i + 2^-1024 (1 + sum_j |lo_j|),
   g(k) = (1 + u)^k - 1 <= 19 u at N = 6, which kBernsteinRounding = 32 u and
   kBernsteinUnderflow = 2^-1000 cover with their own roundings. *)

From Coq Require Import Reals Psatz.
From Flocq Require Import Core.
From Gauss6 Require Import Rounding Allowances Bernstein.
Open Scope R_scope.

(* allowance kBernsteinRounding = 0x1p-48 *)
Definition kBernsteinRounding := bpow radix2 (-48).
(* allowance kBernsteinUnderflow = 0x1p-1000 *)
Definition kBernsteinUnderflow := bpow radix2 (-1000).

Lemma u_bounds : 0 < u < / 1000000.
Proof. unfold u; lra. Qed.

(* ---- Relative error of k roundings: g k = (1 + u)^k - 1 ---- *)
Definition g (k : nat) : R := (1 + u) ^ k - 1.

Lemma g_nonneg k : 0 <= g k.
Proof.
  unfold g. pose proof u_bounds. assert (1 <= (1 + u) ^ k) by (apply pow_R1_Rle; lra). lra.
Qed.
Lemma g_le k k' : (k <= k')%nat -> g k <= g k'.
Proof.
  intros H. unfold g. pose proof u_bounds. assert ((1 + u) ^ k <= (1 + u) ^ k') by (apply Rle_pow; lra || lia). lra.
Qed.
Lemma g_add k1 k2 : g (k1 + k2) = g k1 + g k2 + g k1 * g k2.
Proof. unfold g. rewrite pow_add. ring. Qed.
Lemma g_S k : g (S k) = g k + u + u * g k.
Proof. unfold g. simpl. ring. Qed.
Lemma g_small k : INR k * u <= 1 -> g k <= INR k * u * (1 + INR k * u).
Proof.
  induction k as [|k IH]; intros Hk.
  - unfold g; simpl; lra.
  - rewrite g_S. rewrite S_INR in *. pose proof u_bounds. pose proof (pos_INR k).
    assert (H1 : INR k * u <= 1) by nra. specialize (IH H1).
    set (x := INR k * u) in *. assert (0 <= x) by (unfold x; nra).
    assert (u * g k <= u * (x * (1 + x))) by (apply Rmult_le_compat_l; lra).
    assert (u * (x * x) <= u * x) by (apply Rmult_le_compat_l; nra).
    assert (0 <= u * u) by nra.
    replace ((INR k + 1) * u * (1 + (INR k + 1) * u)) with ((x + u) * (1 + (x + u))) by (unfold x; ring).
    lra.
Qed.
Lemma g_18 : g 18 <= 19 * u.
Proof.
  pose proof u_bounds. assert (E : INR 18 = 18) by (simpl; lra).
  pose proof (g_small 18) as Hs. rewrite E in Hs. specialize (Hs ltac:(lra)). nra.
Qed.
Lemma g_le_half k : (k <= 18)%nat -> g k <= / 2.
Proof. intros Hk; pose proof (g_le _ _ Hk); pose proof g_18; pose proof u_bounds; lra. Qed.

(* ---- err k a x X B: X is within B in magnitude, and the computed x within
   g k B + a of it (a: the absolute errors of underflow) ---- *)
Definition err k a x X B := Rabs X <= B /\ Rabs (x - X) <= g k * B + a.

Lemma err_B k a x X B : err k a x X B -> 0 <= B.
Proof. intros [H _]. pose proof (Rabs_pos X). lra. Qed.
Lemma err_weaken k k' a a' x X B :
  (k <= k')%nat -> a <= a' -> err k a x X B -> err k' a' x X B.
Proof.
  intros Hk Ha [H1 H2]. split; [exact H1|]. pose proof (g_le _ _ Hk).
  assert (0 <= B) by (pose proof (Rabs_pos X); lra).
  assert (g k * B <= g k' * B) by (apply Rmult_le_compat_r; lra). lra.
Qed.
Lemma err_abs k a x X B : err k a x X B -> Rabs x <= (1 + g k) * B + a.
Proof.
  intros [H1 H2]. pose proof (Rabs_triang_inv x X). lra.
Qed.
Lemma err_fl k a x X B : 0 <= a -> err k a x X B -> err (S k) (2 * a + eta) (fl x) X B.
Proof.
  intros Ha E. pose proof (err_abs _ _ _ _ _ E) as Hx. destruct E as [H1 H2].
  split; [exact H1|]. pose proof (fl_err x) as Hf. pose proof u_bounds. pose proof (g_nonneg k).
  assert (0 <= B) by (pose proof (Rabs_pos X); lra).
  replace (fl x - X) with ((fl x - x) + (x - X)) by ring.
  eapply Rle_trans; [apply Rabs_triang|]. rewrite g_S.
  assert (u * Rabs x <= u * ((1 + g k) * B + a)) by (apply Rmult_le_compat_l; lra).
  assert (u * a <= a) by nra. nra.
Qed.
Lemma err_add k a1 a2 x X B1 y Y B2 :
  err k a1 x X B1 -> err k a2 y Y B2 -> err k (a1 + a2) (x + y) (X + Y) (B1 + B2).
Proof.
  intros [H1 H2] [H3 H4]. split.
  - eapply Rle_trans; [apply Rabs_triang | lra].
  - replace (x + y - (X + Y)) with ((x - X) + (y - Y)) by ring.
    eapply Rle_trans; [apply Rabs_triang | lra].
Qed.
Lemma err_scale k a c x X B : err k a x X B -> err k (Rabs c * a) (c * x) (c * X) (Rabs c * B).
Proof.
  intros [H1 H2]. pose proof (Rabs_pos c). split.
  - rewrite Rabs_mult. apply Rmult_le_compat_l; assumption.
  - replace (c * x - c * X) with (c * (x - X)) by ring. rewrite Rabs_mult.
    apply Rle_trans with (Rabs c * (g k * B + a)); [apply Rmult_le_compat_l; assumption | lra].
Qed.
(* A product of nonnegative reals X <= 1 and Y, each computed with its error. *)
Lemma err_mul k1 k2 a1 a2 x X y Y :
  0 <= a1 -> 0 <= a2 -> err k1 a1 x X X -> err k2 a2 y Y Y -> X <= 1 -> Rabs y <= 2 -> g k1 <= 1 ->
  err (k1 + k2) (2 * a1 + 2 * a2) (x * y) (X * Y) (X * Y).
Proof.
  intros Ha1 Ha2 Ex Ey HX Hy Hg. pose proof (err_abs _ _ _ _ _ Ey) as Hy'.
  destruct Ex as [X1 X2]; destruct Ey as [Y1 Y2].
  assert (0 <= X) by (pose proof (Rabs_pos X); lra). assert (0 <= Y) by (pose proof (Rabs_pos Y); lra).
  pose proof (g_nonneg k1); pose proof (g_nonneg k2). unfold err; rewrite g_add.
  split; [rewrite Rabs_pos_eq by nra; lra|].
  replace (x * y - X * Y) with ((x - X) * y + X * (y - Y)) by ring.
  eapply Rle_trans; [apply Rabs_triang|]. rewrite !Rabs_mult, (Rabs_pos_eq X) by lra.
  pose proof (Rabs_pos y); pose proof (Rabs_pos (x - X)); pose proof (Rabs_pos (y - Y)).
  assert (Rabs (x - X) * Rabs y <= (g k1 * X + a1) * Rabs y) by (apply Rmult_le_compat_r; lra).
  assert (g k1 * X * Rabs y <= g k1 * X * ((1 + g k2) * Y + a2)) by (apply Rmult_le_compat_l; nra).
  assert (a1 * Rabs y <= a1 * 2) by (apply Rmult_le_compat_l; lra).
  assert (g k1 * X * a2 <= a2) by (assert (g k1 * X <= 1) by nra; nra).
  assert (X * Rabs (y - Y) <= X * (g k2 * Y + a2)) by (apply Rmult_le_compat_l; lra).
  assert (X * a2 <= a2) by nra.
  nra.
Qed.

(* ---- The code, modelled ---- *)

(* BernsteinBasis(u0, u1): w[0][a] = w[0][a - 1] * u0 from w[0][0] = 1 (and
   row N with u1), each product rounded. *)
Fixpoint cpow (x : R) (a : nat) : R :=
  match a with O => 1 | S a' => fl (cpow x a' * x) end.

(* A loop s = acc; for m = 0 .. n - 1: s += f(b + m), each sum rounded; and
   its exact counterpart sum_{m < n} f (b + m). *)
Fixpoint fsum (acc : R) (f : nat -> R) (b n : nat) : R :=
  match n with O => acc | S n' => fsum (fl (acc + f b)) f (S b) n' end.
Fixpoint rsum (f : nat -> R) (b n : nat) : R :=
  match n with O => 0 | S n' => f b + rsum f (S b) n' end.

(* inner(), row 0 < i < N: e = 0; for b = max(0, j - (N - i)) .. min(i, j):
   e += (C(N - i, j - b) C(i, b)) (p0[j - b] p1[b]); w[i][j] = e / C(N, j).
   (Natural subtraction: j - (N - i) is max(0, j - (N - i)).) *)
Definition cterm N i j u0 u1 b :=
  fl (fl (C (N - i) (j - b) * C i b) * fl (cpow u0 (j - b) * cpow u1 b)).
Definition bmin N i j := (j - (N - i))%nat.
Definition bmax i j := Nat.min i j.
Definition cweight N i j u0 u1 :=
  if Nat.eqb i 0 then cpow u0 j
  else if Nat.eqb i N then cpow u1 j
  else fl (fsum 0 (cterm N i j u0 u1) (bmin N i j) (S (bmax i j) - bmin N i j) / C N j).

(* positive_on, row i: s = sum_j lo_j w[i][j] and t = sum_j |lo_j| w[i][j]
   (j = 0 .. N, from 0); LowerCoefficients::set: sum = Upper{1} + Upper{|lo_j|}
   for j = 0 .. N (each sum rounded up), floor = (Upper{kBernsteinUnderflow}
   * sum).v; the row passes when s > 0 and s - (kBernsteinRounding t + floor)
   > 0. *)
Definition s_c N (lo : nat -> R) u0 u1 i := fsum 0 (fun j => fl (lo j * cweight N i j u0 u1)) 0 (S N).
Definition t_c N (lo : nat -> R) u0 u1 i := fsum 0 (fun j => fl (Rabs (lo j) * cweight N i j u0 u1)) 0 (S N).
Fixpoint usum (acc : R) (f : nat -> R) (b n : nat) : R :=
  match n with O => acc | S n' => usum (next_up (fl (acc + f b))) f (S b) n' end.
Definition floor_c N (lo : nat -> R) := next_up (fl (kBernsteinUnderflow * usum 1 (fun j => Rabs (lo j)) 0 (S N))).
Definition passes N lo u0 u1 i :=
  0 < s_c N lo u0 u1 i /\
  0 < fl (s_c N lo u0 u1 i - fl (fl (kBernsteinRounding * t_c N lo u0 u1 i) + floor_c N lo)).

(* ---- Sums ---- *)
Lemma rsum_last f b n : rsum f b (S n) = rsum f b n + f (b + n)%nat.
Proof.
  revert b; induction n; intros b.
  - simpl. rewrite Nat.add_0_r; ring.
  - change (rsum f b (S (S n))) with (f b + rsum f (S b) (S n)). rewrite IHn.
    change (rsum f b (S n)) with (f b + rsum f (S b) n). replace (S b + n)%nat with (b + S n)%nat by lia. ring.
Qed.
Lemma sum_rsum n f : sum n f = rsum f 0 (S n).
Proof. induction n; [simpl; ring|]. rewrite rsum_last. simpl sum. rewrite IHn. reflexivity. Qed.
Lemma rsum_split f b n m : rsum f b (n + m) = rsum f b n + rsum f (b + n) m.
Proof.
  revert b; induction n; intros b; simpl.
  - rewrite Nat.add_0_r; ring.
  - rewrite IHn. replace (S b + n)%nat with (b + S n)%nat by lia. ring.
Qed.
Lemma rsum_zero f b n : (forall m, (m < n)%nat -> f (b + m)%nat = 0) -> rsum f b n = 0.
Proof.
  revert b; induction n; intros b H; simpl; [reflexivity|].
  rewrite IHn; [rewrite <- (Nat.add_0_r b), H by lia; ring|].
  intros m Hm. replace (S b + m)%nat with (b + S m)%nat by lia. apply H; lia.
Qed.
Lemma rsum_ext f f' b n : (forall m, (m < n)%nat -> f (b + m)%nat = f' (b + m)%nat) -> rsum f b n = rsum f' b n.
Proof.
  revert b; induction n; intros b H; simpl; [reflexivity|].
  rewrite <- (Nat.add_0_r b) at 1 3. rewrite H by lia. rewrite Nat.add_0_r. f_equal.
  apply IHn. intros m Hm. replace (S b + m)%nat with (b + S m)%nat by lia. apply H; lia.
Qed.
Lemma rsum_nonneg f b n : (forall m, (m < n)%nat -> 0 <= f (b + m)%nat) -> 0 <= rsum f b n.
Proof.
  revert b; induction n; intros b H; simpl; [lra|].
  assert (0 <= f b) by (rewrite <- (Nat.add_0_r b); apply H; lia).
  assert (0 <= rsum f (S b) n) by (apply IHn; intros m Hm; replace (S b + m)%nat with (b + S m)%nat by lia; apply H; lia).
  lra.
Qed.
(* A sum over 0..j whose terms vanish outside lo..hi is the sum over lo..hi. *)
Lemma sum_range f j l h :
  (l <= S h)%nat -> (h <= j)%nat -> (forall b, (b <= j)%nat -> (b < l \/ h < b)%nat -> f b = 0) ->
  sum j f = rsum f l (S h - l).
Proof.
  intros Hl Hh Hz. rewrite sum_rsum.
  replace (S j) with (l + ((S h - l) + (j - h)))%nat by lia.
  rewrite !rsum_split. rewrite (rsum_zero f 0 l), (rsum_zero f (0 + l + (S h - l)) (j - h)); [simpl; ring| |].
  - intros m Hm. apply Hz; lia.
  - intros m Hm. apply Hz; lia.
Qed.

(* The loop's error: terms within g k and their own a, the accumulator too. *)
Lemma fsum_err f Fx Bf af n : forall k acc ACC BA aa b,
  0 <= aa -> err k aa acc ACC BA ->
  (forall m, (m < n)%nat -> 0 <= af (b + m)%nat /\ err k (af (b + m)%nat) (f (b + m)%nat) (Fx (b + m)%nat) (Bf (b + m)%nat)) ->
  err (k + n) (2 ^ n * (aa + rsum af b n + INR n * eta)) (fsum acc f b n) (ACC + rsum Fx b n) (BA + rsum Bf b n).
Proof.
  induction n; intros k acc ACC BA aa b Haa E H; cbn [fsum rsum].
  - rewrite Nat.add_0_r. simpl. eapply err_weaken; [| |rewrite !Rplus_0_r; exact E]; [lia | lra].
  - destruct (H 0%nat ltac:(lia)) as [Ha0 E0]. rewrite Nat.add_0_r in Ha0, E0.
    pose proof eta_pos.
    assert (E1 : err (S k) (2 * (aa + af b) + eta) (fl (acc + f b)) (ACC + Fx b) (BA + Bf b))
      by (apply err_fl; [lra | apply err_add; assumption]).
    assert (HR : 0 <= rsum af (S b) n)
      by (apply rsum_nonneg; intros m Hm; replace (S b + m)%nat with (b + S m)%nat by lia;
          destruct (H (S m) ltac:(lia)); assumption).
    specialize (IHn (S k) (fl (acc + f b)) (ACC + Fx b) (BA + Bf b) (2 * (aa + af b) + eta) (S b) ltac:(lra) E1).
    assert (IH : err (S k + n) (2 ^ n * (2 * (aa + af b) + eta + rsum af (S b) n + INR n * eta))
                   (fsum (fl (acc + f b)) f (S b) n) (ACC + Fx b + rsum Fx (S b) n) (BA + Bf b + rsum Bf (S b) n)).
    { apply IHn. intros m Hm. replace (S b + m)%nat with (b + S m)%nat by lia.
      destruct (H (S m) ltac:(lia)) as [A B]. split; [exact A|]. eapply err_weaken; [| |exact B]; [lia | lra]. }
    replace (k + S n)%nat with (S k + n)%nat by lia.
    rewrite <- !Rplus_assoc. refine (err_weaken _ _ _ _ _ _ _ (le_n _) _ IH).
    rewrite S_INR, <- tech_pow_Rmult. pose proof (pow_le 2 n ltac:(lra)). pose proof (pos_INR n).
    set (X := 2 ^ n) in *.
    assert (X * (2 * (aa + af b) + eta + rsum af (S b) n + INR n * eta)
            <= X * (2 * (aa + (af b + rsum af (S b) n) + (INR n + 1) * eta)))
      by (apply Rmult_le_compat_l; [lra|]; assert (0 <= INR n * eta) by (apply Rmult_le_pos; lra); lra).
    lra.
Qed.

Lemma fsum_nonneg f n : forall acc b, 0 <= acc -> (forall m, (m < n)%nat -> 0 <= f (b + m)%nat) -> 0 <= fsum acc f b n.
Proof.
  induction n; intros acc b Ha H; simpl; [exact Ha|].
  apply IHn.
  - apply fl_nonneg. assert (0 <= f b) by (rewrite <- (Nat.add_0_r b); apply H; lia). lra.
  - intros m Hm. replace (S b + m)%nat with (b + S m)%nat by lia. apply H; lia.
Qed.

(* ---- The weights ---- *)
Lemma pow_le_1 x a : 0 <= x <= 1 -> x ^ a <= 1.
Proof. intros Hx. induction a; simpl; [lra|]. pose proof (pow_le x a ltac:(lra)). nra. Qed.

Lemma cpow_nonneg x a : 0 <= x -> 0 <= cpow x a.
Proof. intros Hx; induction a; simpl; [lra | apply fl_nonneg; nra]. Qed.

Lemma cpow_err x a : 0 <= x <= 1 -> (a <= 18)%nat -> err a (5 ^ a * eta) (cpow x a) (x ^ a) (x ^ a).
Proof.
  intros Hx. pose proof eta_pos. induction a; intros Ha.
  - simpl. split; [rewrite Rabs_R1; lra|]. unfold Rminus; rewrite Rplus_opp_r, Rabs_R0.
    pose proof (g_nonneg 0). lra.
  - simpl cpow. assert (Ex : err 0 0 x x x)
      by (split; [rewrite Rabs_pos_eq by lra; lra | unfold Rminus; rewrite Rplus_opp_r, Rabs_R0; pose proof (g_nonneg 0); nra]).
    assert (Hp : 0 <= 5 ^ a) by (apply pow_le; lra).
    assert (Xa : x ^ a <= 1) by (apply pow_le_1; lra).
    pose proof (err_mul a 0 (5 ^ a * eta) 0 (cpow x a) (x ^ a) x x ltac:(nra) ltac:(lra) (IHa ltac:(lia)) Ex Xa
                  ltac:(rewrite Rabs_pos_eq by lra; lra) ltac:(pose proof (g_le_half a ltac:(lia)); lra)) as M.
    apply err_fl in M; [|nra]. rewrite Nat.add_0_r in M.
    replace (x ^ S a) with (x ^ a * x) by (simpl; ring).
    refine (err_weaken _ _ _ _ _ _ _ (le_n _) _ M). simpl.
    assert (1 <= 5 ^ a) by (apply pow_R1_Rle; lra).
    assert (eta <= 5 ^ a * eta) by (rewrite <- (Rmult_1_l eta) at 1; apply Rmult_le_compat_r; lra).
    lra.
Qed.

Lemma cpow_abs x a : 0 <= x <= 1 -> (a <= 18)%nat -> Rabs (cpow x a) <= 2.
Proof.
  intros Hx Ha. pose proof (err_abs _ _ _ _ _ (cpow_err x a Hx Ha)). pose proof (g_le_half a Ha).
  assert (x ^ a <= 1) by (apply pow_le_1; lra). assert (0 <= x ^ a) by (apply pow_le; lra).
  assert (5 ^ a <= 5 ^ 18) by (apply Rle_pow; [lra | lia]).
  assert (5 ^ a * eta <= 5 ^ 18 * eta) by (apply Rmult_le_compat_r; [pose proof eta_pos; lra | assumption]).
  assert (5 ^ 18 * eta <= / 2) by (unfold eta; simpl; lra).
  assert (g a * x ^ a <= / 2) by (pose proof (g_nonneg a); nra). nra.
Qed.

(* C(n, k) <= 2^n, and small products of them are doubles. *)
Lemma binom_le n k : (binom n k <= 2 ^ n)%nat.
Proof.
  revert k; induction n as [|n IHn]; intros k.
  - destruct k; simpl; lia.
  - destruct k as [|k]; simpl.
    + pose proof (IHn 0%nat) as A. destruct n; simpl in A |- *; lia.
    + pose proof (IHn k); pose proof (IHn (S k)); lia.
Qed.
Lemma F_nat m : (m <= 4096)%nat -> F (INR m).
Proof.
  intros Hm. apply generic_format_FLT.
  apply (FLT_spec _ _ _ _ (Float radix2 (Z.of_nat m) 0)).
  - unfold F2R; simpl. rewrite INR_IZR_INZ. ring.
  - simpl. lia.
  - simpl. lia.
Qed.
Lemma fl_binom2 n k n' k' : (n <= 6)%nat -> (n' <= 6)%nat ->
  fl (C n k * C n' k') = C n k * C n' k' /\ C n k * C n' k' <= 4096.
Proof.
  intros H H'. unfold C. rewrite <- mult_INR.
  assert (Hb : (binom n k * binom n' k' <= 4096)%nat).
  { pose proof (binom_le n k); pose proof (binom_le n' k').
    assert (2 ^ n <= 64)%nat by (replace 64%nat with (2 ^ 6)%nat by reflexivity; apply Nat.pow_le_mono_r; lia).
    assert (2 ^ n' <= 64)%nat by (replace 64%nat with (2 ^ 6)%nat by reflexivity; apply Nat.pow_le_mono_r; lia).
    nia. }
  split; [apply fl_F, F_nat, Hb|]. apply le_INR in Hb. simpl in Hb. lra.
Qed.

Definition E_w := bpow radix2 (-1032).   (* the weights' absolute error, 2^43 eta *)
Lemma E_w_eta : E_w = 8796093022208 * eta.
Proof. unfold E_w, eta. replace (-1032)%Z with (43 + -1075)%Z by lia. rewrite bpow_plus. reflexivity. Qed.

(* One term of inner()'s sum: within g (j + 2) and 2^31 eta. *)
Lemma cterm_err N i j u0 u1 b :
  (N <= 6)%nat -> (i <= N)%nat -> (j <= N)%nat -> (b <= j)%nat -> 0 <= u0 <= 1 -> 0 <= u1 <= 1 ->
  err (S (S j)) (bpow radix2 31 * eta) (cterm N i j u0 u1 b)
    (C (N - i) (j - b) * C i b * (u0 ^ (j - b) * u1 ^ b)) (C (N - i) (j - b) * C i b * (u0 ^ (j - b) * u1 ^ b)).
Proof.
  intros HN Hi Hj Hb H0 H1. pose proof eta_pos. unfold cterm.
  destruct (fl_binom2 (N - i) (j - b) i b ltac:(lia) ltac:(lia)) as [Ec Hc]. rewrite Ec.
  set (c := C (N - i) (j - b) * C i b) in *.
  assert (Hc0 : 0 <= c) by (unfold c; pose proof (C_nonneg (N - i) (j - b)); pose proof (C_nonneg i b); nra).
  pose proof (cpow_err u0 (j - b) H0 ltac:(lia)) as A. pose proof (cpow_err u1 b H1 ltac:(lia)) as B.
  assert (0 <= 5 ^ (j - b)) by (apply pow_le; lra). assert (0 <= 5 ^ b) by (apply pow_le; lra).
  pose proof (err_mul _ _ (5 ^ (j - b) * eta) (5 ^ b * eta) _ _ _ _ ltac:(nra) ltac:(nra) A B ltac:(apply pow_le_1; lra)
                (cpow_abs u1 b H1 ltac:(lia)) ltac:(pose proof (g_le_half (j - b) ltac:(lia)); lra)) as M.
  apply err_fl in M; [|nra]. replace (j - b + b)%nat with j in M by lia.
  assert (0 <= 5 ^ (j - b) * eta) by (apply Rmult_le_pos; lra).
  assert (0 <= 5 ^ b * eta) by (apply Rmult_le_pos; lra).
  apply (err_scale _ _ c) in M. rewrite (Rabs_pos_eq c Hc0) in M. apply err_fl in M; [|apply Rmult_le_pos; lra].
  refine (err_weaken _ _ _ _ _ _ _ (le_n _) _ M).
  assert (5 ^ (j - b) <= 5 ^ 6) by (apply Rle_pow; [lra | lia]).
  assert (5 ^ b <= 5 ^ 6) by (apply Rle_pow; [lra | lia]).
  assert (c * (2 * (2 * (5 ^ (j - b) * eta) + 2 * (5 ^ b * eta)) + eta) <= 4096 * (125001 * eta))
    by (apply Rmult_le_compat; try nra; simpl in *; nra).
  simpl. lra.
Qed.

Lemma binom_zero n k : (n < k)%nat -> binom n k = 0%nat.
Proof.
  revert k; induction n as [|n IHn]; intros k Hk; destruct k as [|k]; simpl; try lia; try reflexivity.
  rewrite !IHn by lia. reflexivity.
Qed.
Lemma binom_pos n k : (k <= n)%nat -> (1 <= binom n k)%nat.
Proof.
  revert k; induction n as [|n IHn]; intros k Hk; destruct k as [|k]; simpl; try lia.
  specialize (IHn k ltac:(lia)). lia.
Qed.
Lemma rsum_const c b n : rsum (fun _ => c) b n = INR n * c.
Proof. revert b; induction n; intros b; cbn [rsum]; [simpl; ring|]. rewrite IHn, S_INR. ring. Qed.

(* Every weight BernsteinBasis computes is within g (N + 4) and E_w of the
   exact weight (Bernstein.v's weight). *)
Lemma cweight_err N i j u0 u1 :
  degree_ok N -> (i <= N)%nat -> (j <= N)%nat -> 0 <= u0 <= 1 -> 0 <= u1 <= 1 ->
  err (N + 4) E_w (cweight N i j u0 u1) (weight N i j u0 u1) (weight N i j u0 u1).
Proof.
  intros HN Hi Hj H0 H1. pose proof eta_pos. pose proof HN as HN'. unfold degree_ok in HN'.
  destruct (bernstein_end_rows N u0 u1 j HN Hj) as [R0 RN].
  assert (Hp : forall x, 0 <= x <= 1 -> err (N + 4) E_w (cpow x j) (x ^ j) (x ^ j)).
  { intros x Hx. eapply err_weaken; [| |apply cpow_err; [exact Hx | lia]]; [lia|].
    assert (5 ^ j <= 5 ^ 6) by (apply Rle_pow; [lra | lia]).
    rewrite E_w_eta. apply Rmult_le_compat_r; [lra|]. simpl in *; lra. }
  unfold cweight. destruct (Nat.eqb_spec i 0) as [->|Hi0]; [rewrite R0; apply Hp, H0|].
  destruct (Nat.eqb_spec i N) as [->|HiN]; [rewrite RN; apply Hp, H1|].
  set (l := bmin N i j). set (n := (S (bmax i j) - l)%nat).
  assert (Hn : (n <= N - j + 1)%nat) by (unfold n, l, bmin, bmax; lia).
  set (f := fun b => C (N - i) (j - b) * C i b * (u0 ^ (j - b) * u1 ^ b)).
  assert (Hsum : sum j (fun b => C (N - i) (j - b) * C i b * u0 ^ (j - b) * u1 ^ b) = rsum f l n).
  { rewrite (sum_range _ j l (bmax i j)); [| unfold l, bmin, bmax; lia | unfold bmax; lia |].
    - apply rsum_ext. intros m _. unfold f. ring.
    - intros b Hb [Hlt|Hgt]; unfold C.
      + rewrite (binom_zero (N - i) (j - b)) by (unfold l, bmin in Hlt; lia). simpl; ring.
      + rewrite (binom_zero i b) by (unfold bmax in Hgt; lia). simpl; ring. }
  assert (E0 : err (S (S j)) 0 0 0 0) by (split; rewrite ?Rminus_0_r, Rabs_R0; [lra | pose proof (g_nonneg (S (S j))); lra]).
  pose proof (fsum_err (cterm N i j u0 u1) f f (fun _ => bpow radix2 31 * eta) n (S (S j)) 0 0 0 0 l
                ltac:(lra) E0) as S1.
  assert (Hb31 : 0 <= bpow radix2 31) by apply bpow_ge_0.
  specialize (S1 ltac:(intros m Hm; split; [nra | apply cterm_err; [lia | lia | lia | | lra | lra];
    unfold n, l, bmin, bmax in *; lia])).
  rewrite rsum_const, !Rplus_0_l in S1.
  assert (HC : 1 <= C N j) by (unfold C; apply (le_INR 1); apply binom_pos; lia).
  assert (HiC : 0 < / C N j <= 1) by (split; [apply Rinv_0_lt_compat; lra | rewrite <- Rinv_1; apply Rinv_le_contravar; lra]).
  apply (err_scale _ _ (/ C N j)) in S1. rewrite Rabs_pos_eq in S1 by lra.
  apply err_fl in S1; [|pose proof (pos_INR n); apply Rmult_le_pos; [lra|]; apply Rmult_le_pos; [apply pow_le; lra|];
    apply Rplus_le_le_0_compat; apply Rmult_le_pos; try apply pos_INR; nra].
  unfold weight. rewrite Hsum. unfold Rdiv. rewrite (Rmult_comm (rsum f l n) (/ C N j)), (Rmult_comm (fsum 0 (cterm N i j u0 u1) l n) (/ C N j)).
  eapply (err_weaken (S (S (S j) + n)) (N + 4)); [unfold n, l, bmin, bmax in *; lia| |exact S1].
  assert (H2n : 2 ^ n <= 2 ^ 7) by (apply Rle_pow; [lra | lia]).
  assert (HnR : INR n <= 7) by (replace 7 with (INR 7) by (simpl; lra); apply le_INR; lia). pose proof (pos_INR n).
  assert (0 <= bpow radix2 31 * eta) by (apply Rmult_le_pos; lra).
  assert (INR n * (bpow radix2 31 * eta) <= 7 * (bpow radix2 31 * eta)) by (apply Rmult_le_compat_r; lra).
  assert (INR n * eta <= 7 * eta) by (apply Rmult_le_compat_r; lra).
  assert (0 <= INR n * (bpow radix2 31 * eta)) by (apply Rmult_le_pos; lra).
  assert (0 <= INR n * eta) by (apply Rmult_le_pos; lra).
  set (X := INR n * (bpow radix2 31 * eta) + INR n * eta) in *.
  assert (K : 2 ^ n * X <= 2 ^ 7 * (7 * (bpow radix2 31 * eta) + 7 * eta))
    by (apply Rmult_le_compat; [apply pow_le; lra | unfold X; lra | lra | unfold X; lra]).
  assert (0 <= 2 ^ n * X) by (apply Rmult_le_pos; [apply pow_le; lra | unfold X; lra]).
  assert (K' : / C N j * (2 ^ n * X) <= 2 ^ n * X)
    by (rewrite <- (Rmult_1_l (2 ^ n * X)) at 2; apply Rmult_le_compat_r; lra).
  rewrite E_w_eta. simpl in K |- *. lra.
Qed.

Lemma cweight_nonneg N i j u0 u1 : 0 <= u0 -> 0 <= u1 -> 0 <= cweight N i j u0 u1.
Proof.
  intros H0 H1. unfold cweight.
  destruct (Nat.eqb i 0); [apply cpow_nonneg, H0|]. destruct (Nat.eqb i N); [apply cpow_nonneg, H1|].
  apply fl_nonneg. unfold Rdiv. apply Rmult_le_pos.
  - apply fsum_nonneg; [lra|]. intros m _. unfold cterm. apply fl_nonneg, Rmult_le_pos; apply fl_nonneg.
    + apply Rmult_le_pos; apply C_nonneg.
    + apply Rmult_le_pos; apply cpow_nonneg; assumption.
  - destruct (Req_dec (C N j) 0) as [->|Hc]; [rewrite Rinv_0; lra|].
    apply Rlt_le, Rinv_0_lt_compat. pose proof (C_nonneg N j). lra.
Qed.

Lemma rsum_lin a c f b n : rsum (fun j => a * f j + c) b n = a * rsum f b n + INR n * c.
Proof. revert b; induction n; intros b; cbn [rsum]; [simpl; ring|]. rewrite IHn, S_INR. ring. Qed.

Definition E_s := bpow radix2 (-1024).   (* a row's absolute error, per 1 + sum_j |c_j| *)

(* A row's sum sum_j c_j w_ij, computed as positive_on computes s (c = lo)
   and t (c = |lo|): within g (2N + 6) T + E_s (1 + sum_j |c_j|) of the exact
   one, T = sum_j |c_j| w_ij. *)
Lemma row_err N (c : nat -> R) u0 u1 i :
  degree_ok N -> (i <= N)%nat -> 0 <= u0 <= 1 -> 0 <= u1 <= 1 ->
  err (2 * N + 6) (E_s * (1 + sum N (fun j => Rabs (c j))))
    (fsum 0 (fun j => fl (c j * cweight N i j u0 u1)) 0 (S N))
    (sum N (fun j => c j * weight N i j u0 u1)) (sum N (fun j => Rabs (c j) * weight N i j u0 u1)).
Proof.
  intros HN Hi H0 H1. pose proof eta_pos. pose proof HN as HN'. unfold degree_ok in HN'.
  assert (HE : 0 <= E_w) by apply bpow_ge_0.
  assert (E0 : err (N + 5) 0 0 0 0) by (split; rewrite ?Rminus_0_r, Rabs_R0; [lra | pose proof (g_nonneg (N + 5)); lra]).
  pose proof (fsum_err (fun j => fl (c j * cweight N i j u0 u1)) (fun j => c j * weight N i j u0 u1)
                (fun j => Rabs (c j) * weight N i j u0 u1) (fun j => 2 * (Rabs (c j) * E_w) + eta) (S N)
                (N + 5) 0 0 0 0 0 ltac:(lra) E0) as S1.
  specialize (S1 ltac:(intros m Hm; simpl; split; [pose proof (Rabs_pos (c m)); nra|];
    replace (N + 5)%nat with (S (N + 4)) by lia; apply err_fl; [pose proof (Rabs_pos (c m)); nra|];
    apply err_scale, cweight_err; (assumption || lia))).
  rewrite !Rplus_0_l, <- !sum_rsum in S1.
  assert (Haf : forall M, sum M (fun j => 2 * (Rabs (c j) * E_w) + eta)
                          = 2 * (sum M (fun j => Rabs (c j)) * E_w) + INR (S M) * eta).
  { clear. induction M; [simpl; ring|]. cbn [sum]. rewrite IHM, (S_INR (S M)). ring. }
  rewrite Haf in S1.
  eapply (err_weaken (N + 5 + S N) (2 * N + 6)); [lia| |exact S1].
  set (L := sum N (fun j => Rabs (c j))).
  assert (HL : 0 <= L) by (apply sum_nonneg; intros; apply Rabs_pos).
  assert (H2 : 2 ^ S N <= 2 ^ 7) by (apply Rle_pow; [lra | lia]).
  assert (HnR : INR (S N) <= 7) by (replace 7 with (INR 7) by (simpl; lra); apply le_INR; lia). pose proof (pos_INR (S N)).
  assert (K : 2 ^ S N * (2 * (L * E_w) + INR (S N) * eta + INR (S N) * eta) <= 2 ^ 7 * (2 * (L * E_w) + 7 * eta + 7 * eta)).
  { assert (0 <= L * E_w) by (apply Rmult_le_pos; [lra | apply bpow_ge_0]).
    assert (INR (S N) * eta <= 7 * eta) by (apply Rmult_le_compat_r; lra).
    assert (0 <= INR (S N) * eta) by (apply Rmult_le_pos; lra).
    apply Rmult_le_compat; [apply pow_le; lra | lra | exact H2 | lra]. }
  assert (HEs : E_s = 256 * E_w) by (unfold E_s, E_w; replace (-1024)%Z with (8 + -1032)%Z by lia; rewrite bpow_plus; simpl; lra).
  assert (0 <= L * eta) by (apply Rmult_le_pos; lra).
  rewrite HEs. rewrite E_w_eta in *. replace (2 ^ 7) with 128 in K by (simpl; lra). lra.
Qed.

Lemma usum_ge f n : forall acc b, acc + rsum f b n <= usum acc f b n.
Proof.
  induction n; intros acc b; simpl; [lra|].
  eapply Rle_trans; [|apply IHn]. assert (acc + f b <= next_up (fl (acc + f b))) by (apply up_ge; lra). lra.
Qed.

Lemma fl_0 : fl 0 = 0.
Proof. apply fl_F, generic_format_0. Qed.

(* Theorem bernstein_rounding (bernstein.h, positive_on, in doubles): a row
   that passes positive_on's test, computed in doubles as the code computes
   it, has an exact S_i = sum_j lo_j w_ij > 0. *)
(* covers optimized/gauss6/numeric/bernstein.h "BernsteinBasis(double u0, double u1)" sha256:b969cc1766b1bb97 *)
(* covers optimized/gauss6/numeric/bernstein.h "void inner() const" sha256:c8219bc0710128e9 *)
(* covers optimized/gauss6/numeric/bernstein.h "void set(const Interval (&k)[N + 1])" sha256:f2446e13a9f9d188 *)
(* covers optimized/gauss6/numeric/bernstein.h "bool positive_on(const LowerCoefficients<N>& c, const BernsteinBasis<N>& basis)" sha256:50828dd06bd8f6db *)
Theorem bernstein_rounding N lo u0 u1 i :
  degree_ok N -> 0 <= u0 <= 1 -> 0 <= u1 <= 1 -> (i <= N)%nat -> passes N lo u0 u1 i ->
  0 < sum N (fun j => lo j * weight N i j u0 u1).
Proof.
  intros HN H0 H1 Hi [_ Hpass]. pose proof eta_pos. pose proof u_bounds. pose proof HN as HN'. unfold degree_ok in HN'.
  set (L := sum N (fun j => Rabs (lo j))).
  assert (HL : 0 <= L) by (apply sum_nonneg; intros; apply Rabs_pos).
  set (Us := E_s * (1 + L)).
  assert (HEs : 0 < E_s) by apply bpow_gt_0. assert (HUs : E_s <= Us) by (unfold Us; nra).
  pose proof (row_err N lo u0 u1 i HN Hi H0 H1) as Es. fold L Us in Es. fold (s_c N lo u0 u1 i) in Es.
  pose proof (row_err N (fun j => Rabs (lo j)) u0 u1 i HN Hi H0 H1) as Et. cbv beta in Et.
  rewrite (sum_ext N (fun j => Rabs (Rabs (lo j))) (fun j => Rabs (lo j))) in Et by (intros; apply Rabs_Rabsolu).
  rewrite (sum_ext N (fun j => Rabs (Rabs (lo j)) * weight N i j u0 u1) (fun j => Rabs (lo j) * weight N i j u0 u1)) in Et
    by (intros; rewrite Rabs_Rabsolu; reflexivity).
  fold L Us in Et. fold (t_c N lo u0 u1 i) in Et.
  set (Si := sum N (fun j => lo j * weight N i j u0 u1)) in *.
  set (T := sum N (fun j => Rabs (lo j) * weight N i j u0 u1)) in *.
  set (s := s_c N lo u0 u1 i) in *. set (t := t_c N lo u0 u1 i) in *.
  assert (HT : 0 <= T) by (eapply err_B; exact Et).
  assert (Hg : g (2 * N + 6) * T <= 19 * u * T)
    by (apply Rmult_le_compat_r; [lra | apply Rle_trans with (g 18); [apply g_le; lia | apply g_18]]).
  destruct Es as [_ Es]. destruct Et as [_ Et].
  assert (Hs : s - Si <= 19 * u * T + Us) by (pose proof (Rle_abs (s - Si)); lra).
  assert (Ht : T - t <= 19 * u * T + Us) by (pose proof (Rle_abs (t - T)); rewrite Rabs_minus_sym in Et; pose proof (Rle_abs (T - t)); lra).
  assert (Ht0 : 0 <= t).
  { unfold t, t_c. apply fsum_nonneg; [lra|]. intros m _. apply fl_nonneg, Rmult_le_pos; [apply Rabs_pos | apply cweight_nonneg; lra]. }
  (* the floor: at least kBernsteinUnderflow (1 + L) = 2^24 Us *)
  assert (Hfl : bpow radix2 24 * Us <= floor_c N lo).
  { unfold floor_c. apply up_ge. pose proof (usum_ge (fun j => Rabs (lo j)) (S N) 1 0) as U.
    rewrite <- sum_rsum in U. fold L in U.
    assert (HU : kBernsteinUnderflow = bpow radix2 24 * E_s)
      by (unfold kBernsteinUnderflow, E_s; rewrite <- bpow_plus; f_equal).
    unfold Us. rewrite <- Rmult_assoc, <- HU. apply Rmult_le_compat_l; [apply bpow_ge_0 | lra]. }
  set (fc := floor_c N lo) in *.
  assert (HkR : kBernsteinRounding = 32 * u) by (rewrite bpow_m53; unfold kBernsteinRounding;
    replace (-48)%Z with (5 + -53)%Z by lia; rewrite bpow_plus; simpl; lra).
  set (P := kBernsteinRounding * t).
  assert (HP0 : 0 <= P) by (unfold P; rewrite HkR; nra).
  assert (HP : 32 * u * (T - (19 * u * T + Us)) <= P) by (unfold P; rewrite HkR; apply Rmult_le_compat_l; lra).
  pose proof (fl_lower P HP0) as Z1. set (z1 := fl P) in *.
  assert (Hz0 : 0 <= z1) by (apply fl_nonneg; lra).
  assert (H24 : 0 < bpow radix2 24) by apply bpow_gt_0.
  assert (Hfc0 : 0 <= fc) by nra.
  pose proof (fl_lower (z1 + fc) ltac:(lra)) as Y. set (y := fl (z1 + fc)) in *.
  assert (Hsy : y < s).
  { destruct (Rlt_or_le y s) as [|Hle]; [assumption|].
    exfalso. assert (fl (s - y) <= 0) by (rewrite <- fl_0; apply fl_le; lra). unfold y, z1, P, s in *. lra. }
  assert (Q1 : (1 - u) * P >= 99 / 100 * P) by nra.
  assert (Q2 : (1 - u) * (z1 + fc) >= 99 / 100 * (z1 + fc)) by nra.
  assert (Q3 : u * (u * T) <= / 1000000 * (u * T)) by (apply Rmult_le_compat_r; nra).
  assert (Q4 : u * Us <= / 1000000 * Us) by (apply Rmult_le_compat_r; lra).
  assert (Q5 : 0 <= u * T) by nra.
  assert (Q6 : eta <= E_s) by (unfold eta, E_s; apply bpow_le; lia).
  assert (Q7 : 1000000 <= bpow radix2 24) by (simpl; lra).
  assert (Q8 : 1000000 * Us <= bpow radix2 24 * Us) by (apply Rmult_le_compat_r; lra).
  nra.
Qed.

(* Theorem bernstein_certificate_doubles: positive_on returning true (every
   row passes, rows 0 and N first, then the inner rows) proves every
   polynomial with coefficients k_j >= lo_j > 0 on [u0, u1]. *)
(* covers optimized/gauss6/numeric/bernstein.h "bool positive_on(const LowerCoefficients<N>& c, const BernsteinBasis<N>& basis)" sha256:50828dd06bd8f6db *)
Theorem bernstein_certificate_doubles N k lo u0 u1 u :
  degree_ok N -> 0 <= u0 <= u1 -> u1 <= 1 -> (forall j, (j <= N)%nat -> lo j <= k j) ->
  (forall i, (i <= N)%nat -> passes N lo u0 u1 i) -> u0 <= u <= u1 -> 0 < poly N k u.
Proof.
  intros HN Hu H1 Hk Hp Hin. apply (bernstein_certificate N k lo u0 u1 u HN Hu Hk); [|exact Hin].
  intros i Hi. apply (bernstein_rounding N lo u0 u1 i HN); [lra | lra | exact Hi | apply Hp, Hi].
Qed.

(* The theorems, each answered by tools/check_proofs.sh. *)
Print Assumptions bernstein_rounding.
Print Assumptions bernstein_certificate_doubles.
