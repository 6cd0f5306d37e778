"""launch_testing.tools.output (rosl.launch.testing.tools implements it; no logic here)."""

from rosl.launch.testing.tools import (
    basic_output_filter,
    expect_output,
    expected_output_from_file,
    get_default_filtered_patterns,
    get_default_filtered_prefixes,
)

__all__ = [
    "basic_output_filter",
    "expect_output",
    "expected_output_from_file",
    "get_default_filtered_patterns",
    "get_default_filtered_prefixes",
]
