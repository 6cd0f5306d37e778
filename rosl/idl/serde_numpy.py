"""rosbags' generated (de)serializers with numpy loaded at the first array, not at generation.

rosbags writes each type's CDR functions as Python source that starts with ``import numpy``, so
a process that only ever sends strings and numbers (a CLI echoing ``/chatter``, a node whose
only arrays are the empty ones of its ``ParameterEvent``) loads numpy — a fifth of its start-up
— for nothing. :func:`install` wraps rosbags' one compiling function so that line is dropped
and the functions find ``numpy`` as :data:`SERDE_NUMPY` instead: it hands out numpy's own
attributes (loading numpy then), except ``numpy.uint8`` while numpy is not loaded, which only
an empty sequence (:data:`rosl.idl.sequences.EMPTY`) can be asked to be viewed as. Used by
``store.py`` only; rosbags is pinned to a minor version whose generated code this matches, and
if its compiling function is not found nothing is changed (numpy is then imported as before).
"""

from __future__ import annotations

import importlib
import sys
from typing import TYPE_CHECKING, Any

from rosl.idl.lazy_numpy import np

if TYPE_CHECKING:
    from collections.abc import Callable
    from types import ModuleType

_IMPORT_LINE = "import numpy"
_GENERATORS = ("rosbags.serde.cdr", "rosbags.serde.ros1")


class _SerdeNumpy:
    """What the generated functions see as ``numpy``."""

    def __getattr__(self, name: str) -> Any:
        if name == "uint8" and "numpy" not in sys.modules:
            return "uint8"  # the view of an empty sequence: no numpy array exists yet
        return getattr(np, name)


SERDE_NUMPY = _SerdeNumpy()


def _without_numpy_import(
    compile_lines: Callable[[list[str]], ModuleType],
) -> Callable[[list[str]], ModuleType]:
    def compile_lazily(lines: list[str]) -> ModuleType:
        module = compile_lines([line for line in lines if line != _IMPORT_LINE])
        module.numpy = SERDE_NUMPY  # type: ignore[attr-defined]
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
