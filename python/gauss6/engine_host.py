"""The engine under test in a child process of its own (docs/engine-contract.md, "Isolation"): a
crash, an exit (even exit(0)), a hang or an exception of the engine becomes an EngineFailure
naming it, and the validator lives on to write its report and the trace up to the last good tick.

    host = ProcessHost("build/engine/libgauss6_engine.so", config, step_timeout=2.0, run_timeout=1800)
    host.start()                          # the child: loads the library (or the Python engine), creates it
    host.reset(scene)
    s = host.step(t, xh_p, xh_q)          # Stepped: the EngineStep, the call's wall and CPU seconds
    host.close()

InlineHost serves an engine in this process alike: no isolation (for engine objects a caller built,
and to measure what the isolation costs). Both time the engine's step call themselves, around the
call alone (inside the child for ProcessHost, so that the transport is not charged to the engine),
and both refuse an output that cannot be judged (gauss6.engine.StepCheck).

Transport of a step: shared memory (a memfd both processes map). The validator writes the request
(t, the handle's pose) and bumps its sequence number; the child, spinning on that number for a
while (_Spin) before it blocks on an eventfd, steps the engine, writes the answer and bumps its own
number; the validator spins on it likewise. Each side also writes the other's eventfd, so that a
side that gave up spinning wakes (a stale wake-up costs one more look). A side spins about twice
as long as its recent waits, and not at all once they exceed SPIN_SECONDS: a slow peer or a loaded
machine (where spinning takes the CPU the peer needs) makes both sides block at once. Spinning
relies on x86's ordered stores; elsewhere both sides always block (a system call orders memory).
Set-up and tear-down (start, reset, close) go by pickled messages on a socket pair, whose end of
file tells the validator that the child died: waitpid then names the signal or the exit status.
The validator's watchdogs: a step that does not answer within step_timeout, or a run (its set-up
included, from start) past run_timeout, is a hang; the child is killed.
"""
from __future__ import annotations

import math
import mmap
import os
import platform
import select
import signal
import socket
import subprocess
import sys
import time
import traceback
from dataclasses import dataclass
from multiprocessing.connection import Connection

import numpy as np

from .engine import (CONTACT_CAPACITY, FAILURE_KINDS, EngineFailure, EngineScene, EngineStep, StepCheck,
                     engine_declarations, make_engine)

STEP_TIMEOUT = 2.0     # s: default per-step watchdog (a step's answer)
RUN_TIMEOUT = 3600.0   # s: default per-run watchdog, from the child's start to the last step
SPIN_SECONDS = 200e-6 if platform.machine() in ("x86_64", "AMD64") else 0.0  # the longest spin before blocking
SPIN_AVERAGE = 16      # waits in the spin's exponential average
CLOSE_SECONDS = 2.0    # s: what a child gets to destroy its engine and exit before it is killed

# Shared memory: int64 words, then float64 slots, then the failure's text.
_REQ_SEQ, _RESP_SEQ, _STATUS, _NUM_CONTACTS, _KIND, _DETAIL_LEN = range(6)
_F0 = 8                                   # first float64 slot (after 8 int64 words)
_T, _XH = 0, 1                            # request: t, xh_p (3), xh_q (4)
_XS, _W, _OWN, _WALL, _CPU = 8, 15, 21, 22, 23   # answer: xs_p (3), xs_q (4), wrench (6), own time, wall, cpu
_C = 24                                   # contacts, CONTACT_CAPACITY x 7
_FLOATS = _C + 7 * CONTACT_CAPACITY
_TEXT = 8 * (_F0 + _FLOATS)
_TEXT_SIZE = 4096
_SIZE = _TEXT + _TEXT_SIZE
_ONE = (1).to_bytes(8, sys.byteorder)


@dataclass
class Stepped:
    """A step's answer and the wall and CPU seconds of the engine's step call alone."""
    step: EngineStep
    wall: float
    cpu: float


class _Spin:
    """How long one side spins on the other's sequence number before it blocks: twice its recent
    waits (an exponential average over SPIN_AVERAGE), or not at all while those exceed SPIN_SECONDS."""

    def __init__(self):
        self.average = 0.0

    def until(self, words, index: int, value: int, since: float) -> bool:
        """Whether words[index] became value within the spin (since: when the wait began)."""
        budget = 0.0 if self.average > SPIN_SECONDS else min(2 * self.average, SPIN_SECONDS)
        end = since + budget
        while words[index] != value:
            if time.perf_counter() >= end:
                return False
        self.record(since)
        return True

    def record(self, since: float) -> None:
        self.average += (time.perf_counter() - since - self.average) / SPIN_AVERAGE


def _describe(e: BaseException) -> str:
    """An exception as `Type: message (file:line in function)`, at the frame that raised it."""
    frames = traceback.extract_tb(e.__traceback__)
    where = f" ({os.path.basename(frames[-1].filename)}:{frames[-1].lineno} in {frames[-1].name})" if frames else ""
    return f"{type(e).__name__}: {e}{where}"


def _call(stage: str, fn, *args):
    """fn(*args), with whatever it raises as an EngineFailure naming the stage."""
    try:
        return fn(*args)
    except EngineFailure:
        raise
    except (Exception, SystemExit) as e:
        raise EngineFailure("exception", f"{stage}: {_describe(e)}") from None


def _step(engine, check: StepCheck, t: float, xh_p, xh_q) -> Stepped:
    """One step of an engine, timed around the call (a C engine's step_timed times the call into
    its library alone), its output checked."""
    timed = getattr(engine, "step_timed", None)
    if timed is not None:
        step, wall, cpu = _call(f"step at t = {t!r}", timed, t, xh_p, xh_q)
    else:
        cpu, wall = time.process_time(), time.perf_counter()
        step = _call(f"step at t = {t!r}", engine.step, t, xh_p, xh_q)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    if not isinstance(step, EngineStep):
        raise EngineFailure("abi", f"step at t = {t!r} returned {type(step).__name__}, not an EngineStep")
    check(step, t)
    return Stepped(step, wall, cpu)


class Host:
    """What the driver talks to: start, reset, step, close; name, library, declarations after start;
    isolation() the mode and the per-tick cost of the transport (us: median, p99, max)."""
    mode = ""

    def __init__(self):
        self.name, self.library, self.declarations = "", "", {}
        self._overhead: list[float] = []

    def isolation(self) -> dict:
        o = np.asarray(self._overhead, float) * 1e6
        stats = {"median": float(np.median(o)), "p99": float(np.quantile(o, 0.99)), "max": float(o.max())} \
            if len(o) else {"median": None, "p99": None, "max": None}
        return {"mode": self.mode, "round_trip_us": stats}

    def close(self) -> None:
        pass


class InlineHost(Host):
    """An engine in this process: `InlineHost(engine)` for an object, `InlineHost.of(spec, config)`
    to make one at start. An engine's crash, exit or hang is the process's; its exceptions and
    malformed outputs are EngineFailures."""
    mode = "inline"

    def __init__(self, engine=None, spec: str = "", config: str = ""):
        super().__init__()
        self.engine, self.spec, self.config = engine, spec, config
        self._check = None

    @classmethod
    def of(cls, spec: str, config: str = "") -> "InlineHost":
        return cls(None, spec, config)

    def start(self) -> None:
        if self.engine is None:
            self.engine = _call("create", make_engine, self.spec, self.config)
        self.name = getattr(self.engine, "name", type(self.engine).__name__)
        self.library = getattr(self.engine, "path", self.spec)
        self.declarations = _call("declarations", engine_declarations, self.engine)

    def reset(self, scene: EngineScene) -> None:
        self._check = StepCheck(scene)
        _call("reset", self.engine.reset, scene)

    def step(self, t: float, xh_p, xh_q) -> Stepped:
        start = time.perf_counter()
        s = _step(self.engine, self._check, t, xh_p, xh_q)
        self._overhead.append(time.perf_counter() - start - s.wall)
        return s


class ProcessHost(Host):
    """An engine by spec (a library path or name, python:MODULE:FACTORY) in a child process."""
    mode = "process"

    def __init__(self, spec: str, config: str = "", step_timeout: float = STEP_TIMEOUT,
                 run_timeout: float = RUN_TIMEOUT):
        super().__init__()
        if not (step_timeout > 0 and run_timeout > 0):
            raise ValueError("the watchdogs' timeouts must be > 0 s")
        self.spec, self.config = spec, config
        self.step_timeout, self.run_timeout = float(step_timeout), float(run_timeout)
        self.library = spec
        self._proc = None
        self._tick = 0

    def start(self) -> None:
        self._run_deadline = time.perf_counter() + self.run_timeout
        mem_fd = os.memfd_create("gauss6-engine", os.MFD_CLOEXEC)
        os.ftruncate(mem_fd, _SIZE)
        self._mem = mmap.mmap(mem_fd, _SIZE)
        self._words = memoryview(self._mem).cast("q")
        self._f = np.frombuffer(self._mem, np.float64, _FLOATS, 8 * _F0)
        self._req_fd = os.eventfd(0, os.EFD_NONBLOCK)
        self._resp_fd = os.eventfd(0, os.EFD_NONBLOCK)
        ours, theirs = socket.socketpair()
        fds = (theirs.fileno(), mem_fd, self._req_fd, self._resp_fd)
        # The child imports what this process imports (its sys.path); its stdout goes to stderr, so
        # that what an engine prints never mixes with the report.
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
        self._proc = subprocess.Popen([sys.executable, "-m", "gauss6.engine_host", *map(str, fds)], pass_fds=fds,
                                      stdin=subprocess.DEVNULL, stdout=2, env=env)
        theirs.close()
        os.close(mem_fd)
        self._conn = Connection(ours.detach())
        self._seq = 0
        self._spin = _Spin()
        info = self._message(("start", self.spec, self.config), "in create (loading the engine)")
        self.name, self.library, self.declarations = info["name"], info["library"], info["declarations"]

    def reset(self, scene: EngineScene) -> None:
        self._message(("reset", scene), "in reset")
        self._tick = 0

    def _deadline(self) -> tuple[float, str]:
        step_deadline = time.perf_counter() + self.step_timeout
        if step_deadline <= self._run_deadline:
            return step_deadline, f"the step watchdog ({self.step_timeout:g} s)"
        return self._run_deadline, f"the run watchdog ({self.run_timeout:g} s)"

    def _message(self, message, stage: str):
        """A set-up message and its answer, under the run watchdog (a set-up may take minutes: an
        adapter's convex decomposition)."""
        try:
            self._conn.send(message)
        except OSError:
            self._died(stage)
        deadline, watchdog = self._run_deadline, f"the run watchdog ({self.run_timeout:g} s)"
        while True:
            remaining = deadline - time.perf_counter()
            if remaining <= 0:
                self._hang(stage, watchdog)
            if select.select([self._conn.fileno()], [], [], remaining)[0]:
                break
        try:
            answer = self._conn.recv()
        except (EOFError, OSError):
            self._died(stage)
        if answer[0] == "fail":
            raise EngineFailure(answer[1], answer[2])
        return answer[1]

    def step(self, t: float, xh_p, xh_q) -> Stepped:
        f, words = self._f, self._words
        f[_T:_XH + 7] = [t, *xh_p, *xh_q]
        self._seq += 1
        start = time.perf_counter()
        words[_REQ_SEQ] = self._seq
        os.write(self._req_fd, _ONE)
        if not self._spin.until(words, _RESP_SEQ, self._seq, start):
            self._await(self._seq, t)
            self._spin.record(start)
        total = time.perf_counter() - start
        tick = self._tick
        self._tick += 1
        if words[_STATUS]:
            detail = bytes(self._mem[_TEXT:_TEXT + words[_DETAIL_LEN]]).decode(errors="replace")
            raise EngineFailure(FAILURE_KINDS[words[_KIND]], f"tick {tick}: {detail}")
        m = words[_NUM_CONTACTS]
        a = f[_XS:_C].copy()
        own, wall, cpu = a[_OWN - _XS:_C - _XS].tolist()
        step = EngineStep(a[0:3], a[3:7], a[_W - _XS:_W - _XS + 6],
                          None if m < 0 else f[_C:_C + 7 * m].reshape(m, 7).copy(), None if math.isnan(own) else own)
        self._overhead.append(total - wall)
        return Stepped(step, wall, cpu)

    def _await(self, seq: int, t: float) -> None:
        words = self._words
        deadline, watchdog = self._deadline()
        stage = f"in the step at tick {self._tick} (t = {t!r})"
        while words[_RESP_SEQ] != seq:
            remaining = deadline - time.perf_counter()
            if remaining <= 0:
                self._hang(stage, watchdog)
            ready = select.select([self._resp_fd, self._conn.fileno()], [], [], remaining)[0]
            if self._resp_fd in ready:
                try:
                    os.read(self._resp_fd, 8)
                except BlockingIOError:
                    pass
            elif ready and words[_RESP_SEQ] != seq:
                self._died(stage)  # the child sends nothing during a step: its socket's end of file

    def _died(self, stage: str):
        try:
            code = self._proc.wait(timeout=CLOSE_SECONDS)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            code = self._proc.wait()
        self._proc = None
        if code < 0:
            raise EngineFailure("signal", f"the engine's process was killed by {signal.Signals(-code).name} "
                                          f"({signal.strsignal(-code)}) {stage}")
        raise EngineFailure("exit", f"the engine's process exited with status {code} {stage}")

    def _hang(self, stage: str, watchdog: str):
        self._proc.kill()
        self._proc.wait()
        self._proc = None
        raise EngineFailure("hang", f"no answer {stage} within {watchdog}; the engine's process was killed")

    def close(self) -> None:
        if self._proc is not None:
            try:
                self._conn.send(("close",))
                self._proc.wait(timeout=CLOSE_SECONDS)
            except (OSError, subprocess.TimeoutExpired):
                self._proc.kill()
                self._proc.wait()
            self._proc = None
        for name in ("_req_fd", "_resp_fd"):
            fd = getattr(self, name, None)
            if fd is not None:
                os.close(fd)
                setattr(self, name, None)
        if getattr(self, "_conn", None) is not None:
            self._conn.close()
            self._conn = None

    def __del__(self):
        if getattr(self, "_proc", None) is not None:
            self._proc.kill()
            self._proc.wait()


# ---------------------------------------------------------------------------------------------
# The child.

def _serve(conn_fd: int, mem_fd: int, req_fd: int, resp_fd: int) -> int:
    import ctypes
    import faulthandler
    import resource

    ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG: die with the validator
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))  # a crashing engine leaves no core file
    faulthandler.enable()  # a fatal signal prints the Python frames on stderr, then kills as before
    conn = Connection(conn_fd)
    mem = mmap.mmap(mem_fd, _SIZE)
    os.close(mem_fd)
    words = memoryview(mem).cast("q")
    f = np.frombuffer(mem, np.float64, _FLOATS, 8 * _F0)
    engine, check = None, None
    seq = 0
    spin, answered = _Spin(), time.perf_counter()

    def answer(ok_value=None, failure: EngineFailure | None = None):
        conn.send(("fail", failure.kind, failure.detail) if failure else ("ok", ok_value))

    while True:
        # The next step request, or a message.
        spun = spin.until(words, _REQ_SEQ, seq + 1, answered)
        while words[_REQ_SEQ] == seq:
            ready = select.select([req_fd, conn.fileno()], [], [])[0]
            if req_fd in ready:
                try:
                    os.read(req_fd, 8)
                except BlockingIOError:
                    pass
            elif words[_REQ_SEQ] == seq:
                break
        if words[_REQ_SEQ] == seq:  # a message
            try:
                message = conn.recv()
            except (EOFError, OSError):
                return 0
            try:
                if message[0] == "start":
                    engine = _call("create", make_engine, message[1], message[2])
                    answer({"name": getattr(engine, "name", type(engine).__name__),
                            "library": str(getattr(engine, "path", message[1])),
                            "declarations": _call("declarations", engine_declarations, engine)})
                elif message[0] == "reset":
                    check = StepCheck(message[1])
                    answer(_call("reset", engine.reset, message[1]))
                elif message[0] == "close":
                    close = getattr(engine, "close", None)
                    if close is not None:
                        close()
                    return 0
            except EngineFailure as e:
                answer(failure=e)
            answered = time.perf_counter()
            continue
        if not spun:
            spin.record(answered)
        seq = words[_REQ_SEQ]
        try:
            request = f[_T:_XH + 7].copy()
            s = _step(engine, check, float(request[0]), request[_XH:_XH + 3], request[_XH + 3:_XH + 7])
            step = s.step
            f[_XS:_XS + 3], f[_XS + 3:_XS + 7], f[_W:_W + 6] = step.xs_p, step.xs_q, step.wrench
            f[_OWN:_C] = (math.nan if step.step_seconds is None else step.step_seconds, s.wall, s.cpu)
            m = -1 if step.contacts is None else len(step.contacts)
            if m > 0:
                f[_C:_C + 7 * m] = np.asarray(step.contacts, float).ravel()
            words[_NUM_CONTACTS] = m
            words[_STATUS] = 0
        except EngineFailure as e:
            text = e.detail.encode()[:_TEXT_SIZE]
            mem[_TEXT:_TEXT + len(text)] = text
            words[_DETAIL_LEN], words[_KIND], words[_STATUS] = len(text), FAILURE_KINDS.index(e.kind), 1
        words[_RESP_SEQ] = seq
        os.write(resp_fd, _ONE)
        answered = time.perf_counter()


if __name__ == "__main__":
    sys.exit(_serve(*(int(a) for a in sys.argv[1:5])))
