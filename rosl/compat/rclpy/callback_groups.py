"""rclpy.callback_groups: accepted and ignored (callbacks run one at a time)."""


class CallbackGroup:
    """Accepted for compatibility."""


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """Accepted for compatibility."""


class ReentrantCallbackGroup(CallbackGroup):
    """Accepted for compatibility."""


__all__ = ["CallbackGroup", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup"]
