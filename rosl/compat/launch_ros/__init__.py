"""``import launch_ros`` under rosl."""

from rosl.compat.unsupported import unsupported_names

__all__: list[str] = []
__getattr__ = unsupported_names("launch_ros", __all__)
