"""CDR, message definitions and type hashes — the only module that uses rosbags' type system.

rosbags generates fast CDR (de)serializers per type; we register our parsed types and install
our own message classes before any serializer is generated, so decoding builds our classes
directly. Every rosbags error is turned into an ``InterfaceError`` naming the type or field.
"""

from __future__ import annotations

import struct
import threading
from typing import TYPE_CHECKING, Any, cast

from rosbags.interfaces import Nodetype
from rosbags.serde import SerdeError
from rosbags.typesys.store import Typestore

from rosl.idl.errors import FieldError, InterfaceError
from rosl.idl.flat_serde import flat_serializer
from rosl.idl.lazy_serde import LazyTypestore
from rosl.idl.lazy_serde import install as serde_without_eager_numpy
from rosl.idl.messages import DUMMY_FIELD, check_fields
from rosl.idl.parser import ArrayKind, FieldType
from rosl.idl.wire_view import wire_view

if TYPE_CHECKING:
    import mmap
    from collections.abc import Callable

    from rosl.idl.messages import Message
    from rosl.idl.parser import MessageSpec

_DECODE_ERRORS = (SerdeError, struct.error, ValueError, IndexError, UnicodeDecodeError)
_SERIALIZE_ERRORS = (
    struct.error,
    TypeError,
    AttributeError,
    ValueError,
    OverflowError,
    UnicodeError,
    SerdeError,
)


def _bounded_inside(cls: Any, seen: set[Any] | None = None) -> bool:
    """Whether a message nested in ``cls``'s fields has a bounded string or sequence."""
    seen = set() if seen is None else seen
    seen.add(cls)  # (each nested type is looked at once, however often it is used)
    for attr, ftype in zip(cls._fields, cls._field_types, strict=True):
        if ftype.is_primitive:
            continue
        inner = cls._field_classes[attr]
        if inner in seen:
            continue
        if any(t.string_bound or t.array is ArrayKind.BOUNDED for t in inner._field_types):
            return True
        if _bounded_inside(inner, seen):
            return True
    return False


def field_desc(ftype: FieldType) -> Any:
    """Return rosbags' field descriptor for one of our field types."""
    if ftype.is_primitive:
        inner: Any = (Nodetype.BASE, (ftype.base, ftype.string_bound))
    else:
        inner = (Nodetype.NAME, ftype.base)
    if ftype.array is ArrayKind.NONE:
        return inner
    if ftype.array is ArrayKind.FIXED:
        return (Nodetype.ARRAY, (inner, ftype.size))
    return (Nodetype.SEQUENCE, (inner, ftype.size))


def typesdict_entry(spec: MessageSpec) -> tuple[list[Any], list[Any]]:
    """Return the rosbags typesdict entry (constants, fields) for a resolved message."""
    constants = [(c.name, c.type, c.value) for c in spec.constants]
    fields = [(f.name, field_desc(f.type)) for f in spec.fields]
    if not fields:
        fields = [(DUMMY_FIELD, (Nodetype.BASE, ("uint8", 0)))]
    return constants, fields


_Serializers = tuple[
    "Callable[[Message], bytes | memoryview]",  # any message of the type
    "Callable[[Message], bytes | memoryview]",  # one of the registered class (checked before)
    "type[Message]",  # the registered class
]


class Store:
    """The process-wide registry of CDR serializers for the types in use."""

    def __init__(self) -> None:
        serde_without_eager_numpy()  # before any serializer is generated
        self._typestore: Typestore = LazyTypestore()
        self._lock = threading.Lock()
        self._checked: set[str] = set()
        self._serializers: dict[str, _Serializers] = {}
        self._schemas: dict[tuple[str, str, str], Typestore] = {}  # a recording's definitions

    def __contains__(self, type_name: str) -> bool:
        return type_name in self._typestore.fielddefs

    def add(self, spec: MessageSpec, cls: type[Message]) -> None:
        """Register a resolved message type and its class (its field types must be added)."""
        with self._lock:
            self._typestore.fielddefs[spec.type_name] = typesdict_entry(spec)
            self._typestore.types[spec.type_name] = cls
            if any(f.type.string_bound or f.type.array is ArrayKind.BOUNDED for f in spec.fields):
                self._checked.add(spec.type_name)
            self._serializers.pop(spec.type_name, None)

    def serialize(self, message: Message) -> bytes:
        """Serialize a message to CDR (little endian, with the 4-byte encapsulation header).

        Raises:
            FieldError: a field holds a value its type cannot carry; the error names it.
        """
        return bytes(self.serializer(message.__msgtype__)(message))

    def serialize_view(self, message: Message) -> memoryview:
        """Serialize as :meth:`serialize` does, as a read-only view of the new buffer.

        Saves the copy into ``bytes`` (a pass over every byte of a large message) where any
        buffer will do: sockets, files, the bus.

        Raises:
            FieldError: a field holds a value its type cannot carry; the error names it.
        """
        return memoryview(self.serializer(message.__msgtype__)(message))

    def serializer(self, type_name: str) -> Callable[[Message], bytes | memoryview]:
        """The function :meth:`serialize_view` calls for messages of ``type_name`` (made once).

        For a caller serializing one type again and again: what does not change per message
        is looked up here once, and a flat type's messages of the type's own class are packed
        by :mod:`rosl.idl.flat_serde`. The result is the CDR bytes (read-only: bytes, or a
        view of a new buffer).

        Raises:
            KeyError: ``type_name`` is not registered.
            FieldError: (from the function) a field holds a value its type cannot carry.
        """
        return self._serializers_of(type_name)[0]

    def class_serializer(self, cls: type[Message]) -> Callable[[Message], bytes | memoryview]:
        """:meth:`serializer` for messages whose class is exactly ``cls`` (the caller checks).

        A publisher checks the class anyway: for the registered class of a flat type, this is
        the flat serializer alone (with the errors named as :meth:`serialize` names them).
        """
        generic, own, registered = self._serializers_of(cls.__msgtype__)
        return own if cls is registered else generic

    def _serializers_of(self, type_name: str) -> _Serializers:
        made = self._serializers.get(type_name)
        if made is None:
            made = self._serializers[type_name] = self._make_serializers(type_name)
        return made

    def _make_serializers(self, type_name: str) -> _Serializers:
        typestore = self._typestore
        msgdef = typestore.get_msgdef(type_name)
        getsize, write = msgdef.getsize_cdr, msgdef.serialize_cdr_le
        cls = cast("type[Message]", typestore.types[type_name])
        # messages of the registered class with no byte field and no lazily empty sequence
        # anywhere inside are read by rosbags as they are (see wire_view)
        special = getattr(cls, "_has_bytes", True) or getattr(cls, "_has_sequences", True)
        plain = None if special else cls
        flat = None if plain is None else flat_serializer(cls)
        checked = type_name in self._checked or _bounded_inside(cls)

        def failed(message: Message, err: Exception) -> FieldError:
            check_fields(message)  # names the field when it can
            return FieldError(f"cannot serialize {type_name}: {err}")

        def serialize(message: Message) -> bytes | memoryview:
            if checked:
                check_fields(message)
            try:
                if type(message) is plain:
                    if flat is not None:
                        return flat(message)
                    wire = message
                else:
                    wire = wire_view(message)
                raw = memoryview(bytearray(4 + getsize(0, wire, typestore)))
                raw[1] = 1  # the encapsulation header: CDR, little endian
                write(raw[4:], 0, wire, typestore)
            except _SERIALIZE_ERRORS as err:
                raise failed(message, err) from err
            return raw.toreadonly()

        if flat is None or checked:
            return serialize, serialize, cls

        def serialize_own(message: Message) -> bytes:
            try:
                return flat(message)
            except _SERIALIZE_ERRORS as err:
                raise failed(message, err) from err

        return serialize, serialize_own, cls

    def deserialize(
        self, data: bytes | bytearray | memoryview | mmap.mmap, type_name: str
    ) -> Message:
        """Decode CDR bytes into a message of ``type_name``.

        Raises:
            InterfaceError: the bytes are not a valid ``type_name``.
        """
        try:
            # rosbags slices any buffer (its hints say bytes | memoryview), and it builds our
            # classes: add() installed them. Its arrays are views into what it is given, so it
            # gets a private copy (one memcpy): the arrays are then writable, as in rclpy, and
            # no caller's buffer is aliased. A read-only view is used as is; the message's
            # arrays copy what they keep from it (messages.array_coercer).
            if isinstance(data, memoryview) and data.readonly:
                view: memoryview = data
            else:
                view = memoryview(bytearray(data))
            return cast("Message", self._typestore.deserialize_cdr(cast("bytes", view), type_name))
        except _DECODE_ERRORS as err:
            raise InterfaceError(f"cannot decode {type_name} ({len(data)} bytes): {err}") from err

    def decoder(self, type_name: str) -> Callable[[Any], Message]:
        """:meth:`deserialize` for one registered type, made for a subscription's messages.

        The common case — a read-only view of a little-endian CDR message, as the bus
        delivers — goes straight to the type's generated function, with the checks rosbags
        makes around it; anything else, and every failure, takes :meth:`deserialize`, so the
        result and the errors are its own.
        """
        typestore, slow = self._typestore, self.deserialize
        msgdef: Any = typestore.get_msgdef(type_name)  # (its functions are made on first use)
        cls = msgdef.cls

        def decode(data: Any) -> Any:
            if type(data) is memoryview and data.readonly:
                try:
                    if data[0] == 0 and data[1] == 1:  # CDR, little endian
                        message, end = msgdef.deserialize_cdr_le(data[4:], 0, cls, typestore)
                        if end + 7 >= len(data):  # (as rosbags: at most 3 bytes of padding)
                            return message
                except _DECODE_ERRORS:
                    pass  # (the same call again raises the error)
            return slow(data, type_name)

        return decode

    def deserialize_with_schema(
        self,
        data: bytes | bytearray | memoryview | mmap.mmap,
        type_name: str,
        encoding: str,
        text: str,
    ) -> Any:
        """Decode CDR bytes with the definition a recording carries (its MCAP schema).

        ``encoding`` is ``ros2msg`` (the type's text, then each type it uses after a line of 80
        ``=`` and ``MSG: pkg/Name``, or ``pkg/msg/Name`` as older rosl wrote) or ``ros2idl``
        (sections headed ``IDL: pkg/...``). Each distinct schema gets a type store of its own,
        apart from this process's types, so two recordings may define one name differently.
        The result is a rosbags message object (fields as attributes), not one of this
        process's classes.

        Raises:
            InterfaceError: the schema cannot be read, or the bytes are not that type.
        """
        typestore = self._schema_store(type_name, encoding, text)
        try:
            return typestore.deserialize_cdr(cast("bytes", data), type_name)  # any buffer slices
        except Exception as err:  # rosbags raises several kinds for bytes that do not fit
            raise InterfaceError(
                f"cannot decode {type_name} ({len(data)} bytes) with its schema: "
                f"{type(err).__name__}: {err}"
            ) from err

    def type_hash(self, type_name: str) -> str:
        """Return the RIHS01 hash rosbags gives this type (what bags are checked against)."""
        return self._typestore.hash_rihs01(type_name)

    def ros2_type_hash(self, type_name: str) -> str:
        """Return the RIHS01 hash ROS 2's rosidl gives this type (rmw_zenoh's keys use it).

        It differs from :meth:`type_hash` only for types that hold a .msg ``char``: rosidl
        hashes it as the ``uint8`` it becomes in IDL, rosbags as FIELD_TYPE_CHAR
        (std_msgs/msg/Char, service_msgs/msg/ServiceEventInfo and so every service).
        """
        return Typestore.hash_rihs01(cast("Typestore", _Rihs01View(self._typestore)), type_name)

    def service_type_hash(self, service_type: str) -> str:
        """Return the RIHS01 hash ROS 2 gives a service type (``pkg/srv/Name``).

        ROS 2 hashes a service as a message of three fields: ``request_message``,
        ``response_message`` and ``event_message`` (``<Name>_Request``, ``_Response`` and
        ``_Event``, which must be registered).
        """
        fields = [
            (f"{part}_message", (Nodetype.NAME, f"{service_type}_{suffix}"))
            for part, suffix in (("request", "Request"), ("response", "Response"),
                                 ("event", "Event"))
        ]  # fmt: skip
        with self._lock:
            self._typestore.fielddefs[service_type] = ([], fields)  # type: ignore[assignment]
            try:
                return self.ros2_type_hash(service_type)
            finally:
                del self._typestore.fielddefs[service_type]

    def schema_type_hash(self, type_name: str, encoding: str, text: str) -> str:
        """Return the RIHS01 hash of a type as a recording's schema defines it.

        The schema is read as :meth:`deserialize_with_schema` reads it (its own type store),
        so a type this process cannot load from .msg files still gets its hash.

        Raises:
            InterfaceError: the schema cannot be read, or it does not define ``type_name``.
        """
        typestore = self._schema_store(type_name, encoding, text)
        try:
            return typestore.hash_rihs01(type_name)
        except Exception as err:  # rosbags raises several kinds for an incomplete definition
            raise InterfaceError(
                f"cannot hash {type_name} from its {encoding} schema: {type(err).__name__}: {err}"
            ) from None

    def _schema_store(self, type_name: str, encoding: str, text: str) -> Typestore:
        """The type store of one recording's schema (made once per distinct schema)."""
        key = (type_name, encoding, text)
        with self._lock:
            typestore = self._schemas.get(key)
        if typestore is None:
            typestore = _schema_typestore(type_name, encoding, text)
            with self._lock:
                typestore = self._schemas.setdefault(key, typestore)
        return typestore

    def fielddefs(self, type_name: str) -> Any:
        """Return rosbags' (constants, fields) entry for a registered type."""
        return self._typestore.fielddefs[type_name]


class _Rihs01View:
    """A type store's definitions as rosidl hashes them: ``char`` read as ``uint8``."""

    def __init__(self, typestore: Typestore) -> None:
        self.fielddefs = _CharAsUint8(typestore.fielddefs)


class _CharAsUint8(dict[str, Any]):
    def __init__(self, fielddefs: dict[str, Any]) -> None:
        super().__init__()
        self._source = fielddefs

    def __getitem__(self, type_name: str) -> Any:
        constants, fields = self._source[type_name]
        return constants, [(name, _uint8_char(desc)) for name, desc in fields]


def _uint8_char(desc: Any) -> Any:
    if desc[0] == Nodetype.BASE:
        return (Nodetype.BASE, ("uint8", 0)) if desc[1][0] == "char" else desc
    if desc[0] in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return (desc[0], (_uint8_char(desc[1][0]), desc[1][1]))
    return desc


_SECTION = "=" * 80 + "\n"


def _schema_typestore(type_name: str, encoding: str, text: str) -> Typestore:
    """A type store holding the types one MCAP schema defines."""
    from rosbags.typesys import Stores, get_types_from_idl, get_types_from_msg, get_typestore

    try:
        types: dict[str, Any] = {}
        if encoding == "ros2idl":
            parts = text.split(_SECTION)[1:] if text.startswith(_SECTION) else [text]
            for part in parts:
                types.update(
                    get_types_from_idl(part.split("\n", 1)[1] if part.startswith("IDL: ") else part)
                )
        elif encoding == "ros2msg":
            types.update(get_types_from_msg(text, type_name))
        else:
            raise InterfaceError(
                f"{type_name}: schema encoding '{encoding}' is not ros2msg or ros2idl"
            )
        typestore = get_typestore(Stores.EMPTY)
        typestore.register(types)
    except InterfaceError:
        raise
    except Exception as err:  # rosbags' parsers raise several kinds for a bad definition
        raise InterfaceError(
            f"cannot read the {encoding} schema of {type_name}: {type(err).__name__}: {err}"
        ) from None
    return typestore
