"""ROS 2 names: validation, expansion of relative and private names, and remapping.

Rules follow rcl/rmw: a node name is letters, digits and ``_`` (not starting with a digit);
a fully qualified topic or service name starts with ``/`` and is ``/``-separated tokens of
that alphabet with no empty token; ``~`` expands to ``<namespace>/<node>``, ``{node}`` and
``{ns}``/``{namespace}`` are substituted, a relative name is put under the namespace, and
remap rules apply to the expanded name.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from rosl.node.errors import InvalidNameError

_TOKEN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
MAX_NAME = 255


@dataclass(frozen=True, slots=True)
class Remap:
    """A remap rule ``[node:]from:=to``."""

    source: str
    target: str
    node: str | None = None


def validate_node_name(name: str) -> str:
    """Return ``name`` if it is a valid node name, else raise InvalidNameError."""
    if not name:
        raise InvalidNameError("node name must not be empty")
    if not _TOKEN.match(name):
        bad = (
            "must not start with a number"
            if name[0].isdigit()
            else ("must contain only letters, digits and '_'")
        )
        raise InvalidNameError(f"invalid node name '{name}': it {bad}")
    if len(name) > MAX_NAME:
        raise InvalidNameError(f"invalid node name '{name[:20]}...': longer than {MAX_NAME}")
    return name


def validate_namespace(namespace: str) -> str:
    """Return the absolute namespace (``""`` means ``/``) or raise InvalidNameError."""
    if not namespace:
        return "/"
    if not namespace.startswith("/"):
        namespace = "/" + namespace
    if namespace != "/":
        _check_tokens(namespace.rstrip("/") if namespace.endswith("/") else namespace, "namespace")
    return namespace.rstrip("/") or "/"


def validate_full_name(name: str, what: str = "topic") -> str:
    """Check a fully qualified topic or service name."""
    if not name.startswith("/"):
        raise InvalidNameError(f"invalid {what} name '{name}': it must be absolute after expansion")
    if name == "/":
        raise InvalidNameError(f"invalid {what} name '/': it has no name after the '/'")
    _check_tokens(name, what)
    return name


def _check_tokens(name: str, what: str) -> None:
    if name.endswith("/"):
        raise InvalidNameError(f"invalid {what} name '{name}': it must not end with '/'")
    for token in name[1:].split("/"):
        if not token:
            raise InvalidNameError(f"invalid {what} name '{name}': it contains '//'")
        if not _TOKEN.match(token):
            reason = (
                "a part starts with a number"
                if token[0].isdigit()
                else "use only letters, digits, '_' and '/'"
            )
            raise InvalidNameError(f"invalid {what} name '{name}': {reason}")


def expand(name: str, node_name: str, namespace: str, what: str = "topic") -> str:
    """Expand a topic or service name as rcl does (``~``, ``{node}``, relative names)."""
    if not name:
        raise InvalidNameError(f"{what} name must not be empty")
    ns = namespace.rstrip("/")
    text = (
        name.replace("{node}", node_name)
        .replace("{ns}", ns or "/")
        .replace("{namespace}", ns or "/")
    )
    if text.startswith("~"):
        rest = text[1:]
        if rest and not rest.startswith("/"):
            raise InvalidNameError(f"invalid {what} name '{name}': '~' must be followed by '/'")
        text = f"{ns}/{node_name}{rest}"
    elif not text.startswith("/"):
        text = f"{ns}/{text}"
    if "~" in text or "{" in text or "}" in text:
        raise InvalidNameError(f"invalid {what} name '{name}': '~' or '{{...}}' in the wrong place")
    return validate_full_name(text, what)


def remap(full_name: str, rules: list[Remap], node_name: str, namespace: str) -> str:
    """Apply the first matching remap rule to an expanded name."""
    for rule in rules:
        if (rule.node is not None and rule.node != node_name) or rule.source.startswith("__"):
            continue
        source = expand(_strip_scheme(rule.source), node_name, namespace)
        if source == full_name:
            return expand(rule.target, node_name, namespace)
    return full_name


def _strip_scheme(name: str) -> str:
    for scheme in ("rostopic://", "rosservice://"):
        if name.startswith(scheme):
            return name[len(scheme) :]
    return name


def fully_qualified(namespace: str, node_name: str) -> str:
    """``/ns/node`` from a namespace and a node name."""
    return f"{namespace.rstrip('/')}/{node_name}"
