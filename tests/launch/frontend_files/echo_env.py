"""Prints what the launch file gave it: two environment variables and its arguments."""

import os
import sys

print(
    f"greeting={os.environ.get('SYSTEM_GREETING')} extra={os.environ.get('EXTRA')} "
    f"args={sys.argv[1:]}",
    flush=True,
)
