"""``rosl bag info``: ROS 2's layout (and ``--json``) for a folder or a single MCAP file.

A finished file is described by its MCAP summary (statistics, channels, schemas) without
reading its messages; only an unfinished file (no summary) is read record by record.
"""

from __future__ import annotations

import datetime
from typing import TYPE_CHECKING, Any

from rosl.bag.reader import has_summary
from rosl.bag.trim import SourceChannel, scan

if TYPE_CHECKING:
    from pathlib import Path

LABEL = 19


def summary(target: Path) -> dict[str, Any]:
    """What ``info`` reports, as plain data.

    Raises:
        BagError: the bag cannot be read.
    """
    found = scan(target)
    channels = {name: c for name, c in found.channels.items() if c.count}  # as a scan finds
    for entry in (found.info or {}).get("topics_with_message_count") or []:
        listed = entry.get("topic_metadata") or {}
        name = str(listed.get("name", ""))
        if name and name not in channels:  # subscribed, but nothing came: ROS 2 lists it (Count: 0)
            channels[name] = SourceChannel(name, str(listed.get("type", "")), "", b"")
    topics = [c for c in channels.values() if not c.topic.endswith("/_service_event")]
    services = [c for c in channels.values() if c.topic.endswith("/_service_event")]
    return {
        "files": [p.name for p in found.files],
        "unfinished": [p.name for p in found.files if not has_summary(p)],
        "bag_size": sum(p.stat().st_size for p in found.files),
        "storage_id": "mcap",
        "ros_distro": (found.info or {}).get("ros_distro", "") or "",
        "duration_ns": found.end_ns - found.start_ns,
        "start_ns": found.start_ns,
        "end_ns": found.end_ns,
        "messages": sum(c.count for c in topics),
        "topics": [
            {"name": c.topic, "type": c.type, "count": c.count, "serialization_format": "cdr"}
            for c in sorted(topics, key=lambda c: c.topic)
        ],
        "services": [
            {
                "name": c.topic.removesuffix("/_service_event"),
                "type": c.type.removesuffix("_Event"),
                "event_count": c.count,
                "serialization_format": "cdr",
            }
            for c in sorted(services, key=lambda c: c.topic)
        ],
    }


def _size(size: int) -> str:
    units = ["B", "KiB", "MiB", "GiB", "TiB"]
    value = float(size)
    unit = 0
    while value >= 1024 and unit < len(units) - 1:
        value /= 1024
        unit += 1
    return f"{int(value)} B" if unit == 0 else f"{value:.1f} {units[unit]}"


def _stamp(ns: int) -> str:
    seconds, nanos = divmod(ns, 1_000_000_000)
    moment = datetime.datetime.fromtimestamp(seconds)
    return f"{moment.strftime('%b %e %Y %H:%M:%S')}.{nanos:09d} ({seconds}.{nanos:09d})"


def text(target: Path) -> str:
    """ROS 2's ``bag info`` text."""
    data = summary(target)

    def row(label: str, value: str) -> str:
        return f"{label:<{LABEL}}{value}"

    pad = " " * LABEL
    lines = ["", row("Files:", data["files"][0] if data["files"] else "")]
    lines += [pad + name for name in data["files"][1:]]
    seconds, nanos = divmod(data["duration_ns"], 1_000_000_000)
    lines += [
        row("Bag size:", _size(data["bag_size"])),
        row("Storage id:", "mcap"),
        row("ROS Distro:", data["ros_distro"] or "unknown"),  # as rosbag2 prints an unnamed one
        row("Duration:", f"{seconds}.{nanos:09d}s"),
        row("Start:", _stamp(data["start_ns"])),
        row("End:", _stamp(data["end_ns"])),
        row("Messages:", str(data["messages"])),
    ]
    topic_lines = [
        f"Topic: {t['name']} | Type: {t['type']} | Count: {t['count']} | "
        f"Serialization Format: {t['serialization_format']}"
        for t in data["topics"]
    ]
    lines.append(row("Topic information:", topic_lines[0] if topic_lines else ""))
    lines += [pad + line for line in topic_lines[1:]]
    lines.append(row("Service:", str(len(data["services"]))))
    service_lines = [
        f"Service: {s['name']} | Type: {s['type']} | Event Count: {s['event_count']} | "
        f"Serialization Format: {s['serialization_format']}"
        for s in data["services"]
    ]
    lines.append("Service information: " + (service_lines[0] if service_lines else ""))
    lines += [pad + line for line in service_lines[1:]]
    if data["unfinished"]:
        lines.append(
            f"(unfinished: {', '.join(data['unfinished'])}; run `rosl bag reindex` to repair)"
        )
    return "\n".join(lines) + "\n"
