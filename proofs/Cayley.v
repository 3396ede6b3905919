(* The Cayley in-between motion of optimized/gauss6/ccd/motion.h (METHOD.md
   section 4), exact algebra over the reals: the Cayley matrix
   C(h) = I + 2 / (1 + |h|^2) ([h]x + [h]x^2) (motion.cpp, cayley_rotation) is
   a rotation for every h (cayley_orthogonal, cayley_det); times
   D = 1 + |h|^2 it is the polynomial matrix (1 - |h|^2) I + 2 h h^T + 2 [h]x
   (cayley_polynomial), so every body point moves on a rational quadratic
   curve over D(u) = 1 + u^2 |g|^2 with the coefficients the CCD computes
   (cayley_point_quadratic: ccd.cpp, cayley_coefficients); the vertex/face
   conditions, times D(u), are the cubics ccd.cpp states
   (body_point_cubic, static_point_cubic); and the end pose is
   C(g) R(q0) = R(q1) for g = vec(qr) / scalar(qr), qr = q1 conj(q0), R the
   rational rotation of pose.h (cayley_end_pose).
   The identities are proved entry by entry with `ring` on polynomials (the
   denominators factored out once, in small lemmas), never `field` on whole
   entries. *)

From Coq Require Import Reals Psatz.
Open Scope R_scope.

Record V3 := v3 { x1 : R; x2 : R; x3 : R }.
Record M3 := m3 { e11 : R; e12 : R; e13 : R; e21 : R; e22 : R; e23 : R; e31 : R; e32 : R; e33 : R }.

Definition dot (a b : V3) := x1 a * x1 b + x2 a * x2 b + x3 a * x3 b.
Definition vadd (a b : V3) := v3 (x1 a + x1 b) (x2 a + x2 b) (x3 a + x3 b).
Definition vsub (a b : V3) := v3 (x1 a - x1 b) (x2 a - x2 b) (x3 a - x3 b).
Definition vscale (s : R) (a : V3) := v3 (s * x1 a) (s * x2 a) (s * x3 a).
Definition cross (a b : V3) :=
  v3 (x2 a * x3 b - x3 a * x2 b) (x3 a * x1 b - x1 a * x3 b) (x1 a * x2 b - x2 a * x1 b).

Definition mmul (A B : M3) :=
  m3 (e11 A * e11 B + e12 A * e21 B + e13 A * e31 B) (e11 A * e12 B + e12 A * e22 B + e13 A * e32 B)
     (e11 A * e13 B + e12 A * e23 B + e13 A * e33 B)
     (e21 A * e11 B + e22 A * e21 B + e23 A * e31 B) (e21 A * e12 B + e22 A * e22 B + e23 A * e32 B)
     (e21 A * e13 B + e22 A * e23 B + e23 A * e33 B)
     (e31 A * e11 B + e32 A * e21 B + e33 A * e31 B) (e31 A * e12 B + e32 A * e22 B + e33 A * e32 B)
     (e31 A * e13 B + e32 A * e23 B + e33 A * e33 B).
Definition mtr (A : M3) := m3 (e11 A) (e21 A) (e31 A) (e12 A) (e22 A) (e32 A) (e13 A) (e23 A) (e33 A).
Definition mscale (s : R) (A : M3) :=
  m3 (s * e11 A) (s * e12 A) (s * e13 A) (s * e21 A) (s * e22 A) (s * e23 A) (s * e31 A) (s * e32 A) (s * e33 A).
Definition mvec (A : M3) (v : V3) :=
  v3 (e11 A * x1 v + e12 A * x2 v + e13 A * x3 v) (e21 A * x1 v + e22 A * x2 v + e23 A * x3 v)
     (e31 A * x1 v + e32 A * x2 v + e33 A * x3 v).
Definition det (A : M3) :=
  e11 A * (e22 A * e33 A - e23 A * e32 A) - e12 A * (e21 A * e33 A - e23 A * e31 A)
  + e13 A * (e21 A * e32 A - e22 A * e31 A).
Definition I3 := m3 1 0 0 0 1 0 0 0 1.

(* motion.cpp: cross_matrix(h) and cayley_rotation(h) = I + (2 / (1 + |h|^2)) (K + K K). *)
Definition K (h : V3) := m3 0 (- x3 h) (x2 h) (x3 h) 0 (- x1 h) (- x2 h) (x1 h) 0.
Definition madd (A B : M3) :=
  m3 (e11 A + e11 B) (e12 A + e12 B) (e13 A + e13 B) (e21 A + e21 B) (e22 A + e22 B) (e23 A + e23 B)
     (e31 A + e31 B) (e32 A + e32 B) (e33 A + e33 B).
Definition Dh (h : V3) := 1 + dot h h.
Definition cayley (h : V3) := madd I3 (mscale (2 / Dh h) (madd (K h) (mmul (K h) (K h)))).

(* D C(h) as a polynomial matrix: (1 - |h|^2) I + 2 h h^T + 2 [h]x. *)
Definition P (h : V3) :=
  let a := x1 h in let b := x2 h in let c := x3 h in let s := 1 - dot h h in
  m3 (s + 2 * a * a) (2 * a * b - 2 * c) (2 * a * c + 2 * b)
     (2 * b * a + 2 * c) (s + 2 * b * b) (2 * b * c - 2 * a)
     (2 * c * a - 2 * b) (2 * c * b + 2 * a) (s + 2 * c * c).

Lemma Dh_pos h : 0 < Dh h.
Proof. unfold Dh, dot. nra. Qed.

(* The one division: D (d + 2 / D x) = D d + 2 x. *)
Lemma div_out D d x : D <> 0 -> D * (d + 2 / D * x) = D * d + 2 * x.
Proof. intros. field. assumption. Qed.

Lemma m3_eq a b c d e f g h i a' b' c' d' e' f' g' h' i' :
  a = a' -> b = b' -> c = c' -> d = d' -> e = e' -> f = f' -> g = g' -> h = h' -> i = i' ->
  m3 a b c d e f g h i = m3 a' b' c' d' e' f' g' h' i'.
Proof. intros; subst; reflexivity. Qed.
Lemma v3_eq a b c a' b' c' : a = a' -> b = b' -> c = c' -> v3 a b c = v3 a' b' c'.
Proof. intros; subst; reflexivity. Qed.

(* Theorem cayley_polynomial: D(h) C(h) = P(h). *)
(* covers optimized/gauss6/ccd/motion.cpp "Mat3 cayley_rotation(const Vec3& h)" sha256:8b2a195d0a624d63 *)
Theorem cayley_polynomial h : mscale (Dh h) (cayley h) = P h.
Proof.
  pose proof (Dh_pos h) as HD. assert (HD0 : Dh h <> 0) by lra.
  destruct h as [a b c]. unfold cayley, mscale, madd, mmul, K, I3, P; simpl.
  apply m3_eq; rewrite div_out by exact HD0; unfold Dh, dot; simpl; ring.
Qed.

Lemma cayley_as_P h : cayley h = mscale (/ Dh h) (P h).
Proof.
  pose proof (Dh_pos h) as HD. rewrite <- cayley_polynomial.
  destruct (cayley h). unfold mscale; simpl. apply m3_eq; field; lra.
Qed.

(* P(h)^T P(h) = D^2 I and det P(h) = D^3, polynomial identities. *)
Lemma P_orthogonal h : mmul (mtr (P h)) (P h) = mscale (Dh h * Dh h) I3.
Proof. destruct h as [a b c]. unfold mmul, mtr, P, mscale, I3, Dh, dot; simpl. apply m3_eq; ring. Qed.
Lemma P_det h : det (P h) = Dh h * Dh h * Dh h.
Proof. destruct h as [a b c]. unfold det, P, Dh, dot; simpl. ring. Qed.

Lemma mmul_scale s t A B : mmul (mscale s A) (mscale t B) = mscale (s * t) (mmul A B).
Proof. destruct A, B. unfold mmul, mscale; simpl. apply m3_eq; ring. Qed.
Lemma mtr_scale s A : mtr (mscale s A) = mscale s (mtr A).
Proof. destruct A. reflexivity. Qed.
Lemma det_scale s A : det (mscale s A) = s * s * s * det A.
Proof. destruct A. unfold det, mscale; simpl. ring. Qed.

(* Theorem cayley_orthogonal: C(h)^T C(h) = I for every h. *)
(* covers optimized/gauss6/ccd/motion.cpp "Mat3 cayley_rotation(const Vec3& h)" sha256:8b2a195d0a624d63 *)
Theorem cayley_orthogonal h : mmul (mtr (cayley h)) (cayley h) = I3.
Proof.
  pose proof (Dh_pos h) as HD. rewrite cayley_as_P, mtr_scale, mmul_scale, P_orthogonal.
  unfold mscale, I3; simpl. apply m3_eq; field; lra.
Qed.

(* Theorem cayley_det: det C(h) = 1. *)
(* covers optimized/gauss6/ccd/motion.cpp "Mat3 cayley_rotation(const Vec3& h)" sha256:8b2a195d0a624d63 *)
Theorem cayley_det h : det (cayley h) = 1.
Proof.
  pose proof (Dh_pos h) as HD. rewrite cayley_as_P, det_scale, P_det. field. lra.
Qed.

(* A rotation keeps dot products: (C a).(C b) = a.b. *)
Lemma cayley_dot h a b : dot (mvec (cayley h) a) (mvec (cayley h) b) = dot a b.
Proof.
  pose proof (cayley_orthogonal h) as O. destruct (cayley h) as [c11 c12 c13 c21 c22 c23 c31 c32 c33].
  unfold mmul, mtr, I3 in O; simpl in O. injection O; intros.
  destruct a, b. unfold dot, mvec; simpl.
  transitivity ((c11 * c11 + c21 * c21 + c31 * c31) * x4 * x7 + (c11 * c12 + c21 * c22 + c31 * c32) * x4 * x8
    + (c11 * c13 + c21 * c23 + c31 * c33) * x4 * x9 + (c12 * c11 + c22 * c21 + c32 * c31) * x5 * x7
    + (c12 * c12 + c22 * c22 + c32 * c32) * x5 * x8 + (c12 * c13 + c22 * c23 + c32 * c33) * x5 * x9
    + (c13 * c11 + c23 * c21 + c33 * c31) * x6 * x7 + (c13 * c12 + c23 * c22 + c33 * c32) * x6 * x8
    + (c13 * c13 + c23 * c23 + c33 * c33) * x6 * x9); [ring|].
  rewrite H, H0, H1, H2, H3, H4, H5, H6, H7. ring.
Qed.

(* ---- The motion: p(u) = p0 + u dp, R(u) = C(u g) R0; a body point with
   world-oriented offset w = R0 r_B is at p(u) + C(u g) w. ---- *)
Definition Du (g : V3) (u : R) := 1 + u * u * dot g g.

(* ccd.cpp, cayley_coefficients: c1 = 2 g x v, c2 = 2 (g.v) g - |g|^2 v. *)
Definition c1 (g v : V3) := vscale 2 (cross g v).
Definition c2 (g v : V3) := vsub (vscale (2 * dot g v) g) (vscale (dot g g) v).

(* Theorem cayley_point_quadratic: D(u) C(u g) v = v + u c1 + u^2 c2, every
   coordinate a quadratic in u over D(u). *)
(* covers optimized/gauss6/ccd/u_filter.h "CayleyCoefficients cayley_coefficients(const CcdMotion& m, const IVec3& v)" sha256:23b6441de1e32afa *)
Theorem cayley_point_quadratic g v u :
  vscale (Du g u) (mvec (cayley (vscale u g)) v) = vadd v (vadd (vscale u (c1 g v)) (vscale (u * u) (c2 g v))).
Proof.
  assert (E : Du g u = Dh (vscale u g)) by (destruct g; unfold Du, Dh, dot, vscale; simpl; ring).
  rewrite E, cayley_as_P. pose proof (Dh_pos (vscale u g)) as HD.
  set (D := Dh (vscale u g)) in *.
  assert (R : forall A x, vscale D (mvec (mscale (/ D) A) x) = mvec A x)
    by (intros [] []; unfold vscale, mvec, mscale; simpl; apply v3_eq; field; lra).
  rewrite R. destruct g, v. unfold mvec, P, vadd, vscale, c1, c2, cross, vsub, dot; simpl. apply v3_eq; ring.
Qed.

(* Theorem body_point_cubic (ccd.cpp, body_point_along): for a body point
   with offset w, a static point f and direction m,
   D(u) (x(u) - f).m = (A + w.m) + (E + c1.m) u + (s A + c2.m) u^2 + s E u^3,
   A = (p0 - f).m, E = dp.m, s = |g|^2. *)
(* covers optimized/gauss6/ccd/u_filter.h "Cubic body_point_along(const CcdMotion& m, Interval A, Interval E, const CornerAlong& c)" sha256:c724140c237ab869 *)
Theorem body_point_cubic g p0 dp w f m u :
  let x := vadd (vadd p0 (vscale u dp)) (mvec (cayley (vscale u g)) w) in
  let A := dot (vsub p0 f) m in let E := dot dp m in let s := dot g g in
  Du g u * dot (vsub x f) m =
    (A + dot w m) + (E + dot (c1 g w) m) * u + (s * A + dot (c2 g w) m) * u ^ 2 + s * E * u ^ 3.
Proof.
  intros x A E s. pose proof (cayley_point_quadratic g w u) as Q.
  set (Cw := mvec (cayley (vscale u g)) w) in *.
  assert (Hc : Du g u * dot Cw m = dot (vadd w (vadd (vscale u (c1 g w)) (vscale (u * u) (c2 g w)))) m).
  { rewrite <- Q. destruct Cw, m. unfold dot, vscale; simpl. ring. }
  unfold x. transitivity (Du g u * dot (vsub (vadd p0 (vscale u dp)) f) m + Du g u * dot Cw m).
  - destruct p0, dp, Cw, f, m. unfold dot, vsub, vadd, vscale; simpl. ring.
  - rewrite Hc. unfold A, E, s, Du. destruct p0, dp, f, m, w, g. unfold c1, c2, dot, vsub, vadd, vscale, cross; simpl. ring.
Qed.

(* Theorem static_point_cubic (ccd.cpp, static_point_along): for a static
   point y and the body point f' (offset) with body direction n' (both world
   oriented at u = 0), D(u) (y - x_f(u)).(C(u g) n') =
   (Y.n' - F) + (Y.c1 - dp.n') u + (Y.c2 - dp.c1 - s F) u^2 - dp.c2 u^3,
   Y = y - p0, F = f'.n', c1, c2 those of n' (C is a rotation). *)
(* covers optimized/gauss6/ccd/u_filter.h "Cubic static_point_along(const CcdMotion& m, const DirectionAlong& Y, const DirectionAlong& D," sha256:a8ad990e242f2207 *)
Theorem static_point_cubic g p0 dp fw nw y u :
  let C := cayley (vscale u g) in
  let xf := vadd (vadd p0 (vscale u dp)) (mvec C fw) in
  let Y := vsub y p0 in let F := dot fw nw in let s := dot g g in
  Du g u * dot (vsub y xf) (mvec C nw) =
    (dot Y nw - F) + (dot Y (c1 g nw) - dot dp nw) * u + (dot Y (c2 g nw) - dot dp (c1 g nw) - s * F) * u ^ 2
    - dot dp (c2 g nw) * u ^ 3.
Proof.
  intros C xf Y F s. pose proof (cayley_point_quadratic g nw u) as Q. fold C in Q.
  pose proof (cayley_dot (vscale u g) fw nw) as O. fold C in O.
  set (Cn := mvec C nw) in *. set (Cf := mvec C fw) in *.
  assert (Hn : forall z, Du g u * dot z Cn = dot z (vadd nw (vadd (vscale u (c1 g nw)) (vscale (u * u) (c2 g nw))))).
  { intros z. rewrite <- Q. destruct z, Cn. unfold dot, vscale; simpl. ring. }
  transitivity (Du g u * dot (vsub (vsub y p0) (vscale u dp)) Cn - Du g u * dot Cf Cn).
  - unfold xf. destruct y, p0, dp, Cf, Cn. unfold dot, vsub, vadd, vscale; simpl. ring.
  - rewrite Hn, O. unfold Y, F, s, Du. destruct y, p0, dp, fw, nw, g. unfold c1, c2, dot, vsub, vadd, vscale, cross; simpl. ring.
Qed.

(* ---- The end pose ---- *)
Record Q4 := q4 { qw : R; qx : R; qy : R; qz : R }.
Definition qmul (a b : Q4) :=
  q4 (qw a * qw b - qx a * qx b - qy a * qy b - qz a * qz b)
     (qw a * qx b + qx a * qw b + qy a * qz b - qz a * qy b)
     (qw a * qy b - qx a * qz b + qy a * qw b + qz a * qx b)
     (qw a * qz b + qx a * qy b - qy a * qx b + qz a * qw b).
Definition qconj (a : Q4) := q4 (qw a) (- qx a) (- qy a) (- qz a).
Definition qn2 (a : Q4) := qw a * qw a + qx a * qx a + qy a * qy a + qz a * qz a.
(* pose.h rotation_matrix / motion.cpp rational_rotation: R(q) = N(q) / |q|^2. *)
Definition Nq (q : Q4) :=
  let w := qw q in let x := qx q in let y := qy q in let z := qz q in
  m3 (w * w + x * x - y * y - z * z) (2 * (x * y - w * z)) (2 * (x * z + w * y))
     (2 * (x * y + w * z)) (w * w - x * x + y * y - z * z) (2 * (y * z - w * x))
     (2 * (x * z - w * y)) (2 * (y * z + w * x)) (w * w - x * x - y * y + z * z).
Definition Rq (q : Q4) := mscale (/ qn2 q) (Nq q).

Lemma Nq_mul a b : Nq (qmul a b) = mmul (Nq a) (Nq b).
Proof. destruct a, b. unfold Nq, qmul, mmul; simpl. apply m3_eq; ring. Qed.
Lemma qn2_mul a b : qn2 (qmul a b) = qn2 a * qn2 b.
Proof. destruct a, b. unfold qn2, qmul; simpl. ring. Qed.
Lemma qn2_pos q : q <> q4 0 0 0 0 -> 0 < qn2 q.
Proof.
  destruct q as [w x y z]; unfold qn2; simpl. intros H.
  destruct (Req_dec w 0); destruct (Req_dec x 0); destruct (Req_dec y 0); destruct (Req_dec z 0);
    subst; try (exfalso; apply H; reflexivity); nra.
Qed.
(* qr q0 = q1 conj(q0) q0 = |q0|^2 q1. *)
Lemma qr_q0 q0 q1 : qmul (qmul q1 (qconj q0)) q0 = q4 (qn2 q0 * qw q1) (qn2 q0 * qx q1) (qn2 q0 * qy q1) (qn2 q0 * qz q1).
Proof. destruct q0, q1. unfold qmul, qconj, qn2; simpl. f_equal; ring. Qed.

(* The Gibbs vector of a quaternion with scalar part w <> 0: vec / w; its
   Cayley matrix is R(q) (w^2 D(vec / w) = |q|^2, w^2 P(vec / w) = N(q)). *)
Definition gibbs (q : Q4) := v3 (qx q / qw q) (qy q / qw q) (qz q / qw q).
Lemma cayley_gibbs q : qw q <> 0 -> cayley (gibbs q) = Rq q.
Proof.
  intros Hw. rewrite cayley_as_P.
  assert (HD : Dh (gibbs q) = qn2 q / (qw q * qw q))
    by (destruct q; unfold Dh, gibbs, dot, qn2; simpl in *; field; exact Hw).
  assert (HP : P (gibbs q) = mscale (/ (qw q * qw q)) (Nq q)).
  { destruct q as [w x y z]. unfold P, gibbs, Nq, mscale, dot; simpl in *. apply m3_eq; field; exact Hw. }
  assert (Hn : 0 < qn2 q) by (destruct q as [w x y z]; unfold qn2; simpl in *; nra).
  rewrite HD, HP. unfold Rq. destruct (Nq q). unfold mscale; simpl.
  apply m3_eq; field; split; lra || (intros E; apply Hw; nra).
Qed.

(* Theorem cayley_end_pose (motion.cpp, make_cayley_motion): for q0, q1 <> 0
   and qr = q1 conj(q0) with scalar part <> 0 (the code refuses near-half
   turns, kMaxMotionAngle, and flips qr's sign, which leaves g unchanged),
   g = vec(qr) / scalar(qr) gives C(g) R(q0) = R(q1) exactly. *)
(* covers optimized/gauss6/ccd/motion.cpp "MotionStatus make_cayley_motion(const Pose& x0, const Pose& x1, CayleyMotion* motion)" sha256:772aaa768815ba63 *)
Theorem cayley_end_pose q0 q1 :
  q0 <> q4 0 0 0 0 -> q1 <> q4 0 0 0 0 -> qw (qmul q1 (qconj q0)) <> 0 ->
  mmul (cayley (gibbs (qmul q1 (qconj q0)))) (Rq q0) = Rq q1.
Proof.
  intros H0 H1 Hw. set (qr := qmul q1 (qconj q0)) in *.
  pose proof (qn2_pos q0 H0) as P0. pose proof (qn2_pos q1 H1) as P1.
  assert (Pr : qn2 qr = qn2 q1 * qn2 q0) by (unfold qr; rewrite qn2_mul; destruct q0; unfold qn2, qconj; simpl; ring).
  rewrite cayley_gibbs by exact Hw. unfold Rq. rewrite mmul_scale, <- Nq_mul.
  unfold qr. rewrite qr_q0. fold qr. rewrite Pr.
  destruct q1 as [w x y z]. unfold Nq, mscale; simpl. set (n := qn2 q0) in *. unfold qn2 in *; simpl in *.
  apply m3_eq; field; lra.
Qed.

(* The theorems, each answered by tools/check_proofs.sh. *)
Print Assumptions cayley_polynomial.
Print Assumptions cayley_orthogonal.
Print Assumptions cayley_det.
Print Assumptions cayley_point_quadratic.
Print Assumptions body_point_cubic.
Print Assumptions static_point_cubic.
Print Assumptions cayley_end_pose.
