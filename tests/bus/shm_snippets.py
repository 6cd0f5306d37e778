"""Child programs for the shared-memory tests: a talker of large and small messages, a listener.

The talker publishes, per round ``i``, a 640x480 rgb8 Image whose bytes are ``(k + i) % 251``
(a type with a large array), a 100 KB String ``"i:xxx..."`` (large, no array), a 40 KB String
``"i:mmm..."`` (mid-size: above the 16 KiB threshold, below one datagram) and a small String
``"i:small"``, paced at 20 Hz once ``argv[2]`` subscriptions are matched; then it
prints how many of each went as shared-memory descriptors and spins until Ctrl-C. The
listener checks every message against that pattern and prints ``<topic> <i> ok|bad``.
"""

from __future__ import annotations

IMAGE_BYTES = 640 * 480 * 3
TEXT_BYTES = 100_000
MID_BYTES = 40_000

TALKER = r"""
import sys, time
import numpy as np
import rosl
from sensor_msgs.msg import Image
from std_msgs.msg import String

count, wanted = int(sys.argv[1]), int(sys.argv[2])
rosl.init()
node = rosl.Node("shm_talker")
pubs = [node.create_publisher(Image, "/shm_image", 50),
        node.create_publisher(String, "/shm_text", 50),
        node.create_publisher(String, "/shm_mid", 50),
        node.create_publisher(String, "/shm_small", 50)]
for pub in pubs:
    if pub.wait_for_subscribers(wanted, 30.0) < wanted:
        print("no subscriber", pub.topic, flush=True)
        sys.exit(3)
print("matched", flush=True)
base = np.arange(640 * 480 * 3)
for i in range(count):
    image = Image(height=480, width=640, encoding="rgb8", step=1920)
    image.header.frame_id = str(i)
    image.data = ((base + i) % 251).astype(np.uint8)
    pubs[0].publish(image)
    pubs[1].publish(String(data=f"{i}:" + "x" * 100000))
    pubs[2].publish(String(data=f"{i}:" + "m" * 40000))
    pubs[3].publish(String(data=f"{i}:small"))
    time.sleep(0.05)
print("shm", *[p._writer.shm_sent for p in pubs], flush=True)
rosl.spin(node)
rosl.shutdown()
print("closed", flush=True)
"""

LISTENER = r"""
import sys
import numpy as np
import rosl
from sensor_msgs.msg import Image
from std_msgs.msg import String

rosl.init()
node = rosl.Node(sys.argv[1])
base = np.arange(640 * 480 * 3)

def on_image(msg):
    i = int(msg.header.frame_id)
    good = isinstance(msg.data, np.ndarray) and np.array_equal(msg.data, (base + i) % 251)
    print("image", i, "ok" if good else "bad", flush=True)

def on_text(msg):
    i, _, rest = msg.data.partition(":")
    print("text", i, "ok" if rest == "x" * 100000 else "bad", flush=True)

def on_mid(msg):
    i, _, rest = msg.data.partition(":")
    print("mid", i, "ok" if rest == "m" * 40000 else "bad", flush=True)

def on_small(msg):
    i, _, rest = msg.data.partition(":")
    print("small", i, "ok" if rest == "small" else "bad", flush=True)

node.create_subscription(Image, "/shm_image", on_image, 50)
node.create_subscription(String, "/shm_text", on_text, 50)
node.create_subscription(String, "/shm_mid", on_mid, 50)
node.create_subscription(String, "/shm_small", on_small, 50)
print("up", flush=True)
rosl.spin(node)
reader = node.participant.reader
print("lost", reader.lost(), "dropped", reader.dropped(), flush=True)
rosl.shutdown()
"""


def oks(lines: list[str], topic: str) -> set[int]:
    """The rounds a listener received intact on one topic."""
    return {int(x.split()[1]) for x in lines if x.startswith(f"{topic} ") and x.endswith(" ok")}


def bads(lines: list[str]) -> list[str]:
    """Lines where a listener found a message that did not match the pattern."""
    return [x for x in lines if x.endswith(" bad")]


def complete(lines: list[str], count: int) -> bool:
    """Whether a listener has every round of every topic."""
    rounds = set(range(count))
    return all(oks(lines, topic) >= rounds for topic in ("image", "text", "mid", "small"))
