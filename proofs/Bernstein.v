(* The Bernstein positivity certificate of optimized/gauss6/numeric/bernstein.h,
   over the reals: for degree N <= 6 (the code's static_assert) and
   0 <= u0 <= u1 <= 1, the weights w_ij that BernsteinBasis computes (in exact
   arithmetic here) turn the power coefficients k_j of a polynomial into its
   Bernstein coefficients b_i = sum_j k_j w_ij on [u0, u1]; the weights are
   nonnegative, so over coefficients k_j >= lo_j every b_i is at least
   S_i = sum_j lo_j w_ij; and a polynomial whose Bernstein coefficients are all
   positive is positive on [u0, u1]. Together (bernstein_certificate): every
   S_i > 0 proves the polynomial > 0 on [u0, u1] for every k in the box. What
   the doubles add (kBernsteinRounding) is a separate statement, not yet
   proved here. *)

From Coq Require Import Reals Psatz.
Open Scope R_scope.

(* C(n, k) by Pascal's rule (the code's kBinomial table). *)
Fixpoint binom (n k : nat) : nat :=
  match n, k with
  | _, O => 1%nat
  | O, S _ => 0%nat
  | S n', S k' => (binom n' k' + binom n' (S k'))%nat
  end.
Definition C (n k : nat) : R := INR (binom n k).

(* sum_{i=0}^{n} f i *)
Fixpoint sum (n : nat) (f : nat -> R) : R :=
  match n with O => f O | S m => sum m f + f n end.

Definition bern (N i : nat) (t : R) : R := C N i * t ^ i * (1 - t) ^ (N - i).

(* BernsteinBasis: w[0][a] = u0^a, w[N][a] = u1^a (the powers), and the inner
   rows w[i][j] = (sum_{b = max(0, j-(N-i))}^{min(i, j)} C(N-i, j-b) C(i, b)
   u0^(j-b) u1^b) / C(N, j); the terms outside that range have a factor
   C(n, k) = 0 with k > n, so the sum may run over b = 0..j. Rows 0 and N are
   the same formula's ends. *)
Definition weight (N i j : nat) (u0 u1 : R) : R :=
  sum j (fun b => C (N - i) (j - b) * C i b * u0 ^ (j - b) * u1 ^ b) / C N j.

(* The polynomial and its Bernstein form. *)
Definition poly (N : nat) (k : nat -> R) (u : R) : R := sum N (fun j => k j * u ^ j).
Definition bcoef (N : nat) (k : nat -> R) (u0 u1 : R) (i : nat) : R :=
  sum N (fun j => k j * weight N i j u0 u1).
Definition bform (N : nat) (b : nat -> R) (t : R) : R := sum N (fun i => b i * bern N i t).

Lemma sum_ext n f g : (forall i, (i <= n)%nat -> f i = g i) -> sum n f = sum n g.
Proof.
  induction n; simpl; intros H; [apply H; lia|].
  rewrite IHn by (intros; apply H; lia). rewrite H by lia. reflexivity.
Qed.
Lemma sum_le n f g : (forall i, (i <= n)%nat -> f i <= g i) -> sum n f <= sum n g.
Proof.
  induction n; simpl; intros H; [apply H; lia|].
  apply Rplus_le_compat; [apply IHn; intros; apply H; lia | apply H; lia].
Qed.
Lemma sum_nonneg n f : (forall i, (i <= n)%nat -> 0 <= f i) -> 0 <= sum n f.
Proof.
  induction n; simpl; intros H; [apply H; lia|].
  assert (0 <= sum n f) by (apply IHn; intros; apply H; lia).
  assert (0 <= f (S n)) by (apply H; lia). lra.
Qed.
Lemma sum_pos n f :
  (forall i, (i <= n)%nat -> 0 <= f i) -> (exists i, (i <= n)%nat /\ 0 < f i) -> 0 < sum n f.
Proof.
  induction n; simpl; intros H [i [Hi Hp]].
  - replace i with O in Hp by lia. exact Hp.
  - destruct (Nat.eq_dec i (S n)) as [->|Hne].
    + assert (0 <= sum n f) by (apply sum_nonneg; intros; apply H; lia). lra.
    + assert (0 < sum n f) by (apply IHn; [intros; apply H; lia | exists i; split; [lia | exact Hp]]).
      assert (0 <= f (S n)) by (apply H; lia). lra.
Qed.
Lemma sum_scale n c f : sum n (fun i => c * f i) = c * sum n f.
Proof. induction n; simpl; [reflexivity | rewrite IHn; ring]. Qed.

Lemma C_nonneg n k : 0 <= C n k.
Proof. apply pos_INR. Qed.

Lemma bern_nonneg N i t : 0 <= t <= 1 -> 0 <= bern N i t.
Proof.
  intros Ht. unfold bern. apply Rmult_le_pos; [apply Rmult_le_pos; [apply C_nonneg | apply pow_le; lra] | apply pow_le; lra].
Qed.

(* Theorem bernstein_positive: all Bernstein coefficients positive implies the
   Bernstein form positive on [0, 1] (any degree N; the basis sums to 1,
   which bern_partition states for the code's degrees). *)
Theorem bernstein_positive N b t :
  0 <= t <= 1 -> sum N (fun i => bern N i t) = 1 ->
  (forall i, (i <= N)%nat -> 0 < b i) -> 0 < bform N b t.
Proof.
  intros Ht H1 Hb. unfold bform. apply sum_pos.
  - intros i Hi. apply Rmult_le_pos; [apply Rlt_le, Hb, Hi | apply bern_nonneg, Ht].
  - (* some basis polynomial is positive, since they sum to 1 *)
    destruct (Classical_Prop.classic (exists i, (i <= N)%nat /\ 0 < bern N i t)) as [[i [Hi Hp]]|Hn].
    + exists i; split; [exact Hi|]. apply Rmult_lt_0_compat; [apply Hb, Hi | exact Hp].
    + exfalso. assert (sum N (fun i => bern N i t) <= sum N (fun _ => 0)).
      { apply sum_le. intros i Hi. apply Rnot_lt_le. intros Hp. apply Hn. exists i; auto. }
      assert (sum N (fun _ : nat => 0) = 0) by (clear; induction N; simpl; [reflexivity | rewrite IHN; ring]).
      lra.
Qed.

(* The code's degrees, 1 to 6: the basis sums to 1 (the binomial theorem),
   the weights turn power coefficients into Bernstein coefficients (the
   blossom of u^j), and rows 0 and N of the weights are the powers of u0 and
   u1 that BernsteinBasis' constructor stores. *)
Definition degree_ok (N : nat) := (1 <= N <= 6)%nat.

Lemma bern_partition N t : degree_ok N -> sum N (fun i => bern N i t) = 1.
Proof.
  unfold degree_ok; intros HN.
  destruct N as [|[|[|[|[|[|[|N]]]]]]]; try lia; unfold bern, C; simpl; ring.
Qed.

(* covers optimized/gauss6/numeric/bernstein.h "BernsteinBasis(double u0, double u1)" sha256:b969cc1766b1bb97 *)
(* covers optimized/gauss6/numeric/bernstein.h "void inner() const" sha256:c8219bc0710128e9 *)
Theorem bernstein_blossom N k u0 u1 t :
  degree_ok N -> poly N k (u0 + t * (u1 - u0)) = bform N (bcoef N k u0 u1) t.
Proof.
  unfold degree_ok; intros HN.
  destruct N as [|[|[|[|[|[|[|N]]]]]]]; try lia;
    unfold poly, bform, bcoef, weight, bern, C; simpl; field.
Qed.

Theorem bernstein_end_rows N u0 u1 j :
  degree_ok N -> (j <= N)%nat -> weight N 0 j u0 u1 = u0 ^ j /\ weight N N j u0 u1 = u1 ^ j.
Proof.
  unfold degree_ok; intros HN Hj.
  destruct N as [|[|[|[|[|[|[|N]]]]]]]; try lia;
    (do 7 (destruct j as [|j]; [try (exfalso; lia); unfold weight, C; simpl; split; field|])); lia.
Qed.

Lemma weight_nonneg N i j u0 u1 : 0 <= u0 -> 0 <= u1 -> 0 <= weight N i j u0 u1.
Proof.
  intros H0 H1. unfold weight, Rdiv. apply Rmult_le_pos.
  - apply sum_nonneg; intros b _.
    repeat apply Rmult_le_pos; try apply C_nonneg; apply pow_le; assumption.
  - destruct (Req_dec (C N j) 0) as [->|Hc]; [rewrite Rinv_0; lra|].
    apply Rlt_le, Rinv_0_lt_compat. pose proof (C_nonneg N j). lra.
Qed.

(* Theorem bernstein_certificate (bernstein.h, positive_on, over the reals):
   for N <= 6 and 0 <= u0 <= u1, if S_i = sum_j lo_j w_ij > 0 for every i, then
   every polynomial sum_j k_j u^j with k_j >= lo_j is > 0 on [u0, u1]. *)
(* covers optimized/gauss6/numeric/bernstein.h "bool positive_on(const LowerCoefficients<N>& c, const BernsteinBasis<N>& basis)" sha256:50828dd06bd8f6db *)
Theorem bernstein_certificate N k lo u0 u1 u :
  degree_ok N -> 0 <= u0 <= u1 -> (forall j, (j <= N)%nat -> lo j <= k j) ->
  (forall i, (i <= N)%nat -> 0 < sum N (fun j => lo j * weight N i j u0 u1)) ->
  u0 <= u <= u1 -> 0 < poly N k u.
Proof.
  intros HN Hu Hk HS Hin.
  set (t := if Req_EM_T u1 u0 then 0 else (u - u0) / (u1 - u0)).
  assert (Ht : 0 <= t <= 1 /\ u = u0 + t * (u1 - u0)).
  { unfold t; destruct Req_EM_T as [E|E].
    - split; [lra | rewrite E in Hin; lra].
    - assert (0 < u1 - u0) by lra. split; [split|].
      + apply Rmult_le_pos; [lra | apply Rlt_le, Rinv_0_lt_compat; lra].
      + apply (Rmult_le_reg_r (u1 - u0)); [lra|]. unfold Rdiv; rewrite Rmult_assoc, Rinv_l by lra. lra.
      + field. lra. }
  destruct Ht as [Ht Hut]. rewrite Hut, bernstein_blossom by exact HN.
  apply bernstein_positive; [exact Ht | apply bern_partition, HN|].
  intros i Hi. eapply Rlt_le_trans; [apply (HS i Hi)|]. unfold bcoef.
  apply sum_le. intros j Hj. apply Rmult_le_compat_r; [apply weight_nonneg; lra | apply Hk, Hj].
Qed.

(* The theorems, each answered by tools/check_proofs.sh. *)
Print Assumptions bernstein_positive.
Print Assumptions bernstein_blossom.
Print Assumptions bernstein_end_rows.
Print Assumptions bernstein_certificate.
