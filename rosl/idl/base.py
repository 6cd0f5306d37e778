"""The base classes of generated message and service classes (no numpy at import).

``isinstance(x, Message)`` and the ``Message``/``ServiceType`` names are needed by code that
must stay light to import (the node layer, the CLI); the generated classes and numpy arrive
only when a type is first used (``messages.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from rosl.idl.parser import FieldType, MessageSpec


class Message:
    """Base of every generated message class."""

    __slots__ = ()
    __msgtype__: ClassVar[str]
    _fields: ClassVar[tuple[str, ...]]
    _field_types: ClassVar[tuple[FieldType, ...]]
    _field_classes: ClassVar[dict[str, type[Message]]]
    _python_name: ClassVar[str]
    _spec: ClassVar[MessageSpec]

    def __init__(self, *args: Any, **kwargs: Any) -> None:  # replaced in every subclass
        raise TypeError("Message is abstract")

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(_equal(getattr(self, n), getattr(other, n)) for n in self._fields)

    # unhashable (mutable, as rclpy's messages); typeshed types object.__hash__ as a method
    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        parts = []
        import numpy as np

        from rosl.idl.parser import ArrayKind

        for name, ftype in zip(self._fields, self._field_types, strict=True):
            value = getattr(self, name)
            if isinstance(value, np.ndarray) and ftype.array is not ArrayKind.FIXED:
                text = repr(value.tolist())
            else:
                text = repr(value)
            parts.append(f"{name}={text}")
        return f"{self._python_name}({', '.join(parts)})"

    @classmethod
    def get_fields_and_field_types(cls) -> dict[str, str]:
        """Return field names and their ROS type spellings, as rclpy does."""
        return {n: str(t) for n, t in zip(cls._fields, cls._field_types, strict=True)}


class ServiceType:
    """Base of generated service classes: ``Request`` and ``Response`` message classes."""

    __srvtype__: ClassVar[str]
    Request: ClassVar[type[Message]]
    Response: ClassVar[type[Message]]


class ActionType:
    """Base of generated action classes, as rosidl_generator_py makes them.

    ``Goal``, ``Result`` and ``Feedback`` are message classes; ``Impl`` holds the generated
    ``SendGoalService``, ``GetResultService`` and ``FeedbackMessage`` and action_msgs'
    ``CancelGoalService`` and ``GoalStatusMessage``.
    """

    __actiontype__: ClassVar[str]
    Goal: ClassVar[type[Message]]
    Result: ClassVar[type[Message]]
    Feedback: ClassVar[type[Message]]
    Impl: ClassVar[Any]

    def __init__(self) -> None:
        raise NotImplementedError("Action classes can not be instantiated")


def _equal(a: Any, b: Any) -> bool:
    import numpy as np

    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(np.asarray(a), np.asarray(b)))
    return bool(a == b)
