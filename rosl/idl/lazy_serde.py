"""rosbags' generated (de)serializers, made on first use and loading numpy at the first array.

For every type it meets, rosbags' ``Typestore.get_msgdef`` writes and compiles thirteen
functions as Python source (CDR both byte orders, ROS 1, sizes, conversions), each starting with
``import numpy``. A process uses two or three of them per type, and one that only ever sends
strings and numbers (a CLI echoing ``/chatter``, a node whose only arrays are the empty ones of
its ``ParameterEvent``) need not load numpy, a fifth of its start-up. So:

* :class:`LazyTypestore` hands out a :class:`rosbags.interfaces.Msgdef` whose functions are
  generated (by rosbags' own generators) when first looked up;
* :func:`install` wraps rosbags' one compiling function so the ``import numpy`` line is dropped
  and the functions find ``numpy`` as :data:`SERDE_NUMPY` instead: numpy's own attributes
  (loading numpy then), except ``numpy.uint8`` while numpy is not loaded, which only an empty
  sequence (:data:`rosl.idl.sequences.EMPTY`) can be asked to be viewed as. Once numpy is
  loaded, the functions see numpy itself (no call per attribute).

Used by ``store.py`` only. rosbags is pinned to a minor version whose generated code this
matches; if its compiling function is not found, numpy is simply imported as before.
"""

from __future__ import annotations

import importlib
import sys
from typing import TYPE_CHECKING, Any

from rosbags.interfaces import Msgdef
from rosbags.serde.cdr import generate_deserialize_cdr, generate_getsize_cdr, generate_serialize_cdr
from rosbags.serde.ros1 import (
    generate_cdr_to_ros1,
    generate_deserialize_ros1,
    generate_getsize_ros1,
    generate_ros1_to_cdr,
    generate_serialize_ros1,
)
from rosbags.typesys.base import normalize_fieldname
from rosbags.typesys.store import Typestore

from rosl.idl.lazy_numpy import np

if TYPE_CHECKING:
    from collections.abc import Callable
    from types import ModuleType

_IMPORT_LINE = "import numpy"
_GENERATORS = ("rosbags.serde.cdr", "rosbags.serde.ros1")


_compiled: list[ModuleType] = []  # the generated modules still seeing SERDE_NUMPY


class _SerdeNumpy:
    """What the generated functions see as ``numpy`` until numpy is loaded, then numpy itself."""

    def __getattr__(self, name: str) -> Any:
        if name == "uint8" and "numpy" not in sys.modules:
            return "uint8"  # the view of an empty sequence: no numpy array exists yet
        value = getattr(np, name)
        loaded = sys.modules.get("numpy")
        if loaded is not None:  # no call through here any more (one per array per message)
            for module in _compiled[:]:  # (two threads may get here at once: no pop races)
                module.numpy = loaded  # type: ignore[attr-defined]
            _compiled.clear()
        return value


SERDE_NUMPY = _SerdeNumpy()


def _without_numpy_import(
    compile_lines: Callable[[list[str]], ModuleType],
) -> Callable[[list[str]], ModuleType]:
    def compile_lazily(lines: list[str]) -> ModuleType:
        module = compile_lines([line for line in lines if line != _IMPORT_LINE])
        module.numpy = SERDE_NUMPY  # type: ignore[attr-defined]
        _compiled.append(module)
        return module

    compile_lazily.rosl_lazy = True  # type: ignore[attr-defined]
    return compile_lazily


def install() -> None:
    """Wrap ``compile_lines`` in rosbags' CDR and ROS 1 generators (idempotent)."""
    for name in _GENERATORS:
        try:
            module: Any = importlib.import_module(name)
        except ImportError:
            continue
        original = getattr(module, "compile_lines", None)
        if original is None or getattr(original, "rosl_lazy", False):
            continue
        module.compile_lines = _without_numpy_import(original)


def _sizes(generate: Any, size: str, getsize: str) -> Callable[[_LazyMsgdef], dict[str, Any]]:
    def make(msgdef: _LazyMsgdef) -> dict[str, Any]:
        function, fixed = generate(msgdef.fields, msgdef.typestore)
        return {getsize: function, size: fixed}

    return make


def _one(name: str, make: Callable[[_LazyMsgdef], Any]) -> Callable[[_LazyMsgdef], dict[str, Any]]:
    return lambda msgdef: {name: make(msgdef)}


def _cdr(generate: Any, order: str) -> Callable[[_LazyMsgdef], Any]:
    return lambda m: generate(m.fields, m.typestore, order)


def _conversion(generate: Any, copy: bool) -> Callable[[_LazyMsgdef], Any]:
    return lambda m: generate(m.fields, m.name, m.typestore, copy=copy)


_MAKERS: dict[str, Callable[[_LazyMsgdef], dict[str, Any]]] = {
    "size_cdr": _sizes(generate_getsize_cdr, "size_cdr", "getsize_cdr"),
    "getsize_cdr": _sizes(generate_getsize_cdr, "size_cdr", "getsize_cdr"),
    "size_ros1": _sizes(generate_getsize_ros1, "size_ros1", "getsize_ros1"),
    "getsize_ros1": _sizes(generate_getsize_ros1, "size_ros1", "getsize_ros1"),
    "serialize_cdr_le": _one("serialize_cdr_le", _cdr(generate_serialize_cdr, "le")),
    "serialize_cdr_be": _one("serialize_cdr_be", _cdr(generate_serialize_cdr, "be")),
    "deserialize_cdr_le": _one("deserialize_cdr_le", _cdr(generate_deserialize_cdr, "le")),
    "deserialize_cdr_be": _one("deserialize_cdr_be", _cdr(generate_deserialize_cdr, "be")),
    "serialize_ros1": _one(
        "serialize_ros1", lambda m: generate_serialize_ros1(m.fields, m.typestore)
    ),
    "deserialize_ros1": _one(
        "deserialize_ros1", lambda m: generate_deserialize_ros1(m.fields, m.typestore)
    ),
    "getsize_ros1_to_cdr": _one("getsize_ros1_to_cdr", _conversion(generate_ros1_to_cdr, False)),
    "ros1_to_cdr": _one("ros1_to_cdr", _conversion(generate_ros1_to_cdr, True)),
    "getsize_cdr_to_ros1": _one("getsize_cdr_to_ros1", _conversion(generate_cdr_to_ros1, False)),
    "cdr_to_ros1": _one("cdr_to_ros1", _conversion(generate_cdr_to_ros1, True)),
}


class _LazyMsgdef(Msgdef[object]):
    """A Msgdef whose generated functions are made when first looked up."""

    typestore: Typestore

    def __getattr__(self, name: str) -> Any:  # only for what is not made yet
        maker = _MAKERS.get(name)
        if maker is None:
            raise AttributeError(name)
        for key, value in maker(self).items():
            object.__setattr__(self, key, value)
        return object.__getattribute__(self, name)


class LazyTypestore(Typestore):
    """rosbags' type store, making each type's functions as they are first used."""

    def get_msgdef(self, typename: str) -> Msgdef[object]:
        """The message definition of ``typename`` (functions made on first use)."""
        msgdef = self.cache.get(typename)
        if msgdef is None:
            msgdef = object.__new__(_LazyMsgdef)
            fields = [(normalize_fieldname(n), desc) for n, desc in self.fielddefs[typename][1]]
            for key, value in (
                ("name", typename), ("fields", fields), ("cls", self.types[typename]),
                ("typestore", self),
            ):  # fmt: skip
                object.__setattr__(msgdef, key, value)
            self.cache[typename] = msgdef
        return msgdef
