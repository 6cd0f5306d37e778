"""launch_testing_ros.actions' ``EnableRmwIsolation``: keep a launch test's traffic to itself.

rosl's transport stays on this host unless told otherwise; what isolates two launch tests
running at once is the domain. A domain given in the environment (``ROSL_DOMAIN_ID`` or
``ROS_DOMAIN_ID``, as a test harness sets it) is kept; without one, the action picks a domain
from this process's id, for the launched processes and for the test's own nodes alike.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from rosl.launch.description import Action

if TYPE_CHECKING:
    from rosl.launch.context import LaunchContext

FIRST_DOMAIN = 120  # picked domains: 120..219 (ROS 2 allows up to 232 on Linux)
DOMAINS = 100


class EnableRmwIsolation(Action):
    """Run this launch (and the test's own nodes) in a domain of its own, on this host only."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)

    def execute(self, context: LaunchContext) -> None:
        """Pick the domain and put it in the environment of what starts from now on."""
        domain = os.environ.get("ROSL_DOMAIN_ID") or os.environ.get("ROS_DOMAIN_ID")
        if not domain:
            domain = str(FIRST_DOMAIN + os.getpid() % DOMAINS)
        settings = {"ROSL_DOMAIN_ID": domain, "ROS_DOMAIN_ID": domain,
                    "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}  # fmt: skip
        os.environ.update(settings)  # the test's own rclpy nodes join it too
        context.scope.environment.update(settings)
        context.scope.unset.difference_update(settings)


__all__ = ["EnableRmwIsolation"]
