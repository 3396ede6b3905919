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
temporary name then renamed: a file present is complete), after out/campaign.json
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


@dataclass
class CampaignRun:
    summary: Any
    chunks_run: int        # chunks computed by this run
    chunks_resumed: int    # chunks read back from the output folder
    seconds: float         # wall time of this run
    workers: int           # 0: serial in this process


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


class _Store:
    """The output folder: campaign.json, then one file per finished chunk."""

    def __init__(self, out: Path | None, campaign: Campaign):
        self.dir = None if out is None else Path(out) / "chunks"
        if out is None:
            return
        out = Path(out)
        header = _header(campaign)
        head_path = out / "campaign.json"
        if head_path.exists():
            try:
                old = json.loads(head_path.read_text())
            except json.JSONDecodeError:
                raise CampaignError(f"{head_path}: not a campaign header (invalid JSON)") from None
            if old != header:
                raise CampaignError(f"{out}: holds another campaign ({old.get('name')!r}, "
                                    f"{old.get('num_chunks')} chunks, parameters {old.get('parameters')}); "
                                    f"use another --out or remove it")
        else:
            out.mkdir(parents=True, exist_ok=True)
            _write_atomic(head_path, json.dumps(header, indent=1) + "\n")
        self.dir.mkdir(exist_ok=True)

    def path(self, index: int) -> Path:
        return self.dir / f"{index:06d}.json"

    def load(self, index: int) -> tuple[bool, Any]:
        if self.dir is None or not self.path(index).exists():
            return False, None
        return True, json.loads(self.path(index).read_text())["result"]

    def save(self, index: int, chunk: Any, result: Any) -> None:
        if self.dir is not None:
            _write_atomic(self.path(index), _dumps({"chunk": chunk, "result": result}) + "\n")


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
    return CampaignRun(summary, len(todo), resumed, time.perf_counter() - t0, n_workers)


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


def add_arguments(parser) -> None:
    """The options every campaign command shares."""
    parser.add_argument("--workers", type=int, default=None,
                        help="worker processes of the embedded LocalCluster (default: all cores; 0: serial, "
                             "in this process)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on an existing Dask cluster (tcp://host:port) instead of a LocalCluster")
    parser.add_argument("--out", type=Path, help="folder for the per-chunk results; a rerun into it resumes")


def chunk_ranges(count: int, chunk_size: int) -> list[tuple[int, int]]:
    """[begin, end) index ranges of at most chunk_size covering range(count)."""
    return [(b, min(b + chunk_size, count)) for b in range(0, count, chunk_size)]
