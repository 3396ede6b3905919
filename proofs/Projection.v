(* Projection.v: machine-checked properties of the quasi-static projection of
   gauss6 (METHOD.md sections 2, 3 and 5, properties 1 to 4).

   The projection: given the unconstrained acceleration au, the mass matrix M
   (symmetric positive definite) and the contact Jacobian J (one row per
   contact, m rows, any m), the constrained acceleration is
     ac = argmin { 1/2 (a - au)^T M (a - au) : J a >= b }
   with b = 0 without constraint offsets, and b the offset right-hand side of
   METHOD.md section 3 otherwise. The coupling force is Fc = kh M (ac - au).
   The solvers of the project return a KKT point (ac, lambda):
     (K1) M (ac - au) = J^T lambda       (stationarity)
     (K2) lambda >= 0                    (dual feasibility)
     (K3) J ac >= b                      (primal feasibility)
     (K4) lambda_k ((J ac)_k - b_k) = 0  (complementarity)
   Every theorem below holds over any ordered field R (realFieldType: the
   rationals, the real algebraic numbers, the reals), for any dimension n of
   the acceleration (6 in the method) and any number m of contact rows.
   Vectors are column matrices 'cV[R]_n; inequalities between vectors are
   componentwise. *)

Set Warnings "-notation-overridden,-ambiguous-paths".
From mathcomp Require Import all_ssreflect all_algebra.
Import GRing.Theory Num.Theory.

Set Implicit Arguments.
Unset Strict Implicit.
Unset Printing Implicit Defensive.

Local Open Scope ring_scope.

(* ------------------------------------------------------------------------ *)
(* Scalar product of column vectors and its algebra.                        *)
(* ------------------------------------------------------------------------ *)

(* dot u v = u^T v, the 1x1 matrix product read as a scalar. *)
Definition dot {R : ringType} {n : nat} (u v : 'cV[R]_n) : R := (u^T *m v) 0 0.

Section DotAlgebra.
Variables (R : realFieldType) (n : nat).
Implicit Types (u v w : 'cV[R]_n) (M : 'M[R]_n).

Lemma dotE u v : dot u v = \sum_i u i 0 * v i 0.
Proof. by rewrite /dot mxE; apply: eq_bigr => i _; rewrite mxE. Qed.

Lemma dotC u v : dot u v = dot v u.
Proof. by rewrite !dotE; apply: eq_bigr => i _; rewrite mulrC. Qed.

Lemma dotDl u v w : dot (u + v) w = dot u w + dot v w.
Proof. by rewrite !dotE -big_split; apply: eq_bigr => i _; rewrite mxE mulrDl. Qed.

Lemma dotDr u v w : dot u (v + w) = dot u v + dot u w.
Proof. by rewrite ![dot u _]dotC dotDl. Qed.

Lemma dotNl u v : dot (- u) v = - dot u v.
Proof. by rewrite !dotE -sumrN; apply: eq_bigr => i _; rewrite mxE mulNr. Qed.

Lemma dotNr u v : dot u (- v) = - dot u v.
Proof. by rewrite ![dot u _]dotC dotNl. Qed.

Lemma dotBl u v w : dot (u - v) w = dot u w - dot v w.
Proof. by rewrite dotDl dotNl. Qed.

Lemma dotBr u v w : dot u (v - w) = dot u v - dot u w.
Proof. by rewrite dotDr dotNr. Qed.

Lemma dot0l u : dot 0 u = 0.
Proof. by rewrite dotE big1 // => i _; rewrite mxE mul0r. Qed.

Lemma dot0r u : dot u 0 = 0.
Proof. by rewrite dotC dot0l. Qed.

Lemma dotZl (k : R) u v : dot (k *: u) v = k * dot u v.
Proof. by rewrite !dotE mulr_sumr; apply: eq_bigr => i _; rewrite mxE mulrA. Qed.

(* Moving a matrix across the scalar product: u^T (A v) = (A^T u)^T v. *)
Lemma dot_mulmx m (A : 'M[R]_(m, n)) (u : 'cV[R]_m) v :
  dot u (A *m v) = dot (A^T *m u) v.
Proof. by rewrite /dot trmx_mul trmxK mulmxA. Qed.

(* With M symmetric, u^T M v = v^T M u. *)
Lemma dot_sym M u v : M^T = M -> dot u (M *m v) = dot v (M *m u).
Proof. by move=> sM; rewrite (dot_mulmx M) sM dotC. Qed.

(* The quadratic form x^T M x, as the brief states it, is dot x (M x). *)
Lemma quadE M u : (u^T *m M *m u) 0 0 = dot u (M *m u).
Proof. by rewrite /dot mulmxA. Qed.

(* Componentwise sign conditions turn into sign conditions on dot. *)
Lemma dot_ge0 u v :
  (forall k, 0 <= u k 0) -> (forall k, 0 <= v k 0) -> 0 <= dot u v.
Proof. by move=> u0 v0; rewrite dotE sumr_ge0 // => i _; rewrite mulr_ge0. Qed.

Lemma dot_le0 u v :
  (forall k, 0 <= u k 0) -> (forall k, v k 0 <= 0) -> dot u v <= 0.
Proof.
move=> u0 v0; rewrite -oppr_ge0 -dotNr dot_ge0 // => k.
by rewrite mxE oppr_ge0.
Qed.

Lemma dot_compl u v : (forall k, u k 0 * v k 0 = 0) -> dot u v = 0.
Proof. by move=> uv; rewrite dotE big1. Qed.

Lemma cV_subE u v k : (u - v) k 0 = u k 0 - v k 0.
Proof. by rewrite !mxE. Qed.

End DotAlgebra.

(* Two rearrangements of sums used below. *)
Lemma sum_rearrange (V : zmodType) (p q x : V) : p + x + (x + q) = q + p + x *+ 2.
Proof. by rewrite mulr2n [x + q]addrC addrACA [p + q]addrC. Qed.

Lemma diff_rearrange (V : zmodType) (x y z : V) : x - y - (y - z) = x + (z - y) - y.
Proof. by rewrite opprB addrAC. Qed.

(* ------------------------------------------------------------------------ *)
(* The projection problem and its KKT conditions.                           *)
(* ------------------------------------------------------------------------ *)

(* M is symmetric. *)
Definition symmetric {R : ringType} {n : nat} (M : 'M[R]_n) := M^T = M.

(* M is positive definite: x^T M x > 0 for every x <> 0. *)
Definition posdef {R : realFieldType} {n : nat} (M : 'M[R]_n) :=
  forall x : 'cV[R]_n, x != 0 -> 0 < (x^T *m M *m x) 0 0.

(* a satisfies every contact row: J a >= b componentwise. *)
Definition feasible {R : realFieldType} {m n : nat}
    (J : 'M[R]_(m, n)) (b : 'cV[R]_m) (a : 'cV[R]_n) :=
  forall k, b k 0 <= (J *m a) k 0.

(* (ac, lambda) is a KKT point of min 1/2 (a-au)^T M (a-au) s.t. J a >= b. *)
Definition kkt {R : realFieldType} {m n : nat} (M : 'M[R]_n) (J : 'M[R]_(m, n))
    (au : 'cV[R]_n) (b : 'cV[R]_m) (ac : 'cV[R]_n) (lambda : 'cV[R]_m) :=
  [/\ M *m (ac - au) = J^T *m lambda,                       (* K1 *)
      forall k, 0 <= lambda k 0,                            (* K2 *)
      feasible J b ac                                       (* K3 *)
    & forall k, lambda k 0 * ((J *m ac) k 0 - b k 0) = 0].  (* K4 *)

(* Gauss' constraint: the objective f(a) = 1/2 (a - au)^T M (a - au). *)
Definition gauss {R : realFieldType} {n : nat} (M : 'M[R]_n) (au a : 'cV[R]_n) : R :=
  2^-1 * dot (a - au) (M *m (a - au)).

Section Projection.
Variables (R : realFieldType) (m n : nat).
Implicit Types (M : 'M[R]_n) (J : 'M[R]_(m, n)) (au ac a x : 'cV[R]_n)
               (b lambda : 'cV[R]_m).

Lemma posdef_ge0 M x : posdef M -> 0 <= dot x (M *m x).
Proof.
move=> pd; case: (eqVneq x 0) => [->|nz]; first by rewrite dot0l.
by apply: Order.POrderTheory.ltW; rewrite -quadE; apply: pd.
Qed.

Lemma posdef_eq0 M x : posdef M -> dot x (M *m x) = 0 -> x = 0.
Proof.
move=> pd q0; case: (eqVneq x 0) => // nz.
by have := pd x nz; rewrite quadE q0 Order.POrderTheory.ltxx.
Qed.

(* Complementarity summed over the rows: lambda^T (J ac - b) = 0. *)
Lemma kkt_compl M J au b ac lambda :
  kkt M J au b ac lambda -> dot lambda (J *m ac - b) = 0.
Proof. by case=> _ _ _ K4; apply: dot_compl => k; rewrite cV_subE K4. Qed.

(* For a feasible a and lambda >= 0: lambda^T (J a - b) >= 0. *)
Lemma feasible_gap J b a lambda :
  feasible J b a -> (forall k, 0 <= lambda k 0) -> 0 <= dot lambda (J *m a - b).
Proof.
move=> fa l0; apply: dot_ge0 => // k.
by rewrite cV_subE subr_ge0; apply: fa.
Qed.

(* The cross term of the expansion of f around ac:
   (a - ac)^T M (ac - au) = lambda^T (J a - b). *)
Lemma kkt_cross M J au b ac lambda a :
  symmetric M -> kkt M J au b ac lambda ->
  dot (a - ac) (M *m (ac - au)) = dot lambda (J *m a - b).
Proof.
move=> sM K; case: (K) => K1 _ _ _.
rewrite K1 dot_mulmx trmxK dotC mulmxBr.
have -> : J *m a - J *m ac = (J *m a - b) - (J *m ac - b).
  by rewrite opprB addrA subrK.
by rewrite dotBr (kkt_compl K) subr0.
Qed.

(* Exact expansion of the objective around a KKT point (twice f):
   (a-au)^T M (a-au) = (ac-au)^T M (ac-au) + (a-ac)^T M (a-ac)
                       + 2 lambda^T (J a - b). *)
Lemma gauss_expand M J au b ac lambda a :
  symmetric M -> kkt M J au b ac lambda ->
  dot (a - au) (M *m (a - au)) =
    dot (ac - au) (M *m (ac - au)) + dot (a - ac) (M *m (a - ac))
    + dot lambda (J *m a - b) *+ 2.
Proof.
move=> sM K.
have -> : a - au = (a - ac) + (ac - au) by rewrite addrA subrK.
rewrite mulmxDr dotDl [dot (a - ac) _]dotDr [dot (ac - au) _]dotDr.
rewrite (dot_sym (ac - au) (a - ac) sM) (kkt_cross a sM K).
exact: sum_rearrange.
Qed.

(* ------------------------------------------------------------------------ *)
(* Property 1 (METHOD.md section 5): orthogonality.                         *)
(* ------------------------------------------------------------------------ *)

(* With offsets (any b): (ac - au)^T M ac = lambda^T b. *)
Theorem orthogonality_offset M J au b ac lambda :
  symmetric M -> kkt M J au b ac lambda ->
  dot (ac - au) (M *m ac) = dot lambda b.
Proof.
move=> sM K; case: (K) => K1 _ _ _.
rewrite (dot_sym _ _ sM) K1 dot_mulmx trmxK dotC.
by have := kkt_compl K; rewrite dotBr => /eqP; rewrite subr_eq0 => /eqP.
Qed.

(* Property 1, without offsets (b = 0): (ac - au)^T M ac = 0. *)
Theorem orthogonality M J au ac lambda :
  symmetric M -> kkt M J au 0 ac lambda ->
  dot (ac - au) (M *m ac) = 0.
Proof. by move=> sM K; rewrite (orthogonality_offset sM K) dot0r. Qed.

(* Property 1, the force: with Fc = kh M (ac - au) and b = 0, Fc^T ac = 0,
   for any gain kh. *)
Theorem force_orthogonal M J au ac lambda (kh : R) :
  symmetric M -> kkt M J au 0 ac lambda ->
  dot (kh *: (M *m (ac - au))) ac = 0.
Proof.
move=> sM K.
by rewrite dotZl dotC -(dot_sym _ _ sM) (orthogonality sM K) mulr0.
Qed.

(* With offsets: Fc^T ac = kh lambda^T b. *)
Theorem force_orthogonal_offset M J au b ac lambda (kh : R) :
  symmetric M -> kkt M J au b ac lambda ->
  dot (kh *: (M *m (ac - au))) ac = kh * dot lambda b.
Proof.
move=> sM K.
by rewrite dotZl dotC -(dot_sym _ _ sM) (orthogonality_offset sM K).
Qed.

(* ------------------------------------------------------------------------ *)
(* Property 2: the force lies in the normal cone of the contacts.           *)
(* ------------------------------------------------------------------------ *)

(* Fc = kh J^T lambda with lambda >= 0. *)
Theorem force_in_cone M J au b ac lambda (kh : R) :
  kkt M J au b ac lambda ->
  kh *: (M *m (ac - au)) = kh *: (J^T *m lambda) /\ forall k, 0 <= lambda k 0.
Proof. by case=> K1 K2 _ _; rewrite K1. Qed.

(* For kh >= 0, Fc is a non-negative combination of the rows' wrenches J_k^T:
   Fc = sum_k c_k J_k^T with every c_k >= 0 (c_k = kh lambda_k). *)
Theorem force_cone_combination M J au b ac lambda (kh : R) :
  0 <= kh -> kkt M J au b ac lambda ->
  exists c : 'I_m -> R, (forall k, 0 <= c k) /\
    kh *: (M *m (ac - au)) = \sum_k c k *: (row k J)^T.
Proof.
move=> kh0 [K1 K2 _ _]; exists (fun k => kh * lambda k 0); split.
  by move=> k; rewrite mulr_ge0.
rewrite K1; apply/matrixP => i j; rewrite (ord1 j) summxE !mxE mulr_sumr.
by apply: eq_bigr => k _; rewrite !mxE -mulrA [J k i * _]mulrC.
Qed.

(* ------------------------------------------------------------------------ *)
(* Property 3, first part: a KKT point is the unique minimiser.             *)
(* ------------------------------------------------------------------------ *)

(* If (ac, lambda) is a KKT point, then for every feasible a (J a >= b),
   f(a) >= f(ac) with f(a) = 1/2 (a-au)^T M (a-au), and f(a) = f(ac) only
   if a = ac. *)
Theorem kkt_unique_minimiser M J au b ac lambda a :
  symmetric M -> posdef M -> kkt M J au b ac lambda -> feasible J b a ->
  gauss M au ac <= gauss M au a /\ (gauss M au a = gauss M au ac -> a = ac).
Proof.
move=> sM pd K fa; case: (K) => _ l0 _ _.
have h2 : 0 < 2^-1 :> R by rewrite invr_gt0 ltr0n.
have qd := posdef_ge0 (a - ac) pd.
have gap := feasible_gap fa l0.
rewrite /gauss (gauss_expand a sM K); split.
  by rewrite ler_pmul2l // -addrA ler_addl addr_ge0 // mulrn_wge0.
move/(mulfI (lt0r_neq0 h2)); rewrite -addrA -[RHS]addr0 => /addrI /eqP.
rewrite paddr_eq0 ?mulrn_wge0 // => /andP [/eqP q0 _].
exact/subr0_eq/(posdef_eq0 pd).
Qed.

(* Strict form: every other feasible a has a strictly larger f. *)
Theorem kkt_strict_minimiser M J au b ac lambda a :
  symmetric M -> posdef M -> kkt M J au b ac lambda -> feasible J b a ->
  a != ac -> gauss M au ac < gauss M au a.
Proof.
move=> sM pd K fa; have [le eq] := kkt_unique_minimiser sM pd K fa.
rewrite Order.POrderTheory.lt_neqAle le andbT; apply: contra => /eqP e.
by apply/eqP/eq; rewrite e.
Qed.

(* Two KKT points of the same problem have the same ac (their multipliers
   may differ when the rows of J are dependent). *)
Theorem kkt_unique M J au b ac1 lambda1 ac2 lambda2 :
  symmetric M -> posdef M ->
  kkt M J au b ac1 lambda1 -> kkt M J au b ac2 lambda2 -> ac1 = ac2.
Proof.
move=> sM pd K1 K2.
have [_ _ f1 _] := K1; have [_ _ f2 _] := K2.
have [le12 eq21] := kkt_unique_minimiser sM pd K1 f2.
have [le21 _] := kkt_unique_minimiser sM pd K2 f1.
by apply/esym/eq21/Order.POrderTheory.le_anti; rewrite le12 le21.
Qed.

(* ------------------------------------------------------------------------ *)
(* Property 3: no force in free space or when moving away.                  *)
(* ------------------------------------------------------------------------ *)

(* If J au >= b (b = 0: J au >= 0), then ac = au and Fc = kh M (ac - au) = 0. *)
Theorem free_motion M J au b ac lambda (kh : R) :
  symmetric M -> posdef M -> feasible J b au -> kkt M J au b ac lambda ->
  ac = au /\ kh *: (M *m (ac - au)) = 0.
Proof.
move=> sM pd fu K.
have K0 : kkt M J au b au 0.
  split=> // [|k|k]; first by rewrite subrr !mulmx0.
    by rewrite mxE.
  by rewrite mxE mul0r.
have e := kkt_unique sM pd K K0.
by split=> //; rewrite e subrr mulmx0 scaler0.
Qed.

(* ------------------------------------------------------------------------ *)
(* Property 4: dissipativity.                                               *)
(* ------------------------------------------------------------------------ *)

(* With offsets: Fu^T ac <= Fu^T au + lambda^T b, where Fu = M au. *)
Theorem dissipativity_offset M J au b ac lambda :
  symmetric M -> posdef M -> kkt M J au b ac lambda ->
  dot (M *m au) ac <= dot (M *m au) au + dot lambda b.
Proof.
move=> sM pd K.
have orth := orthogonality_offset sM K; rewrite dotBl in orth.
have q := posdef_ge0 (au - ac) pd.
rewrite mulmxBr dotBl !dotBr (dot_sym ac au sM) in q.
rewrite [dot _ ac]dotC [dot _ au]dotC (dot_sym ac au sM) -orth -subr_ge0.
by rewrite -diff_rearrange.
Qed.

(* Property 4 (b = 0): Fu^T ac <= Fu^T au with Fu = M au. *)
Theorem dissipativity M J au ac lambda :
  symmetric M -> posdef M -> kkt M J au 0 ac lambda ->
  dot (M *m au) ac <= dot (M *m au) au.
Proof. by move=> sM pd K; have := dissipativity_offset sM pd K; rewrite dot0r addr0. Qed.

(* Offsets of METHOD.md section 3 start at d_k < 0 and rise to 0, so b <= 0:
   then the constraints still only remove energy, Fu^T ac <= Fu^T au. *)
Theorem dissipativity_nonpositive_offset M J au b ac lambda :
  symmetric M -> posdef M -> kkt M J au b ac lambda -> (forall k, b k 0 <= 0) ->
  dot (M *m au) ac <= dot (M *m au) au.
Proof.
move=> sM pd K b0; case: (K) => _ l0 _ _.
apply: Order.POrderTheory.le_trans (dissipativity_offset sM pd K) _.
by rewrite ger_addl dot_le0.
Qed.

End Projection.

(* ------------------------------------------------------------------------ *)
(* The hypotheses are satisfiable: a one-dimensional instance.              *)
(* ------------------------------------------------------------------------ *)

(* A guard against vacuous theorems: with n = m = 1, M = 1, one contact row
   J = 1 (the constraint a >= 0), au = -1 (pushing into the wall), the point
   ac = 0 with lambda = 1 is a KKT point, and M is symmetric positive
   definite. So every hypothesis of the theorems above can hold at once. *)
Section Witness.
Variable R : realFieldType.
Let M1 : 'M[R]_1 := 1%:M.
Let J1 : 'M[R]_1 := 1%:M.
Let au1 : 'cV[R]_1 := const_mx (-1).
Let ac1 : 'cV[R]_1 := 0.
Let lambda1 : 'cV[R]_1 := const_mx 1.

Example hypotheses_satisfiable :
  symmetric M1 /\ posdef M1 /\ kkt M1 J1 au1 0 ac1 lambda1.
Proof.
split; first exact: trmx1.
split.
  move=> x nz; rewrite mulmx1 -/(dot x x) dotE big_ord1 -expr2 lt0r sqr_ge0 andbT.
  rewrite sqrf_eq0; apply: contraNneq nz => x0.
  by apply/eqP/matrixP => i j; rewrite !ord1 x0 mxE.
split.
- rewrite /M1 /J1 trmx1 !mul1mx /ac1 /au1 /lambda1 sub0r.
  by apply/matrixP => i j; rewrite !mxE opprK.
- by move=> k; rewrite mxE ler01.
- by move=> k; rewrite /ac1 mulmx0 !mxE.
- by move=> k; rewrite /ac1 mulmx0 !mxE subr0 mulr0.
Qed.
End Witness.

(* Every theorem is closed: no axiom, no hypothesis left open. The checks sit
   after the sections close, where the section variables have become ordinary
   universally quantified arguments. *)
Print Assumptions orthogonality_offset.
Print Assumptions orthogonality.
Print Assumptions force_orthogonal.
Print Assumptions force_orthogonal_offset.
Print Assumptions force_in_cone.
Print Assumptions force_cone_combination.
Print Assumptions kkt_unique_minimiser.
Print Assumptions kkt_strict_minimiser.
Print Assumptions kkt_unique.
Print Assumptions free_motion.
Print Assumptions dissipativity_offset.
Print Assumptions dissipativity.
Print Assumptions dissipativity_nonpositive_offset.
Print Assumptions hypotheses_satisfiable.
