"""An ament_python package's ``console_scripts``, read from its setup.py without running it.

setup.py is parsed, never executed. The ``entry_points`` given to ``setup(...)`` is evaluated
from literals and the module-level names it uses, so the ways ROS 2 packages spell their
entries all work: ``'talker = demo.talker:main'``, ``'server = ' + package_name +
'.server:main'``, ``f'{package_name}.node:main'``, ``'{}.x:main'.format(package_name)`` and
``'%s.x:main' % package_name``. What needs the file to run (a call, an import, a loop) is a
:class:`PackageError` of one line naming ``setup.py:line`` and the expression.
"""

from __future__ import annotations

import ast
from typing import TYPE_CHECKING, Any

from rosl.pkg.errors import PackageError

if TYPE_CHECKING:
    from pathlib import Path

__all__ = ["console_script_lines", "console_scripts"]


class _UnreadableError(Exception):
    """An expression that cannot be evaluated without running setup.py."""

    def __init__(self, node: ast.AST, why: str) -> None:
        super().__init__(why)
        self.node = node
        self.why = why


def console_scripts(path: Path) -> list[str]:
    """Return setup.py's ``console_scripts`` entries (``'name = module:function'``).

    Raises:
        PackageError: setup.py cannot be read or parsed, or its entry points cannot be
            evaluated without running it (``path:line: ...``).
    """
    return [entry for entry, _ in _entries(path)]


def console_script_lines(path: Path) -> dict[str, int]:
    """Each executable's name and the setup.py line of its entry ({} when unreadable)."""
    try:
        entries = _entries(path)
    except PackageError:
        return {}
    return {entry.partition("=")[0].strip(): line for entry, line in entries}


def _entries(path: Path) -> list[tuple[str, int]]:
    try:
        text = path.read_text(encoding="utf-8")
        tree = ast.parse(text, filename=str(path))
    except (OSError, UnicodeDecodeError) as err:
        raise PackageError(f"{path}: cannot read setup.py ({err})") from None
    except SyntaxError as err:
        raise PackageError(f"{path}:{err.lineno}:{err.offset}: {err.msg}") from None
    reader = _Reader(tree, text)
    try:
        return reader.console_scripts()
    except _UnreadableError as err:
        line = getattr(err.node, "lineno", 0)
        code = ast.get_source_segment(text, err.node) or ""
        code = code if len(code) <= 60 else code[:57] + "..."
        raise PackageError(
            f"{path}:{line}: cannot read console_scripts without running setup.py: "
            f"{err.why} in `{code}`"
        ) from None


class _Reader:
    """Evaluates the expressions setup.py's entry points are built from."""

    def __init__(self, tree: ast.Module, text: str) -> None:
        self.text = text
        self.names: dict[str, ast.expr] = {}
        self.busy: set[str] = set()
        self.setup: ast.Call | None = None
        for statement in tree.body:  # module level, in order: the last binding before setup()
            if self.setup is None:
                self._bind(statement)
            call = _setup_call(statement)
            if call is not None and self.setup is None:
                self.setup = call
        self.tree = tree

    def _bind(self, statement: ast.stmt) -> None:
        if isinstance(statement, ast.Assign):
            for target in statement.targets:
                if isinstance(target, ast.Name):
                    self.names[target.id] = statement.value
        elif (
            isinstance(statement, ast.AnnAssign)
            and isinstance(statement.target, ast.Name)
            and statement.value is not None
        ):
            self.names[statement.target.id] = statement.value

    def console_scripts(self) -> list[tuple[str, int]]:
        """Each entry with the line of the expression that gives it."""
        entry_points = self._entry_points()
        if entry_points is None:
            return []
        value = self.eval(entry_points)
        if not isinstance(value, dict):
            raise _UnreadableError(entry_points, "entry_points is not a dict")
        scripts = value.get("console_scripts", [])
        if isinstance(scripts, str):
            scripts = scripts.splitlines()
        if not isinstance(scripts, (list, tuple)) or not all(isinstance(s, str) for s in scripts):
            raise _UnreadableError(entry_points, "console_scripts is not a list of strings")
        lines = self._element_lines(entry_points)
        if len(lines) != len(scripts):
            lines = [entry_points.lineno] * len(scripts)
        return [(s, line) for s, line in zip(scripts, lines, strict=True) if s.strip()]

    def _element_lines(self, entry_points: ast.expr) -> list[int]:
        """The line of each element of a literal console_scripts list (else [])."""
        node = self._resolved(entry_points)
        if not isinstance(node, ast.Dict):
            return []
        for key, value in zip(node.keys, node.values, strict=True):
            if isinstance(key, ast.Constant) and key.value == "console_scripts":
                found = self._resolved(value)
                if isinstance(found, (ast.List, ast.Tuple)):
                    return [element.lineno for element in found.elts]
        return []

    def _resolved(self, node: ast.expr) -> ast.expr:
        seen: set[str] = set()
        while isinstance(node, ast.Name) and node.id in self.names and node.id not in seen:
            seen.add(node.id)
            node = self.names[node.id]
        return node

    def _entry_points(self) -> ast.expr | None:
        if self.setup is not None:
            for keyword in self.setup.keywords:
                if keyword.arg == "entry_points":
                    return keyword.value
            for keyword in self.setup.keywords:  # setup(**options), options a dict or dict()
                options = self._resolved(keyword.value) if keyword.arg is None else None
                if isinstance(options, ast.Dict):
                    for key, value in zip(options.keys, options.values, strict=True):
                        if isinstance(key, ast.Constant) and key.value == "entry_points":
                            return value
                elif isinstance(options, ast.Call):
                    for option in options.keywords:
                        if option.arg == "entry_points":
                            return option.value
            return None
        for node in ast.walk(self.tree):  # no setup(...) call: any dict naming console_scripts
            if isinstance(node, ast.Dict) and any(
                isinstance(k, ast.Constant) and k.value == "console_scripts" for k in node.keys
            ):
                return node
        return None

    def eval(self, node: ast.expr) -> Any:
        """The value of ``node``, or :class:`_UnreadableError`."""
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            return self._name(node)
        if isinstance(node, (ast.List, ast.Tuple)):
            items = [self.eval(e) for e in node.elts]
            return items if isinstance(node, ast.List) else tuple(items)
        if isinstance(node, ast.Dict):
            result = {}
            for key, value in zip(node.keys, node.values, strict=True):
                if key is None:
                    raise _UnreadableError(node, "a ** in a dict")
                result[self.eval(key)] = self.eval(value)
            return result
        if isinstance(node, ast.JoinedStr):
            return "".join(self._formatted(v) for v in node.values)
        if isinstance(node, ast.BinOp):
            return self._binop(node)
        if isinstance(node, ast.Call):
            return self._call(node)
        if isinstance(node, ast.ListComp):
            return self._list_comprehension(node)
        raise _UnreadableError(node, f"a {type(node).__name__.lower()} expression")

    def _list_comprehension(self, node: ast.ListComp) -> list[Any]:
        """``[f'{n} = pkg.{n}:main' for n in nodes]``: one loop over a known list, no ``if``."""
        loop = node.generators[0]
        if len(node.generators) != 1 or loop.ifs or not isinstance(loop.target, ast.Name):
            raise _UnreadableError(node, "a comprehension other than [... for name in list]")
        name = loop.target.id
        items = self.eval(loop.iter)
        if not isinstance(items, (list, tuple)):
            raise _UnreadableError(loop.iter, "a loop over something not a list")
        saved = self.names.get(name)
        result = []
        try:
            for item in items:
                self.names[name] = ast.Constant(item)
                result.append(self.eval(node.elt))
        finally:
            if saved is None:
                self.names.pop(name, None)
            else:
                self.names[name] = saved
        return result

    def _name(self, node: ast.Name) -> Any:
        bound = self.names.get(node.id)
        if bound is None:
            raise _UnreadableError(node, f"'{node.id}' is not a plain module-level value")
        if node.id in self.busy:
            raise _UnreadableError(node, f"'{node.id}' refers to itself")
        self.busy.add(node.id)
        try:
            return self.eval(bound)
        finally:
            self.busy.discard(node.id)

    def _formatted(self, node: ast.expr) -> str:
        if isinstance(node, ast.Constant):
            return str(node.value)
        if isinstance(node, ast.FormattedValue):
            value = self.eval(node.value)
            spec = "" if node.format_spec is None else str(self.eval(node.format_spec))
            converted = {-1: value, 115: str(value), 114: repr(value), 97: ascii(value)}
            return format(converted.get(node.conversion, value), spec)
        raise _UnreadableError(node, "an f-string part")

    def _binop(self, node: ast.BinOp) -> Any:
        left, right = self.eval(node.left), self.eval(node.right)
        try:
            if isinstance(node.op, ast.Add):
                return left + right
            if isinstance(node.op, ast.Mod) and isinstance(left, str):
                return left % right
        except (TypeError, ValueError) as err:
            raise _UnreadableError(node, str(err)) from None
        raise _UnreadableError(node, f"the operator {type(node.op).__name__}")

    def _call(self, node: ast.Call) -> Any:
        func = node.func
        if isinstance(func, ast.Attribute) and func.attr == "format" and not node.keywords:
            template = self.eval(func.value)
            if isinstance(template, str):
                try:
                    return template.format(*[self.eval(a) for a in node.args])
                except (IndexError, KeyError, ValueError) as err:
                    raise _UnreadableError(node, f"format fails ({err})") from None
        if isinstance(func, ast.Name) and func.id in ("dict", "list", "tuple") and not node.args:
            return {"dict": dict, "list": list, "tuple": tuple}[func.id](
                **{k.arg: self.eval(k.value) for k in node.keywords if k.arg}
            )
        raise _UnreadableError(node, "a call")


def _setup_call(statement: ast.stmt) -> ast.Call | None:
    """The ``setup(...)`` call a module-level statement makes, if it is one."""
    node = statement.value if isinstance(statement, ast.Expr) else None
    if isinstance(node, ast.Call):
        func = node.func
        name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")
        if name == "setup":
            return node
    return None
