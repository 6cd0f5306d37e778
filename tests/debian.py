"""Debian packages the tests need from outside (chromium, node and npm), installed where missing.

:func:`install` runs apt-get when the program is absent and this process may (root, apt-get
present); it returns the reason it cannot, for the test's skip, or None once it is there.
One install runs at a time on the machine (a lock file): pytest workers that need a package
at once would otherwise meet dpkg's lock.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
from pathlib import Path

APT_LISTS = Path("/var/lib/apt/lists")
APT_LOCK = Path("/tmp/rosl-test-apt.lock")
APT_UPDATE_S = 300
APT_INSTALL_S = 900


def _apt(args: list[str], timeout: float) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    return subprocess.run(
        ["apt-get", *args], env=env, capture_output=True, text=True, timeout=timeout, check=False
    )


def _last_line(done: subprocess.CompletedProcess[str]) -> str:
    lines = [line for line in (done.stderr + done.stdout).splitlines() if line.strip()]
    return lines[-1] if lines else f"exit code {done.returncode}"


def _present(program: str) -> bool:
    return Path(program).exists() if program.startswith("/") else shutil.which(program) is not None


def install(packages: list[str], programs: list[str]) -> str | None:
    """Install ``packages`` unless every one of ``programs`` (paths or names) is there.

    Returns:
        None once the programs are there, else the reason they cannot be.
    """
    missing = [p for p in programs if not _present(p)]
    if not missing:
        return None
    what = f"{missing[0]} is" if len(missing) == 1 else f"{', '.join(missing)} are"
    if os.geteuid() != 0:
        return f"{what} missing and cannot be installed: apt-get needs root"
    if shutil.which("apt-get") is None:
        return f"{what} missing and cannot be installed: there is no apt-get here"
    with APT_LOCK.open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # another worker's install ends within its timeouts
        if all(_present(p) for p in programs):
            return None  # it installed them meanwhile
        return _install(packages, programs)


def _install(packages: list[str], programs: list[str]) -> str | None:
    command = ["install", "-y", *packages]
    try:
        if not any(APT_LISTS.glob("*_Packages*")):
            _apt(["update"], APT_UPDATE_S)
        done = _apt(command, APT_INSTALL_S)
        if done.returncode != 0:  # stale package lists: update once, then try again
            _apt(["update"], APT_UPDATE_S)
            done = _apt(command, APT_INSTALL_S)
    except subprocess.TimeoutExpired as err:
        return f"apt-get did not finish within {err.timeout:.0f} s: {' '.join(map(str, err.cmd))}"
    still = [p for p in programs if not _present(p)]
    if done.returncode != 0 or still:
        return f"apt-get install {' '.join(packages)} failed: {_last_line(done)}"
    return None
