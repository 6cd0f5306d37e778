"""A client of another node's six parameter services (rclpy's AsyncParameterClient).

Each call sends one request and returns the client's Future; ``wait_for_services`` blocks
until the remote node serves all six.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from rosl.idl.registry import get_message_class, get_service_class
from rosl.node.parameter_values import parameter_dict_from_yaml_file
from rosl.node.parameters import Parameter

if TYPE_CHECKING:
    import os

    from rosl.executor import Future
    from rosl.node.callback_groups import CallbackGroup
    from rosl.node.client import Client
    from rosl.node.node import Node
    from rosl.node.qos import QoSProfile

__all__ = ["AsyncParameterClient"]

_SERVICES = (
    ("get_parameters", "GetParameters"),
    ("list_parameters", "ListParameters"),
    ("set_parameters", "SetParameters"),
    ("get_parameter_types", "GetParameterTypes"),
    ("describe_parameters", "DescribeParameters"),
    ("set_parameters_atomically", "SetParametersAtomically"),
)

Done = Callable[[Any], None] | None


class AsyncParameterClient:
    """Reads and changes the parameters of the node named ``remote_node_name``."""

    def __init__(
        self,
        node: Node,
        remote_node_name: str,
        qos_profile: QoSProfile | None = None,
        callback_group: CallbackGroup | None = None,
    ) -> None:
        self.node = node
        self.remote_node_name = remote_node_name
        self._clients: dict[str, Client] = {
            name: node.create_client(
                get_service_class(f"rcl_interfaces/srv/{type_name}"),
                f"{remote_node_name}/{name}",
                qos_profile=qos_profile,
                callback_group=callback_group,
            )
            for name, type_name in _SERVICES
        }

    def services_are_ready(self) -> bool:
        """Whether the remote node serves all six parameter services."""
        return all(client.service_is_ready() for client in self._clients.values())

    def wait_for_services(self, timeout_sec: float | None = None) -> bool:
        """Block until all six services are there (None: no limit); return whether they are."""
        deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
        for client in self._clients.values():
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            if not client.wait_for_service(timeout_sec=left):
                return False
        return True

    def _call(self, name: str, request: Any, callback: Done) -> Future[Any]:
        future = self._clients[name].call_async(request)
        if callback is not None:
            future.add_done_callback(callback)
        return future

    def _request(self, name: str) -> Any:
        return self._clients[name].srv_type.Request()

    def list_parameters(
        self, prefixes: list[str] | None = None, depth: int | None = None, callback: Done = None
    ) -> Future[Any]:
        """ListParameters with these prefixes, down to ``depth`` (None/0: unlimited)."""
        request = self._request("list_parameters")
        request.prefixes = list(prefixes or [])
        request.depth = depth or 0
        return self._call("list_parameters", request, callback)

    def _by_names(self, service: str, names: list[str], callback: Done) -> Future[Any]:
        request = self._request(service)
        request.names = list(names)
        return self._call(service, request, callback)

    def get_parameters(self, names: list[str], callback: Done = None) -> Future[Any]:
        """GetParameters of these names."""
        return self._by_names("get_parameters", names, callback)

    def get_parameter_types(self, names: list[str], callback: Done = None) -> Future[Any]:
        """GetParameterTypes of these names."""
        return self._by_names("get_parameter_types", names, callback)

    def describe_parameters(self, names: list[str], callback: Done = None) -> Future[Any]:
        """DescribeParameters of these names."""
        return self._by_names("describe_parameters", names, callback)

    def set_parameters(self, parameters: Sequence[Any], callback: Done = None) -> Future[Any]:
        """SetParameters: each a Parameter or an rcl_interfaces/msg/Parameter."""
        request = self._request("set_parameters")
        request.parameters = _messages(parameters)
        return self._call("set_parameters", request, callback)

    def set_parameters_atomically(
        self, parameters: Sequence[Any], callback: Done = None
    ) -> Future[Any]:
        """SetParametersAtomically: all of them or none."""
        request = self._request("set_parameters_atomically")
        request.parameters = _messages(parameters)
        return self._call("set_parameters_atomically", request, callback)

    def delete_parameters(self, names: list[str], callback: Done = None) -> Future[Any]:
        """Unset these parameters (a SetParameters of NOT_SET values)."""
        return self.set_parameters([Parameter(name) for name in names], callback)

    def load_parameter_file(
        self,
        parameter_file: str | os.PathLike[str],
        use_wildcard: bool = False,
        callback: Done = None,
    ) -> Future[Any]:
        """SetParameters with every parameter of a YAML parameter file."""
        return self.set_parameters(_from_file(parameter_file, use_wildcard), callback)

    def load_parameter_file_atomically(
        self,
        parameter_file: str | os.PathLike[str],
        use_wildcard: bool = False,
        callback: Done = None,
    ) -> Future[Any]:
        """SetParametersAtomically with every parameter of a YAML parameter file."""
        return self.set_parameters_atomically(_from_file(parameter_file, use_wildcard), callback)

    def on_parameter_event(
        self, callback: Callable[..., None], qos_profile: Any = None, **kwargs: Any
    ) -> Any:
        """Subscribe to /parameter_events (every node's parameter changes)."""
        from rosl.node.qos import qos_profile_parameter_events

        return self.node.create_subscription(
            get_message_class("rcl_interfaces/msg/ParameterEvent"),
            "/parameter_events",
            callback,
            qos_profile or qos_profile_parameter_events,
            **kwargs,
        )


def _messages(parameters: Sequence[Any]) -> list[Any]:
    return [p.to_parameter_msg() if isinstance(p, Parameter) else p for p in parameters]


def _from_file(parameter_file: str | os.PathLike[str], use_wildcard: bool) -> list[Any]:
    return list(parameter_dict_from_yaml_file(parameter_file, use_wildcard).values())
