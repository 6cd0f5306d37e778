"""tf2_ros.buffer."""

from rosl.tf2.buffer import Buffer

__all__ = ["Buffer"]
