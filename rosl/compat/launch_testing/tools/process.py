"""launch_testing.tools.process (rosl.launch.testing.process_proxy implements it)."""

from rosl.launch.testing.process_proxy import ProcessProxy, launch_process

__all__ = ["ProcessProxy", "launch_process"]
