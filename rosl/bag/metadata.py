"""rosbag2's ``metadata.yaml`` (version 9): what the folder holds, per topic and per file."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

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
        raise BagError(f"cannot write {path}: {err.strerror}") from None
    return path


def read(folder: Path) -> dict[str, Any]:
    """Read a folder's ``metadata.yaml``.

    Raises:
        BagError: not YAML or not rosbag2's layout.
    """
    path = folder / "metadata.yaml"
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
        information = data["rosbag2_bagfile_information"]
        information["relative_file_paths"]
    except (OSError, yaml.YAMLError, KeyError, TypeError) as err:
        raise BagError(
            f"{path} is not a rosbag2 metadata file ({type(err).__name__}: {err})"
        ) from None
    return information  # type: ignore[no-any-return]
