"""The six parameter services every node serves, so tools can read and change parameters live.

``~/get_parameters``, ``~/set_parameters``,
``~/set_parameters_atomically``, ``~/list_parameters``, ``~/describe_parameters``,
``~/get_parameter_types``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.idl.registry import get_service_class
from rosl.node.parameters import Parameter

if TYPE_CHECKING:
    from rosl.node.node import Node
    from rosl.node.parameters import ParameterStore

SEPARATOR = "."


class ParameterServices:
    """Serves one node's parameters."""

    def __init__(self, node: Node, store: ParameterStore) -> None:
        self.node = node
        self.store = store
        for name, handler in (
            ("get_parameters", self._get),
            ("get_parameter_types", self._types),
            ("set_parameters", self._set),
            ("set_parameters_atomically", self._set_atomically),
            ("list_parameters", self._list),
            ("describe_parameters", self._describe),
        ):
            srv = get_service_class(f"rcl_interfaces/srv/{_camel(name)}")
            node.create_service(srv, f"~/{name}", handler)

    def _get(self, request: Any, response: Any) -> Any:
        response.values = [
            self.store.get(n).get_parameter_value() if self.store.has(n)
            else Parameter(n).get_parameter_value()
            for n in request.names
        ]  # fmt: skip
        return response

    def _types(self, request: Any, response: Any) -> Any:
        response.types = [
            int(self.store.get(n).type_) if self.store.has(n) else 0 for n in request.names
        ]
        return response

    def _set(self, request: Any, response: Any) -> Any:
        params = [Parameter.from_parameter_msg(p) for p in request.parameters]
        results = self.store.set(params)
        response.results = self.node._results(results)
        return response

    def _set_atomically(self, request: Any, response: Any) -> Any:
        params = [Parameter.from_parameter_msg(p) for p in request.parameters]
        response.result = self.node._results(self.store.set(params, atomically=True))[0]
        return response

    def _list(self, request: Any, response: Any) -> Any:
        prefixes = list(request.prefixes)
        depth = int(request.depth)
        names = []
        for name in self.store.names():
            if prefixes and not any(name == p or name.startswith(p + SEPARATOR) for p in prefixes):
                continue
            if depth and name.count(SEPARATOR) >= depth:
                continue
            names.append(name)
        response.result.names = names
        response.result.prefixes = sorted(
            {n.rsplit(SEPARATOR, 1)[0] for n in names if SEPARATOR in n}
        )
        return response

    def _describe(self, request: Any, response: Any) -> Any:
        response.descriptors = [
            self.node.describe_parameter(n) for n in request.names if self.store.has(n)
        ]
        return response


def _camel(name: str) -> str:
    return "".join(part.capitalize() for part in name.split("_"))
