"""``from geometry_msgs.msg import Twist`` in a fresh process, and what the hook leaves alone."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from typing import TYPE_CHECKING

from tests.conftest import write_package

if TYPE_CHECKING:
    from pathlib import Path


def run_python(
    code: str, cwd: Path, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    full_env = {**os.environ, **(env or {})}
    full_env.pop("ROSL_PACKAGE_PATH", None) if "ROSL_PACKAGE_PATH" not in (env or {}) else None
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        cwd=cwd,
        env=full_env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


def test_standard_and_workspace_interfaces_import_after_rosl(workspace):
    write_package(
        workspace / "src",
        "tutorial_pkg",
        {
            "msg/MyData.msg": "int32 counter\nfloat64 value\nstring label\n",
            "srv/CountImages.srv": "string folder_path\n---\nint32 count\nstring message\n",
        },
    )
    result = run_python(
        """
        import rosl
        from geometry_msgs.msg import Twist
        from tutorial_pkg.msg import MyData
        from tutorial_pkg.srv import CountImages
        print(Twist().linear.x, MyData(counter=3).counter, CountImages.Request(folder_path='/x'))
        """,
        workspace,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split("\n")[0] == (
        "0.0 3 tutorial_pkg.srv.CountImages_Request(folder_path='/x')"
    )


def test_importing_rosl_does_not_load_numpy(tmp_path):
    result = run_python("import sys, rosl; print('numpy' in sys.modules)", tmp_path)
    assert result.stdout.strip() == "False", result.stderr


def test_a_real_module_of_the_same_name_wins(tmp_path):
    write_package(tmp_path / "pkgs", "std_msgs", {"msg/Fake.msg": "int32 x\n"})
    real = tmp_path / "real" / "std_msgs"
    real.mkdir(parents=True)
    (real / "__init__.py").write_text("")
    (real / "msg.py").write_text("MARKER = 'real module'\n")
    result = run_python(
        "import rosl, std_msgs.msg; print(std_msgs.msg.MARKER)",
        tmp_path,
        {"PYTHONPATH": str(tmp_path / "real"), "ROSL_PACKAGE_PATH": str(tmp_path / "pkgs")},
    )
    assert result.stdout.strip() == "real module", result.stderr


def test_a_folder_of_msg_files_on_sys_path_does_not_hide_the_interfaces(workspace):
    write_package(workspace / "src", "tutorial_pkg", {"msg/MyData.msg": "int32 counter\n"})
    # running from src/ puts src/ on sys.path: tutorial_pkg/ and tutorial_pkg/msg/ are plain folders
    result = run_python(
        "import rosl; from tutorial_pkg.msg import MyData; print(MyData())",
        workspace / "src",
    )
    assert result.stdout.strip() == "tutorial_pkg.msg.MyData(counter=0)", result.stderr


def test_a_bad_definition_raises_its_located_error_on_import(workspace):
    write_package(workspace / "src", "demo", {"msg/Bad.msg": "int32 a\nflaot64 b\n"})
    result = run_python(
        """
        import rosl
        try:
            from demo.msg import Bad
        except rosl.RoslError as err:
            print(err)
        """,
        workspace,
    )
    assert result.stdout.strip().endswith(
        "Bad.msg:2:1: unknown type 'flaot64' (did you mean 'float64'?)"
    ), result.stderr


def test_an_unknown_name_is_an_import_error_naming_the_folder(tmp_path):
    result = run_python(
        """
        import rosl
        try:
            from geometry_msgs.msg import Twsit
        except ImportError as err:
            print(err)
        """,
        tmp_path,
    )
    assert "cannot import name 'Twsit'" in result.stdout
    assert "geometry_msgs/msg" in result.stdout


def test_get_interface_returns_message_and_service_classes():
    import rosl

    assert rosl.get_interface("geometry_msgs/msg/Twist").__msgtype__ == "geometry_msgs/msg/Twist"
    assert rosl.get_interface("std_srvs/srv/Trigger").Response().success is False
    assert rosl.get_interface("std_srvs/Trigger").__srvtype__ == "std_srvs/srv/Trigger"
