"""ament_python packages whose setup.py builds console_scripts in code, run with `rosl run`."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.cli.conftest import Result, assert_user_error

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

MANIFEST = (
    '<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n'
    "  <version>0.0.0</version>\n"
    "  <export><build_type>ament_python</build_type></export>\n</package>\n"
)

# written as ros2 pkg create and the tutorials write it, with the entries built in code
SETUP_PY = """\
import os
from glob import glob

from setuptools import find_packages, setup

package_name = 'calc_py'
suffix: str = '_node'

setup(
    name=package_name,
    version='0.0.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/' + package_name, ['package.xml']),
        (os.path.join('share', package_name, 'launch'), glob('launch/*.py')),
    ],
    entry_points={
        'console_scripts': [
            'server = ' + package_name + '.server:main',
            f'client = {package_name}.client:main',
            'adder{} = {}.adder:main'.format(suffix, package_name),
            'echo = %s.%s:main' % (package_name, 'echo'),
        ],
    },
)
"""

MODULE = """\
import sys


def main():
    print('{name} ran with', sys.argv[1:])
"""


def _package(make_package: Callable[..., Path], setup_py: str) -> Path:
    files = {"setup.py": setup_py, "calc_py/__init__.py": ""}
    for name in ("server", "client", "adder", "echo"):
        files[f"calc_py/{name}.py"] = MODULE.format(name=name)
    return make_package("calc_py", files, manifest=MANIFEST.format(name="calc_py"))


def test_console_scripts_built_by_concatenation_are_the_package_executables(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    _package(make_package, SETUP_PY)
    result = rosl("pkg", "executables", "calc_py")
    assert result.code == 0, result
    assert sorted(result.out.splitlines()) == [
        "calc_py adder_node",
        "calc_py client",
        "calc_py echo",
        "calc_py server",
    ]


def test_rosl_run_starts_an_executable_whose_entry_is_concatenated(
    make_package: Callable[..., Path], workspace: Path, rosl_process: Callable[..., Result]
) -> None:
    _package(make_package, SETUP_PY)
    server = rosl_process("run", "calc_py", "server", "a", "b", cwd=workspace)
    assert server.code == 0, server
    assert server.out == "server ran with ['a', 'b']\n"
    adder = rosl_process("run", "calc_py", "adder_node", cwd=workspace)
    assert adder.out == "adder ran with []\n", adder


def test_a_setup_py_that_computes_its_package_name_is_one_line_naming_setup_py_and_line(
    make_package: Callable[..., Path], workspace: Path, rosl_process: Callable[..., Result]
) -> None:
    computed = SETUP_PY.replace("package_name = 'calc_py'", "package_name = read_name()")
    folder = _package(make_package, computed)
    line = assert_user_error(
        rosl_process("run", "calc_py", "server", cwd=workspace),
        f"{folder / 'setup.py'}:6:",
        "without running setup.py",
        "read_name()",
    )
    assert "Traceback" not in line


def test_a_setup_py_with_a_syntax_error_is_one_line_with_its_line(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    folder = _package(make_package, SETUP_PY.replace("version='0.0.0',", "version='0.0.0',,"))
    assert_user_error(rosl("run", "calc_py", "server"), f"{folder / 'setup.py'}:11:")
    assert rosl("pkg", "list").code == 0  # the package still lists


def test_an_entry_built_in_code_naming_a_missing_module_points_at_its_setup_py_line(
    make_package: Callable[..., Path], workspace: Path, rosl_process: Callable[..., Result]
) -> None:
    folder = _package(make_package, SETUP_PY.replace("'.server:main'", "'.servr:main'"))
    assert_user_error(
        rosl_process("run", "calc_py", "server", cwd=workspace),
        f"{folder / 'setup.py'}:19:",
        "module 'calc_py.servr' not found",
        "did you mean 'calc_py.server'",
    )


def test_pkg_executables_of_a_package_whose_setup_py_cannot_be_read_is_one_line(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    folder = _package(make_package, SETUP_PY.replace("suffix: str = '_node'", "suffix = x()"))
    assert_user_error(rosl("pkg", "executables", "calc_py"), f"{folder / 'setup.py'}:7:", "x()")


def test_entries_from_a_comprehension_and_setup_options_in_a_dict_are_found(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    setup_py = (
        "from setuptools import setup\n"
        "package_name = 'multi_py'\n"
        "nodes = ['talker', 'listener']\n"
        "options = dict(\n"
        "    name=package_name,\n"
        "    entry_points={'console_scripts': [\n"
        "        f'{node} = {package_name}.{node}:main' for node in nodes\n"
        "    ] + ['relay = multi_py.relay:main']},\n"
        ")\n"
        "setup(**options)\n"
    )
    make_package("multi_py", {"setup.py": setup_py}, manifest=MANIFEST.format(name="multi_py"))
    result = rosl("pkg", "executables", "multi_py")
    assert sorted(result.out.splitlines()) == [
        "multi_py listener",
        "multi_py relay",
        "multi_py talker",
    ], result


def test_a_filtered_comprehension_is_one_line_naming_its_line(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    setup_py = (
        "from setuptools import setup\n"
        "nodes = ['a', 'b']\n"
        "setup(name='filt_py', entry_points={'console_scripts': [\n"
        "    f'{n} = filt_py.{n}:main' for n in nodes if n != 'b']})\n"
    )
    folder = make_package(
        "filt_py", {"setup.py": setup_py}, manifest=MANIFEST.format(name="filt_py")
    )
    assert_user_error(
        rosl("run", "filt_py", "a"), f"{folder / 'setup.py'}:3:", "a comprehension other than"
    )
