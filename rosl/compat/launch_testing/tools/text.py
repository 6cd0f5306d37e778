"""launch_testing.tools.text (rosl.launch.testing.tools implements it; no logic here)."""

from rosl.launch.testing.tools import build_line_match, build_text_match, normalize_lineseps

__all__ = ["build_line_match", "build_text_match", "normalize_lineseps"]
