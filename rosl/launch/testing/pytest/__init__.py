"""launch_testing's pytest plugin (``hooks``), registered by rosl's ``pytest11`` entry point."""
