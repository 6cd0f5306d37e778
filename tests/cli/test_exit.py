"""How a command ends: printing commands skip the interpreter's teardown, losing nothing.

Run through the ``rosl`` console script (as a user types it), as real processes: the output
is whole (also when it is large and piped), the exit status is the command's, and atexit
handlers still run.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROSL = Path(sys.executable).parent / "rosl"

SITE = """
import atexit
import os

marker = os.environ.get("EXIT_MARKER")
if marker:
    atexit.register(lambda: open(marker, "a").write("atexit ran\\n"))


class _TornDown:
    def __init__(self, path):
        self.path = path

    def __del__(self, open=open):  # at the interpreter's teardown (modules cleared)
        if self.path:
            with open(self.path, "a") as handle:
                handle.write("torn down\\n")


_kept = _TornDown(marker)
"""


def _run(
    args: list[str], tmp_path: Path, script: bool
) -> tuple[subprocess.CompletedProcess[str], str]:
    site = tmp_path / "site"
    site.mkdir(exist_ok=True)
    (site / "sitecustomize.py").write_text(SITE, encoding="utf-8")
    marker = tmp_path / f"marker-{script}"
    env = {"PYTHONPATH": str(site), "EXIT_MARKER": str(marker), "PATH": "/usr/bin:/bin"}
    command = [str(ROSL)] if script else [sys.executable, "-m", "rosl"]
    done = subprocess.run(
        [*command, *args], capture_output=True, text=True, timeout=120, env=env, check=False
    )
    return done, marker.read_text() if marker.exists() else ""


def test_a_printing_command_ends_with_its_whole_output_status_and_atexit_handlers(
    tmp_path: Path,
) -> None:
    fast, fast_marker = _run(["interface", "list"], tmp_path, script=True)
    slow, slow_marker = _run(["interface", "list"], tmp_path, script=False)  # a normal exit

    assert fast.returncode == 0, fast.stderr
    assert fast.stdout == slow.stdout
    assert len(fast.stdout.splitlines()) > 100  # large enough to need flushing
    assert fast_marker == "atexit ran\n"  # and no teardown: it ended at once
    assert slow_marker == "atexit ran\ntorn down\n"


def test_a_failing_printing_command_keeps_its_status(tmp_path: Path) -> None:
    done, marker = _run(["interface", "show", "std_msgs/msg/Nope"], tmp_path, script=True)

    assert done.returncode == 1
    assert "std_msgs/msg/Nope" in done.stderr
    assert marker == "atexit ran\n"
