"""`gauss6 crosscheck qp`: the optimized projection against the exact reference and OSQP.

For every instance of every family (datasets_generated/qp/): the optimized
solver's answer (cold start; warm starts along the "warm" family's sequences),
the exact certificate of its active set (reference/: the exact KKT point of the
active set, checked exactly for lambda >= 0 and J a >= b), a full exact solve
(CGAL's QP solver) on a sample, and OSQP (eps 1e-10, polished) as an independent
floating-point check.

Errors are measured in the M-norm |x|_M = sqrt(x^T M x), the norm in which the
projection is defined:
- rel_err_ac    = |ac - ac*|_M / |au|_M   (|ac*|_M <= |au|_M when b = 0: the
  natural scale of the answer, defined even when ac* = 0);
- rel_err_force = |ac - ac*|_M / |ac* - au|_M, the force error relative to the
  exact force in its own (M^-1) norm, since |Fc - Fc*|_{M^-1} = kh |ac - ac*|_M;
  where the exact force is zero, relative to |au|_M.
- certificate: the exact KKT point of the optimized active set must satisfy
  lambda >= 0 and J a >= b exactly; where it violates rows by at most
  CERTIFICATE_TOL of their scale, the answer is certified as the exact optimum
  of a problem within that much of the given one (a backward error, counted in
  the "near-deg" column of the table: see certified_optimum); a larger failure
  is a certificate failure.
- kkt residual: the solver's own KKT residuals made relative: stationarity over
  |M au|_inf, primal infeasibility over |J|_inf |au|_inf + |b|_inf, complementarity
  over the product of both scales.
"""
from __future__ import annotations

import contextlib
import functools
import math
import os
import sys
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from . import _gauss6, qp_instances

DEFAULT_TOLERANCE = 1e-9
# An exact certificate that fails by at most this much, relative to the row's
# scale (|J_k| |au| + |b_k| for a constraint, |M au| for a multiplier), is a
# near-degenerate instance, resolved by a full exact solve (see check_instance).
CERTIFICATE_TOL = 1e-12
EXACT_SAMPLE_EVERY = 10  # a full exact solve on one instance in ten


# The verdict's numbers are computed in an order that does not depend on where the
# arrays lie in memory: numpy's BLAS products and sums take different paths for
# differently aligned arrays, so the same instance gave errors one ulp apart in the
# campaign's own process and in a worker process (a summary that must be identical,
# serial or distributed). Each product rounds once and math.fsum sums exactly, so these
# are the same bits everywhere; the sizes (n = 6, m rows) make it cheap.
def matvec(M: np.ndarray, x: np.ndarray) -> list[float]:
    xs = [float(v) for v in x]
    return [math.fsum(float(a) * v for a, v in zip(row, xs)) for row in M]


def norm2(x) -> float:
    return math.sqrt(math.fsum(float(v) * float(v) for v in x))


def m_norm(M: np.ndarray, x: np.ndarray) -> float:
    return math.sqrt(max(math.fsum(float(a) * b for a, b in zip(x, matvec(M, x))), 0.0))


@contextlib.contextmanager
def c_stdout_silenced():
    """OSQP's C code prints ("Polishing not needed ...") to the process's stdout
    even with verbose=False: send file descriptor 1 to /dev/null meanwhile, so
    that the command's own output (JSON) stays clean."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def solve_osqp(M: np.ndarray, au: np.ndarray, J: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """OSQP at eps 1e-10, polished: the independent floating-point cross-check."""
    import osqp
    import scipy.sparse as sp

    m = J.shape[0]
    if m == 0:
        return au.copy()
    solver = osqp.OSQP()
    solver.setup(sp.csc_matrix(np.triu(M)), -M @ au, sp.csc_matrix(J), b, np.full(m, np.inf),
                 eps_abs=1e-10, eps_rel=1e-10, polishing=True, verbose=False, max_iter=200000)
    with c_stdout_silenced():
        r = solver.solve()
    return None if r.info.status not in ("solved", "solved inaccurate") else np.asarray(r.x)


@dataclass
class FamilyReport:
    name: str
    count: int = 0
    max_rel_err_ac: float = 0.0
    max_rel_err_force: float = 0.0
    max_kkt_residual: float = 0.0
    certificate_failures: int = 0
    osqp_max_rel_err_ac: float = 0.0
    statuses: Counter = field(default_factory=Counter)
    exact_solves: int = 0
    near_degenerate: int = 0  # judged by backward error (see certified_optimum)
    osqp_failures: int = 0    # instances OSQP did not solve (status not "solved")
    failures: list[str] = field(default_factory=list)

    def as_json(self) -> dict:
        return {"name": self.name, "count": self.count, "max_rel_err_ac": self.max_rel_err_ac,
                "max_rel_err_force": self.max_rel_err_force, "max_kkt_residual": self.max_kkt_residual,
                "certificate_failures": self.certificate_failures,
                "osqp_max_rel_err_ac": self.osqp_max_rel_err_ac, "statuses": dict(sorted(self.statuses.items()))}

    # A campaign chunk's report travels as JSON (state) and chunks add up (absorb).
    MAX_FAILURES_KEPT = 20

    def state(self) -> dict:
        return {**self.as_json(), "exact_solves": self.exact_solves, "near_degenerate": self.near_degenerate,
                "osqp_failures": self.osqp_failures, "failures": self.failures[:self.MAX_FAILURES_KEPT],
                "num_failures": len(self.failures)}

    def absorb(self, st: dict) -> None:
        for k in ("count", "certificate_failures", "exact_solves", "near_degenerate", "osqp_failures"):
            setattr(self, k, getattr(self, k) + st[k])
        for k in ("max_rel_err_ac", "max_rel_err_force", "max_kkt_residual", "osqp_max_rel_err_ac"):
            setattr(self, k, max(getattr(self, k), st[k]))
        self.statuses.update(st["statuses"])
        self.failures += st["failures"][:max(self.MAX_FAILURES_KEPT - len(self.failures), 0)]


def certified_optimum(M, au, J, b, active) -> tuple[np.ndarray | None, str, str]:
    """The exact optimum (rounded to doubles) that a floating-point active set is
    measured against, from the exact certificate: (ac*, how, message).

    how = "certificate": the active set's exact KKT point passed: ac* is the exact
      optimum of the given problem.
    how = "backward": it violated rows by at most CERTIFICATE_TOL of their scale;
      relaxing those b_k by that much (to just below J_k a_W) makes the exact
      certificate pass, so a_W is the exact optimum of a problem whose b differs
      by at most CERTIFICATE_TOL: a backward error. This is how ill-posed
      instances are judged (a jammed body, whose exact feasible cone is a thin
      wedge that the rounding of J to doubles decides: a 1e-20 change of b there
      moves the exact optimum by O(|au|), so no floating-point solver can have a
      small forward error; see reference/include/gauss6/reference/quasistatics.h).
    how = "exact": a near-zero negative multiplier: a full exact solve gives ac*.
    how = "failed": ac* is None and message says why.
    """
    cert = _gauss6.reference.check_certificate(M, au, J, b, active)
    if cert["pass"]:
        return np.asarray(cert["ac"]), "certificate", ""
    first = cert
    if cert["failure"] == "violated_constraint":
        relaxed = b.astype(float).copy()
        for _ in range(4 * len(b) + 4):
            if cert["pass"]:
                return np.asarray(cert["ac"]), "backward", ""
            if cert["failure"] != "violated_constraint":
                break
            k = cert["row"]
            new_bk = np.nextafter(relaxed[k] - cert["amount"], -np.inf)
            if b[k] - new_bk > CERTIFICATE_TOL * certificate_scale(M, au, J, b, cert):
                break
            relaxed[k] = new_bk
            cert = _gauss6.reference.check_certificate(M, au, J, relaxed, active)
    elif (cert["failure"] == "negative_multiplier"
          and cert["amount"] <= CERTIFICATE_TOL * certificate_scale(M, au, J, b, cert)):
        exact = _gauss6.reference.project(M, au, J, b)
        if exact["status"] != "optimal":
            return None, "exact", f"exact solve says {exact['status']}"
        return np.asarray(exact["ac"]), "exact", ""
    return None, "failed", (f"certificate failed: {first['failure']} at row {first['row']} "
                            f"by {first['amount']:.3g}")


def certificate_scale(M, au, J, b, cert) -> float:
    """The scale against which a failed certificate's amount is judged (see CERTIFICATE_TOL)."""
    if cert["failure"] == "negative_multiplier":
        return norm2(matvec(M, au))
    k = cert["row"]
    return norm2(J[k]) * norm2(au) + abs(float(b[k]))


def relative_kkt(res, M, au, J, b) -> float:
    """The solver's KKT residuals made relative to the problem's scales (see the module doc)."""
    force_scale = max(abs(v) for v in matvec(M, au)) or 1.0
    row_scale = (float(np.abs(J).max()) if J.size else 0.0) * float(np.abs(au).max()) + (
        float(np.abs(b).max()) if b.size else 0.0) or 1.0
    return max(res.stationarity / force_scale, res.primal_infeasibility / row_scale,
               res.dual_infeasibility / force_scale, res.complementarity / (force_scale * row_scale))


def check_instance(rep: FamilyReport, inst, res, index: int, with_osqp: bool) -> None:
    M, au, J, b = inst.M, inst.au, inst.J, inst.b
    rep.count += 1
    rep.statuses[res.status] += 1
    au_norm = m_norm(M, au) or 1.0
    if res.status == "infeasible_offsets":
        # Only an exact solve can certify infeasibility.
        exact = _gauss6.reference.project(M, au, J, b)
        rep.exact_solves += 1
        if exact["status"] != "infeasible":
            rep.certificate_failures += 1
            rep.failures.append(f"{inst.id}: optimized says infeasible, exact says {exact['status']}")
        return
    if res.status != "optimal":
        rep.certificate_failures += 1
        rep.failures.append(f"{inst.id}: status {res.status}")
        return
    rep.max_kkt_residual = max(rep.max_kkt_residual, relative_kkt(res, M, au, J, b))
    ac_star, how, message = certified_optimum(M, au, J, b, list(res.active))
    if how == "exact":
        rep.exact_solves += 1
    if how == "backward":
        rep.near_degenerate += 1
    if ac_star is None:
        rep.certificate_failures += 1
        rep.failures.append(f"{inst.id}: {message}")
        return
    err = m_norm(M, res.ac - ac_star)
    rep.max_rel_err_ac = max(rep.max_rel_err_ac, err / au_norm)
    force_norm = m_norm(M, ac_star - au)
    rep.max_rel_err_force = max(rep.max_rel_err_force, err / (force_norm if force_norm > 0 else au_norm))
    if how == "certificate" and index % EXACT_SAMPLE_EVERY == 0:
        # A full exact solve on a sample: it must agree with the certified optimum.
        exact = _gauss6.reference.project(M, au, J, b)
        rep.exact_solves += 1
        if exact["status"] != "optimal" or m_norm(M, np.asarray(exact["ac"]) - ac_star) > 1e-15 * au_norm:
            rep.certificate_failures += 1
            rep.failures.append(f"{inst.id}: exact solve disagrees with the certificate ({exact['status']})")
    if with_osqp:
        # OSQP's error over the instances it solves; those it fails on are counted apart.
        x = solve_osqp(M, au, J, b)
        if x is None:
            rep.osqp_failures += 1
        else:
            rep.osqp_max_rel_err_ac = max(rep.osqp_max_rel_err_ac, m_norm(M, x - ac_star) / au_norm)


def crosscheck_family(name: str, with_osqp: bool = True, progress=None) -> FamilyReport:
    return check_instances(name, qp_instances.load_family(name), with_osqp, progress)


def check_instances(name: str, instances: list, with_osqp: bool = True, progress=None) -> FamilyReport:
    """One family's instances checked (the warm family with warm starts along its sequences)."""
    from . import project, Projector

    rep = FamilyReport(name)
    if name == "warm":
        # Warm starts along each sequence, in step order, one projector per sequence.
        projectors: dict[int, Projector] = {}
        for i, inst in enumerate(sorted(instances, key=lambda x: (x.sequence, x.step))):
            proj = projectors.setdefault(inst.sequence, Projector())
            check_instance(rep, inst, proj.project(inst.M, inst.au, inst.J, inst.b), i, with_osqp)
            if progress:
                progress.update(1)
    else:
        for i, inst in enumerate(instances):
            check_instance(rep, inst, project(inst.M, inst.au, inst.J, inst.b), i, with_osqp)
            if progress:
                progress.update(1)
    return rep


def crosscheck(families: list[str] | None = None, tolerance: float = DEFAULT_TOLERANCE,
               with_osqp: bool = True, show_progress: bool = True) -> tuple[dict, list[str]]:
    """Runs the crosscheck; returns (the JSON object, the failure messages)."""
    from tqdm import tqdm

    names = families or qp_instances.family_names()
    total = sum(len(qp_instances.load_family(n)) for n in names)
    reports = []
    with tqdm(total=total, desc="crosscheck qp", disable=not show_progress, unit="qp") as bar:
        for n in names:
            reports.append(crosscheck_family(n, with_osqp, bar))
    failures = [f for r in reports for f in r.failures]
    for r in reports:
        if r.max_rel_err_ac > tolerance:
            failures.append(f"{r.name}: max_rel_err_ac {r.max_rel_err_ac:.3g} > {tolerance:g}")
        if r.max_rel_err_force > tolerance:
            failures.append(f"{r.name}: max_rel_err_force {r.max_rel_err_force:.3g} > {tolerance:g}")
    ok = not failures
    result = {"ok": ok, "tolerance": tolerance, "families": [r.as_json() for r in reports]}
    return result, failures, reports


def format_table(result: dict, reports: list[FamilyReport]) -> str:
    head = (f"{'family':<15} {'count':>6} {'err ac':>10} {'err force':>10} {'kkt':>10} {'cert fail':>9} "
            f"{'near-deg':>8} {'exact':>6} {'osqp err':>10} {'osqp x':>6}  statuses")
    lines = [head, "-" * len(head)]
    for f, r in zip(result["families"], reports):
        f = dict(f, near_degenerate=r.near_degenerate, exact_solves=r.exact_solves, osqp_failures=r.osqp_failures)
        st = ", ".join(f"{k} {v}" for k, v in f["statuses"].items())
        lines.append(f"{f['name']:<15} {f['count']:>6} {f['max_rel_err_ac']:>10.2e} {f['max_rel_err_force']:>10.2e} "
                     f"{f['max_kkt_residual']:>10.2e} {f['certificate_failures']:>9} {f['near_degenerate']:>8} "
                     f"{f['exact_solves']:>6} {f['osqp_max_rel_err_ac']:>10.2e} {f['osqp_failures']:>6}  {st}")
    lines.append(f"tolerance {result['tolerance']:g}: {'OK' if result['ok'] else 'FAILED'}")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------
# Seeded campaigns: instances generated on the fly (qp_seeded.py), chunks as tasks (campaign.py)
# --------------------------------------------------------------------------------------

def seeded_campaign(count: int, seed: int = 1, families: list[str] | None = None, with_osqp: bool = False,
                    tolerance: float = DEFAULT_TOLERANCE, chunk_size: int | None = None):
    """The campaign of at least `count` seeded instances: whole chunks of chunk_size
    (default qp_seeded.CHUNK_SIZE), the families in turn (chunk j is family j mod F,
    its chunk j // F)."""
    from . import qp_seeded
    from .campaign import Campaign

    names = families or qp_seeded.default_family_names()
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1):
        raise ValueError(f"chunk_size must be an integer >= 1, not {chunk_size!r}")
    size = chunk_size or qp_seeded.CHUNK_SIZE
    if count < 1 or size < 1:
        raise ValueError(f"a campaign of {count} instances in chunks of {size}: both must be >= 1")
    for n in names:
        if n not in qp_seeded.family_names():
            raise ValueError(f"no QP family {n!r} (families: {', '.join(qp_seeded.family_names())})")
    chunks, total, j = [], 0, 0
    while total < count:
        fam = names[j % len(names)]
        chunks.append({"family": fam, "seed": seed, "index": j // len(names), "size": size, "osqp": with_osqp})
        total += qp_seeded.chunk_size(fam, size)
        j += 1
    params = {"count": count, "seed": seed, "families": names, "osqp": with_osqp,
              "chunk_size": size}
    merge = functools.partial(merge_seeded, names=names, tolerance=tolerance)
    return Campaign("crosscheck-qp", chunks, run_seeded_chunk, merge, params, sources=("gauss6.qp_seeded",))


def run_seeded_chunk(chunk: dict) -> dict:
    """One chunk: its instances generated and checked; the family report's state."""
    from . import qp_seeded

    instances = qp_seeded.chunk_instances(chunk["family"], chunk["seed"], chunk["index"], chunk["size"])
    return check_instances(chunk["family"], instances, chunk["osqp"]).state()


def merge_seeded(results: list[dict], names: list[str], tolerance: float) -> tuple[dict, list[str], list]:
    """The chunks' reports added up per family: (result JSON, failures, reports), as crosscheck()."""
    reports = {n: FamilyReport(n) for n in names}
    for st in results:
        reports[st["name"]].absorb(st)
    reports = [r for r in reports.values() if r.count]
    failures = [f for r in reports for f in r.failures]
    not_kept = sum(st["num_failures"] for st in results) - len(failures)
    if not_kept:
        failures.append(f"... and {not_kept} more failures (not kept)")
    for r in reports:
        if r.max_rel_err_ac > tolerance:
            failures.append(f"{r.name}: max_rel_err_ac {r.max_rel_err_ac:.3g} > {tolerance:g}")
        if r.max_rel_err_force > tolerance:
            failures.append(f"{r.name}: max_rel_err_force {r.max_rel_err_force:.3g} > {tolerance:g}")
    result = {"ok": not failures, "tolerance": tolerance, "families": [r.as_json() for r in reports],
              "instances": sum(r.count for r in reports)}
    return result, failures, reports
