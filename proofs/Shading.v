(* Shading.v: machine-checked properties of force shading (METHOD.md section 6,
   property 7 of section 5), over any ordered field, beside Projection.v.

   The two passes of force shading (the paper's Fig. 7), with the same M:
     pass 1 (coupling loop): (asc, mu) a KKT point of
        min 1/2 (a - au)^T M (a - au)   s.t.  Js a >= bs
       with Js the shading rows (interpolated normals, perturbed by a
       texture), bs = 0 or the offsets of METHOD.md section 3;
       the force is Fs = kh M (asc - au);
     pass 2 (sim loop): (ac, lambda) a KKT point of
        min 1/2 (a - asc)^T M (a - asc)  s.t.  J a >= b
       with J the true rows; the god-object moves by ac.
   Nothing links Js to J: the theorems hold for any shading rows, so for any
   crease angle, interpolation rule or texture. *)

Set Warnings "-notation-overridden,-ambiguous-paths".
From mathcomp Require Import all_ssreflect all_algebra.
From Gauss6 Require Import Projection.
Import GRing.Theory Num.Theory.

Set Implicit Arguments.
Unset Strict Implicit.
Unset Printing Implicit Defensive.

Local Open Scope ring_scope.

Section Shading.
Variables (R : realFieldType) (ms m n : nat).
Implicit Types (M : 'M[R]_n) (Js : 'M[R]_(ms, n)) (J : 'M[R]_(m, n))
               (au asc ac : 'cV[R]_n) (bs mu : 'cV[R]_ms) (b lambda : 'cV[R]_m).

(* Property 7: whatever the shading rows and whatever pass 1 gives, the
   god-object's own motion ac meets the true constraints J ac >= b. *)
Theorem shaded_motion_feasible M Js J au bs asc mu b ac lambda :
  kkt M Js au bs asc mu -> kkt M J asc b ac lambda -> feasible J b ac.
Proof. by move=> _ [_ _ K3 _]. Qed.

(* Property 7 without offsets: J ac >= 0, row by row. *)
Theorem shaded_motion_nonpenetrating M Js J au bs asc mu ac lambda :
  kkt M Js au bs asc mu -> kkt M J asc 0 ac lambda -> forall k, 0 <= (J *m ac) k 0.
Proof. by move=> K1 K2 k; have := shaded_motion_feasible K1 K2 k; rewrite mxE. Qed.

(* Pass 2 changes nothing when the shaded motion already meets the true
   constraints: J asc >= b implies ac = asc (the god-object follows the shaded
   motion exactly, as on a smooth surface). *)
Theorem shaded_motion_kept M Js J au bs asc mu b ac lambda :
  symmetric M -> posdef M -> kkt M Js au bs asc mu ->
  feasible J b asc -> kkt M J asc b ac lambda -> ac = asc.
Proof. by move=> sM pd _ f K; have [] := free_motion (0 : R) sM pd f K. Qed.

(* Shaded orthogonality (bs = 0): the shaded force is orthogonal to the shaded
   motion, Fs^T asc = 0 with Fs = kh M (asc - au), for every gain kh. *)
Theorem shaded_orthogonality M Js au asc mu (kh : R) :
  symmetric M -> kkt M Js au 0 asc mu ->
  dot (kh *: (M *m (asc - au))) asc = 0.
Proof. exact: force_orthogonal. Qed.

(* With offsets on the shading rows: Fs^T asc = kh mu^T bs. *)
Theorem shaded_orthogonality_offset M Js au bs asc mu (kh : R) :
  symmetric M -> kkt M Js au bs asc mu ->
  dot (kh *: (M *m (asc - au))) asc = kh * dot mu bs.
Proof. exact: force_orthogonal_offset. Qed.

(* The shaded force's work on the god-object's motion is all in the part of
   the motion that pass 2 changed: Fs^T ac = Fs^T (ac - asc) (bs = 0). This is
   the energy shading can inject: zero when pass 2 keeps asc (above), and
   small when the shading normals are close to the true ones. *)
Theorem shading_work M Js J au asc mu b ac lambda (kh : R) :
  symmetric M -> kkt M Js au 0 asc mu -> kkt M J asc b ac lambda ->
  dot (kh *: (M *m (asc - au))) ac = dot (kh *: (M *m (asc - au))) (ac - asc).
Proof.
by move=> sM K1 _; rewrite dotBr (shaded_orthogonality kh sM K1) subr0.
Qed.

(* Pass 2 is dissipative with respect to the shaded command (b = 0):
   (M asc)^T ac <= (M asc)^T asc. *)
Theorem shaded_dissipativity M Js J au bs asc mu ac lambda :
  symmetric M -> posdef M -> kkt M Js au bs asc mu -> kkt M J asc 0 ac lambda ->
  dot (M *m asc) ac <= dot (M *m asc) asc.
Proof. by move=> sM pd _ K; exact: dissipativity sM pd K. Qed.

End Shading.

Print Assumptions shaded_motion_feasible.
Print Assumptions shaded_motion_nonpenetrating.
Print Assumptions shaded_motion_kept.
Print Assumptions shaded_orthogonality.
Print Assumptions shaded_orthogonality_offset.
Print Assumptions shading_work.
Print Assumptions shaded_dissipativity.
