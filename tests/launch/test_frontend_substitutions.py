"""``$(...)`` strings as XML and YAML launch files write them, and the substitutions they make.

The parser follows launch's grammar: arguments split by spaces, quoted with '...' or "..."
(substitutions nest inside both), ``\\x`` is ``x``. Each substitution is then resolved against
a LaunchContext, as the launch does while it processes the file.
"""

from __future__ import annotations

import os
import re
import shutil
import sys
from pathlib import Path

import pytest

from rosl.launch import substitutions as subs
from rosl.launch.context import LaunchContext
from rosl.launch.errors import LaunchError
from rosl.launch.substitution_text import SubstitutionSyntaxError, parse_substitution
from tests.launch.support import EXAMPLES

HERE = Path("/launch/files/here.launch.xml")


def resolve(text: str, configurations: dict[str, str] | None = None) -> str:
    """Parse ``text`` and resolve it in a context holding ``configurations``."""
    context = LaunchContext(None, configurations or {})
    return subs.perform(context, parse_substitution(text, path=HERE))


# --- parsing -------------------------------------------------------------------------------


def test_plain_text_stays_a_plain_string() -> None:
    assert parse_substitution("plain text, 5$ and (parentheses)") == (
        "plain text, 5$ and (parentheses)"
    )
    assert parse_substitution("") == ""


def test_text_and_substitutions_make_a_list_in_order() -> None:
    parts = parse_substitution("a $(var x) b")

    assert isinstance(parts, list)
    assert parts[0] == "a "
    assert isinstance(parts[1], subs.LaunchConfiguration)
    assert parts[1].variable_name == "x"
    assert parts[2] == " b"


def test_a_backslash_escapes_the_next_character() -> None:
    assert parse_substitution(r"\$(var x) and \\ and \q") == "$(var x) and \\ and q"


def test_substitutions_nest_in_arguments_and_in_quotes() -> None:
    values = {"a": "b", "b_c": "deep", "word": "two words"}

    assert resolve("$(var $(var a)_c)", values) == "deep"
    assert resolve("""$(eval "'$(var word)' == 'two words'")""", values) == "True"
    assert resolve("""$(eval '"$(var a)" * 3')""", values) == "bbb"
    assert resolve("$(var missing 'a default with spaces')") == "a default with spaces"
    assert resolve(r"$(var missing a\ b\)c)") == "a b)c"


def test_optenv_takes_the_rest_of_its_arguments_as_the_default(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv("ROSL_TEST_UNSET", raising=False)
    monkeypatch.setenv("ROSL_TEST_SET", "set value")

    assert resolve("$(optenv ROSL_TEST_UNSET)") == ""
    assert resolve("$(optenv ROSL_TEST_UNSET two words)") == "two words"
    assert resolve("$(optenv ROSL_TEST_SET two words)") == "set value"
    assert resolve("$(env ROSL_TEST_UNSET fallback)") == "fallback"
    with pytest.raises(LaunchError, match="environment variable 'ROSL_TEST_UNSET' is not set"):
        resolve("$(env ROSL_TEST_UNSET)")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("$(var x", "'$(var' at column 1 is not closed with ')'"),
        ("a $(", "a substitution name must follow '$(' at column 3"),
        ("$(var.x)", "unexpected '.' at column 6 in '$(var ...)'"),
        ("$(vr x)", "unknown substitution '$(vr)' (did you mean 'var'?)"),
        ("$(var)", "$(var) takes 1 to 2 argument(s), not 0"),
        ("$(dirname x)", "$(dirname) takes 0 argument(s), not 1"),
        ("$(find-pkg-share a b)", "$(find-pkg-share) takes 1 argument(s), not 2"),
        ("$(eval 1+(2))", "'(' at column 10 inside an argument: quote the whole argument"),
        ("$(eval 'open)", "the quote ' at column 8 is not closed"),
        ("$(eval 'a'b)", "a space or ')' must follow the quoted argument at column 8"),
        ("$(eval 'x' $(var a))", "the module list of $(eval) must be plain text"),
        ("$(eval '$(var a')", "'$(var' at column 9 is not closed with ')'"),
    ],
)
def test_a_malformed_string_says_what_and_where(text: str, message: str) -> None:
    with pytest.raises(SubstitutionSyntaxError) as caught:
        parse_substitution(text)

    assert str(caught.value).startswith(message), str(caught.value)


# --- the substitutions ---------------------------------------------------------------------


def test_dirname_and_filename_name_the_file_they_are_written_in() -> None:
    assert resolve("$(dirname)/x.yaml") == "/launch/files/x.yaml"
    assert resolve("$(filename)") == str(HERE)


def test_this_launch_file_of_python_is_the_file_being_processed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    context = LaunchContext(None, {})
    with pytest.raises(LaunchError, match="ThisLaunchFileDir used outside of a launch file"):
        subs.ThisLaunchFileDir().perform(context)
    monkeypatch.chdir(tmp_path)

    context.files.append(Path("a.launch.py"))  # as given on the command line

    assert subs.ThisLaunchFileDir().perform(context) == str(tmp_path.resolve())
    assert subs.ThisLaunchFile().perform(context) == str((tmp_path / "a.launch.py").resolve())


def test_anon_gives_one_unique_name_per_name_for_the_whole_launch() -> None:
    context = LaunchContext(None, {})
    first = subs.AnonName("node").perform(context)

    assert re.fullmatch(rf"node_{os.getpid()}_\d+", first)
    assert subs.AnonName(["no", "de"]).perform(context) == first
    assert subs.AnonName("other").perform(context) != first
    assert subs.AnonName("node").perform(LaunchContext(None, {})) != first


def test_eval_has_math_builtins_and_the_modules_it_names() -> None:
    assert resolve("$(eval 'floor(pi) + math.ceil(0.5)')") == "4"
    assert resolve("$(eval 'int(\"3\") * len([1, 2])')") == "6"
    assert resolve("$(eval 'os.path.basename(\"/a/b\")' os)") == "b"
    with pytest.raises(LaunchError, match="PythonExpression: no Python module 'surely_nope'"):
        resolve("$(eval '1' surely_nope)")
    with pytest.raises(LaunchError, match=re.escape("PythonExpression '1 +' failed: SyntaxError")):
        resolve("$(eval '1 +')")


def test_command_gives_stdout_and_refuses_stderr_unless_told(tmp_path: Path) -> None:
    noisy = f"{sys.executable} -c 'import sys; print(1, file=sys.stderr); sys.stdout.write(str(2))'"

    assert resolve("$(command 'printf \"a b\"')") == "a b"
    assert resolve("$(command 'echo $(var x)')", {"x": "given"}) == "given\n"  # as launch
    assert resolve(f'$(command "{noisy}" ignore)') == "2"
    assert resolve(f'$(command "{noisy}" warn)') == "2"
    assert resolve(f'$(command "{noisy}" capture)') == "1\n2"
    with pytest.raises(LaunchError, match=r"wrote to stderr: 1 \(give 'warn' or 'ignore'"):
        resolve(f'$(command "{noisy}")')
    with pytest.raises(LaunchError, match="on_stderr is 'loud', not one of fail, warn"):
        resolve(f'$(command "{noisy}" loud)')
    with pytest.raises(LaunchError, match=r"command 'false' exited with code 1$"):
        resolve("$(command false)")
    with pytest.raises(LaunchError, match="failed: 'surely-no-such-tool' not found"):
        resolve("$(command surely-no-such-tool)")


def test_command_sees_the_environment_the_launch_file_set() -> None:
    context = LaunchContext(None, {})
    context.scope.environment["ROSL_TEST_SCOPED"] = "scoped"
    command = subs.Command(
        f"{sys.executable} -c 'import os; print(os.environ[\"ROSL_TEST_SCOPED\"])'"
    )

    assert command.perform(context) == "scoped\n"


def test_find_exec_searches_the_path() -> None:
    assert resolve("$(find-exec sh)") == shutil.which("sh")
    with pytest.raises(LaunchError, match="executable 'surely-not-here' not found on the PATH"):
        resolve("$(find-exec surely-not-here)")


def test_package_substitutions_find_rosl_packages(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(EXAMPLES))
    folder = str(EXAMPLES / "tutorial_pkg")

    assert resolve("$(find-pkg-share tutorial_pkg)/launch") == f"{folder}/launch"
    assert resolve("$(find-pkg-prefix tutorial_pkg)") == folder
    assert resolve("$(find-package tutorial_pkg)") == folder
    assert subs.FindPackageShare.find("tutorial_pkg") == folder
    with pytest.raises(LaunchError, match="package 'surely_nope' not found"):
        resolve("$(find-pkg-share surely_nope)")


def test_exec_in_package_is_a_path_for_files_and_an_argv_for_python_entries(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(EXAMPLES))
    context = LaunchContext(None, {})
    entry = subs.ExecutableInPackage("timer_node", "tutorial_pkg")

    argv = entry.command(context)

    assert argv[-2:] == ["tutorial_pkg.timer_node:main", "timer_node"]
    with pytest.raises(LaunchError, match="is a Python entry point, not a file"):
        resolve("$(exec-in-package timer_node tutorial_pkg)")


def test_not_and_or_read_true_false_and_one_zero() -> None:
    assert resolve("$(not true) $(not 0)") == "false true"
    assert resolve("$(and true 1) $(and true false)") == "true false"
    assert resolve("$(or false 0) $(or $(var a) false)", {"a": "TRUE"}) == "false true"
    with pytest.raises(LaunchError, match="and: 'maybe' is not a boolean"):
        resolve("$(and true maybe)")


def test_describe_shows_each_substitution_unresolved() -> None:
    shown = {
        "$(var a)": "LaunchConfig('a')",
        "$(env HOME)": "EnvVar('HOME')",
        "$(find-pkg-share p)/x": "Pkg(pkg='p') + '/x'",
        "$(find-exec sh)": "FindExec('sh')",
        "$(exec-in-pkg e p)": "ExecInPkg(pkg='p', exec='e')",
        "$(eval '1 + 1')": "PythonExpr('1 + 1')",
        "$(command 'ls -l')": "Command('ls -l')",
        "$(anon n)": "AnonName('n')",
        "$(dirname)": "ThisLaunchFileDir()",
        "$(filename)": "ThisLaunchFile()",
        "$(not $(var a))": "NotSubstitution(LaunchConfig('a'))",
        "$(or a b)": "OrSubstitution('a' 'b')",
    }
    for text, description in shown.items():
        assert subs.describe(parse_substitution(text)) == description, text
