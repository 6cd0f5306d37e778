"""Large messages through rosl's message classes vs rosbags' own serializer, in one run.

Two messages as rclpy users build them:

  image   sensor_msgs/msg/Image, 1 MB (512 x 512 rgb8... as 1 MiB of uint8), data set from numpy
  cloud   sensor_msgs/msg/PointCloud2 of 100k points (x, y, z, intensity float32: 1.6 MB),
          built with sensor_msgs_py.point_cloud2.create_cloud from a (N, 4) numpy array

rosl    the publisher's path, ``Store.serialize_view`` (CDR into one buffer, what ``publish``
        sends), and the subscription's, ``Store.deserialize`` of the bytes received, to a
        message whose arrays are writable numpy arrays of their own.
rosbags ``Typestore.serialize_cdr`` and ``deserialize_cdr`` on rosbags' own dataclasses
        (ROS 2 Humble store), the deserializer given the same received ``bytes``.

Both encode the same message to the same bytes (checked). Each call runs --repeat times in
a row (as a publisher or a subscription runs them), the four blocks alternate --runs times;
prints MB/s of serialize, deserialize and the round trip (medians), and the ratio rosl /
rosbags of the round trip (above 1: rosl is faster). Both make the same copies (serialize:
a zeroed buffer and the data into it; deserialize: the bytes once), so expect about 1x; rosl's
received arrays are writable and its own, rosbags' are read-only views of its copy. Also the
time to set ``data`` from bytes, numpy and array.array, and to read a cloud back with
``read_points_numpy``.

    python bench/big_messages.py [--runs 7] [--repeat 20]
"""

from __future__ import annotations

import argparse
import array
import statistics
import time
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Callable

POINTS = 100_000


def _messages() -> dict[str, Any]:
    import rosl.compat

    rosl.compat.install()
    from sensor_msgs.msg import Image, PointField
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    rng = np.random.default_rng(7)
    image = Image(height=512, width=512, encoding="rgb8", step=2048)
    image.data = rng.integers(0, 255, 1 << 20, dtype=np.uint8)
    fields = [
        PointField(name=name, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, name in enumerate(("x", "y", "z", "intensity"))
    ]
    points = rng.random((POINTS, 4), dtype=np.float32)
    cloud = point_cloud2.create_cloud(Header(frame_id="map"), fields, points)
    return {"image": image, "cloud": cloud}


def _per_call(repeat: int, call: Callable[[], object]) -> float:
    start = time.perf_counter()
    for _ in range(repeat):
        call()
    return (time.perf_counter() - start) / repeat


def measure(name: str, message: Any, runs: int, repeat: int) -> dict[str, float]:
    """Seconds per serialize and per deserialize, rosl and rosbags (medians)."""
    from rosbags.typesys import Stores, get_typestore

    from rosl.idl.registry import store

    ours = store()
    theirs = get_typestore(Stores.ROS2_HUMBLE)
    type_name = message.__msgtype__
    received = bytes(ours.serialize_view(message))  # what a subscription gets from the bus
    their_message = theirs.deserialize_cdr(received, type_name)
    if bytes(theirs.serialize_cdr(their_message, type_name, little_endian=True)) != received:
        raise SystemExit(f"{name}: rosl and rosbags encode different bytes")
    decoded = ours.deserialize(received, type_name)
    if decoded != message or not decoded.data.flags.writeable:
        raise SystemExit(f"{name}: rosl does not decode what it encoded")
    times: dict[str, list[float]] = {k: [] for k in ("ser", "de", "rb_ser", "rb_de")}
    for _ in range(runs):  # interleaved, so load on the machine hits both alike
        times["ser"].append(_per_call(repeat, lambda: ours.serialize_view(message)))
        times["rb_ser"].append(
            _per_call(repeat, lambda: theirs.serialize_cdr(their_message, type_name))
        )
        times["de"].append(_per_call(repeat, lambda: ours.deserialize(received, type_name)))
        times["rb_de"].append(
            _per_call(repeat, lambda: theirs.deserialize_cdr(received, type_name))
        )
    result = {k: statistics.median(v) for k, v in times.items()}
    result["size"] = len(received)
    return result


def setters(repeat: int) -> None:
    """Setting Image.data from common sources, and reading a cloud back as numpy."""
    from sensor_msgs.msg import Image
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    raw = bytes(1 << 20)
    sources = {
        "bytes": raw,
        "numpy uint8": np.frombuffer(raw, np.uint8).copy(),
        "array.array('B')": array.array("B", raw),
        "bytearray": bytearray(raw),
    }
    image = Image()
    for label, value in sources.items():

        def assign(value: object = value) -> None:
            image.data = value

        print(f"  set Image.data (1 MB) from {label:<18} {_per_call(repeat, assign) * 1e6:8.0f} us")
    cloud = point_cloud2.create_cloud_xyz32(Header(), np.zeros((POINTS, 3), np.float32))
    read = _per_call(repeat, lambda: point_cloud2.read_points_numpy(cloud))
    print(f"  read_points_numpy, {POINTS} points         {read * 1e6:8.0f} us")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    print(f"serialize + deserialize, rosl message classes vs rosbags; median of {args.runs} runs")
    print(f"{'message':<8}{'MB':>6}  {'':<8}{'ser MB/s':>10}{'de MB/s':>10}{'both MB/s':>11}")
    for name, message in _messages().items():
        t = measure(name, message, args.runs, args.repeat)
        mb = t["size"] / 1e6
        for label, ser, de in (("rosl", t["ser"], t["de"]), ("rosbags", t["rb_ser"], t["rb_de"])):
            print(
                f"{name:<8}{mb:>6.2f}  {label:<8}{mb / ser:>10.0f}{mb / de:>10.0f}"
                f"{mb / (ser + de):>11.0f}"
            )
        ratio = (t["rb_ser"] + t["rb_de"]) / (t["ser"] + t["de"])
        print(f"{name:<8}ratio rosl / rosbags (round trip MB/s): {ratio:.2f}x")
    setters(args.repeat)


if __name__ == "__main__":
    main()
