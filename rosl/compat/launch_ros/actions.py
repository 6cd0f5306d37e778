"""launch_ros.actions (components are refused in one line)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.lifecycle import LifecycleNode, LifecycleTransition
from rosl.launch.ros_actions import (
    ComposableNodeContainer,
    LoadComposableNodes,
    Node,
    PushRosNamespace,
    RosTimer,
    SetParameter,
    SetParametersFromFile,
    SetRemap,
    SetUseSimTime,
)

PushROSNamespace = PushRosNamespace  # the later distros' spelling

__all__ = [
    "ComposableNodeContainer",
    "LifecycleNode",
    "LifecycleTransition",
    "LoadComposableNodes",
    "Node",
    "PushROSNamespace",
    "PushRosNamespace",
    "RosTimer",
    "SetParameter",
    "SetParametersFromFile",
    "SetRemap",
    "SetUseSimTime",
]
__getattr__ = unsupported_names("launch_ros.actions", __all__)
