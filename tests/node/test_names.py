"""Names: expansion with the node's namespace, remapping, renaming, and the errors for bad ones."""

from __future__ import annotations

import pytest

from tests.node.helpers import spin_until


def test_relative_absolute_and_private_topic_names_resolve_with_the_namespace(ros):
    from std_msgs.msg import String

    node = ros.Node("cam", namespace="/robot")
    assert node.get_namespace() == "/robot"
    assert node.get_fully_qualified_name() == "/robot/cam"
    assert node.create_publisher(String, "chatter", 10).topic_name == "/robot/chatter"
    assert node.create_publisher(String, "/chatter", 10).topic_name == "/chatter"
    assert node.create_publisher(String, "~/status", 10).topic_name == "/robot/cam/status"
    assert node.create_publisher(String, "~", 10).topic_name == "/robot/cam"
    assert node.create_publisher(String, "a/b", 10).topic_name == "/robot/a/b"
    assert node.resolve_topic_name("{node}/info") == "/robot/cam/info"
    assert node.resolve_service_name("reset") == "/robot/reset"
    assert ros.Node("plain").resolve_topic_name("chatter") == "/chatter"


def test_a_namespace_without_a_leading_slash_is_made_absolute(ros):
    node = ros.Node("n", namespace="robot/arm")
    assert node.get_namespace() == "/robot/arm"
    assert node.get_fully_qualified_name() == "/robot/arm/n"


def test_a_node_local_remap_applies_to_its_topics_and_services(ros):
    from std_msgs.msg import String

    node = ros.Node(
        "remapped",
        namespace="/ns",
        cli_args=["--ros-args", "-r", "chatter:=talk", "-r", "/abs:=/elsewhere"],
    )
    assert node.create_publisher(String, "chatter", 10).topic_name == "/ns/talk"
    assert node.create_publisher(String, "/abs", 10).topic_name == "/elsewhere"
    assert node.create_publisher(String, "untouched", 10).topic_name == "/ns/untouched"
    assert node.resolve_topic_name("chatter", only_expand=True) == "/ns/chatter"


def test_a_remap_rule_for_another_node_is_ignored(ros):
    node = ros.Node("mine", cli_args=["--ros-args", "-r", "theirs:chatter:=other"])
    assert node.resolve_topic_name("chatter") == "/chatter"
    node2 = ros.Node("theirs", cli_args=["--ros-args", "-r", "theirs:chatter:=other"])
    assert node2.resolve_topic_name("chatter") == "/other"


RENAMED = """
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node("talker")
chatter = node.create_publisher(String, "chatter", 10)
status = node.create_publisher(String, "~/status", 10)
print("fqn", node.get_fully_qualified_name(), flush=True)
print("topics", chatter.topic_name, status.topic_name, flush=True)

def tick():
    chatter.publish(String(data="on chatter"))
    status.publish(String(data="on status"))

node.create_timer(0.05, tick)
rosl.spin(node)
"""


def test_command_line_remaps_rename_the_node_its_namespace_and_its_topics(ros, spawn):
    from std_msgs.msg import String

    child = spawn(
        RENAMED,
        "--ros-args", "-r", "chatter:=other", "-r", "__node:=renamed", "-r", "__ns:=/robot1",
    )  # fmt: skip
    child.expect("^fqn /robot1/renamed$")
    child.expect("^topics /robot1/other /robot1/renamed/status$")

    node = ros.Node("observer")
    got: dict[str, str] = {}
    node.create_subscription(String, "/robot1/other", lambda m: got.update(other=m.data), 10)
    node.create_subscription(
        String, "/robot1/renamed/status", lambda m: got.update(status=m.data), 10
    )
    node.create_subscription(String, "/chatter", lambda m: got.update(chatter=m.data), 10)

    assert spin_until(node, lambda: {"other", "status"} <= set(got), 20.0), got
    assert got["other"] == "on chatter"
    assert got["status"] == "on status"
    assert "chatter" not in got
    assert spin_until(
        node, lambda: ("renamed", "/robot1") in node.get_node_names_and_namespaces(), 15.0
    )
    assert ("talker", "/") not in node.get_node_names_and_namespaces()


@pytest.mark.parametrize(
    ("name", "fragment"),
    [
        ("bad-name", "must contain only letters, digits and '_'"),
        ("1node", "must not start with a number"),
        ("has space", "must contain only letters, digits and '_'"),
        ("", "must not be empty"),
    ],
)
def test_an_invalid_node_name_raises_an_error_saying_why(ros, name, fragment):
    from rosl.node.errors import InvalidNameError

    with pytest.raises(InvalidNameError) as err:
        ros.Node(name)
    assert fragment in str(err.value)
    if name:
        assert repr(name) in str(err.value)


@pytest.mark.parametrize(
    ("topic", "fragment"),
    [
        ("a//b", "'//'"),
        ("bad name", "use only letters, digits, '_' and '/'"),
        ("trailing/", "must not end with '/'"),
        ("9lives", "a part starts with a number"),
        ("~bad", "'~' must be followed by '/'"),
        ("", "must not be empty"),
    ],
)
def test_an_invalid_topic_name_raises_an_error_saying_why(ros, topic, fragment):
    from std_msgs.msg import String

    from rosl.node.errors import InvalidNameError

    node = ros.Node("namer")
    with pytest.raises(InvalidNameError) as err:
        node.create_publisher(String, topic, 10)
    assert fragment in str(err.value)
    assert "topic" in str(err.value)
    with pytest.raises(InvalidNameError):
        node.create_subscription(String, topic, lambda m: None, 10)


def test_an_invalid_namespace_is_refused(ros):
    from rosl.node.errors import InvalidNameError

    with pytest.raises(InvalidNameError, match="namespace"):
        ros.Node("ok_name", namespace="/bad ns")


def test_unknown_ros_args_flags_are_a_clear_error(domain_id):
    import rosl
    from rosl.node.errors import RosArgsError

    with pytest.raises(RosArgsError) as err:
        rosl.init(["prog", "--ros-args", "--bogus-flag", "x"])
    assert "unknown ROS argument '--bogus-flag'" in str(err.value)
    assert "-p/--param" in str(err.value)
    assert not rosl.ok()


def test_a_ros_args_flag_without_its_value_is_a_clear_error(ros):
    from rosl.node.errors import RosArgsError

    with pytest.raises(RosArgsError, match="'-p' needs a value"):
        ros.Node("n", cli_args=["--ros-args", "-p"])
    with pytest.raises(RosArgsError, match="expected name:=value"):
        ros.Node("n", cli_args=["--ros-args", "-r", "chatter=other"])


def test_a_script_with_an_unknown_ros_arg_fails_with_the_flag_named(spawn):
    child = spawn(
        """
        import rosl
        rosl.init()
        print("should not get here", flush=True)
        """,
        "--ros-args", "--frobnicate",
    )  # fmt: skip
    out, err = child.finish()
    assert child.returncode != 0
    assert "should not get here" not in out
    assert "--frobnicate" in err
