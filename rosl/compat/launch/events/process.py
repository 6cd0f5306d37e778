"""launch.events.process: ``ProcessIO``, what OnProcessIO's callables get."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.event_handlers import ProcessIO

__all__ = ["ProcessIO"]
__getattr__ = unsupported_names("launch.events.process", __all__)
