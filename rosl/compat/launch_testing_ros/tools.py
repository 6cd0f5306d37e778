"""launch_testing_ros.tools: ``basic_output_filter`` (rosl.launch.testing.tools has it)."""

from rosl.launch.testing.tools import basic_output_filter

__all__ = ["basic_output_filter"]
