(* The CCD's guarantee composed from its discards (issue 45: the narrow
   phase's proved pieces into the hypothesis of StopPose.v's
   stop_pose_separation). Over the reals, no rounding: the rounding is in the
   pieces. The structure the code has (step/ccd_step.h, ccd/bisection.cpp):
   the motion's parameter u in [0, 1], and for every pair of a god-object
   point and an obstacle point (their triangles and the parameters on them) a
   "box" of (u, parameters) is discarded only when its enclosure proves their
   distance above the separation d: a BVH node pair whose swept boxes are
   apart (ObbAllowances.v swept_box_encloses with separating_axis_gap,
   ObbSeparation.v, ObbCrossAxes.v), a triangle pair whose separating axis
   keeps it apart over a u-interval (AxisAllowances.v axis_gap_distance,
   axis_turn_rounding), a feature pair whose Bernstein certificate is
   positive over a u-interval (BernsteinRounding.v
   bernstein_certificate_doubles with LinesDistance.v lines_filter_sound and
   Cayley.v's conditions). Here each discard is an abstract box with a lower
   bound that is sound (the bound at most the distance at every (u, point)
   of the box: what those theorems prove of each filter) and above d (the
   discard's test); the discarded boxes cover [0, u_hit] for every point
   pair (the bisection's bookkeeping). *)

From Coq Require Import Reals Psatz.
From Gauss6 Require Import StopPose.
Open Scope R_scope.

(* Every point pair x stays more than d apart at every u of [0, u_hit], and
   no pair comes within d before u_hit: u_hit <= u*, u* the first u at which
   some pair is within d. *)
Theorem ccd_cover_separation {Pt Box : Type} (gap : R -> Pt -> R) (in_box : Box -> R -> Pt -> Prop)
    (lower : Box -> R) (discarded : Box -> Prop) (d u_hit : R) :
  (forall b u x, discarded b -> in_box b u x -> lower b <= gap u x) ->
  (forall b, discarded b -> d < lower b) ->
  (forall u x, 0 <= u <= u_hit -> exists b, discarded b /\ in_box b u x) ->
  (forall u x, 0 <= u <= u_hit -> d < gap u x) /\
  (forall u x, 0 <= u -> gap u x <= d -> u_hit < u).
Proof.
  intros Hsound Hdisc Hcover. assert (H : forall u x, 0 <= u <= u_hit -> d < gap u x).
  { intros u x Hu. destruct (Hcover u x Hu) as (b & Hb & Hin).
    pose proof (Hsound b u x Hb Hin). pose proof (Hdisc b Hb). lra. }
  split; [exact H|].
  intros u x Hu Hg. destruct (Rlt_or_le u_hit u) as [Hlt|Hle]; [exact Hlt|].
  pose proof (H u x (conj Hu Hle)). lra.
Qed.
Print Assumptions ccd_cover_separation.

(* With the exact motion's body point U u r and obstacle points y, the
   discards covering [0, u_hit] give stop_pose_separation's hypothesis at
   u_hit: at the double pose X (within dev of the motion's pose at u_hit,
   stop_pose_deviation) every body point is at least d - dev from every
   obstacle point. *)
Theorem ccd_stop_separation {Box : Type} (dev d u_hit : R) (X : R -> R -> R -> R * R * R)
    (U : R -> R -> R -> R -> R * R * R) (in_box : Box -> R -> (R * R * R) * (R * R * R) -> Prop)
    (lower : Box -> R) (discarded : Box -> Prop) :
  let gap u (x : (R * R * R) * (R * R * R)) :=
    let '((r0, r1, r2), (y0, y1, y2)) := x in
    let '(v0, v1, v2) := U u r0 r1 r2 in norm3 (v0 - y0) (v1 - y1) (v2 - y2) in
  0 <= u_hit ->
  (forall r0 r1 r2 y0 y1 y2,
     let '(x0, x1, x2) := X r0 r1 r2 in let '(v0, v1, v2) := U u_hit r0 r1 r2 in
     Rabs (norm3 (x0 - y0) (x1 - y1) (x2 - y2) - norm3 (v0 - y0) (v1 - y1) (v2 - y2)) <= dev) ->
  (forall b u x, discarded b -> in_box b u x -> lower b <= gap u x) ->
  (forall b, discarded b -> d < lower b) ->
  (forall u x, 0 <= u <= u_hit -> exists b, discarded b /\ in_box b u x) ->
  forall r0 r1 r2 y0 y1 y2, let '(x0, x1, x2) := X r0 r1 r2 in d - dev <= norm3 (x0 - y0) (x1 - y1) (x2 - y2).
Proof.
  intros gap Hu Hdev Hsound Hdisc Hcover.
  destruct (ccd_cover_separation gap in_box lower discarded d u_hit Hsound Hdisc Hcover) as [Hsep _].
  assert (HS : forall r0 r1 r2 y0 y1 y2, let '(v0, v1, v2) := U u_hit r0 r1 r2 in d <= norm3 (v0 - y0) (v1 - y1) (v2 - y2)).
  { intros r0 r1 r2 y0 y1 y2. pose proof (Hsep u_hit ((r0, r1, r2), (y0, y1, y2)) (conj Hu (Rle_refl _))) as G.
    unfold gap in G. destruct (U u_hit r0 r1 r2) as [[v0 v1] v2]. lra. }
  exact (proj1 (stop_pose_separation dev d 0 X (U u_hit) Hdev HS)).
Qed.
Print Assumptions ccd_stop_separation.
