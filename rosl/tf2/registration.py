"""tf2_ros's conversion registries: how to transform a type, and how to convert between types.

Keys are message type names (``geometry_msgs/msg/PointStamped``) for rosl's message classes
and the class itself for anything else, so a class rebuilt after an interface cache clear
still finds its functions. The geometry_msgs functions register themselves on first need,
so ``buffer.transform(point, 'map')`` works without importing tf2_geometry_msgs first.
"""

from __future__ import annotations

import copy
from typing import Any

from rosl.tf2.errors import TypeException

Callback = Any  # a user function; its signature is the caller's business

_transforms: dict[Any, Callback] = {}
_to_msg: dict[Any, Callback] = {}
_from_msg: dict[Any, Callback] = {}
_converts: dict[tuple[Any, Any], Callback] = {}


def _key(kind: Any) -> Any:
    return getattr(kind, "__msgtype__", kind)


def _missing(kind: Any) -> TypeException:
    return TypeException(f"Type {kind} is not loaded or supported")


def _geometry_loaded() -> None:
    import rosl.tf2.geometry  # noqa: F401 - registers the geometry_msgs types


class TransformRegistration:
    """``do_transform`` functions by type (tf2_ros.TransformRegistration)."""

    def add(self, key: Any, callback: Callback) -> None:
        """Register ``callback(obj, transform_stamped)`` for ``key``."""
        _transforms[_key(key)] = callback

    def get(self, key: Any) -> Callback:
        """The function that transforms a ``key``.

        Raises:
            TypeException: nothing registered for it.
        """
        if _key(key) not in _transforms:
            _geometry_loaded()
        if _key(key) not in _transforms:
            raise _missing(key)
        return _transforms[_key(key)]

    def print_me(self) -> None:
        """Print the registry (as tf2_ros does)."""
        print(_transforms)


class ConvertRegistration:
    """to_msg / from_msg / direct conversions by type (tf2_ros.ConvertRegistration)."""

    def add_from_msg(self, key: Any, callback: Callback) -> None:
        """Register how to build a ``key`` from a message."""
        _from_msg[_key(key)] = callback

    def add_to_msg(self, key: Any, callback: Callback) -> None:
        """Register how to turn a ``key`` into a message."""
        _to_msg[_key(key)] = callback

    def add_convert(self, key: tuple[Any, Any], callback: Callback) -> None:
        """Register a direct conversion between two types."""
        _converts[(_key(key[0]), _key(key[1]))] = callback

    def get_from_msg(self, key: Any) -> Callback:
        """Raises TypeException when nothing is registered."""
        return _get(_from_msg, key)

    def get_to_msg(self, key: Any) -> Callback:
        """Raises TypeException when nothing is registered."""
        return _get(_to_msg, key)

    def get_convert(self, key: tuple[Any, Any]) -> Callback:
        """Raises TypeException when nothing is registered."""
        found = _converts.get((_key(key[0]), _key(key[1])))
        if found is None:
            raise _missing(key)
        return found


def _get(table: dict[Any, Callback], key: Any) -> Callback:
    if _key(key) not in table:
        _geometry_loaded()
    if _key(key) not in table:
        raise _missing(key)
    return table[_key(key)]


def convert(a: Any, b_type: Any) -> Any:
    """``a`` as a ``b_type``: a direct conversion, a copy, or through its message."""
    registry = ConvertRegistration()
    try:
        return registry.get_convert((type(a), b_type))(a)
    except TypeException:
        if _key(type(a)) == _key(b_type):
            return copy.deepcopy(a)
        return registry.get_from_msg(b_type)(registry.get_to_msg(type(a))(a))


__all__ = ["ConvertRegistration", "TransformRegistration", "convert"]
