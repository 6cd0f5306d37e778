"""rosl: ROS 2's everyday workflow in pure Python.

The public API. Importing rosl is cheap (no numpy, pymunk or mcap) and installs the import
hook that makes ``from geometry_msgs.msg import Twist`` work for every interface package on
rosl's search path.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.compat import install as _install_import_hook
from rosl.errors import RoslError

if TYPE_CHECKING:
    from rosl.idl.messages import Message, ServiceType

__all__ = ["RoslError", "get_interface"]
__version__ = "0.1.0"

_install_import_hook()


def get_interface(type_name: str) -> type[Message] | type[ServiceType]:
    """Return the class of a message or service type, e.g. ``"geometry_msgs/msg/Twist"``.

    Raises:
        rosl.idl.errors.InterfaceError: unknown type, or a bad definition file.
    """
    from rosl.idl.registry import get_interface as _get

    return _get(type_name)


def __getattr__(name: str) -> Any:
    raise AttributeError(f"module 'rosl' has no attribute '{name}'")
