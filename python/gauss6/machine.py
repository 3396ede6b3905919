"""The machine a measurement ran on, as every report and JSON file of gauss6 states it: the
platform, the CPU model (/proc/cpuinfo's model name on Linux, else what Python's platform
module knows), the CPUs this process may run on, the Python version."""
from __future__ import annotations

import os
import platform
from pathlib import Path


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _cpus() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not on Linux
        return os.cpu_count() or 1


def machine() -> dict:
    """{"platform", "processor", "cpus", "python"} (validation.json, certify.json, the reports)."""
    return {"platform": platform.platform(), "processor": _cpu_model(), "cpus": _cpus(),
            "python": platform.python_version()}


def machine_line() -> str:
    """One sentence for a report: `Machine: MODEL, N CPUs (PLATFORM, Python X.Y.Z).`"""
    m = machine()
    return f"Machine: {m['processor']}, {m['cpus']} CPUs ({m['platform']}, Python {m['python']})."
