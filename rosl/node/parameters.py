"""Parameters: rclpy's Parameter, a node's ParameterStore, and its rcl_interfaces services.

Types are checked as ROS 2 does (a double stays a double unless the descriptor allows dynamic
typing), with one kindness: a whole number given for a double parameter becomes a double
(``-p timer_period_s:=1``). ``on set`` callbacks can refuse a change with a reason. Every
change is published on ``/parameter_events``.
"""

from __future__ import annotations

import enum
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from rosl.node.errors import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterAlreadyDeclaredException,
    ParameterNotDeclaredException,
)


class ParameterType(enum.IntEnum):
    """rcl_interfaces ParameterType values."""

    NOT_SET = 0
    BOOL = 1
    INTEGER = 2
    DOUBLE = 3
    STRING = 4
    BYTE_ARRAY = 5
    BOOL_ARRAY = 6
    INTEGER_ARRAY = 7
    DOUBLE_ARRAY = 8
    STRING_ARRAY = 9

    @property
    def word(self) -> str:
        """ROS 2's lowercase name of the type ("double", "string array", ...)."""
        return _WORDS[self]

    @classmethod
    def from_parameter_value(cls, value: Any) -> ParameterType:
        """Infer the type of a Python value."""
        if value is None:
            return cls.NOT_SET
        if isinstance(value, bool):
            return cls.BOOL
        if isinstance(value, int):
            return cls.INTEGER
        if isinstance(value, float):
            return cls.DOUBLE
        if isinstance(value, str):
            return cls.STRING
        if isinstance(value, (bytes, bytearray)):
            return cls.BYTE_ARRAY
        if isinstance(value, (list, tuple)):
            items = list(value)
            if all(isinstance(v, bool) for v in items):
                return cls.BOOL_ARRAY if items else cls.STRING_ARRAY
            if all(isinstance(v, int) and not isinstance(v, bool) for v in items):
                return cls.INTEGER_ARRAY
            if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in items):
                return cls.DOUBLE_ARRAY
            if all(isinstance(v, str) for v in items):
                return cls.STRING_ARRAY
            if all(isinstance(v, bytes) for v in items):
                return cls.BYTE_ARRAY
        raise InvalidParameterValueException(
            f"a parameter value must be a bool, int, float, str, bytes or a list of one of "
            f"them, not {type(value).__name__} {value!r}"
        )


_WORDS = {
    ParameterType.NOT_SET: "not set",
    ParameterType.BOOL: "boolean",
    ParameterType.INTEGER: "integer",
    ParameterType.DOUBLE: "double",
    ParameterType.STRING: "string",
    ParameterType.BYTE_ARRAY: "byte array",
    ParameterType.BOOL_ARRAY: "boolean array",
    ParameterType.INTEGER_ARRAY: "integer array",
    ParameterType.DOUBLE_ARRAY: "double array",
    ParameterType.STRING_ARRAY: "string array",
}
_VALUE_FIELDS = {
    ParameterType.BOOL: "bool_value",
    ParameterType.INTEGER: "integer_value",
    ParameterType.DOUBLE: "double_value",
    ParameterType.STRING: "string_value",
    ParameterType.BYTE_ARRAY: "byte_array_value",
    ParameterType.BOOL_ARRAY: "bool_array_value",
    ParameterType.INTEGER_ARRAY: "integer_array_value",
    ParameterType.DOUBLE_ARRAY: "double_array_value",
    ParameterType.STRING_ARRAY: "string_array_value",
}


class Parameter:
    """A named, typed value (rclpy.parameter.Parameter)."""

    Type = ParameterType

    def __init__(self, name: str, type_: ParameterType | None = None, value: Any = None) -> None:
        if type_ is None:
            type_ = ParameterType.from_parameter_value(value)
        self._name = name
        self._type = ParameterType(type_)
        self._value = _normalize(self._type, value)

    @property
    def name(self) -> str:
        """The parameter's name."""
        return self._name

    @property
    def type_(self) -> ParameterType:
        """Its type."""
        return self._type

    @property
    def value(self) -> Any:
        """Its value (lists for arrays)."""
        return self._value

    def as_bool(self) -> bool:
        """The value, checked to be a bool (rclcpp's as_bool)."""
        return bool(self._as(ParameterType.BOOL))

    def as_int(self) -> int:
        """The value, checked to be an integer."""
        return int(self._as(ParameterType.INTEGER))

    def as_double(self) -> float:
        """The value, checked to be a double."""
        return float(self._as(ParameterType.DOUBLE))

    def as_string(self) -> str:
        """The value, checked to be a string."""
        return str(self._as(ParameterType.STRING))

    def as_bool_array(self) -> list[bool]:
        """The value, checked to be a bool array."""
        return list(self._as(ParameterType.BOOL_ARRAY))

    def as_integer_array(self) -> list[int]:
        """The value, checked to be an integer array."""
        return list(self._as(ParameterType.INTEGER_ARRAY))

    def as_double_array(self) -> list[float]:
        """The value, checked to be a double array."""
        return list(self._as(ParameterType.DOUBLE_ARRAY))

    def as_string_array(self) -> list[str]:
        """The value, checked to be a string array."""
        return list(self._as(ParameterType.STRING_ARRAY))

    def _as(self, wanted: ParameterType) -> Any:
        if self._type is not wanted:
            raise InvalidParameterTypeException(
                f"parameter '{self._name}' is of type {self._type.word}, not {wanted.word}"
            )
        return self._value

    def get_parameter_value(self) -> Any:
        """Return an rcl_interfaces/msg/ParameterValue."""
        from rosl.idl.registry import get_message_class

        msg = get_message_class("rcl_interfaces/msg/ParameterValue")(type=int(self._type))
        if self._type is not ParameterType.NOT_SET:
            value = self._value
            if self._type is ParameterType.BYTE_ARRAY:
                value = list(value)
            setattr(msg, _VALUE_FIELDS[self._type], value)
        return msg

    def to_parameter_msg(self) -> Any:
        """Return an rcl_interfaces/msg/Parameter."""
        from rosl.idl.registry import get_message_class

        return get_message_class("rcl_interfaces/msg/Parameter")(
            name=self._name, value=self.get_parameter_value()
        )

    @classmethod
    def from_parameter_msg(cls, msg: Any) -> Parameter:
        """Build from an rcl_interfaces/msg/Parameter."""
        return cls(msg.name, *value_from_msg(msg.value))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Parameter) and (self._name, self._type, self._value) == (
            other._name,
            other._type,
            other._value,
        )

    def __repr__(self) -> str:
        return f"Parameter(name={self._name!r}, type_={self._type.name}, value={self._value!r})"


def value_from_msg(msg: Any) -> tuple[ParameterType, Any]:
    """(type, Python value) of an rcl_interfaces/msg/ParameterValue."""
    kind = ParameterType(msg.type)
    if kind is ParameterType.NOT_SET:
        return kind, None
    value = getattr(msg, _VALUE_FIELDS[kind])
    if hasattr(value, "tolist"):
        value = value.tolist()
    if kind is ParameterType.BYTE_ARRAY:
        value = _to_bytes(value)
    return kind, value


def _to_bytes(values: Any) -> bytes:
    """A byte array as one ``bytes``: from rclpy's list of 1-byte ``bytes``, or of 0..255."""
    return b"".join(v if isinstance(v, bytes) else bytes((int(v) & 0xFF,)) for v in values)


def _normalize(kind: ParameterType, value: Any) -> Any:
    if kind in (ParameterType.BOOL_ARRAY, ParameterType.INTEGER_ARRAY, ParameterType.STRING_ARRAY):
        return list(value)
    if kind is ParameterType.DOUBLE_ARRAY:
        return [float(v) for v in value]
    if kind is ParameterType.DOUBLE and isinstance(value, int):
        return float(value)
    if kind is ParameterType.BYTE_ARRAY and isinstance(value, (list, tuple)):
        return _to_bytes(value)
    return value


@dataclass(slots=True)
class Descriptor:
    """What a parameter may hold (a plain view of rcl_interfaces/msg/ParameterDescriptor)."""

    description: str = ""
    additional_constraints: str = ""
    read_only: bool = False
    dynamic_typing: bool = False
    floating_point_range: tuple[float, float, float] | None = None  # from, to, step
    integer_range: tuple[int, int, int] | None = None

    @classmethod
    def from_msg(cls, msg: Any) -> Descriptor:
        """Build from an rcl_interfaces/msg/ParameterDescriptor (or None)."""
        if msg is None:
            return cls()
        if isinstance(msg, Descriptor):
            return msg
        fp = msg.floating_point_range[0] if msg.floating_point_range else None
        ir = msg.integer_range[0] if msg.integer_range else None
        return cls(
            msg.description,
            msg.additional_constraints,
            bool(msg.read_only),
            bool(msg.dynamic_typing),
            (fp.from_value, fp.to_value, fp.step) if fp else None,
            (ir.from_value, ir.to_value, ir.step) if ir else None,
        )

    def to_msg(self, name: str, kind: ParameterType) -> Any:
        """Return an rcl_interfaces/msg/ParameterDescriptor."""
        from rosl.idl.registry import get_message_class

        msg: Any = get_message_class("rcl_interfaces/msg/ParameterDescriptor")(
            name=name,
            type=int(kind),
            description=self.description,
            additional_constraints=self.additional_constraints,
            read_only=self.read_only,
            dynamic_typing=self.dynamic_typing,
        )
        if self.floating_point_range:
            cls = get_message_class("rcl_interfaces/msg/FloatingPointRange")
            msg.floating_point_range = [cls(*self.floating_point_range)]
        if self.integer_range:
            cls = get_message_class("rcl_interfaces/msg/IntegerRange")
            msg.integer_range = [cls(*self.integer_range)]
        return msg


@dataclass(slots=True)
class SetResult:
    """The outcome of setting one parameter (rcl_interfaces/msg/SetParametersResult)."""

    successful: bool
    reason: str = ""


Callback = Callable[[list[Parameter]], Any]


class ParameterStore:
    """The parameters of one node: declaration, typed updates, callbacks, events."""

    def __init__(
        self,
        node_name: str,
        overrides: dict[str, Any],
        on_event: Callable[[list[Parameter], list[Parameter], list[Parameter]], None],
        allow_undeclared: bool = False,
    ) -> None:
        self.node_name = node_name
        self.overrides = dict(overrides)
        self.allow_undeclared = allow_undeclared
        self._values: dict[str, Parameter] = {}
        self._descriptors: dict[str, Descriptor] = {}
        self._callbacks: list[Callback] = []
        self._pre_callbacks: list[Callback] = []
        self._post_callbacks: list[Callback] = []
        self._on_event = on_event
        self._lock = threading.RLock()
        # told when an on-set callback raises (the change then fails); None: the error propagates
        self.on_callback_error: Callable[[Exception], None] | None = None

    # --- declaration -------------------------------------------------------------------------

    def declare(
        self,
        name: str,
        value: Any = None,
        descriptor: Any = None,
        ignore_override: bool = False,
    ) -> Parameter:
        """Declare a parameter; a command-line or file override wins over ``value``."""
        with self._lock:
            if name in self._values:
                raise ParameterAlreadyDeclaredException(f"parameter '{name}' is already declared")
            desc = Descriptor.from_msg(descriptor)
            if isinstance(value, Parameter.Type):  # declare_parameter('x', Parameter.Type.DOUBLE)
                kind, initial = value, None
            else:
                initial = value
                kind = ParameterType.from_parameter_value(value)
            if not ignore_override and name in self.overrides:
                override = self.overrides[name]
                kind, initial = _coerce(
                    name, kind, ParameterType.from_parameter_value(override), override, desc
                )
            param = Parameter(name, kind, initial)
            problem = self._check_range(param, desc)
            if problem:
                raise InvalidParameterValueException(problem)
            self._descriptors[name] = desc
            self._values[name] = param
        self._on_event([param], [], [])
        return param

    def undeclare(self, name: str) -> None:
        """Remove a declared parameter."""
        with self._lock:
            if name not in self._values:
                raise ParameterNotDeclaredException(f"parameter '{name}' is not declared")
            if self._descriptors[name].read_only:
                raise InvalidParameterValueException(f"parameter '{name}' is read-only")
            param = self._values.pop(name)
            del self._descriptors[name]
        self._on_event([], [], [param])

    # --- reading -----------------------------------------------------------------------------

    def has(self, name: str) -> bool:
        """Whether ``name`` is declared."""
        return name in self._values

    def get(self, name: str) -> Parameter:
        """The parameter ``name``."""
        try:
            return self._values[name]
        except KeyError:
            if self.allow_undeclared:
                return Parameter(name, ParameterType.NOT_SET)
            raise ParameterNotDeclaredException(
                f"parameter '{name}' is not declared on node '{self.node_name}'"
            ) from None

    def names(self) -> list[str]:
        """Declared parameter names, sorted."""
        return sorted(self._values)

    def holding(self, value: object) -> list[str]:
        """Names of the number parameters whose value is ``value`` (NaN matches NaN), sorted."""
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            return []
        return [
            name
            for name, param in sorted(self._values.items())
            if param.type_ in (ParameterType.DOUBLE, ParameterType.INTEGER)
            and (param.value == value or (value != value and param.value != param.value))
        ]

    def descriptor(self, name: str) -> Descriptor:
        """The descriptor of a declared parameter."""
        self.get(name)
        return self._descriptors.get(name, Descriptor())

    # --- updates -----------------------------------------------------------------------------

    def add_callback(self, callback: Callback) -> Callback:
        """Register an on-set callback (it may refuse a change)."""
        self._callbacks.insert(0, callback)
        return callback

    def remove_callback(self, callback: Callback) -> None:
        """Unregister an on-set callback."""
        self._callbacks.remove(callback)

    def add_pre_set_callback(self, callback: Callback) -> None:
        """Register a pre-set callback: it gets the list to set and returns the list to set."""
        self._pre_callbacks.insert(0, callback)

    def remove_pre_set_callback(self, callback: Callback) -> None:
        """Unregister a pre-set callback."""
        self._pre_callbacks.remove(callback)

    def add_post_set_callback(self, callback: Callback) -> None:
        """Register a post-set callback: told the parameters once they are set."""
        self._post_callbacks.insert(0, callback)

    def remove_post_set_callback(self, callback: Callback) -> None:
        """Unregister a post-set callback."""
        self._post_callbacks.remove(callback)

    def set(self, params: Sequence[Parameter], atomically: bool = False) -> list[SetResult]:
        """Set parameters, each on its own (or all or nothing when ``atomically``).

        Pre-set callbacks may change the list first (one result per parameter of the changed
        list); post-set callbacks hear each change that was made.
        """
        with self._lock:
            for pre in list(self._pre_callbacks):
                params = list(pre(list(params)))
            if not params and self._pre_callbacks:
                return [
                    SetResult(
                        False,
                        "parameter list cannot be empty, this might be due "
                        "to pre_set_parameters_callback modifying the original "
                        "parameters list.",
                    )
                ]
            if atomically:
                checked = [self._prepare(p) for p in params]
                failure = next((r for r, _ in checked if not r.successful), None)
                if failure is None:
                    failure = self._run_callbacks([p for _, p in checked])
                if failure is not None:
                    return [failure]
                self._commit([p for _, p in checked])
                self._run_post_callbacks([p for _, p in checked])
                return [SetResult(True)]
            results = []
            for param in params:
                result, ready = self._prepare(param)
                if result.successful:
                    refused = self._run_callbacks([ready])
                    if refused is not None:
                        result = refused
                    else:
                        self._commit([ready])
                        self._run_post_callbacks([ready])
                results.append(result)
            return results

    def _run_post_callbacks(self, params: list[Parameter]) -> None:
        for callback in list(self._post_callbacks):
            callback(params)

    def _prepare(self, param: Parameter) -> tuple[SetResult, Parameter]:
        name = param.name
        if name not in self._values:
            if not self.allow_undeclared:
                return SetResult(False, f"parameter '{name}' is not declared"), param
            return SetResult(True), param
        desc = self._descriptors[name]
        if desc.read_only:
            return SetResult(False, f"Trying to set a read-only parameter: {name}."), param
        current = self._values[name]
        if param.type_ is ParameterType.NOT_SET:  # deletion (rclpy's rules and words)
            if not desc.dynamic_typing:
                return SetResult(False, "Static parameter cannot be undeclared"), param
            return SetResult(True), param
        if not (desc.dynamic_typing or _same_kind(current.type_, param)):
            return SetResult(
                False,
                f"Wrong parameter type, expected 'Type.{current.type_.name}' "
                f"got 'Type.{param.type_.name}'",
            ), param
        try:
            kind, value = _coerce(name, current.type_, param.type_, param.value, desc)
        except InvalidParameterTypeException as err:
            return SetResult(False, str(err)), param
        ready = Parameter(name, kind, value)
        problem = self._check_range(ready, desc)
        if problem:
            return SetResult(False, problem), param
        return SetResult(True), ready

    def _run_callbacks(self, params: list[Parameter]) -> SetResult | None:
        for callback in list(self._callbacks):
            try:
                result = callback(params)
            except Exception as err:  # the node's own bug: refuse the change, keep running
                if self.on_callback_error is None:
                    raise
                self.on_callback_error(err)
                return SetResult(False, f"{type(err).__name__}: {err}")
            if result is not None and not getattr(result, "successful", True):
                return SetResult(False, str(getattr(result, "reason", "")))
        return None

    def _commit(self, params: list[Parameter]) -> None:
        new: list[Parameter] = []
        changed: list[Parameter] = []
        deleted: list[Parameter] = []
        for param in params:
            if param.type_ is ParameterType.NOT_SET:
                if param.name in self._values:
                    deleted.append(self._values.pop(param.name))
                    self._descriptors.pop(param.name, None)
                continue
            (changed if param.name in self._values else new).append(param)
            self._values[param.name] = param
            self._descriptors.setdefault(param.name, Descriptor())
        self._on_event(new, changed, deleted)

    @staticmethod
    def _check_range(param: Parameter, desc: Descriptor) -> str:
        value = param.value
        if desc.floating_point_range and param.type_ is ParameterType.DOUBLE:
            low, high, _ = desc.floating_point_range
            if not low <= value <= high:
                return f"Parameter {{{param.name}}} doesn't comply with floating point range."
        if desc.integer_range and param.type_ is ParameterType.INTEGER:
            low, high, step = desc.integer_range
            if not low <= value <= high or (step and (value - low) % step):
                return f"Parameter {{{param.name}}} doesn't comply with integer range."
        return ""


def _same_kind(declared: ParameterType, param: Parameter) -> bool:
    """Whether a set keeps a statically typed parameter's type (as rclpy checks it).

    An empty list reads as a string array; it may empty any array parameter.
    """
    if declared in (param.type_, ParameterType.NOT_SET):
        return True
    empty = param.type_ is ParameterType.STRING_ARRAY and not param.value
    return empty and "ARRAY" in declared.name


def _coerce(
    name: str, declared: ParameterType, given: ParameterType, value: Any, desc: Descriptor
) -> tuple[ParameterType, Any]:
    if declared in (given, ParameterType.NOT_SET) or desc.dynamic_typing:
        return given, value
    if declared is ParameterType.DOUBLE and given is ParameterType.INTEGER:
        return declared, float(value)
    if declared is ParameterType.DOUBLE_ARRAY and given is ParameterType.INTEGER_ARRAY:
        return declared, [float(v) for v in value]
    if given is ParameterType.STRING_ARRAY and value == [] and "ARRAY" in declared.name:
        return declared, []
    raise InvalidParameterTypeException(
        f"Wrong parameter type, parameter {{{name}}} is of type {{{declared.word}}}, "
        f"setting it to {{{given.word}}} is not allowed."
    )
