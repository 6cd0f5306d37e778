"""launch_testing.tools (rosl.launch.testing.tools and .process_proxy implement it)."""

from rosl.launch.testing.process_proxy import ProcessProxy, launch_process
from rosl.launch.testing.tools import (
    basic_output_filter,
    expect_output,
    expected_output_from_file,
)

__all__ = [
    "ProcessProxy",
    "basic_output_filter",
    "expect_output",
    "expected_output_from_file",
    "launch_process",
]
