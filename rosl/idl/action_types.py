"""The types rosidl generates for an action, from its goal, result and feedback.

For ``pkg/action/Name``: the service ``Name_SendGoal`` (request: ``goal_id`` and ``goal``;
response: ``accepted`` and ``stamp``), the service ``Name_GetResult`` (request: ``goal_id``;
response: ``status`` and ``result``) and the message ``Name_FeedbackMessage`` (``goal_id`` and
``feedback``) — the same fields, in the same order, as rosidl_adapter's action conversion, so
their CDR and RIHS01 hashes are ROS 2's.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rosl.idl.parser import Field, FieldType, MessageSpec, ServiceSpec

if TYPE_CHECKING:
    from rosl.idl.parser import ActionSpec

UUID = "unique_identifier_msgs/msg/UUID"
TIME = "builtin_interfaces/msg/Time"

# suffix -> the (field name, type) pairs; a type starting with '_' is the action's own part
_MESSAGES: dict[str, tuple[tuple[str, str], ...]] = {
    "_SendGoal_Request": (("goal_id", UUID), ("goal", "_Goal")),
    "_SendGoal_Response": (("accepted", "bool"), ("stamp", TIME)),
    "_GetResult_Request": (("goal_id", UUID),),
    "_GetResult_Response": (("status", "int8"), ("result", "_Result")),
    "_FeedbackMessage": (("goal_id", UUID), ("feedback", "_Feedback")),
}
SERVICES = ("_SendGoal", "_GetResult")


def derived_spec(action: ActionSpec, suffix: str) -> MessageSpec | ServiceSpec:
    """The spec of one generated type of ``action`` (``suffix`` as in ``_SendGoal``)."""
    if suffix in SERVICES:
        request = derived_spec(action, f"{suffix}_Request")
        response = derived_spec(action, f"{suffix}_Response")
        assert isinstance(request, MessageSpec)
        assert isinstance(response, MessageSpec)
        text = f"{request.text}---\n{response.text}"
        return ServiceSpec(f"{action.type_name}{suffix}", request, response, action.path, text)
    parts = {"_Goal": action.goal, "_Result": action.result, "_Feedback": action.feedback}
    if suffix in parts:
        return parts[suffix]
    fields = []
    lines = []
    for name, written in _MESSAGES[suffix]:
        base = f"{action.type_name}{written}" if written.startswith("_") else written
        fields.append(Field(name, FieldType(base), written=base))
        lines.append(f"{base.replace('/msg/', '/')} {name}")
    text = "".join(line + "\n" for line in lines)
    return MessageSpec(f"{action.type_name}{suffix}", tuple(fields), (), action.path, text)
