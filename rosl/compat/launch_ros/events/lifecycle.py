"""launch_ros.events.lifecycle: ChangeState, StateTransition, matches_node_name."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.lifecycle_events import ChangeState, StateTransition, matches_node_name

__all__ = ["ChangeState", "StateTransition", "matches_node_name"]
__getattr__ = unsupported_names("launch_ros.events.lifecycle", __all__)
