"""The .msg/.srv parser: grammar accepted, and precise file:line:col errors."""

from __future__ import annotations

import pytest

from rosl.idl.errors import InterfaceError
from rosl.idl.parser import ArrayKind, parse_message, parse_service


def parse(text: str, name: str = "demo/msg/Thing"):
    return parse_message(text, name, "msg/Thing.msg")


def error_of(text: str) -> str:
    with pytest.raises(InterfaceError) as caught:
        parse(text)
    return str(caught.value)


def test_parser_reads_primitive_fields_in_order():
    spec = parse("int32 counter\nfloat64 value\nstring label\n")
    assert [(f.name, f.type.base) for f in spec.fields] == [
        ("counter", "int32"),
        ("value", "float64"),
        ("label", "string"),
    ]


def test_parser_reads_fixed_bounded_and_unbounded_arrays():
    spec = parse("float64[9] k\nfloat32[<=3] d\nuint8[] data\nstring<=5[2] names\n")
    kinds = [(f.type.array, f.type.size, f.type.string_bound) for f in spec.fields]
    assert kinds == [
        (ArrayKind.FIXED, 9, 0),
        (ArrayKind.BOUNDED, 3, 0),
        (ArrayKind.UNBOUNDED, 0, 0),
        (ArrayKind.FIXED, 2, 5),
    ]


def test_parser_reads_constants_with_and_without_spaces_around_equals():
    spec = parse('uint8 A=1\nint8 B = -2\nstring S="x # not a comment"\nbool FLAG=true\n')
    assert [(c.name, c.type, c.value) for c in spec.constants] == [
        ("A", "uint8", 1),
        ("B", "int8", -2),
        ("S", "string", "x # not a comment"),
        ("FLAG", "bool", True),
    ]


def test_parser_reads_default_values_for_scalars_and_arrays():
    spec = parse(
        "float64 w 1\nstring name 'bob'\nint32[3] xs [1, 2, 3]\nstring[] tags ['a,b', \"c\"]\n"
    )
    assert [f.default for f in spec.fields] == [1.0, "bob", [1, 2, 3], ["a,b", "c"]]


def test_parser_ignores_comments_and_blank_lines():
    spec = parse("# header comment\n\nint32 a  # trailing\n   # indented comment\nint32 b\n")
    assert [f.name for f in spec.fields] == ["a", "b"]


def test_parser_qualifies_same_package_and_other_package_names():
    spec = parse("Other same\ngeometry_msgs/Point p\ngeometry_msgs/msg/Point q\ntime t\n")
    assert [f.type.base for f in spec.fields] == [
        "demo/msg/Other",
        "geometry_msgs/msg/Point",
        "geometry_msgs/msg/Point",
        "builtin_interfaces/msg/Time",
    ]


def test_parser_reports_line_and_column_for_unknown_type_with_suggestion():
    assert error_of("int32 counter\nflaot64 value\n") == (
        "msg/Thing.msg:2:1: unknown type 'flaot64' (did you mean 'float64'?)"
    )


def test_parser_reports_constant_out_of_range_at_the_value():
    assert error_of("int32 a\nuint8 BIG=300\n") == (
        "msg/Thing.msg:2:11: value 300 is out of range for uint8 (0 to 255)"
    )


def test_parser_reports_negative_value_for_unsigned_constant():
    assert "out of range for uint16" in error_of("uint16 X=-1\n")


def test_parser_reports_duplicate_field_with_first_line():
    assert error_of("int32 a\nfloat64 b\nint32 a\n") == (
        "msg/Thing.msg:3:7: duplicate field 'a' (first defined on line 1)"
    )


def test_parser_reports_duplicate_constant():
    assert "duplicate constant 'X'" in error_of("int32 X=1\nint32 X=2\n")


@pytest.mark.parametrize(
    ("line", "bound"),
    [
        ("float64[0] x", "0"),
        ("float64[-3] x", "-3"),
        ("float64[abc] x", "abc"),
        ("int8[<=] x", "nothing"),
    ],
)
def test_parser_reports_bad_array_bound(line, bound):
    message = error_of(line + "\n")
    assert message.startswith("msg/Thing.msg:1:")
    assert f"bad array bound '{bound}'" in message


@pytest.mark.parametrize(
    ("line", "limit", "kind"),
    [
        ("int32[100000000000] big", 2**26, "numbers"),
        ("string[70000] names", 2**16, "strings"),
        ("geometry_msgs/Point[70000] points", 2**16, "messages"),
    ],
    ids=["numbers", "strings", "messages"],
)
def test_parser_refuses_a_fixed_array_too_large_to_construct_at_its_size(line, limit, kind):
    token = line.split()[0]
    size = token[token.index("[") + 1 : -1]
    message = error_of(f"int32 a\n{line}\n")
    assert message == (
        f"msg/Thing.msg:2:{token.index('[') + 2}: fixed array '{token}' is too large: {size} "
        f"elements, at most {limit} for {kind} (use a sequence '{token[: token.index('[')]}[]' "
        "for big data)"
    )


def test_parser_accepts_fixed_arrays_up_to_the_limits_and_any_sequence_bound():
    spec = parse(f"uint8[{2**26}] image\nstring[{2**16}] names\nint32[<=100000000000] many\n")
    assert [f.type.size for f in spec.fields] == [2**26, 2**16, 100000000000]


def test_parser_reports_bad_string_bound():
    assert "bad string bound '0'" in error_of("string<=0 s\n")


def test_parser_reports_invalid_field_and_constant_names():
    assert "invalid field name 'Value'" in error_of("float64 Value\n")
    assert "invalid constant name 'lower'" in error_of("int32 lower=1\n")


def test_parser_rejects_constants_of_message_type():
    assert "must have a primitive, non-array type" in error_of("geometry_msgs/Point P=1\n")


def test_parser_reports_a_missing_field_name():
    assert (
        error_of("float64\n") == "msg/Thing.msg:1:1: expected a field name after the type 'float64'"
    )


def test_parser_rejects_separator_in_a_message_file():
    assert "a .msg file cannot contain it" in error_of("int32 a\n---\nint32 b\n")


def test_parser_checks_default_array_lengths_and_bounded_strings():
    assert "needs exactly 3 values" in error_of("int32[3] xs [1, 2]\n")
    assert "holds at most 2 values" in error_of("int32[<=2] xs [1, 2, 3]\n")
    assert "more than its bound 2" in error_of("string<=2 s 'abc'\n")


def test_parser_rejects_a_bad_bool_and_a_bad_number():
    assert "bool value must be true, false, 1 or 0" in error_of("bool B=maybe\n")
    assert "is not a number (float64)" in error_of("float64 F=1.2.3\n")


def test_service_splits_into_request_and_response():
    spec = parse_service(
        "string folder_path\n---\nint32 count\nstring message\n", "t/srv/CountImages"
    )
    assert spec.request.type_name == "t/srv/CountImages_Request"
    assert [f.name for f in spec.request.fields] == ["folder_path"]
    assert [f.name for f in spec.response.fields] == ["count", "message"]


def test_service_with_empty_request_is_valid():
    spec = parse_service("---\nbool success\nstring message\n", "std_srvs/srv/Trigger")
    assert spec.request.fields == ()
    assert len(spec.response.fields) == 2


def test_service_response_errors_use_file_line_numbers():
    with pytest.raises(InterfaceError) as caught:
        parse_service("string a\n---\nint32 ok\nflaot32 x\n", "t/srv/S", "srv/S.srv")
    assert str(caught.value).startswith("srv/S.srv:4:1: unknown type 'flaot32'")


def test_service_with_two_separators_is_rejected_at_the_second():
    with pytest.raises(InterfaceError) as caught:
        parse_service("int32 a\n---\nint32 b\n---\nint32 c\n", "t/srv/S", "srv/S.srv")
    assert str(caught.value).startswith("srv/S.srv:4:1: more than one '---'")
    assert "first is on line 2" in str(caught.value)


def test_service_without_separator_is_rejected():
    with pytest.raises(InterfaceError, match="needs a line '---'"):
        parse_service("int32 a\n", "t/srv/S", "srv/S.srv")
