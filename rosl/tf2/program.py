"""What the tf2_ros programs share: their arguments, one node's life, spinning for a while."""

from __future__ import annotations

import os
import sys
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable


def user_args(args: list[str] | None) -> list[str]:
    """The program's own arguments: ``args`` (default ``sys.argv``) without ROS arguments."""
    from rosl.node.ros_args import remove_ros_args

    return remove_ros_args(sys.argv if args is None else args)[1:]


def run(args: list[str] | None, node_name: str, body: Callable[[Any], None]) -> int:
    """Init rosl, run ``body(node)`` with a node named ``node_name``, then clean up.

    A closed stdout (the program piped into ``head``) ends the program quietly.
    """
    import rosl

    rosl.init(sys.argv if args is None else args)
    node = rosl.Node(node_name)
    try:
        body(node)
    except BrokenPipeError:  # `tf2_echo a b | head`: the reader is gone, so are we
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    finally:
        node.destroy_node()
        rosl.try_shutdown()
    return 0


def spin_for(executor: Any, seconds: float) -> None:
    """Run the executor's callbacks for ``seconds`` (less after Ctrl-C)."""
    import rosl

    deadline = time.monotonic() + seconds
    while rosl.ok() and (left := deadline - time.monotonic()) > 0:
        executor.spin_once(timeout_sec=left)


__all__ = ["run", "spin_for", "user_args"]
