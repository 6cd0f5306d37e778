"""rosbag2's ``metadata.yaml`` (version 9): what the folder holds, per topic and per file."""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import yaml

from rosl.bag.errors import BagError

if TYPE_CHECKING:
    from collections.abc import Mapping
    from pathlib import Path

VERSION = 9
DISTRO = "humble"
_FOREVER = {"sec": 2147483647, "nsec": 4294967295}


@dataclass(slots=True)
class TopicInfo:
    """One recorded topic."""

    name: str
    type: str
    serialization_format: str = "cdr"
    qos: list[dict[str, Any]] = field(default_factory=list)
    type_hash: str = ""
    count: int = 0


@dataclass(slots=True)
class FileInfo:
    """One MCAP file of the bag."""

    path: str
    start_ns: int = 0
    end_ns: int = 0
    count: int = 0


def qos_entry(words: dict[str, Any]) -> dict[str, Any]:
    """A QoS profile in metadata v9's form, from discovery's QoS words."""
    return {
        "history": str(words.get("history", "KEEP_LAST")).lower(),
        "depth": int(words.get("depth", 10)),
        "reliability": str(words.get("reliability", "RELIABLE")).lower(),
        "durability": str(words.get("durability", "VOLATILE")).lower(),
        "deadline": dict(_FOREVER),
        "lifespan": dict(_FOREVER),
        "liveliness": str(words.get("liveliness", "AUTOMATIC")).lower(),
        "liveliness_lease_duration": dict(_FOREVER),
        "avoid_ros_namespace_conventions": False,
    }


def offered_qos(channel_metadata: Mapping[str, str]) -> list[dict[str, Any]]:
    """The QoS profiles an MCAP channel's ``offered_qos_profiles`` (a YAML text) lists."""
    text = channel_metadata.get("offered_qos_profiles", "")
    try:
        profiles = yaml.safe_load(text) if text else []
    except yaml.YAMLError:
        return []
    return [p for p in profiles if isinstance(p, dict)] if isinstance(profiles, list) else []


def write(
    folder: Path,
    topics: list[TopicInfo],
    files: list[FileInfo],
    custom: dict[str, str] | None = None,
) -> Path:
    """Write ``metadata.yaml`` atomically (a temporary file, then a rename)."""
    starts = [f.start_ns for f in files if f.count]
    ends = [f.end_ns for f in files if f.count]
    start = min(starts) if starts else 0
    end = max(ends) if ends else 0
    information = {
        "version": VERSION,
        "storage_identifier": "mcap",
        "duration": {"nanoseconds": end - start},
        "starting_time": {"nanoseconds_since_epoch": start},
        "message_count": sum(t.count for t in topics),
        "topics_with_message_count": [
            {
                "topic_metadata": {
                    "name": t.name,
                    "type": t.type,
                    "serialization_format": t.serialization_format,
                    "offered_qos_profiles": t.qos,
                    "type_description_hash": t.type_hash,
                },
                "message_count": t.count,
            }
            for t in topics
        ],
        "compression_format": "",
        "compression_mode": "",
        "relative_file_paths": [f.path for f in files],
        "files": [
            {
                "path": f.path,
                "starting_time": {"nanoseconds_since_epoch": f.start_ns},
                "duration": {"nanoseconds": max(0, f.end_ns - f.start_ns)},
                "message_count": f.count,
            }
            for f in files
        ],
        "custom_data": dict(custom or {}),
        "ros_distro": DISTRO,
    }
    path = folder / "metadata.yaml"
    temporary = path.with_suffix(".yaml.tmp")
    try:
        temporary.write_text(
            yaml.safe_dump({"rosbag2_bagfile_information": information}, sort_keys=False)
        )
        temporary.replace(path)
    except OSError as err:
        with contextlib.suppress(OSError):
            temporary.unlink(missing_ok=True)
        raise BagError(f"cannot write {path}: {err.strerror}") from None
    return path


def read(folder: Path) -> dict[str, Any]:
    """Read a folder's ``metadata.yaml``, its keys checked to have rosbag2's shapes.

    Raises:
        BagError: not YAML, not rosbag2's layout, or a key of the wrong shape (named).
    """
    path = folder / "metadata.yaml"
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as err:
        raise BagError(f"cannot read {path}: {err.strerror}") from None
    except UnicodeDecodeError:
        raise BagError(f"{path} is not a rosbag2 metadata file (not UTF-8 text)") from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark is not None else str(path)
        problem = getattr(err, "problem", None) or type(err).__name__
        raise BagError(f"{where}: not valid YAML ({problem})") from None
    information = data.get("rosbag2_bagfile_information") if isinstance(data, dict) else None
    if not isinstance(information, dict):
        raise BagError(
            f"{path} is not a rosbag2 metadata file (no 'rosbag2_bagfile_information' mapping)"
        )
    _check_shapes(path, information)
    return information


def _check_shapes(path: Path, information: dict[str, Any]) -> None:
    """Raise a BagError naming the first key whose value has the wrong shape."""
    if "relative_file_paths" not in information:
        raise BagError(f"{path}: 'relative_file_paths' is missing")
    _expect(path, "relative_file_paths", information["relative_file_paths"], list)
    for index, name in enumerate(information["relative_file_paths"]):
        _expect(path, f"relative_file_paths[{index}]", name, str)
    for key, kind in (("ros_distro", str), ("custom_data", dict), ("storage_identifier", str)):
        if information.get(key) is not None:
            _expect(path, key, information[key], kind)
    for index, entry in enumerate(_optional_list(path, information, "files")):
        key = f"files[{index}]"
        _expect(path, key, entry, dict)
        _expect(path, f"{key}.path", entry.get("path"), str)
        if entry.get("message_count") is not None:
            _expect(path, f"{key}.message_count", entry["message_count"], int)
    for index, entry in enumerate(_optional_list(path, information, "topics_with_message_count")):
        key = f"topics_with_message_count[{index}]"
        _expect(path, key, entry, dict)
        meta = entry.get("topic_metadata")
        _expect(path, f"{key}.topic_metadata", meta, dict)
        for name in ("name", "type"):
            _expect(path, f"{key}.topic_metadata.{name}", meta.get(name), str)
        for name in ("serialization_format", "type_description_hash"):
            if meta.get(name) is not None:
                _expect(path, f"{key}.topic_metadata.{name}", meta[name], str)
        qos = meta.get("offered_qos_profiles")
        if qos is not None and not isinstance(qos, (list, str)):  # a YAML text before v9
            _expect(path, f"{key}.topic_metadata.offered_qos_profiles", qos, list)
        if entry.get("message_count") is not None:
            _expect(path, f"{key}.message_count", entry["message_count"], int)


def _optional_list(path: Path, information: dict[str, Any], key: str) -> list[Any]:
    value = information.get(key)
    if value is None:
        return []
    _expect(path, key, value, list)
    return cast("list[Any]", value)  # _expect refused anything else


_SHAPES = {list: "a list", dict: "a mapping", str: "a text", int: "a whole number"}


def _expect(path: Path, key: str, value: Any, kind: type) -> None:
    if isinstance(value, kind) and not (kind is int and isinstance(value, bool)):
        return
    found = "nothing" if value is None else f"{type(value).__name__} {_short(value)}"
    raise BagError(f"{path}: '{key}' must be {_SHAPES[kind]}, not {found}")


def _short(value: Any) -> str:
    text = repr(value).replace("\n", " ")
    return text if len(text) <= 40 else text[:37] + "..."
