(* The edge/edge conditions of the rigid u-filter (optimized/gauss6/ccd/u_filter.h,
   conditions (1) and (4)), exact algebra over the reals, on the Cayley motion of
   Cayley.v: a body edge from a0 along ea (world-oriented offsets at u = 0) moves
   to x_a0(u) = p0 + u dp + C(u g) a0 along C(u g) ea; the static edge runs from
   b0 along eb.
   - edge_edge_normal: N(u) = D(u) (C(u g) ea x eb) is the quadratic
     T0 + u T1 + u^2 T2 with T0 = ea x eb, T1 = c1(ea) x eb, T2 = c2(ea) x eb.
   - edge_edge_cubic: P(u) = (x_a0(u) - b0).N(u) is the cubic whose coefficients
     edge_edge_cubic (u_filter.h) computes from Q = p0 - b0, dp, the T's,
     Z = a0 x ea and eb's Cayley coefficients (a rotation turns a cross
     product with it, and C(h)^T = C(-h)).
   - lines_sextic: the coefficients lines_sextic (u_filter.h) accumulates are
     those of S(u) = P(u)^2 - d^2 |N(u)|^2, a polynomial of degree 6.
   - lines_apart: where S(u) > 0, every point of the moving edge's line is
     more than d from every point of the static edge's line (N is normal to
     both lines, so (x - y).N = P for any points x, y of them; Cauchy-Schwarz).
   - lines_filter_sound: the two together: S(u) > 0 at u leaves no pair of
     points of the two segments at u within d, whatever the edges and the
     motion (parallel edges give N = 0 and S = 0: never excluded).
   The coefficients are computed in interval arithmetic whose operations
   enclose the exact results (Rounding.v), so the computed intervals enclose
   the coefficients stated here; positive_on (bernstein.h,
   Bernstein.v, BernsteinRounding.v) then proves S > 0 over a u-interval. *)

From Coq Require Import Reals Psatz.
From Gauss6 Require Import Cayley.
Open Scope R_scope.

Definition vnorm2 (a : V3) := dot a a.
Definition lin (a b : V3) (s : R) := vadd a (vscale s b).

(* Three quadratic coefficients of a vector polynomial, at u. *)
Definition quad (t0 t1 t2 : V3) (u : R) := vadd t0 (vadd (vscale u t1) (vscale (u * u) t2)).

(* A rotation through the Cayley matrix turns cross products with it: P(h) x times
   P(h) y = D(h) P(h) (x cross y), a polynomial identity. *)
Lemma P_cross h x y : cross (mvec (P h) x) (mvec (P h) y) = vscale (Dh h) (mvec (P h) (cross x y)).
Proof.
  destruct h as [a b c], x, y. unfold cross, mvec, P, vscale, Dh, dot; simpl. apply v3_eq; ring.
Qed.

Lemma mvec_scale s A x : mvec (mscale s A) x = vscale s (mvec A x).
Proof. destruct A, x. unfold mvec, mscale, vscale; simpl. apply v3_eq; ring. Qed.

Lemma cross_scale s t a b : cross (vscale s a) (vscale t b) = vscale (s * t) (cross a b).
Proof. destruct a, b. unfold cross, vscale; simpl. apply v3_eq; ring. Qed.

Lemma cayley_cross h x y : cross (mvec (cayley h) x) (mvec (cayley h) y) = mvec (cayley h) (cross x y).
Proof.
  pose proof (Dh_pos h) as HD. rewrite cayley_as_P, !mvec_scale, cross_scale, P_cross.
  destruct (mvec (P h) (cross x y)). unfold vscale; simpl. apply v3_eq; field; lra.
Qed.

(* C(h)^T = C(-h): moving a dot product across the rotation. *)
Lemma dot_mvec A x y : dot (mvec A x) y = dot x (mvec (mtr A) y).
Proof. destruct A, x, y. unfold dot, mvec, mtr; simpl. ring. Qed.

Lemma Dh_neg h : Dh (vscale (-1) h) = Dh h.
Proof. destruct h. unfold Dh, dot, vscale; simpl. ring. Qed.

Lemma P_transpose h : mtr (P h) = P (vscale (-1) h).
Proof. destruct h as [a b c]. unfold mtr, P, vscale, dot; simpl. apply m3_eq; ring. Qed.

Lemma cayley_transpose h : mtr (cayley h) = cayley (vscale (-1) h).
Proof. rewrite !cayley_as_P, mtr_scale, P_transpose, Dh_neg. reflexivity. Qed.

(* D(u) C(-u g) v = v - u c1(v) + u^2 c2(v): eb's Cayley coefficients serve C^T. *)
Lemma cayley_back_quadratic g v u :
  vscale (Du g u) (mvec (cayley (vscale (-1) (vscale u g))) v)
  = vadd v (vadd (vscale (- u) (c1 g v)) (vscale (u * u) (c2 g v))).
Proof.
  assert (E : vscale (-1) (vscale u g) = vscale (- u) g) by (destruct g; unfold vscale; simpl; apply v3_eq; ring).
  assert (D : Du g u = Du g (- u)) by (unfold Du; ring).
  rewrite E, D, cayley_point_quadratic. f_equal. f_equal. f_equal. ring.
Qed.

(* Theorem edge_edge_normal: N(u) = D(u) (C(u g) ea x eb) = T0 + u T1 + u^2 T2. *)
(* covers optimized/gauss6/ccd/u_filter.h "EdgeEdgeCubic edge_edge_cubic(const CcdMotion& m, const IVec3& a0W, const IVec3& eaW," sha256:9eb1765fff106d79 *)
Theorem edge_edge_normal g ea eb u :
  vscale (Du g u) (cross (mvec (cayley (vscale u g)) ea) eb)
  = quad (cross ea eb) (cross (c1 g ea) eb) (cross (c2 g ea) eb) u.
Proof.
  assert (H : vscale (Du g u) (cross (mvec (cayley (vscale u g)) ea) eb)
              = cross (vscale (Du g u) (mvec (cayley (vscale u g)) ea)) eb)
    by (destruct (mvec (cayley (vscale u g)) ea), eb; unfold vscale, cross; simpl; apply v3_eq; ring).
  rewrite H, cayley_point_quadratic. destruct ea, eb, (c1 g _), (c2 g _).
  unfold quad, cross, vadd, vscale; simpl. apply v3_eq; ring.
Qed.

(* The cubic's coefficients as edge_edge_cubic computes them. *)
Definition ee_k0 (Q dp T0 T1 T2 Z eb cb1 cb2 : V3) := dot Q T0 + dot Z eb.
Definition ee_k1 (Q dp T0 T1 T2 Z eb cb1 cb2 : V3) := (dot Q T1 + dot dp T0) - dot Z cb1.
Definition ee_k2 (Q dp T0 T1 T2 Z eb cb1 cb2 : V3) := (dot Q T2 + dot dp T1) + dot Z cb2.
Definition ee_k3 (Q dp T0 T1 T2 Z eb cb1 cb2 : V3) := dot dp T2.

(* Theorem edge_edge_cubic: P(u) = (x_a0(u) - b0).N(u) = k0 + k1 u + k2 u^2 + k3 u^3
   with Q = p0 - b0, Z = a0 x ea, T_i as in edge_edge_normal, cb1, cb2 eb's
   Cayley coefficients. *)
(* covers optimized/gauss6/ccd/u_filter.h "EdgeEdgeCubic edge_edge_cubic(const CcdMotion& m, const IVec3& a0W, const IVec3& eaW," sha256:9eb1765fff106d79 *)
Theorem edge_edge_cubic g p0 dp a0 ea b0 eb u :
  let C := cayley (vscale u g) in
  let x := vadd (vadd p0 (vscale u dp)) (mvec C a0) in
  let N := vscale (Du g u) (cross (mvec C ea) eb) in
  let Q := vsub p0 b0 in let Z := cross a0 ea in
  let T0 := cross ea eb in let T1 := cross (c1 g ea) eb in let T2 := cross (c2 g ea) eb in
  let k := fun f : V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> R =>
             f Q dp T0 T1 T2 Z eb (c1 g eb) (c2 g eb) in
  dot (vsub x b0) N = k ee_k0 + k ee_k1 * u + k ee_k2 * u ^ 2 + k ee_k3 * u ^ 3.
Proof.
  cbv zeta beta. set (C := cayley (vscale u g)).
  (* The moving offset's part: D (C a0).(C ea x eb) = (a0 x ea).(D C^T eb). *)
  assert (HZ : Du g u * dot (mvec C a0) (cross (mvec C ea) eb)
               = dot (cross a0 ea) (vadd eb (vadd (vscale (- u) (c1 g eb)) (vscale (u * u) (c2 g eb))))).
  { rewrite <- cayley_back_quadratic, <- cayley_transpose. fold C.
    transitivity (Du g u * dot (cross (mvec C a0) (mvec C ea)) eb).
    - generalize (mvec C a0) (mvec C ea). intros [] []. destruct eb. unfold dot, cross; simpl. ring.
    - unfold C. rewrite cayley_cross, dot_mvec.
      generalize (cross a0 ea) (mvec (mtr (cayley (vscale u g))) eb). intros [] []. unfold dot, vscale; simpl. ring. }
  pose proof (edge_edge_normal g ea eb u) as HN. fold C in HN.
  transitivity (dot (vadd (vsub p0 b0) (vscale u dp)) (vscale (Du g u) (cross (mvec C ea) eb))
                + Du g u * dot (mvec C a0) (cross (mvec C ea) eb)).
  - generalize (mvec C a0) (cross (mvec C ea) eb). intros [] []. destruct p0, dp, b0.
    unfold dot, vsub, vadd, vscale; simpl. ring.
  - rewrite HZ, HN. unfold ee_k0, ee_k1, ee_k2, ee_k3, quad. cbv beta.
    generalize (c1 g eb) (c2 g eb) (cross ea eb) (cross (c1 g ea) eb) (cross (c2 g ea) eb) (cross a0 ea)
               (vsub p0 b0).
    intros [] [] [] [] [] [] []. destruct dp, eb. unfold dot, vadd, vscale; simpl. ring.
Qed.

(* The sextic's coefficients as lines_sextic accumulates them: P's square (the
   squares on even powers, twice the products on i + j), less d^2 times each
   component's square of N = T0 + u T1 + u^2 T2. *)
Definition sq3 (n0 n1 n2 : R) (i : nat) :=
  match i with
  | 0%nat => n0 * n0 | 1%nat => 2 * (n0 * n1) | 2%nat => n1 * n1 + 2 * (n0 * n2)
  | 3%nat => 2 * (n1 * n2) | 4%nat => n2 * n2 | _ => 0 end.
Definition sq4 (p0 p1 p2 p3 : R) (i : nat) :=
  match i with
  | 0%nat => p0 * p0 | 1%nat => 2 * (p0 * p1) | 2%nat => p1 * p1 + 2 * (p0 * p2)
  | 3%nat => 2 * (p0 * p3) + 2 * (p1 * p2) | 4%nat => p2 * p2 + 2 * (p1 * p3)
  | 5%nat => 2 * (p2 * p3) | 6%nat => p3 * p3 | _ => 0 end.
Definition sextic_k (p0 p1 p2 p3 d : R) (t0 t1 t2 : V3) (i : nat) :=
  sq4 p0 p1 p2 p3 i - d * d * (sq3 (x1 t0) (x1 t1) (x1 t2) i + sq3 (x2 t0) (x2 t1) (x2 t2) i
                               + sq3 (x3 t0) (x3 t1) (x3 t2) i).
Definition sextic_at (p0 p1 p2 p3 d : R) (t0 t1 t2 : V3) (u : R) :=
  let k := sextic_k p0 p1 p2 p3 d t0 t1 t2 in
  k 0%nat + k 1%nat * u + k 2%nat * u ^ 2 + k 3%nat * u ^ 3 + k 4%nat * u ^ 4 + k 5%nat * u ^ 5
  + k 6%nat * u ^ 6.

(* Theorem lines_sextic: the accumulated coefficients are those of
   S(u) = P(u)^2 - d^2 |N(u)|^2. *)
(* covers optimized/gauss6/ccd/u_filter.h "Sextic lines_sextic(const EdgeEdgeCubic& e, double d)" sha256:8eb8b6d70a85d37b *)
Theorem lines_sextic p0 p1 p2 p3 d t0 t1 t2 u :
  sextic_at p0 p1 p2 p3 d t0 t1 t2 u
  = let P := p0 + p1 * u + p2 * u ^ 2 + p3 * u ^ 3 in P * P - d * d * vnorm2 (quad t0 t1 t2 u).
Proof.
  destruct t0, t1, t2. unfold sextic_at, sextic_k, sq4, sq3, vnorm2, quad, dot, vadd, vscale; simpl. ring.
Qed.

(* Cauchy-Schwarz in three dimensions. *)
Lemma cauchy_schwarz v n : dot v n * dot v n <= dot v v * dot n n.
Proof.
  destruct v as [a b c], n as [x y z]. unfold dot; simpl.
  assert (E : (a * a + b * b + c * c) * (x * x + y * y + z * z) - (a * x + b * y + c * z) * (a * x + b * y + c * z)
              = (a * y - b * x) * (a * y - b * x) + (a * z - c * x) * (a * z - c * x)
                + (b * z - c * y) * (b * z - c * y)) by ring.
  pose proof (Rle_0_sqr (a * y - b * x)). pose proof (Rle_0_sqr (a * z - c * x)).
  pose proof (Rle_0_sqr (b * z - c * y)). unfold Rsqr in *. lra.
Qed.

(* Theorem lines_apart: for N normal to both directions ea, eb, P = (x - y).N
   with P^2 - d^2 |N|^2 > 0 puts every point of the line x + s ea more than d
   from every point of the line y + t eb (no sign hypothesis on d). *)
Theorem lines_apart x y ea eb N d s t :
  dot ea N = 0 -> dot eb N = 0 ->
  dot (vsub x y) N * dot (vsub x y) N - d * d * vnorm2 N > 0 ->
  d * d < vnorm2 (vsub (lin x ea s) (lin y eb t)).
Proof.
  intros Ha Hb HS. set (v := vsub (lin x ea s) (lin y eb t)).
  assert (Hv0 : dot v N = dot (vsub x y) N + s * dot ea N - t * dot eb N)
    by (unfold v, lin; destruct x, y, ea, eb, N; unfold dot, vsub, vadd, vscale; simpl; ring).
  assert (Hv : dot v N = dot (vsub x y) N) by (rewrite Hv0, Ha, Hb; ring).
  pose proof (cauchy_schwarz v N) as CS. rewrite Hv in CS. unfold vnorm2 in *.
  assert (H0 : 0 <= dot N N).
  { destruct N as [a b c]. unfold dot; simpl.
    pose proof (Rle_0_sqr a). pose proof (Rle_0_sqr b). pose proof (Rle_0_sqr c). unfold Rsqr in *. lra. }
  assert (HN : 0 < dot N N).
  { destruct (Rle_or_lt (dot N N) 0) as [Hle|]; [|assumption]. exfalso.
    assert (E : dot N N = 0) by lra. rewrite E in CS, HS. lra. }
  destruct (Rlt_or_le (d * d) (dot v v)) as [|Hle]; [assumption|]. exfalso.
  assert (dot v v * dot N N <= d * d * dot N N) by (apply Rmult_le_compat_r; lra). lra.
Qed.

(* Theorem lines_filter_sound: where the sextic of the code's coefficients is
   positive at u, the moving segment a0 + s ea and the static one b0 + t eb (any
   s, t: the whole lines) are more than d apart at u. *)
(* covers optimized/gauss6/ccd/u_filter.h "Sextic lines_sextic(const EdgeEdgeCubic& e, double d)" sha256:8eb8b6d70a85d37b *)
Theorem lines_filter_sound g p0 dp a0 ea b0 eb d u s t :
  let C := cayley (vscale u g) in
  let Q := vsub p0 b0 in let Z := cross a0 ea in
  let T0 := cross ea eb in let T1 := cross (c1 g ea) eb in let T2 := cross (c2 g ea) eb in
  let k := fun f : V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> V3 -> R =>
             f Q dp T0 T1 T2 Z eb (c1 g eb) (c2 g eb) in
  sextic_at (k ee_k0) (k ee_k1) (k ee_k2) (k ee_k3) d T0 T1 T2 u > 0 ->
  d * d < vnorm2 (vsub (lin (vadd (vadd p0 (vscale u dp)) (mvec C a0)) (mvec C ea) s) (lin b0 eb t)).
Proof.
  cbv zeta beta. intros HS. rewrite lines_sextic in HS. cbv zeta in HS.
  pose proof (edge_edge_cubic g p0 dp a0 ea b0 eb u) as HP. cbv zeta beta in HP.
  pose proof (edge_edge_normal g ea eb u) as HN.
  set (C := cayley (vscale u g)) in *.
  set (N := vscale (Du g u) (cross (mvec C ea) eb)) in *.
  apply (lines_apart _ _ _ _ N).
  - unfold N. generalize (mvec C ea). intros []. destruct eb. unfold dot, cross, vscale; simpl. ring.
  - unfold N. generalize (mvec C ea). intros []. destruct eb. unfold dot, cross, vscale; simpl. ring.
  - rewrite HP, HN. lra.
Qed.

Print Assumptions edge_edge_normal.
Print Assumptions edge_edge_cubic.
Print Assumptions lines_sextic.
Print Assumptions lines_apart.
Print Assumptions lines_filter_sound.
