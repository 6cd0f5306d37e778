"""``import launch_xml`` under rosl (its launch description source; no logic here)."""

from rosl.compat.launch_xml import launch_description_sources

__all__ = ["launch_description_sources"]
