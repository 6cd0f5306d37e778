"""The packages here are run by the launch tests (tests/launch/test_*.py), not collected."""

collect_ignore_glob = ["*/test/*.py"]  # launch_testing_check's launch tests: `rosl launch_test`
