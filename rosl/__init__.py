"""rosl: ROS 2's everyday workflow in pure Python.

The public API. ``import rosl`` is cheap (no numpy, pymunk or mcap) and installs the import
hook that makes ``from geometry_msgs.msg import Twist`` work for every interface package on
rosl's search path. Nodes are written as in rclpy::

    import rosl
    from std_msgs.msg import String

    rosl.init()
    node = rosl.Node("talker")
    pub = node.create_publisher(String, "chatter", 10)
    node.create_timer(1.0, lambda: pub.publish(String(data="hello")))
    rosl.spin(node)
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from rosl.compat import install as _install_import_hook
from rosl.errors import RoslError

if TYPE_CHECKING:
    from rosl.executor import Executor, Future, MultiThreadedExecutor, SingleThreadedExecutor
    from rosl.idl.messages import ActionType, Message, ServiceType
    from rosl.node.client import Client
    from rosl.node.clock import Clock, ClockType, Duration, Time
    from rosl.node.node import Node
    from rosl.node.parameters import Parameter
    from rosl.node.publisher import Publisher
    from rosl.node.qos import QoSProfile
    from rosl.node.service import Service
    from rosl.node.subscription import Subscription
    from rosl.node.timer import Rate, Timer
    from rosl.runtime import (
        create_node,
        get_default_context,
        get_global_executor,
        init,
        ok,
        shutdown,
        spin,
        spin_once,
        spin_until_future_complete,
        try_shutdown,
    )

# public name -> module; loaded on first use so `import rosl` (and the CLI) stays fast
_LAZY = {
    "Client": "rosl.node.client",
    "Clock": "rosl.node.clock",
    "ClockType": "rosl.node.clock",
    "Duration": "rosl.node.clock",
    "Executor": "rosl.executor",
    "Future": "rosl.executor",
    "MultiThreadedExecutor": "rosl.executor",
    "Node": "rosl.node.node",
    "Parameter": "rosl.node.parameters",
    "Publisher": "rosl.node.publisher",
    "QoSProfile": "rosl.node.qos",
    "Rate": "rosl.node.timer",
    "Service": "rosl.node.service",
    "SingleThreadedExecutor": "rosl.executor",
    "Subscription": "rosl.node.subscription",
    "Time": "rosl.node.clock",
    "Timer": "rosl.node.timer",
    **dict.fromkeys(
        [
            "create_node",
            "get_default_context",
            "get_global_executor",
            "init",
            "ok",
            "shutdown",
            "spin",
            "spin_once",
            "spin_until_future_complete",
            "try_shutdown",
        ],
        "rosl.runtime",
    ),
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'rosl' has no attribute '{name}'")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


__all__ = [
    "Client",
    "Clock",
    "ClockType",
    "Duration",
    "Executor",
    "Future",
    "MultiThreadedExecutor",
    "Node",
    "Parameter",
    "Publisher",
    "QoSProfile",
    "Rate",
    "RoslError",
    "Service",
    "SingleThreadedExecutor",
    "Subscription",
    "Time",
    "Timer",
    "create_node",
    "get_default_context",
    "get_global_executor",
    "get_interface",
    "init",
    "ok",
    "shutdown",
    "spin",
    "spin_once",
    "spin_until_future_complete",
    "try_shutdown",
]
__version__ = "0.1.0"

_install_import_hook()


def get_interface(type_name: str) -> type[Message] | type[ServiceType] | type[ActionType]:
    """Return the class of a message, service or action type, e.g. ``"geometry_msgs/msg/Twist"``.

    Raises:
        rosl.idl.errors.InterfaceError: unknown type, or a bad definition file.
    """
    from rosl.idl.registry import get_interface as _get

    return _get(type_name)
