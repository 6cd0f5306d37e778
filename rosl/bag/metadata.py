"""rosbag2's ``metadata.yaml`` in the layout of the distro a bag is labelled with.

rosbag2 changed the file over the years (version 1 to 9). A bag labelled ``humble`` is written
in the version 5 layout Humble's rosbag2 parses: each topic's ``offered_qos_profiles`` is one
YAML *text*, and its QoS policies are rmw's enum numbers. Iron writes version 8 (custom data,
type hashes, the distro), Jazzy and later version 9, where ``offered_qos_profiles`` is a YAML
list and the policies are words (``reliable``). A reader of Humble fails on a list where it
expects a text, so the layout follows the distro: ``ROS_DISTRO`` or ``--distro`` choose it,
``humble`` by default. Reading accepts every version: QoS profiles are kept here in version 9's
words (:func:`normalize_profile`) and rendered for the layout being written.
"""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import yaml

from rosl.bag.errors import BagError

if TYPE_CHECKING:
    from collections.abc import Mapping
    from pathlib import Path

VERSIONS = {"humble": 5, "iron": 8, "jazzy": 9, "kilted": 9, "rolling": 9}
DISTRO = "humble"
READABLE = range(1, 10)  # the metadata versions rosbag2 has written
_NO_WRAP = 1 << 30  # a QoS text on one line, as yaml-cpp writes it
_INFINITE = {"sec": 9223372036854775807, "nsec": 4294967295}  # rmw's "infinite", as bags hold it
# what Foxy's middlewares reported for "infinite" (Cyclone, Fast DDS, Connext)
_FOXY_INFINITE = {(9223372036, 854775807), (2147483647, 4294967295), (2147483647, 2147483647)}
# rmw's enum numbers (rmw/types.h), the form of QoS policies before version 9
_POLICIES: dict[str, tuple[str, ...]] = {
    "history": ("system_default", "keep_last", "keep_all", "unknown"),
    "reliability": ("system_default", "reliable", "best_effort", "unknown", "best_available"),
    "durability": ("system_default", "transient_local", "volatile", "unknown", "best_available"),
    "liveliness": ("system_default", "automatic", "manual_by_node", "manual_by_topic", "unknown",
                   "best_available"),
}  # fmt: skip
_PROFILE_KEYS = (
    "history", "depth", "reliability", "durability", "deadline", "lifespan", "liveliness",
    "liveliness_lease_duration", "avoid_ros_namespace_conventions",
)  # fmt: skip


def distro(given: str | None = None) -> str:
    """The distro a new bag is labelled with: ``given``, else ``ROS_DISTRO``, else humble.

    ``ROS_DISTRO`` naming a distro without a layout here (an older one) gives humble's.

    Raises:
        BagError: a ``given`` distro whose rosbag2 layout is not known here.
    """
    if not given:  # an environment set up for another distro (foxy, noetic) writes humble's
        name = os.environ.get("ROS_DISTRO", "").strip().lower()
        return name if name in VERSIONS else DISTRO
    name = given.strip().lower()
    if name not in VERSIONS:
        raise BagError(f"unknown ROS distro '{name}' (choose one of {', '.join(sorted(VERSIONS))})")
    return name


@dataclass(slots=True)
class TopicInfo:
    """One recorded topic (its QoS profiles in version 9's words)."""

    name: str
    type: str
    serialization_format: str = "cdr"
    qos: list[dict[str, Any]] = field(default_factory=list)
    type_hash: str = ""
    count: int = 0


@dataclass(slots=True)
class FileInfo:
    """One file of the bag."""

    path: str
    start_ns: int = 0
    end_ns: int = 0
    count: int = 0

    def add(self, log_time: int) -> None:
        """Count one message logged at ``log_time``."""
        self.count += 1
        self.start_ns = log_time if self.count == 1 else min(self.start_ns, log_time)
        self.end_ns = max(self.end_ns, log_time)


def qos_entry(words: Mapping[str, Any]) -> dict[str, Any]:
    """A QoS profile in version 9's words, from discovery's QoS words (durations in ns)."""
    durations = {
        key: {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}
        for key in ("deadline", "lifespan", "liveliness_lease_duration")
        if isinstance(ns := words.get(key), int) and ns > 0
    }
    return normalize_profile(
        {
            "history": words.get("history", "KEEP_LAST"),
            "depth": int(words.get("depth", 10)),
            "reliability": words.get("reliability", "RELIABLE"),
            "durability": words.get("durability", "VOLATILE"),
            "liveliness": words.get("liveliness", "AUTOMATIC"),
            **durations,
        }
    )


def normalize_profile(profile: Mapping[str, Any]) -> dict[str, Any]:
    """A QoS profile of any metadata version in version 9's words (infinite durations filled)."""
    result: dict[str, Any] = {}
    for key in _PROFILE_KEYS:
        value = profile.get(key)
        if key in _POLICIES:
            names = _POLICIES[key]
            if isinstance(value, int) and not isinstance(value, bool):
                value = names[value] if 0 <= value < len(names) else "unknown"
            elif value is None:
                value = "system_default"
            else:
                value = str(value).lower() if str(value).lower() in names else "unknown"
        elif key == "depth":  # a bag written by another tool may hold anything here
            value = value if isinstance(value, int) and not isinstance(value, bool) else 0
        elif key == "avoid_ros_namespace_conventions":
            value = bool(value)
        elif not _duration(value):  # missing, or Foxy's "infinite" (rosbag2 reads it so too)
            value = dict(_INFINITE)
        result[key] = value
    return result


def _duration(value: Any) -> bool:
    """Whether a profile's duration is a finite ``{sec, nsec}`` or today's infinite."""
    return (
        isinstance(value, dict)
        and all(isinstance(value.get(k), int) for k in ("sec", "nsec"))
        and (value["sec"], value["nsec"]) not in _FOXY_INFINITE
    )


def render_profile(profile: Mapping[str, Any], version: int) -> dict[str, Any]:
    """A profile (version 9's words) as a bag of ``version`` holds it: numbers before 9."""
    words = normalize_profile(profile)
    if version >= 9:
        return words
    return {
        key: _POLICIES[key].index(value) if key in _POLICIES and value in _POLICIES[key] else value
        for key, value in words.items()
    }


def qos_text(profiles: list[dict[str, Any]], version: int) -> str:
    """The YAML text of a topic's profiles, as MCAP channels (and version < 9 files) hold it."""
    if not profiles:
        return ""
    return yaml.safe_dump(
        [render_profile(p, version) for p in profiles], sort_keys=False, width=_NO_WRAP
    )


def offered_qos(channel_metadata: Mapping[str, str]) -> list[dict[str, Any]]:
    """The QoS profiles (version 9's words) an MCAP channel's ``offered_qos_profiles`` lists."""
    return parse_profiles(channel_metadata.get("offered_qos_profiles", ""))


def parse_profiles(value: Any) -> list[dict[str, Any]]:
    """Profiles from a metadata value: a YAML text (versions 4-8, channels) or a list (9)."""
    if isinstance(value, str):
        try:
            value = yaml.safe_load(value) if value.strip() else []
        except yaml.YAMLError:
            return []
    if not isinstance(value, list):
        return []
    return [normalize_profile(p) for p in value if isinstance(p, dict)]


def information(
    topics: list[TopicInfo],
    files: list[FileInfo],
    *,
    custom: Mapping[str, str] | None = None,
    ros_distro: str = DISTRO,
    storage: str = "mcap",
    compression: tuple[str, str] = ("", ""),
) -> dict[str, Any]:
    """The ``rosbag2_bagfile_information`` mapping in the layout of ``ros_distro``."""
    version = VERSIONS[ros_distro]
    starts = [f.start_ns for f in files if f.count]
    ends = [f.end_ns for f in files if f.count]
    start = min(starts) if starts else 0
    end = max(ends) if ends else 0

    def topic_metadata(t: TopicInfo) -> dict[str, Any]:
        entry: dict[str, Any] = {
            "name": t.name,
            "type": t.type,
            "serialization_format": t.serialization_format,
            "offered_qos_profiles": (
                [render_profile(p, version) for p in t.qos]
                if version >= 9
                else qos_text(t.qos, version)
            ),
        }
        if version >= 7:
            entry["type_description_hash"] = t.type_hash
        return entry

    result: dict[str, Any] = {
        "version": version,
        "storage_identifier": storage,
        "duration": {"nanoseconds": end - start},
        "starting_time": {"nanoseconds_since_epoch": start},
        "message_count": sum(t.count for t in topics),
        "topics_with_message_count": [
            {"topic_metadata": topic_metadata(t), "message_count": t.count} for t in topics
        ],
        "compression_format": compression[0],
        "compression_mode": compression[1],
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
    }
    if version >= 6 or custom:
        result["custom_data"] = dict(custom or {})
    result["ros_distro"] = ros_distro  # a key of version 8; earlier readers pass it by
    return result


def serialized(info: Mapping[str, Any]) -> str:
    """The YAML text of a ``rosbag2_bagfile_information`` mapping (as the MCAP record holds it)."""
    return yaml.safe_dump(dict(info), sort_keys=False, width=_NO_WRAP)


def write(
    folder: Path,
    topics: list[TopicInfo],
    files: list[FileInfo],
    custom: Mapping[str, str] | None = None,
    *,
    ros_distro: str = DISTRO,
    storage: str = "mcap",
) -> Path:
    """Write ``metadata.yaml`` atomically (a temporary file, then a rename).

    Raises:
        BagError: the file cannot be written.
    """
    body = information(topics, files, custom=custom, ros_distro=ros_distro, storage=storage)
    path = folder / "metadata.yaml"
    temporary = path.with_suffix(".yaml.tmp")
    text = yaml.safe_dump({"rosbag2_bagfile_information": body}, sort_keys=False, width=_NO_WRAP)
    try:
        with temporary.open("w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())  # on disk before it replaces the old one
        temporary.replace(path)
        sync_folder(folder)
    except OSError as err:
        with contextlib.suppress(OSError):
            temporary.unlink(missing_ok=True)
        raise BagError(f"cannot write {path}: {err.strerror}") from None
    return path


def sync_folder(folder: Path) -> None:
    """Make a rename in ``folder`` survive a crash: fsync the folder (where the system can)."""
    with contextlib.suppress(OSError):
        descriptor = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)


def labelled(info: Mapping[str, Any] | None) -> str:
    """The distro a bag's metadata names, when this module knows its layout (else humble)."""
    name = str((info or {}).get("ros_distro") or "").lower()
    return name if name in VERSIONS else DISTRO


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
    if information.get("version") is not None:
        _expect(path, "version", information["version"], int)
        if information["version"] not in READABLE:
            raise BagError(
                f"{path}: metadata version {information['version']} is not one rosbag2 has "
                f"written ({READABLE.start}-{READABLE.stop - 1})"
            )
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
