"""Golden-log tests for pytest: record a launch, compare it with a golden bag, regenerate it.

A test runs a launch for a bounded time while everything on the bus is recorded, then checks
the recording against a golden bag kept in the repository::

    from rosl.testing import assert_matches_golden, record_launch

    GOLDEN = Path(__file__).parent / "golden" / "avoidance"

    def test_avoidance_run_matches_the_golden_log(tmp_path):
        bag = record_launch(("my_package", "sim.launch.py"), arguments={"speed": "0.3"},
                            duration=10.0, output=tmp_path / "run")
        assert_matches_golden(bag, GOLDEN, topics=["/odom", "/cmd_vel"], tolerance=1e-3)

A mismatch fails with the differences ``rosl bag diff`` prints (``/odom #12
pose.pose.position.x: 1.2345 vs 1.2501 (|d|=0.0156 > 0.001)``). After an intended change,
rewrite the golden bags from the new runs with ``pytest --rosl-regenerate-golden`` (or
``ROSL_REGENERATE_GOLDEN=1 pytest``), review and commit them. Installing rosl registers this
module as a pytest plugin (the ``pytest11`` entry point ``rosl.testing``), so the flag needs no
``-p rosl.testing`` (which, like ``pytest_plugins = ["rosl.testing"]``, still works). By
default the comparison leaves out ``/rosout``, ``/parameter_events``, ``/clock`` and service
events, and ignores ``header.stamp`` fields at any depth — they change from run to run.

In a launch test (``rosl launch_test`` or pytest), the ``Record`` launch action records the
launch itself and a post-shutdown test compares the bag::

    @pytest.mark.launch_test
    def generate_test_description():
        record = Record()  # the bag of this run, in a fresh temporary folder
        return LaunchDescription([record, Node(...), ReadyToTest()]), {"bag": record.output}

    @launch_testing.post_shutdown_test()
    class TestRecording(unittest.TestCase):
        def test_run_matches_the_golden_log(self, bag):
            assert_matches_golden(bag, GOLDEN, topics=["/chatter"])
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import time
from typing import IO, TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pathlib import Path

    import pytest

    from rosl.bag.diff import DiffResult
    from rosl.launch.runner import Record

__unittest = True  # a launch test's report shows the user's line, not the comparison's
FLAG = "--rosl-regenerate-golden"
ENV = "ROSL_REGENERATE_GOLDEN"
DEFAULT_EXCLUDE = r"^/(rosout|parameter_events|clock)$|/_service_event$"
DEFAULT_IGNORE = ("header.stamp", "*.header.stamp")
_flag_given = False


def __getattr__(name: str) -> Any:
    """``Record`` (a launch action), imported on first use: this module is a pytest plugin."""
    if name == "Record":
        from rosl.launch.runner import Record

        return Record
    raise AttributeError(f"module 'rosl.testing' has no attribute '{name}'")


def pytest_addoption(parser: pytest.Parser) -> None:
    """Register ``--rosl-regenerate-golden``."""
    parser.addoption(
        FLAG,
        action="store_true",
        default=False,
        help="rosl: overwrite golden bags with the new recordings instead of comparing",
    )


def pytest_configure(config: pytest.Config) -> None:
    """Remember whether golden bags are to be regenerated in this run."""
    global _flag_given
    _flag_given = bool(config.getoption(FLAG, default=False))


def regenerating() -> bool:
    """Whether this run rewrites golden bags (the pytest flag or ROSL_REGENERATE_GOLDEN=1)."""
    return _flag_given or os.environ.get(ENV, "").strip().lower() in ("1", "true", "yes")


def _launch_records() -> bool:
    """Whether ``rosl launch`` takes ``--record DIR`` in this installation."""
    from rosl.cli.launch import command

    return any("--record" in getattr(p, "opts", ()) for p in command.params)


def record_launch(
    launch: str | Path | tuple[str, str],
    *,
    output: Path,
    arguments: dict[str, str] | None = None,
    duration: float = 5.0,
    stop_timeout: float = 20.0,
    env: dict[str, str] | None = None,
) -> Path:
    """Run a launch while recording everything on the bus; return the bag folder.

    The launch runs until it ends by itself or ``duration`` seconds have passed, then gets
    Ctrl-C and is waited for (``stop_timeout``; killed after that). Its output goes to
    ``<output>.log`` next to the bag.

    Args:
        launch: a launch file path, or (package, file name).
        output: the bag folder to create.
        arguments: launch arguments (``name:=value``).
        duration: the longest time the launch runs (seconds).
        stop_timeout: how long to wait for a clean exit after Ctrl-C.
        env: extra environment variables (e.g. ``ROSL_DOMAIN_ID``).

    Raises:
        AssertionError: no readable bag was recorded (the message ends with the log's tail).
    """
    target = [str(part) for part in launch] if isinstance(launch, tuple) else [str(launch)]
    args = [f"{key}:={value}" for key, value in (arguments or {}).items()]
    rosl = [sys.executable, "-P", "-m", "rosl"]  # -P: a rosl/ folder here cannot shadow rosl
    full_env = {**os.environ, "PYTHONUNBUFFERED": "1", **(env or {})}
    log_path = output.parent / f"{output.name}.log"
    output.parent.mkdir(parents=True, exist_ok=True)
    with log_path.open("w") as log:
        recorder = None
        if _launch_records():
            command = [*rosl, "launch", "--record", str(output), *target, *args]
        else:  # an older rosl: record beside the launch
            recorder = _start([*rosl, "bag", "record", "-a", "-o", str(output)], log, full_env)
            _wait_for_text(log_path, "Recording to", 10.0)
            command = [*rosl, "launch", *target, *args]
        child = _start(command, log, full_env)
        try:
            child.wait(timeout=duration)
        except subprocess.TimeoutExpired:
            _stop(child, stop_timeout)
        if recorder is not None:
            _stop(recorder, stop_timeout)
    _check_bag(output, log_path)
    return output


def _start(command: list[str], log: IO[str], env: dict[str, str]) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        command, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, env=env,
        start_new_session=True,
    )  # fmt: skip


def _stop(child: subprocess.Popen[bytes], timeout: float) -> None:
    """Ctrl-C one child and wait; kill its session if it does not end in time."""
    if child.poll() is None:
        child.send_signal(signal.SIGINT)
    try:
        child.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(child.pid, signal.SIGKILL)
        child.wait(timeout=5.0)


def _wait_for_text(path: Path, text: str, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if text in path.read_text(errors="replace"):
            return True
        time.sleep(0.05)
    return False


def _check_bag(output: Path, log_path: Path) -> None:
    from rosl.bag.errors import BagError
    from rosl.bag.reader import bag_files

    try:
        bag_files(output)
    except BagError as err:
        tail = "\n".join(log_path.read_text(errors="replace").splitlines()[-20:])
        raise AssertionError(
            f"no recording from the launch: {err}\n--- {log_path}:\n{tail}"
        ) from None


def assert_matches_golden(
    new_bag: Path,
    golden_bag: Path,
    *,
    topics: list[str] | None = None,
    exclude: str | None = DEFAULT_EXCLUDE,
    tolerance: float = 1e-3,
    time_tolerance: float | None = None,
    ignore_fields: tuple[str, ...] | list[str] = DEFAULT_IGNORE,
    regenerate: bool | None = None,
) -> DiffResult | None:
    """Fail unless ``new_bag`` matches ``golden_bag`` (or overwrite the golden bag).

    Args:
        new_bag: the recording to check (folder or MCAP file).
        golden_bag: the reference recording.
        topics: compare only these topics (all that ``exclude`` leaves when None).
        exclude: leave out topics matching this regular expression (None: none).
        tolerance: the largest absolute difference accepted between floats.
        time_tolerance: the largest difference of relative log times (s); None: unchecked.
        ignore_fields: field paths not compared (glob patterns).
        regenerate: copy ``new_bag`` over ``golden_bag`` instead of comparing; None: when
            ``--rosl-regenerate-golden`` or ROSL_REGENERATE_GOLDEN=1 is given.

    Returns:
        The comparison (None when the golden bag was regenerated).

    Raises:
        AssertionError: the bags differ (the message lists the differences), or there is no
            golden bag and regeneration was not asked for.
    """
    from rosl.bag.diff import compare

    if regenerating() if regenerate is None else regenerate:
        replace_golden(new_bag, golden_bag)
        return None
    if not golden_bag.exists():
        raise AssertionError(
            f"no golden bag at {golden_bag}; create it from this run with "
            f"`pytest {FLAG}` (or {ENV}=1)"
        )
    result = compare(
        golden_bag, new_bag, topics=topics, exclude=exclude, tolerance=tolerance,
        time_tolerance=time_tolerance, ignore_fields=tuple(ignore_fields),
    )  # fmt: skip
    if not result.matched:
        raise AssertionError(
            f"{new_bag} does not match the golden bag {golden_bag}:\n{result.text()}"
            f"(if the change is intended, regenerate with `pytest {FLAG}` or {ENV}=1)"
        )
    return result


def replace_golden(new_bag: Path, golden_bag: Path) -> None:
    """Make ``golden_bag`` a copy of ``new_bag`` (a folder, or one MCAP file)."""
    from rosl.bag.reader import bag_files

    files, _ = bag_files(new_bag)
    golden_bag.parent.mkdir(parents=True, exist_ok=True)
    if golden_bag.suffix == ".mcap":
        if len(files) != 1:
            raise AssertionError(f"{new_bag} has {len(files)} MCAP files; a folder is needed")
        shutil.copyfile(files[0], golden_bag)
        return
    staging = golden_bag.with_name(golden_bag.name + ".regenerating")
    shutil.rmtree(staging, ignore_errors=True)
    if new_bag.is_dir():
        shutil.copytree(new_bag, staging)
    else:
        staging.mkdir()
        shutil.copyfile(new_bag, staging / new_bag.name)
    if golden_bag.exists():
        shutil.rmtree(golden_bag) if golden_bag.is_dir() else golden_bag.unlink()
    staging.rename(golden_bag)


__all__ = [
    "Record",
    "assert_matches_golden",
    "record_launch",
    "regenerating",
    "replace_golden",
]
