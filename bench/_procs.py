"""Process helpers for the CLI benchmarks: the `rosl` command, environments, bounded stops."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def rosl_cmd() -> list[str]:
    """The `rosl` console script next to this interpreter (what a user types), else -m rosl."""
    script = Path(sys.executable).parent / "rosl"
    return [str(script)] if script.is_file() else [sys.executable, "-m", "rosl"]


PYCACHE = Path(tempfile.gettempdir()) / "rosl-bench-pycache"


def bench_env(domain: int) -> dict[str, str]:
    """This environment with the bench's domain, as a user's shell would have it.

    Byte code is cached (as after `pip install`) but under a temporary prefix, so the
    benchmarks leave no files in the work tree even when PYTHONDONTWRITEBYTECODE is set here.
    """
    env = {**os.environ, "ROSL_DOMAIN_ID": str(domain), "PYTHONUNBUFFERED": "1"}
    env["PYTHONPYCACHEPREFIX"] = str(PYCACHE)
    for name in ("ROS_DOMAIN_ID", "ROSL_INTERFACE", "PYTHONDONTWRITEBYTECODE"):
        env.pop(name, None)
    return env


def stop(child: subprocess.Popen, sig: int = signal.SIGTERM, timeout: float = 10.0) -> None:
    """Signal ``child`` by pid, wait (bounded), then SIGKILL it; never raises."""
    if child.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            child.send_signal(sig)
        try:
            child.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                child.kill()
            child.wait(timeout=10)
    for stream in (child.stdout, child.stderr):
        if stream is not None:
            with contextlib.suppress(OSError):
                stream.close()


def alive(pid: int) -> bool:
    """Whether ``pid`` exists and is not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False


def children_of(pid: int) -> list[int]:
    """The direct children of ``pid`` (Linux /proc)."""
    found: list[int] = []
    with contextlib.suppress(FileNotFoundError):
        for task in os.listdir(f"/proc/{pid}/task"):
            path = f"/proc/{pid}/task/{task}/children"
            with contextlib.suppress(FileNotFoundError), open(path) as f:
                found.extend(int(p) for p in f.read().split())
    return found


def kill_pids(pids: list[int]) -> None:
    """SIGKILL each leftover pid we caused to exist (by pid, one at a time)."""
    for pid in pids:
        if alive(pid):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, signal.SIGKILL)


def wait_until(predicate, timeout: float, step: float = 0.02) -> float | None:
    """Poll ``predicate`` until true; return the seconds it took, or None at ``timeout``."""
    start = time.perf_counter()
    while True:
        if predicate():
            return time.perf_counter() - start
        if time.perf_counter() - start > timeout:
            return None
        time.sleep(step)
