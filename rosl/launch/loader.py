"""Loading launch files: Python (``generate_launch_description()``), ROS 2's XML and YAML.

A Python launch file runs with ``launch``/``launch_ros`` served by rosl; XML and YAML files are
read by ``xml_format``/``yaml_format`` through the shared ``frontend``. Every problem is one
line naming the file and line: a syntax error, an exception while the file runs, a missing
``generate_launch_description``, a name rosl's launch does not provide, an unknown tag.
"""

from __future__ import annotations

import traceback
from pathlib import Path
from typing import Any

from rosl.launch.description import LaunchDescription
from rosl.launch.errors import LaunchError

_cache: dict[Path, LaunchDescription] = {}


def load_description(path: Path) -> LaunchDescription:
    """Load a launch file (``.py``, ``.xml``, ``.yaml``/``.yml``); cached per path.

    Raises:
        LaunchError: the file is missing, broken, or does not return a LaunchDescription.
    """
    path = path.expanduser().resolve()
    if path in _cache:
        return _cache[path]
    if not path.is_file():
        raise LaunchError(f"launch file {path} does not exist")
    if path.suffix in (".yaml", ".yml"):
        from rosl.launch.yaml_format import load_yaml

        description = load_yaml(path)
    elif path.suffix == ".xml":
        from rosl.launch.xml_format import load_xml

        description = load_xml(path)
    else:
        description = _load_python(path)
    _cache[path] = description
    return description


def _load_python(path: Path) -> LaunchDescription:
    import rosl.compat

    rosl.compat.install(force=True)
    try:
        source = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise LaunchError(f"{path}: cannot read: {err}") from None
    try:
        code = compile(source, str(path), "exec")
    except SyntaxError as err:
        raise LaunchError(
            f"{path}:{err.lineno}:{err.offset or 0}: syntax error: {err.msg}"
        ) from None
    namespace: dict[str, Any] = {"__file__": str(path), "__name__": f"rosl_launch_{path.stem}"}
    _run(path, lambda: exec(code, namespace))
    generate = namespace.get("generate_launch_description")
    if not callable(generate):
        raise LaunchError(
            f"{path}: no generate_launch_description() function; a launch file must define it "
            "and return a LaunchDescription"
        )
    result = _run(path, generate)
    if not isinstance(result, LaunchDescription):
        raise LaunchError(
            f"{path}: generate_launch_description() returned {type(result).__name__}, "
            "not a LaunchDescription"
        )
    return result


def _run(path: Path, call: Any) -> Any:
    try:
        return call()
    except LaunchError as err:
        line = _line_in(path, err)
        text = str(err)
        raise LaunchError(text if str(path) in text else f"{path}:{line}: {text}") from None
    except Exception as err:
        raise LaunchError(f"{path}:{_line_in(path, err)}: {type(err).__name__}: {err}") from None


def _line_in(path: Path, err: BaseException) -> int:
    frames = [f for f in traceback.extract_tb(err.__traceback__) if Path(f.filename) == path]
    return frames[-1].lineno or 0 if frames else 0


def description_from_file(launch_file_path: str | Path) -> LaunchDescription:
    """The LaunchDescription of a launch file of any format (launch_description_sources').

    Raises:
        LaunchError: the file is missing or broken (one line naming it).
    """
    return load_description(Path(launch_file_path))


def find_in_package(package: str, file_name: str) -> Path:
    """Find ``file_name`` anywhere in a package's folder, as ros2 launch does.

    Raises:
        LaunchError: unknown package; no such file (close names listed); several.
    """
    from rosl.idl.names import did_you_mean
    from rosl.pkg.errors import PackageError
    from rosl.pkg.manifest import get_package

    try:
        folder = get_package(package).path
    except PackageError as err:
        raise LaunchError(str(err)) from None
    found = sorted(
        p for p in folder.rglob(file_name) if p.is_file() and "__pycache__" not in p.parts
    )
    if not found:
        launch_files = {p.name for p in folder.rglob("*") if p.suffix in (".py", ".yaml", ".xml")
                        and "launch" in p.name}  # fmt: skip
        raise LaunchError(
            f"file '{file_name}' was not found in the share directory of package '{package}' "
            f"which is at '{folder}'{did_you_mean(file_name, launch_files)}"
        )
    if len(found) > 1:
        listed = ", ".join(str(p.relative_to(folder)) for p in found)
        raise LaunchError(f"file '{file_name}' is ambiguous in package '{package}': {listed}")
    return found[0]


def parse_arguments(arguments: list[str]) -> dict[str, str]:
    """``name:=value`` launch arguments (the last of a name wins).

    Raises:
        LaunchError: an argument without ``:=``.
    """
    parsed: dict[str, str] = {}
    for text in arguments:
        if ":=" not in text:
            raise LaunchError(
                f"malformed launch argument '{text}', expected format '<name>:=<value>'"
            )
        name, value = text.split(":=", 1)
        parsed[name] = value
    return parsed


def clear_cache() -> None:
    """Forget loaded launch files."""
    _cache.clear()
