"""Running rosl in this process: init, ok, shutdown, spin (rclpy's module functions)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.executor import Executor, Future, SingleThreadedExecutor
from rosl.node.context import Context, default_context

if TYPE_CHECKING:
    from types import TracebackType

    from rosl.node.node import Node

_global_executor: Executor | None = None


class InitContextManager:
    """What ``init`` returns: ``with rclpy.init():`` shuts the context down on leaving.

    rclpy since Jazzy returns such an object; Humble returns None, and code that ignores the
    value works with either.
    """

    def __init__(self, context: Context) -> None:
        self.context = context

    def __enter__(self) -> InitContextManager:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        shutdown(context=self.context)


def init(
    args: list[str] | None = None,
    *,
    context: Context | None = None,
    domain_id: int | str | None = None,
    callback_errors: str = "log",
) -> InitContextManager:
    """Initialize rosl (rclpy.init): read ``--ros-args`` from ``args`` (default sys.argv).

    Args:
        args: the command line; only its ``--ros-args ... --`` part is read.
        context: the context to initialize (the default one).
        domain_id: overrides ROSL_DOMAIN_ID / ROS_DOMAIN_ID.
        callback_errors: "log" keeps spinning after a callback raises; "raise" stops spin.
    """
    ctx = context or default_context
    ctx.init(args, domain_id=domain_id)
    ctx.callback_errors = callback_errors
    return InitContextManager(ctx)


def ok(*, context: Context | None = None) -> bool:
    """Whether rosl is initialized and not shutting down."""
    return (context or default_context).ok()


def shutdown(*, context: Context | None = None) -> None:
    """Destroy every node and leave the bus (safe to call twice)."""
    global _global_executor
    (context or default_context).try_shutdown()
    _global_executor = None


try_shutdown = shutdown


def get_default_context() -> Context:
    """The context ``init`` uses by default."""
    return default_context


def get_global_executor() -> Executor:
    """The executor behind ``spin``."""
    global _global_executor
    if _global_executor is None:
        _global_executor = SingleThreadedExecutor()
    return _global_executor


def create_node(node_name: str, **kwargs: Any) -> Node:
    """Create a node (rclpy.create_node)."""
    from rosl.node.node import Node

    return Node(node_name, **kwargs)


def _executor_for(node: Node | None, executor: Executor | None) -> Executor:
    chosen = executor or get_global_executor()
    if node is not None:
        chosen.add_node(node)
    return chosen


def spin(node: Node, executor: Executor | None = None) -> None:
    """Run the node's callbacks until shutdown (Ctrl-C)."""
    chosen = _executor_for(node, executor)
    try:
        chosen.spin()
    finally:
        chosen.remove_node(node)


def spin_once(
    node: Node, *, executor: Executor | None = None, timeout_sec: float | None = None
) -> None:
    """Wait up to ``timeout_sec`` for work and do it."""
    chosen = _executor_for(node, executor)
    try:
        chosen.spin_once(timeout_sec=timeout_sec)
    finally:
        chosen.remove_node(node)


def spin_until_future_complete(
    node: Node,
    future: Future[Any],
    executor: Executor | None = None,
    timeout_sec: float | None = None,
) -> None:
    """Spin until ``future`` completes or ``timeout_sec`` passes."""
    chosen = _executor_for(node, executor)
    try:
        chosen.spin_until_future_complete(future, timeout_sec)
    finally:
        chosen.remove_node(node)
