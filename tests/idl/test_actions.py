"""Action types: .action parsing, rosidl's generated types and hashes, classes, imports."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from rosl.idl import registry
from rosl.idl.errors import FieldError, InterfaceError
from rosl.idl.parser import parse_action

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

FIBONACCI = "example_interfaces/action/Fibonacci"

# RIHS01 hashes ROS 2 (Jazzy) gives example_interfaces/action/Fibonacci's generated types
ROS2_HASHES = {
    "_Goal": "226cb437e4355dcd3e914f930382a3b0cc1da81545bd319ed554e95a03255f51",
    "_Result": "fea81394f25aa4502217953f1a021fb750e79c10bbd43f13dd94632da6569649",
    "_Feedback": "2b12e37361da6f408d4c85bc24a18de64333f29082f2ca34b5ee33dc4c8b42a9",
    "_SendGoal_Request": "3d088942b413247db536576f0286768c6be8fcd5d0c9a5d544f359fba090a238",
    "_SendGoal_Response": "d8c07bb3d5b766fe4b43159c9a5222af5214e2fcc29229b991d826166c512be1",
    "_GetResult_Request": "c8a4f5e7d13b81286ee1043e2ecd084281cecf1ff06aaa799464f5f15479f003",
    "_GetResult_Response": "6021dc98ab9b4bbe395e48aa4de81ee5f68eb570f88358affcc648146668b24f",
    "_FeedbackMessage": "c1de71afd52e49a89c53d8262366884185bc0a02f78ce051c4e46b0a7fe59bb2",
}


def test_an_action_parses_into_goal_result_and_feedback() -> None:
    spec = parse_action("int32 a\n---\n# r\nstring b\n---\nfloat64 c\n", "p/action/A")

    assert [f.name for f in spec.goal.fields] == ["a"]
    assert [f.name for f in spec.result.fields] == ["b"]
    assert [f.name for f in spec.feedback.fields] == ["c"]
    assert spec.result.type_name == "p/action/A_Result"
    assert spec.feedback.fields[0].line == 6  # its line in the file


@pytest.mark.parametrize(
    ("text", "where", "words"),
    [
        ("int32 a\nint32 b\n", "A.action:2:", "this file has no '---' line"),
        ("int32 a\n---\nint32 b\n", "A.action:3:", "this file has one '---' (line 2)"),
        ("a\n---\n---\n---\n", "A.action:4:1:", "more than two '---'"),
        ("int32 a\n---\n---\nfloat65 c\n", "A.action:4:1:", "unknown type 'float65'"),
    ],
    ids=["no-separator", "one-separator", "three-separators", "bad-feedback-line"],
)
def test_a_malformed_action_names_the_file_and_line(
    tmp_path: Path, text: str, where: str, words: str
) -> None:
    path = tmp_path / "A.action"
    with pytest.raises(InterfaceError) as caught:
        parse_action(text, "p/action/A", path)

    assert str(caught.value).startswith(str(path).rsplit("/", 1)[0])
    assert where in str(caught.value)
    assert words in str(caught.value)
    assert "\n" not in str(caught.value)


def test_a_bad_action_file_in_a_package_fails_in_one_line_at_import(
    make_package: Callable[..., Path],
) -> None:
    make_package("demo_actions", {"action/Move.action": "int32 x\n---\nint32 y\n"})

    with pytest.raises(InterfaceError, match=r"Move\.action:3: an action has three parts"):
        registry.get_action_class("demo_actions/action/Move")


def test_generated_types_hash_as_in_ros2() -> None:
    registry.get_action_class(FIBONACCI)
    store = registry.store()

    for suffix, digest in ROS2_HASHES.items():
        assert store.type_hash(FIBONACCI + suffix) == f"RIHS01_{digest}", suffix


def test_the_action_class_has_rosidl_pythons_attributes() -> None:
    from example_interfaces.action import Fibonacci

    impl = Fibonacci.Impl
    assert Fibonacci.Goal(order=3).order == 3
    assert Fibonacci.Goal.__msgtype__ == f"{FIBONACCI}_Goal"
    assert Fibonacci.Result.__msgtype__ == f"{FIBONACCI}_Result"
    assert Fibonacci.Feedback.__msgtype__ == f"{FIBONACCI}_Feedback"
    assert impl.SendGoalService.__srvtype__ == f"{FIBONACCI}_SendGoal"
    assert impl.GetResultService.__srvtype__ == f"{FIBONACCI}_GetResult"
    assert impl.FeedbackMessage.__msgtype__ == f"{FIBONACCI}_FeedbackMessage"
    assert impl.CancelGoalService.__srvtype__ == "action_msgs/srv/CancelGoal"
    assert impl.GoalStatusMessage.__msgtype__ == "action_msgs/msg/GoalStatusArray"
    assert list(impl.SendGoalService.Request.get_fields_and_field_types()) == ["goal_id", "goal"]
    assert impl.SendGoalService.Response.get_fields_and_field_types() == {
        "accepted": "bool", "stamp": "builtin_interfaces/msg/Time"
    }  # fmt: skip
    assert list(impl.GetResultService.Response.get_fields_and_field_types()) == [
        "status", "result"
    ]  # fmt: skip
    assert repr(Fibonacci.Goal(order=2)) == "example_interfaces.action.Fibonacci_Goal(order=2)"
    with pytest.raises(NotImplementedError):
        Fibonacci()


def test_generated_messages_round_trip_through_cdr() -> None:
    from example_interfaces.action import Fibonacci

    message = Fibonacci.Impl.FeedbackMessage()
    message.goal_id.uuid = bytes(range(16))
    message.feedback.sequence = [0, 1, 1, 2]
    store = registry.store()

    back = store.deserialize(store.serialize(message), message.__msgtype__)

    assert back == message
    assert list(back.feedback.sequence) == [0, 1, 1, 2]


def test_a_sequence_field_grows_like_rclpys_array() -> None:
    from example_interfaces.action import Fibonacci

    feedback = Fibonacci.Feedback()
    feedback.sequence = [0, 1]
    for i in range(1, 5):
        feedback.sequence.append(feedback.sequence[i] + feedback.sequence[i - 1])
    feedback.sequence.extend([13, 21])
    feedback.sequence.insert(0, -1)

    assert feedback.sequence.pop(0) == -1
    assert list(feedback.sequence) == [0, 1, 1, 2, 3, 5, 13, 21]
    assert all(type(v) is int for v in feedback.sequence)
    assert str(feedback.sequence) == "array('i', [0, 1, 1, 2, 3, 5, 13, 21])"
    with pytest.raises(FieldError, match="int32"):
        feedback.sequence.append(1.5)
    with pytest.raises(FieldError, match="slice"):
        feedback.sequence[1:].append(1)


def test_a_copied_message_grows_its_own_sequence() -> None:
    import copy

    from example_interfaces.action import Fibonacci

    original = Fibonacci.Feedback(sequence=[0, 1])
    shallow, deep = copy.copy(original), copy.deepcopy(original)
    shallow.sequence.append(2)
    deep.sequence.append(3)
    original.sequence.append(4)

    assert [list(m.sequence) for m in (original, shallow, deep)] == [
        [0, 1, 4],
        [0, 1, 2],
        [0, 1, 3],
    ]


def test_an_unknown_action_names_the_closest() -> None:
    with pytest.raises(InterfaceError, match="did you mean 'Fibonacci'"):
        registry.get_action_class("example_interfaces/action/Fibonaci")
