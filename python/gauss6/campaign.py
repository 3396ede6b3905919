"""Campaigns: many independent chunks of work run as tasks on Dask distributed.

A campaign is three things (the `Campaign` dataclass):
    chunks     a list of chunk descriptions: JSON-ready values (dicts, lists, numbers,
               strings), each naming one piece of work completely (a family, a seed, a
               range of indices);
    run_chunk  a pure function chunk -> result: a module-level function (so that a
               worker process can import it), whose result is JSON-ready and depends on
               the chunk alone (not on the worker, the order or the other chunks);
    merge      a function (list of results, in the order of `chunks`) -> the summary.

`run_campaign(campaign, ...)` runs the chunks serially in this process (workers=0), on a
`LocalCluster` of worker processes started for the run (workers=N, default all cores),
or on an existing Dask cluster (scheduler="tcp://host:port"); in every case the
results are merged in chunk order, so the summary is the same. With an output folder,
each finished chunk's result is written at once (out/chunks/NNNNNN.json, written to a
temporary name then renamed: a file present is complete; it states what it is: the chunk's
index and description, the generator's source hash, the code version, its result's sha256,
and is checked against them on resume: a file that is unreadable or does not match is set
aside, named in CampaignRun.recomputed, and its chunk recomputed), after out/campaign.json
(the campaign's name, parameters and the sha256 of its chunk list); a run into a folder that already
holds the same campaign takes the finished chunks from disk and runs only the others,
so a killed campaign resumes where it stopped. A folder holding another campaign is
refused. Dask retries the tasks of a worker that dies (`allowed_failures`), so a lost
worker costs only its unfinished chunks. A chunk that raises stops the campaign with a
CampaignError naming it (the chunks finished before stay written). Progress is a tqdm
bar on stderr.
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

FORMAT = "gauss6-campaign"
FORMAT_VERSION = 1


@dataclass
class Campaign:
    name: str                             # e.g. "crosscheck-qp"
    chunks: list[Any]                     # JSON-ready chunk descriptions
    run_chunk: Callable[[Any], Any]       # pure, module-level: chunk -> JSON-ready result
    merge: Callable[[list[Any]], Any]     # results in chunk order -> summary
    parameters: dict = field(default_factory=dict)  # what defines the campaign (recorded, compared on resume)
    sources: tuple = ()                   # modules whose code makes the chunks, beside run_chunk's (hashed)


@dataclass
class CampaignRun:
    summary: Any
    chunks_run: int        # chunks computed by this run
    chunks_resumed: int    # chunks read back from the output folder
    seconds: float         # wall time of this run
    workers: int           # 0: serial in this process
    recomputed: list = field(default_factory=list)  # chunk files set aside and recomputed: "path: why"


class CampaignError(RuntimeError):
    """A campaign that cannot run as asked (a folder holding another campaign, a bad
    scheduler address); the message names the problem."""


def _dumps(value: Any) -> str:
    return json.dumps(value, separators=(",", ":"), sort_keys=True, allow_nan=False)


def _header(campaign: Campaign) -> dict:
    chunks = _dumps(campaign.chunks)
    return {"format": FORMAT, "version": FORMAT_VERSION, "name": campaign.name,
            "parameters": campaign.parameters, "num_chunks": len(campaign.chunks),
            "chunks_sha256": hashlib.sha256(chunks.encode()).hexdigest()}


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


CHUNK_FORMAT = "gauss6-campaign-chunk"
CHUNK_FORMAT_VERSION = 2  # version 1 files (chunk and result only) are recomputed


def _sha256(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def generator_hash(campaign: Campaign) -> str:
    """sha256 of the source files of the code that computes the chunks: run_chunk's module and
    the modules of campaign.sources (a chunk computed by other code is not resumed)."""
    import importlib

    names = [campaign.run_chunk.__module__, *campaign.sources]
    h = hashlib.sha256()
    for name in names:
        module = importlib.import_module(name)
        h.update(name.encode() + b"\0" + Path(module.__file__).read_bytes() + b"\0")
    return h.hexdigest()


def code_version() -> str:
    from . import __version__

    return __version__


class _Store:
    """The output folder: campaign.json, then one file per finished chunk. Each chunk file says
    what it is (the campaign's name, its index, its chunk description (the seeds and index range
    it covers), the generator's source hash, the code version) and the sha256 of its result; on
    resume, a file that is unreadable or does not match is set aside (renamed *.damaged-N) and its
    chunk recomputed, and `problems` names it."""

    def __init__(self, out: Path | None, campaign: Campaign):
        self.dir = None if out is None else Path(out) / "chunks"
        self.campaign = campaign
        self.problems: list[str] = []   # "path: what was wrong" for every chunk file set aside
        if out is None:
            return
        out = Path(out)
        self.identity = {"campaign": campaign.name, "generator_sha256": generator_hash(campaign),
                         "code_version": code_version()}
        header = _header(campaign)
        head_path = out / "campaign.json"
        try:
            if out.exists() and not out.is_dir():
                raise CampaignError(f"{out}: the campaign folder exists and is not a directory")
            if head_path.exists() or head_path.is_symlink():
                try:
                    old = json.loads(_read_small(head_path))
                except OSError as e:
                    raise CampaignError(f"{head_path}: not a campaign header: {e}") from None
                except (ValueError, UnicodeDecodeError, RecursionError):
                    raise CampaignError(f"{head_path}: not a campaign header (invalid JSON)") from None
                if not isinstance(old, dict):
                    kind = {list: "list", str: "string", bool: "boolean", int: "number", float: "number"}.get(
                        type(old), "null")
                    raise CampaignError(f"{head_path}: not a campaign header (a JSON {kind}, not an object)")
                if old != header:
                    raise CampaignError(f"{out}: holds another campaign ({old.get('name')!r}, "
                                        f"{old.get('num_chunks')} chunks, parameters {old.get('parameters')}); "
                                        f"use another --out or remove it")
            else:
                out.mkdir(parents=True, exist_ok=True)
                _write_atomic(head_path, json.dumps(header, indent=1) + "\n")
            if self.dir.exists() and not self.dir.is_dir():
                raise CampaignError(f"{self.dir}: exists and is not a directory")
            self.dir.mkdir(exist_ok=True)
        except OSError as e:
            raise CampaignError(f"{e.filename or out}: {e.strerror or e}") from None

    def path(self, index: int) -> Path:
        return self.dir / f"{index:06d}.json"

    def load(self, index: int) -> tuple[bool, Any]:
        """(True, result) for a chunk file that is this chunk's; (False, None) when there is none
        or it was set aside (self.problems says why)."""
        if self.dir is None:
            return False, None
        path = self.path(index)
        if not (path.exists() or path.is_symlink()):
            return False, None
        problem = None
        try:
            doc = json.loads(_read_small(path))
        except OSError as e:
            problem = f"unreadable ({e.strerror or e})"
        except (ValueError, UnicodeDecodeError, RecursionError):
            problem = "not a chunk file (empty, truncated or not JSON)"
        else:
            problem = self._mismatch(index, doc)
        if problem is None:
            return True, doc["result"]
        self._set_aside(path, problem)
        return False, None

    def _mismatch(self, index: int, doc: Any) -> str | None:
        """What makes doc not the result of chunk `index` of this campaign, or None."""
        if not isinstance(doc, dict) or doc.get("format") != CHUNK_FORMAT:
            return "not a chunk file of this format"
        if doc.get("version") != CHUNK_FORMAT_VERSION:
            return f"chunk file version {doc.get('version')!r}, expected {CHUNK_FORMAT_VERSION}"
        expected = {**self.identity, "index": index, "chunk": self.campaign.chunks[index]}
        try:
            for key, want in expected.items():  # compared as JSON: a chunk's tuples read back as lists
                if _dumps(doc.get(key)) != _dumps(want):
                    return f"{key} {_short(doc.get(key))} does not match this chunk's {_short(want)}"
            if "result" not in doc:
                return "no result"
            digest = _sha256(_dumps(doc["result"]))
        except ValueError:  # NaN or Infinity, which this code never writes
            return "not plain JSON (NaN or Infinity)"
        if doc.get("result_sha256") != digest:
            return "its result does not match its result_sha256 (edited or damaged)"
        return None

    def _set_aside(self, path: Path, problem: str) -> None:
        for n in range(1, 1000):
            aside = path.with_name(f"{path.name}.damaged-{n}")
            if not (aside.exists() or aside.is_symlink()):
                break
        try:
            os.rename(path, aside)
            where = f"set aside as {aside.name}"
        except OSError as e:
            raise CampaignError(f"{path}: {problem}, and cannot be set aside ({e.strerror or e})") from None
        self.problems.append(f"{path}: {problem}; {where}, chunk {path.stem.lstrip('0') or '0'} recomputed")

    def save(self, index: int, chunk: Any, result: Any) -> None:
        if self.dir is not None:
            doc = {"format": CHUNK_FORMAT, "version": CHUNK_FORMAT_VERSION, **self.identity, "index": index,
                   "chunk": chunk, "result_sha256": _sha256(_dumps(result)), "result": result}
            _write_atomic(self.path(index), _dumps(doc) + "\n")


MAX_CHUNK_FILE = 1 << 30  # bytes: a chunk file larger than this is not one this code wrote


def _read_small(path: Path) -> str:
    """A campaign file's text: a regular file of at most MAX_CHUNK_FILE bytes (paths.read_input_text),
    OSError otherwise (a directory, a FIFO, ...), ValueError when not UTF-8."""
    from .paths import PathError, read_input_text

    try:
        return read_input_text(path, "campaign file", MAX_CHUNK_FILE)
    except PathError as e:
        raise OSError(str(e).split(": ", 1)[-1]) from None


def _short(value: Any) -> str:
    text = json.dumps(value, sort_keys=True, default=str)
    return text if len(text) <= 80 else text[:77] + "..."


def default_workers() -> int:
    """All cores of this machine."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _progress(total: int, initial: int, desc: str, show: bool):
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc=desc, unit="chunk", disable=not show, file=sys.stderr,
                dynamic_ncols=True)


def run_campaign(campaign: Campaign, out: Path | str | None = None, workers: int | None = None,
                 scheduler: str | None = None, show_progress: bool = True) -> CampaignRun:
    """Runs every chunk not already in `out` and merges all results in chunk order.

    workers: 0 runs serially in this process; N >= 1 starts a LocalCluster of N worker
    processes (one thread each) for this run; None means all cores. scheduler: the
    address of an existing Dask scheduler (then workers is ignored)."""
    t0 = time.perf_counter()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 0):
        raise CampaignError(f"workers must be an integer >= 0 (0: serial), not {workers!r}")
    store = _Store(Path(out) if out is not None else None, campaign)
    results: list[Any] = [None] * len(campaign.chunks)
    todo = []
    for i in range(len(campaign.chunks)):
        done, value = store.load(i)
        if done:
            results[i] = value
        else:
            todo.append(i)
    resumed = len(campaign.chunks) - len(todo)
    n_workers = 0 if scheduler is None and workers == 0 else (default_workers() if workers is None else workers)
    with _progress(len(campaign.chunks), resumed, campaign.name, show_progress) as bar:
        if todo and scheduler is None and n_workers == 0:
            for i in todo:
                results[i] = _result_of(campaign, i, lambda: campaign.run_chunk(campaign.chunks[i]))
                store.save(i, campaign.chunks[i], results[i])
                bar.update(1)
        elif todo:
            n_workers = _run_distributed(campaign, todo, results, store, bar, n_workers, scheduler)
    summary = campaign.merge(results)
    return CampaignRun(summary, len(todo), resumed, time.perf_counter() - t0, n_workers, store.problems)


def _result_of(campaign: Campaign, i: int, get: Callable[[], Any]) -> Any:
    """A chunk's result, or CampaignError naming the chunk (its own error chained)."""
    try:
        return get()
    except Exception as e:  # noqa: BLE001  (any error of a chunk, named with it)
        raise CampaignError(f"{campaign.name}: chunk {i} {_dumps(campaign.chunks[i])} failed: "
                            f"{type(e).__name__}: {e}") from e


def _run_distributed(campaign: Campaign, todo: list[int], results: list, store: _Store, bar, n_workers: int,
                     scheduler: str | None) -> int:
    """The chunks of `todo` as Dask tasks; each result saved as it arrives. Returns the
    number of workers the cluster had at the start."""
    import logging

    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise CampaignError("Dask distributed is not installed (pip install -r requirements.txt, or the "
                            "'campaign' extra of the gauss6 package); --workers 0 runs serially without it") from None

    # The cluster's own INFO lines would interleave with the progress bar.
    for name in ("distributed", "distributed.worker", "distributed.scheduler", "distributed.nanny"):
        logging.getLogger(name).setLevel(logging.ERROR)
    cluster = None
    try:
        if scheduler is None:
            cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, host="127.0.0.1", silence_logs=logging.ERROR)
            client = Client(cluster)
        else:
            try:
                client = Client(scheduler, timeout="10s")
            except (OSError, TimeoutError, ValueError) as e:
                raise CampaignError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
        with client:
            n_workers = len(client.scheduler_info()["workers"])
            # pure=False: a chunk is recomputed if asked again, never served from another run's cache.
            run_id = uuid.uuid4().hex[:12]
            futures = client.map(campaign.run_chunk, [campaign.chunks[i] for i in todo], pure=False,
                                 key=[f"{campaign.name}-{run_id}-{i}" for i in todo])
            index = {f.key: i for f, i in zip(futures, todo)}
            for fut in as_completed(futures):
                i = index[fut.key]
                results[i] = _result_of(campaign, i, fut.result)
                store.save(i, campaign.chunks[i], results[i])
                bar.update(1)
                fut.release()
    finally:
        if cluster is not None:
            cluster.close()
    return n_workers


def chunk_ranges(count: int, chunk_size: int) -> list[tuple[int, int]]:
    """[begin, end) index ranges of at most chunk_size covering range(count)."""
    return [(b, min(b + chunk_size, count)) for b in range(0, count, chunk_size)]
