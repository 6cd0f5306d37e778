"""``import launch_yaml`` under rosl (its launch description source; no logic here)."""

from rosl.compat.launch_yaml import launch_description_sources

__all__ = ["launch_description_sources"]
