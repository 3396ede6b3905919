"""Reader of the projection-instance families (datasets_generated/qp/, format in its README.md).

An instance is one quasi-static projection (METHOD.md sections 2-3):
    ac = argmin 1/2 (a - au)^T M (a - au)   s.t.   J a >= b,
M (6, 6) the god-object's generalised mass (world frame), J (m, 6) the contact rows,
au (6,) the unconstrained step, b (m,) the offsets. `load_family("box")` returns the
instances of datasets_generated/qp/box.json; `check_all()` regenerates every family in a
temporary directory and compares it with MANIFEST.json.

One family is derived from the files rather than stored: `row_scaled` (ROW_SCALED), each
instance of the other families (but ROW_SCALED_LEFT_OUT) twice, its rows scaled by positive
factors whose norms span 16 orders of magnitude, then the same rows rescaled by another
such draw (see row_scaled()). The feasible cone, hence the exact answer, is the same for
every positive scaling of a row: the projection must give it either way.
"""
from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .paths import DATASETS_DIR

FAMILIES_DIR = DATASETS_DIR / "qp"
GENERATOR_MODULE = "gauss6.generators.qp"
FORMAT = "gauss6-qp-instances"
FORMAT_VERSION = 1
PUSH_LABELS = ("all", "some", "none")
ROW_SCALED = "row_scaled"
# Row factors 10^U(-ROW_SCALE_DECADES, ROW_SCALE_DECADES): well inside the projection's
# range of lengths (quasistatics.cpp: kMinLength, kMaxLength) for every stored family.
ROW_SCALE_DECADES = 8
ROW_SCALED_SEED = 1201
# Families row_scaled does not draw from: warm (its steps are a sequence, solved warm) and
# inertia, whose accuracy M's condition sets (2e-11 against the exact answer with its rows
# as stored; eps sqrt(cond M)): row_scaled is held to 1e-12, the rows' part alone.
ROW_SCALED_LEFT_OUT = ("warm", "inertia")


@dataclass
class Instance:
    """One projection problem. push: 'all' (every J_k au < 0), 'none' (J au >= 0) or
    'some'; sequence/step: position in a warm-start sequence, -1 outside one."""
    id: str
    M: np.ndarray    # (6, 6) symmetric positive definite, kg and kg m^2, world frame
    au: np.ndarray   # (6,) linear (m) then angular (rad), world frame
    J: np.ndarray    # (m, 6), m >= 0
    b: np.ndarray    # (m,), m
    push: str
    sequence: int = -1
    step: int = -1
    tags: dict = field(default_factory=dict)

    @property
    def num_rows(self) -> int:
        return len(self.J)


def family_names() -> list[str]:
    """The families listed in MANIFEST.json, in generation order."""
    manifest = json.loads((FAMILIES_DIR / "MANIFEST.json").read_text())
    return [Path(f).stem for f in manifest["outputs"]]


def crosscheck_family_names() -> list[str]:
    """The families `gauss6 crosscheck qp` checks by default: the stored ones, then row_scaled."""
    return family_names() + [ROW_SCALED]


def row_scaled(instances: list[Instance], rng: np.random.Generator) -> list[Instance]:
    """Each instance with rows twice: J_k, b_k scaled by s_k = 10^U(-D, D) (row norms
    spanning 2 D orders of magnitude; D = ROW_SCALE_DECADES), then by another draw t_k
    (ids "<id>/rows-a", "<id>/rows-b"). With offsets (b != 0) the factors are powers of
    two over the same range, so that the scaled rows are exactly the given ones times s_k:
    the offsets family's infeasible instances (a row and its exact opposite) stay exactly
    infeasible, where a rounded factor would tilt one row by an ulp and make them feasible."""
    out = []
    for inst in instances:
        J, b = inst.J, inst.b
        exact = bool(np.any(b != 0))
        for tag in ("a", "b"):
            s = 10.0 ** rng.uniform(-ROW_SCALE_DECADES, ROW_SCALE_DECADES, inst.num_rows)
            if exact:
                s = np.exp2(np.round(np.log2(s)))
            J, b = J * s[:, None], b * s
            out.append(Instance(id=f"{inst.id}/rows-{tag}", M=inst.M, au=inst.au, J=J, b=b, push=inst.push,
                                tags=dict(inst.tags, row_scaled=tag)))
    return out


def row_scaled_family() -> list[Instance]:
    """The derived family: row_scaled() of every stored family but ROW_SCALED_LEFT_OUT, in turn."""
    rng = np.random.default_rng(ROW_SCALED_SEED)
    return [x for name in family_names() if name not in ROW_SCALED_LEFT_OUT
            for x in row_scaled(load_family(name), rng)]


def _family_path(name_or_path: str | Path) -> Path:
    """A bare name ('box') is a family of FAMILIES_DIR; anything else is a path."""
    if isinstance(name_or_path, str) and name_or_path.isidentifier():
        return FAMILIES_DIR / f"{name_or_path}.json"
    return Path(name_or_path)


def _int(path: Path, iid: str, key: str, value) -> int:
    if not isinstance(value, int) or isinstance(value, bool):
        raise ValueError(f"{path}: instance {iid}: '{key}' is not an integer")
    return value


def _array(path: Path, iid: str, key: str, value, shape: tuple[int, ...]) -> np.ndarray:
    """value as a float array of the given shape (-1: any length), or ValueError naming the place."""
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{path}: instance {iid}: '{key}' is not an array of numbers") from e
    if key == "J" and a.size == 0:
        a = a.reshape(0, 6)
    if a.ndim != len(shape) or any(s != -1 and s != n for s, n in zip(shape, a.shape)):
        raise ValueError(f"{path}: instance {iid}: '{key}' has shape {a.shape}, expected {shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{path}: instance {iid}: '{key}' has a non-finite value")
    return a


def load_family(name_or_path: str | Path) -> list[Instance]:
    """The instances of one family: a name ('box', 'peg', ...) or a path to a family file.

    Raises ValueError naming the file and the problem for a malformed file."""
    if name_or_path == ROW_SCALED:
        return row_scaled_family()
    path = _family_path(name_or_path)
    try:
        doc = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not valid JSON: {e}") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise ValueError(f"{path}: not a {FORMAT} file")
    if doc.get("version") != FORMAT_VERSION:
        raise ValueError(f"{path}: format version {doc.get('version')!r}, this reader knows {FORMAT_VERSION}")
    return [from_record(path, k, rec) for k, rec in enumerate(doc.get("instances", []))]


def from_record(path: Path | str, k: int, rec: dict) -> Instance:
    """One instance record (the generator's dict, as in a family file) as an Instance;
    ValueError naming `path` and the instance for a malformed record."""
    iid = str(rec.get("id", f"#{k}"))
    try:
        J = _array(path, iid, "J", rec["J"], (-1, 6))
        inst = Instance(
            id=iid,
            M=_array(path, iid, "M", rec["M"], (6, 6)),
            au=_array(path, iid, "au", rec["au"], (6,)),
            J=J,
            b=_array(path, iid, "b", rec["b"], (len(J),)),
            push=rec["push"],
            sequence=_int(path, iid, "sequence", rec["sequence"]),
            step=_int(path, iid, "step", rec["step"]),
            tags=rec.get("tags", {}),
        )
    except KeyError as e:
        raise ValueError(f"{path}: instance {iid}: missing key {e}") from None
    if inst.push not in PUSH_LABELS:
        raise ValueError(f"{path}: instance {iid}: push {inst.push!r} is not one of {PUSH_LABELS}")
    return inst


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def generate(out_dir: Path | None = None, datasets_dir: Path | None = None) -> None:
    """Run the generator (gauss6.generators.qp): every family and MANIFEST.json into out_dir
    (default: in place), on the meshes of datasets_dir (default: paths.DATASETS_DIR). It runs
    in a process of its own, so that it loads numpy's OpenBLAS with the kernels it pins (see
    the generator's imports): the files are then the same bytes on every x86-64 machine.
    Raises RuntimeError with the generator's own error output when it fails."""
    cmd = [sys.executable, "-m", GENERATOR_MODULE, "--out", str(out_dir if out_dir is not None else FAMILIES_DIR)]
    env = {**os.environ, "GAUSS6_DATASETS_DIR": str(datasets_dir if datasets_dir is not None else DATASETS_DIR)}
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    if r.returncode != 0:
        raise RuntimeError(f"{GENERATOR_MODULE} failed (exit {r.returncode}):\n{r.stderr}")
    sys.stderr.write(r.stderr)


def check_all() -> list[str]:
    """Regenerate every family in a temporary directory and compare with MANIFEST.json.

    Returns one line per problem (a generator source, committed file or regenerated file
    whose checksum differs from the manifest); an empty list when everything matches."""
    from .generators import source

    manifest = json.loads((FAMILIES_DIR / "MANIFEST.json").read_text())
    gen_path, gen_sha = source(GENERATOR_MODULE)
    problems = []
    if gen_sha != manifest["source_sha256"]:
        problems.append(f"{gen_path}: source changed since MANIFEST.json was written")
    with tempfile.TemporaryDirectory() as tmp:
        generate(Path(tmp))
        for name, want in manifest["outputs"].items():
            committed, fresh = FAMILIES_DIR / name, Path(tmp) / name
            if not committed.exists():
                problems.append(f"{committed}: missing")
            elif _sha256(committed) != want:
                problems.append(f"{committed}: checksum differs from MANIFEST.json")
            if not fresh.exists() or _sha256(fresh) != want:
                problems.append(f"{name}: regenerated file differs from MANIFEST.json")
    return problems
