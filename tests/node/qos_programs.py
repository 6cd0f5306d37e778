"""Programs in the style of ROS 2's quality_of_service_demo (our own code), run as rclpy.

Each takes its settings as one JSON argument and prints one line per event, so tests read
outcomes: ``offered incompatible total=1 change=1 policy=RELIABILITY``, ``heard: msg 3``...
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

from tests.node.helpers import snippet

if TYPE_CHECKING:
    from pathlib import Path

RUN_AS_RCLPY = (
    "import rosl.compat; rosl.compat.install(force=True); import runpy, sys; "
    "runpy.run_path(sys.argv[1], run_name='__main__')"
)

PROFILE = """
import json
import os
import sys

import rclpy
from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy

cfg = json.loads(sys.argv[-1])


def say(text):
    print(text, flush=True)


def profile(cfg):
    settings = {"depth": cfg.get("depth", 10)}
    for name, policy in (("reliability", ReliabilityPolicy), ("durability", DurabilityPolicy),
                         ("liveliness", LivelinessPolicy)):
        if name in cfg:
            settings[name] = policy[cfg[name]]
    for name in ("deadline", "lifespan", "liveliness_lease_duration"):
        if name in cfg:
            settings[name] = Duration(seconds=cfg[name])
    return QoSProfile(**settings)
"""

TALKER = (
    PROFILE
    + """
from rclpy.qos_event import PublisherEventCallbacks
from std_msgs.msg import String

rclpy.init()
node = rclpy.create_node(cfg.get("name", "talker"))
callbacks = None
if cfg.get("callbacks", True):
    callbacks = PublisherEventCallbacks(
        incompatible_qos=lambda e: say(
            f"offered incompatible total={e.total_count} change={e.total_count_change} "
            f"policy={e.last_policy_kind.name}"),
        deadline=lambda e: say(
            f"offered deadline missed total={e.total_count} change={e.total_count_change}"),
        liveliness=lambda e: on_lost(e),
        matched=lambda e: say(
            f"publisher matched total={e.total_count} change={e.total_count_change} "
            f"current={e.current_count} current_change={e.current_count_change}"),
    )
topic = cfg.get("topic", "qos_chatter")
pub = node.create_publisher(String, topic, profile(cfg), event_callbacks=callbacks)
count = 0
asserting = False


def on_lost(event):
    say(f"liveliness lost total={event.total_count} change={event.total_count_change}")
    if cfg.get("assert_after_lost"):
        node.create_timer(cfg["assert_after_lost"], start_asserting)


def start_asserting():
    global asserting
    asserting = True


def tick():
    global count
    if asserting:
        pub.assert_liveliness()
        return
    if count >= cfg.get("count", 1 << 30):
        return
    if cfg.get("wait_matched") and pub.get_subscription_count() < 1:
        return  # (its first message goes to a subscription that is there)
    count += 1
    pub.publish(String(data=f"{cfg.get('prefix', 'msg')} {count}"))
    say(f"published {count}")


burst = cfg.get("burst")


def burst_when_told():
    if burst and os.path.exists(burst["file"]):
        os.remove(burst["file"])
        payload = "x" * burst["size"]
        for i in range(burst["messages"]):
            pub.publish(String(data=payload))
        say("burst done")


node.create_timer(cfg.get("period", 0.1), tick)
if burst:
    node.create_timer(0.05, burst_when_told)
say("ready")
rclpy.spin(node)
"""
)

LISTENER = (
    PROFILE
    + """
from rclpy.event_handler import SubscriptionEventCallbacks
from std_msgs.msg import String

rclpy.init()
node = rclpy.create_node(cfg.get("name", "listener"))
callbacks = None
if cfg.get("callbacks", True):
    callbacks = SubscriptionEventCallbacks(
        incompatible_qos=lambda e: say(
            f"requested incompatible total={e.total_count} change={e.total_count_change} "
            f"policy={e.last_policy_kind.name}"),
        deadline=lambda e: say(
            f"requested deadline missed total={e.total_count} change={e.total_count_change}"),
        liveliness=lambda e: say(
            f"liveliness changed alive={e.alive_count} not_alive={e.not_alive_count} "
            f"alive_change={e.alive_count_change} not_alive_change={e.not_alive_count_change}"),
        message_lost=lambda e: say(
            f"message lost total={e.total_count} change={e.total_count_change}"),
        incompatible_type=lambda e: say(
            f"incompatible type total={e.total_count} change={e.total_count_change}"),
    )
for topic in cfg.get("topics", ["qos_chatter"]):
    node.create_subscription(
        String, topic, lambda m, topic=topic: say(f"heard on {topic}: {m.data[:40]}"),
        profile(cfg), event_callbacks=callbacks)
say("ready")
rclpy.spin(node)
"""
)


def write(tmp_path: Path, source: str, name: str) -> str:
    """Write one program to a file; return its path."""
    script = tmp_path / f"{name}.py"
    script.write_text(snippet(source))
    return str(script)


def start(spawn: Any, tmp_path: Path, source: str, name: str, cfg: dict[str, Any]) -> Any:
    """Run one program (as rclpy code) with its settings."""
    return spawn(RUN_AS_RCLPY, write(tmp_path, source, name), json.dumps({"name": name, **cfg}))


OVERRIDDEN = (
    PROFILE
    + """
from rclpy.qos import QoSPolicyKind
from rclpy.qos_overriding_options import QosCallbackResult, QoSOverridingOptions
from std_msgs.msg import String

rclpy.init()
node = rclpy.create_node(cfg.get("name", "overridden"))


def reasonable(qos):
    if cfg.get("bool_callback"):
        return qos.depth <= 100
    result = QosCallbackResult()
    result.successful = qos.depth <= 100
    if not result.successful:
        result.reason = "expected a depth of at most 100"
    return result


kinds = [QoSPolicyKind[k] for k in cfg["kinds"]] if "kinds" in cfg else None
options = (QoSOverridingOptions(kinds, callback=reasonable, entity_id=cfg.get("entity_id"))
           if kinds else QoSOverridingOptions.with_default_policies(
               callback=reasonable, entity_id=cfg.get("entity_id")))
pub = node.create_publisher(String, "qos_chatter", profile(cfg), qos_overriding_options=options)
sub = node.create_subscription(String, "qos_chatter", lambda m: None, profile(cfg),
                               qos_overriding_options=options)
for entity in ("publisher", "subscription"):
    qos = pub.qos_profile if entity == "publisher" else sub.qos_profile
    say(f"{entity} history={qos.history.name} depth={qos.depth} "
        f"reliability={qos.reliability.name} durability={qos.durability.name} "
        f"deadline={qos.deadline.nanoseconds}")
say("ready")
rclpy.spin(node)
"""
)

ONE_PROCESS = """
import rclpy
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.qos import QoSLivelinessPolicy, QoSProfile
from rclpy.qos_event import PublisherEventCallbacks, SubscriptionEventCallbacks
from std_msgs.msg import String

rclpy.init()
qos = QoSProfile(
    depth=10,
    liveliness=QoSLivelinessPolicy.RMW_QOS_POLICY_LIVELINESS_MANUAL_BY_NODE,
    liveliness_lease_duration=Duration(seconds=1.0),
)
listener = Node("one_listener")
listener.create_subscription(
    String, "one_chatter", lambda m: None, qos,
    event_callbacks=SubscriptionEventCallbacks(liveliness=lambda e: print(
        f"changed alive={e.alive_count} not_alive={e.not_alive_count}", flush=True)))
talker = Node("one_talker")
talker.create_publisher(
    String, "one_chatter", qos,
    event_callbacks=PublisherEventCallbacks(liveliness=lambda e: print(
        f"lost total={e.total_count}", flush=True)))
asserter = talker.create_timer(0.2, talker.assert_liveliness)
listener.create_timer(3.0, asserter.cancel)
executor = SingleThreadedExecutor()
executor.add_node(listener)
executor.add_node(talker)
executor.spin()
"""
