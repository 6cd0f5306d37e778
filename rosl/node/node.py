"""Node: rclpy's names and factories; the work lives in the modules it delegates to.

A node owns its name and namespace, its endpoints (publishers, subscriptions, timers,
services, clients), its ParameterStore, clock and logger. Graph queries go to the process's
discovery cache.
"""

from __future__ import annotations

import itertools
import sys
import traceback
import weakref
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.graph.records import PUBLISHER, SUBSCRIPTION, NodeRecord
from rosl.idl.base import Message, ServiceType
from rosl.node import names
from rosl.node.callback_groups import CallbackGroup, MutuallyExclusiveCallbackGroup
from rosl.node.clock import NS, Clock, ClockType, Duration
from rosl.node.context import Context, default_context
from rosl.node.logging import Logger
from rosl.node.parameters import Parameter, ParameterStore, ParameterType
from rosl.node.qos import (
    QoSProfile,
    as_profile,
    qos_profile_parameter_events,
    qos_profile_rosout_default,
    qos_profile_sensor_data,
)

_ROSL_DIR = str(Path(__file__).resolve().parent.parent)

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator, Sequence

    from rosl.executor import Executor
    from rosl.node.callback_groups import Executable
    from rosl.node.client import Client
    from rosl.node.guard_condition import GuardCondition
    from rosl.node.participant import Participant
    from rosl.node.publisher import Publisher
    from rosl.node.qos_overrides import QoSOverridingOptions
    from rosl.node.qos_watch import QoSWatch
    from rosl.node.service import Service
    from rosl.node.subscription import Subscription
    from rosl.node.timer import Rate, Timer
    from rosl.node.waitable import Waitable


class Node:
    """A ROS node (rclpy.node.Node)."""

    def __init__(
        self,
        node_name: str,
        *,
        context: Context | None = None,
        cli_args: list[str] | None = None,
        namespace: str | None = None,
        use_global_arguments: bool = True,
        enable_rosout: bool = True,
        start_parameter_services: bool = True,
        parameter_overrides: list[Parameter] | None = None,
        allow_undeclared_parameters: bool = False,
        automatically_declare_parameters_from_overrides: bool = False,
    ) -> None:
        from rosl.node import ros_args

        self.context = context or default_context
        self.participant: Participant = self.context.ensure_participant()
        local = ros_args.parse(cli_args) if cli_args else ros_args.RosArgs()
        global_args = self.context.args if use_global_arguments else ros_args.RosArgs()
        self._remaps = [*local.remaps, *global_args.remaps]
        name = local.node_name(global_args.node_name(node_name))
        self._name = names.validate_node_name(name)
        ns = local.namespace(global_args.namespace(namespace, node_name), node_name)
        self._namespace = names.validate_namespace(ns or "/")
        self.publishers: list[Publisher] = []
        self.subscriptions: list[Subscription] = []
        self.timers: list[Timer] = []
        self.services: list[Service] = []
        self.clients: list[Client] = []
        self.guards: list[GuardCondition] = []
        self.waitables: list[Waitable] = []
        self.default_callback_group: CallbackGroup = MutuallyExclusiveCallbackGroup()
        self.callback_groups: list[CallbackGroup] = [self.default_callback_group]
        self._executor: weakref.ref[Executor] | None = None
        self._destroyed = False
        self._clock = Clock(clock_type=ClockType.ROS_TIME)
        self._clock_subscription: Subscription | None = None
        self._rosout: Publisher | None = None
        logger_name = ".".join([*self._namespace.strip("/").split("/"), self._name]).strip(".")
        self._logger = Logger(logger_name, self._to_rosout)
        overrides = {**global_args.overrides(self.fully_qualified),
                     **local.overrides(self.fully_qualified)}  # fmt: skip
        overrides.update({p.name: p.value for p in parameter_overrides or []})
        self._parameters = ParameterStore(
            self._name, overrides, self._parameter_event, allow_undeclared_parameters
        )
        self._events: Publisher | None = None
        self._qos_watch: QoSWatch | None = None  # QoS events (rosl/node/qos_watch.py)
        self.index = self.participant.add_node(self.record)
        self.context.nodes.append(self)
        if enable_rosout and global_args.enable_rosout:
            self._rosout = self._publisher_for(
                "rcl_interfaces/msg/Log", "/rosout", qos_profile_rosout_default
            )
        self._events = self._publisher_for(
            "rcl_interfaces/msg/ParameterEvent", "/parameter_events", qos_profile_parameter_events
        )
        self._parameters.on_callback_error = lambda err: self._callback_failed(
            err, "on_set_parameters"
        )
        self._parameters.add_callback(self._on_use_sim_time)
        sim_time = self.declare_parameter("use_sim_time", False)
        self._set_sim_time(sim_time.type_ is ParameterType.BOOL and bool(sim_time.value))
        if automatically_declare_parameters_from_overrides:
            for key, value in overrides.items():
                if not self.has_parameter(key):
                    self.declare_parameter(key, value)
        if start_parameter_services:
            from rosl.node.parameter_services import ParameterServices

            self._parameter_services = ParameterServices(self, self._parameters)
        self.participant.discovery.changed()
        self._name_check = self.create_timer(0.5, self._check_duplicate_name)
        self._name_check._internal = True

    # --- names -------------------------------------------------------------------------------

    def get_name(self) -> str:
        """The node's name."""
        return self._name

    def get_namespace(self) -> str:
        """The node's namespace (``/`` at the root)."""
        return self._namespace

    def get_fully_qualified_name(self) -> str:
        """``/namespace/name``."""
        return self.fully_qualified

    @property
    def fully_qualified(self) -> str:
        """``/namespace/name``."""
        return names.fully_qualified(self._namespace, self._name)

    @property
    def name(self) -> str:
        """The node's name."""
        return self._name

    def resolve_topic_name(self, topic: str, *, only_expand: bool = False) -> str:
        """Expand a topic name and apply remap rules."""
        full = names.expand(topic, self._name, self._namespace, "topic")
        return full if only_expand else names.remap(full, self._remaps, self._name, self._namespace)

    def resolve_service_name(self, service: str, *, only_expand: bool = False) -> str:
        """Expand a service name and apply remap rules."""
        full = names.expand(service, self._name, self._namespace, "service")
        return full if only_expand else names.remap(full, self._remaps, self._name, self._namespace)

    # --- endpoints ---------------------------------------------------------------------------

    def create_publisher(
        self,
        msg_type: type[Message],
        topic: str,
        qos_profile: QoSProfile | int,
        *,
        callback_group: Any = None,
        event_callbacks: Any = None,
        qos_overriding_options: QoSOverridingOptions | None = None,
        coalesce: bool | None = None,
        publisher_class: type[Publisher] | None = None,
    ) -> Publisher:
        """Create a publisher of ``msg_type`` on ``topic`` (relative names use the namespace).

        ``coalesce=True`` batches small messages into shared datagrams, each at most 1 ms late
        (default: the ``ROSL_COALESCE`` environment variable, else off). ``publisher_class``
        (a subclass of Publisher, as rclpy.lifecycle's LifecyclePublisher) builds the publisher.
        """
        from rosl.node.publisher import Publisher
        from rosl.node.qos_overrides import overridden
        from rosl.node.qos_watch import watch

        del callback_group
        name = self.resolve_topic_name(topic)
        profile = as_profile(qos_profile)
        profile = overridden(self, "publisher", name, profile, qos_overriding_options)
        publisher = (publisher_class or Publisher)(
            self, _message_class(msg_type), name, profile, coalesce
        )
        watch(self).add_publisher(publisher, event_callbacks)
        self.publishers.append(publisher)
        self.participant.discovery.changed()
        return publisher

    def create_subscription(
        self,
        msg_type: type[Message],
        topic: str,
        callback: Callable[..., Any],
        qos_profile: QoSProfile | int = 10,
        *,
        callback_group: CallbackGroup | None = None,
        event_callbacks: Any = None,
        qos_overriding_options: QoSOverridingOptions | None = None,
        raw: bool = False,
    ) -> Subscription:
        """Call ``callback(msg)`` for each message on ``topic``."""
        from rosl.node.qos_overrides import overridden
        from rosl.node.qos_watch import watch
        from rosl.node.subscription import Subscription

        name = self.resolve_topic_name(topic)
        profile = as_profile(qos_profile)
        profile = overridden(self, "subscription", name, profile, qos_overriding_options)
        subscription = Subscription(self, _message_class(msg_type), name, callback, profile, raw)
        watch(self).add_subscription(subscription, event_callbacks)
        self._join(subscription, callback_group)
        self.subscriptions.append(subscription)
        self.participant.discovery.changed()
        return subscription

    def create_timer(
        self,
        timer_period_sec: float,
        callback: Callable[[], Any] | None,
        callback_group: CallbackGroup | None = None,
        clock: Clock | None = None,
    ) -> Timer:
        """Call ``callback`` every ``timer_period_sec`` seconds of this node's clock.

        Raises:
            TimerPeriodError: the period is not a finite number of seconds > 0 (a parameter
                holding that value is named).
        """
        from rosl.node.errors import TimerPeriodError
        from rosl.node.timer import Timer, seconds_to_period_ns

        try:
            period = seconds_to_period_ns(timer_period_sec)
        except TimerPeriodError as err:
            held = self._parameters.holding(timer_period_sec)
            hint = f" (the value of parameter '{held[0]}')" if len(held) == 1 else ""
            raise TimerPeriodError(f"{err}{hint}") from None
        timer = Timer(callback, period, clock or self._clock, self.participant.notify)
        self._join(timer, callback_group)
        self.timers.append(timer)
        self.participant.notify()
        return timer

    def create_rate(self, frequency: float, clock: Clock | None = None) -> Rate:
        """A Rate that sleeps on this node's clock."""
        from rosl.node.timer import Rate

        return Rate(frequency, clock or self._clock)

    def create_service(
        self,
        srv_type: type[ServiceType],
        srv_name: str,
        callback: Callable[[Any, Any], Any],
        *,
        qos_profile: QoSProfile | None = None,
        callback_group: CallbackGroup | None = None,
    ) -> Service:
        """Serve ``srv_name``: ``callback(request, response)`` returns the response."""
        from rosl.node.service import Service

        del qos_profile
        service = Service(
            self, _service_class(srv_type), self.resolve_service_name(srv_name), callback
        )
        self._join(service, callback_group)
        self.services.append(service)
        self.participant.discovery.changed()
        return service

    def create_client(
        self,
        srv_type: type[ServiceType],
        srv_name: str,
        *,
        qos_profile: QoSProfile | None = None,
        callback_group: CallbackGroup | None = None,
    ) -> Client:
        """A client of ``srv_name``."""
        from rosl.node.client import Client

        del qos_profile
        client = Client(self, _service_class(srv_type), self.resolve_service_name(srv_name))
        self._join(client, callback_group)
        self.clients.append(client)
        self.participant.discovery.changed()
        return client

    def create_guard_condition(
        self, callback: Callable[[], Any], callback_group: CallbackGroup | None = None
    ) -> GuardCondition:
        """A guard condition: ``trigger()`` (any thread) makes the executor run ``callback``."""
        from rosl.node.guard_condition import GuardCondition

        guard = GuardCondition(callback, None, self.context)
        self._join(guard, callback_group)
        self.guards.append(guard)
        return guard

    def destroy_guard_condition(self, guard: GuardCondition) -> bool:
        """Remove a guard condition."""
        guard.destroy()
        if guard not in self.guards:
            return False
        self.guards.remove(guard)
        return True

    def add_waitable(self, waitable: Waitable) -> None:
        """Let this node's executor run ``waitable``."""
        if waitable.callback_group is None:
            self._join(waitable, None)
        self.waitables.append(waitable)
        self.participant.notify()

    def remove_waitable(self, waitable: Waitable) -> None:
        """Stop running ``waitable``."""
        if waitable in self.waitables:
            self.waitables.remove(waitable)

    def _join(self, entity: Executable, group: CallbackGroup | None) -> None:
        chosen = group if group is not None else self.default_callback_group
        entity._join(chosen)
        if chosen not in self.callback_groups:
            self.callback_groups.append(chosen)

    def _entities(self) -> Iterator[Executable]:
        """What an executor looks at, in rclpy's order."""
        return itertools.chain(
            self.waitables, self.timers, self.subscriptions, self.guards, self.clients,
            self.services,
        )  # fmt: skip

    @property
    def executor(self) -> Executor | None:
        """The executor running this node's callbacks (setting it moves the node there)."""
        return None if self._executor is None else self._executor()

    @executor.setter
    def executor(self, executor: Executor | None) -> None:
        current = self.executor
        if current is executor:
            return
        self._executor = None if executor is None else weakref.ref(executor)
        if current is not None:
            current.remove_node(self)
        if executor is not None:
            executor.add_node(self)

    def _publisher_for(self, type_name: str, topic: str, qos: QoSProfile) -> Publisher:
        from rosl.idl.registry import get_message_class

        return self.create_publisher(get_message_class(type_name), topic, qos)

    def assert_liveliness(self) -> None:
        """Assert the liveliness of this node's manual-by-node publishers."""
        from rosl.node.qos import LivelinessPolicy

        for publisher in self.publishers:
            if publisher.qos_profile.liveliness is LivelinessPolicy.MANUAL_BY_NODE:
                publisher.assert_liveliness()

    def destroy_publisher(self, publisher: Publisher) -> bool:
        """Remove a publisher (sending what it still holds); False if it is not this node's."""
        if publisher not in self.publishers:
            return False
        publisher.flush()
        self.participant.remove_replayer(publisher.topic, publisher)
        drop = getattr(self.participant.transport, "drop_history", None)
        if drop is not None and publisher.qos_profile.keeps_history:  # Zenoh's cache of it
            drop(publisher._writer.topic)
        if publisher._writer in self.participant.writers:
            self.participant.writers.remove(publisher._writer)
        publisher._writer.close()  # its shared-memory ring, if it made one
        return self._remove(self.publishers, publisher)

    def destroy_subscription(self, subscription: Subscription) -> bool:
        """Remove a subscription; False if it is not this node's."""
        if subscription not in self.subscriptions:
            return False
        subscription.close()
        return self._remove(self.subscriptions, subscription)

    def destroy_timer(self, timer: Timer) -> bool:
        """Remove a timer; False if it is not this node's (None, or destroyed before)."""
        if timer not in self.timers:
            return False
        timer.destroy()
        return self._remove(self.timers, timer)

    def destroy_service(self, service: Service) -> bool:
        """Remove a service server; False if it is not this node's."""
        if service not in self.services:
            return False
        service.close()
        return self._remove(self.services, service)

    def destroy_client(self, client: Client) -> bool:
        """Remove a service client; False if it is not this node's."""
        if client not in self.clients:
            return False
        client.close()
        return self._remove(self.clients, client)

    def _remove(self, items: list[Any], item: Any) -> bool:
        if item not in items:
            return False
        items.remove(item)
        item.destroyed = True
        self.participant.discovery.changed()
        return True

    def destroy_node(self) -> None:
        """Remove the node from the graph (idempotent)."""
        if self._destroyed:
            return
        self._destroyed = True
        for subscription in list(self.subscriptions):
            subscription.close()
        for service in list(self.services):
            service.close()
        for client in list(self.clients):
            client.close()
        for timer in self.timers:
            timer.destroy()
        for guard in self.guards:
            guard.destroy()
        for publisher in self.publishers:
            self.participant.remove_replayer(publisher.topic, publisher)
        self.participant.remove_node(self.index)
        self.executor = None
        if self in self.context.nodes:
            self.context.nodes.remove(self)

    # --- logging, clock ----------------------------------------------------------------------

    def get_logger(self) -> Logger:
        """The node's logger (also publishes to /rosout)."""
        return self._logger

    def get_clock(self) -> Clock:
        """The node's ROS-time clock (sim time when ``use_sim_time`` is true)."""
        return self._clock

    def _to_rosout(
        self, level: int, name: str, message: str, file: str, function: str, line: int
    ) -> None:
        if self._rosout is None or self._destroyed:
            return
        from rosl.idl.registry import get_message_class

        log = get_message_class("rcl_interfaces/msg/Log")(
            stamp=self._clock.now().to_msg(), level=int(level), name=name, msg=message,
            file=file, function=function, line=int(line),
        )  # fmt: skip
        self._rosout.publish(log)

    def _on_use_sim_time(self, params: list[Parameter]) -> Any:
        for param in params:
            if param.name == "use_sim_time":
                self._set_sim_time(param.type_ is ParameterType.BOOL and bool(param.value))
        return None

    def _set_sim_time(self, active: bool) -> None:
        if active == self._clock.ros_time_is_active:
            return
        self._clock.set_sim_time(active)
        for timer in self.timers:
            timer.reset()
        if active and self._clock_subscription is None:
            from rosl.idl.registry import get_message_class

            clock_type = get_message_class("rosgraph_msgs/msg/Clock")
            self._clock_subscription = self.create_subscription(
                clock_type, "/clock", self._on_clock, qos_profile_sensor_data
            )
        elif not active and self._clock_subscription is not None:
            self.destroy_subscription(self._clock_subscription)
            self._clock_subscription = None

    def _on_clock(self, msg: Any) -> None:
        self._clock.set_sim_now(msg.clock.sec * NS + msg.clock.nanosec)

    # --- callbacks ---------------------------------------------------------------------------

    def _callback_failed(self, err: Exception, what: str) -> None:
        """Log a user callback's exception and its line (re-raised in ``raise`` mode)."""
        if self.context.callback_errors == "raise":
            raise err
        every = traceback.extract_tb(err.__traceback__)
        frames = [f for f in every if not f.filename.startswith(_ROSL_DIR)] or every
        where = frames[-1]
        self._logger.error(
            f"exception in callback for {what}: {type(err).__name__}: {err} "
            f"(at {where.filename}:{where.lineno} in {where.name}); the node keeps running"
        )
        lines = traceback.format_list(frames) + traceback.format_exception_only(err)
        sys.stderr.write("Traceback (most recent call last):\n" + "".join(lines))

    def _check_duplicate_name(self) -> None:
        self.destroy_timer(self._name_check)
        twins = [n for n in self.participant.graph.find_node(self.fully_qualified)
                 if n.key != (self.participant.sender, self.index)]  # fmt: skip
        if twins:
            self._logger.warn(
                f"another node is also named {self.fully_qualified}; names should be unique "
                "or tools will mix them up"
            )

    # --- parameters --------------------------------------------------------------------------

    def declare_parameter(
        self,
        name: str,
        value: Any = None,
        descriptor: Any = None,
        ignore_override: bool = False,
    ) -> Parameter:
        """Declare a parameter (a ``--ros-args -p`` or params-file value wins)."""
        return self._parameters.declare(name, value, descriptor, ignore_override)

    def declare_parameters(
        self, namespace: str, parameters: Sequence[tuple[Any, ...]], ignore_override: bool = False
    ) -> list[Parameter]:
        """Declare several: ``[(name, value), (name, value, descriptor), ...]``."""
        declared = []
        for entry in parameters:
            name = f"{namespace}.{entry[0]}" if namespace else entry[0]
            value = entry[1] if len(entry) > 1 else None
            descriptor = entry[2] if len(entry) > 2 else None
            declared.append(self.declare_parameter(name, value, descriptor, ignore_override))
        return declared

    def undeclare_parameter(self, name: str) -> None:
        """Remove a declared parameter."""
        self._parameters.undeclare(name)

    def has_parameter(self, name: str) -> bool:
        """Whether ``name`` is declared."""
        return self._parameters.has(name)

    def get_parameter(self, name: str) -> Parameter:
        """A declared parameter."""
        return self._parameters.get(name)

    def get_parameter_or(self, name: str, alternative_value: Parameter | None = None) -> Parameter:
        """A parameter, or ``alternative_value`` when not declared."""
        if self._parameters.has(name):
            return self._parameters.get(name)
        return alternative_value or Parameter(name, ParameterType.NOT_SET)

    def get_parameters(self, names_: Sequence[str]) -> list[Parameter]:
        """Several declared parameters."""
        return [self.get_parameter(n) for n in names_]

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Parameter]:
        """Parameters under ``prefix.``, keyed by the rest of their names."""
        start = f"{prefix}." if prefix else ""
        return {
            n[len(start) :]: self._parameters.get(n)
            for n in self._parameters.names()
            if n.startswith(start)
        }

    def set_parameters(self, parameter_list: Sequence[Parameter]) -> list[Any]:
        """Set parameters one by one; return a SetParametersResult for each."""
        return self._results(self._parameters.set(parameter_list))

    def set_parameters_atomically(self, parameter_list: Sequence[Parameter]) -> Any:
        """Set all or none."""
        return self._results(self._parameters.set(parameter_list, atomically=True))[0]

    def add_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> Any:
        """Register a callback that may refuse parameter changes (returns SetParametersResult)."""
        return self._parameters.add_callback(callback)

    def remove_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        """Unregister such a callback."""
        self._parameters.remove_callback(callback)

    def add_pre_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], list[Parameter]]
    ) -> None:
        """Register a callback that may change the list of parameters about to be set."""
        self._parameters.add_pre_set_callback(callback)

    def remove_pre_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], list[Parameter]]
    ) -> None:
        """Unregister such a callback."""
        self._parameters.remove_pre_set_callback(callback)

    def add_post_set_parameters_callback(self, callback: Callable[[list[Parameter]], None]) -> None:
        """Register a callback told of the parameters once they were set."""
        self._parameters.add_post_set_callback(callback)

    def remove_post_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], None]
    ) -> None:
        """Unregister such a callback."""
        self._parameters.remove_post_set_callback(callback)

    def describe_parameter(self, name: str) -> Any:
        """An rcl_interfaces/msg/ParameterDescriptor."""
        return self._parameters.descriptor(name).to_msg(name, self.get_parameter(name).type_)

    def describe_parameters(self, names_: Sequence[str]) -> list[Any]:
        """Descriptors of several parameters."""
        return [self.describe_parameter(n) for n in names_]

    @staticmethod
    def _results(results: Sequence[Any]) -> list[Any]:
        from rosl.idl.registry import get_message_class

        cls = get_message_class("rcl_interfaces/msg/SetParametersResult")
        return [cls(successful=r.successful, reason=r.reason) for r in results]

    def _parameter_event(
        self, new: list[Parameter], changed: list[Parameter], deleted: list[Parameter]
    ) -> None:
        if self._events is None or self._destroyed:
            return
        from rosl.idl.registry import get_message_class

        event = get_message_class("rcl_interfaces/msg/ParameterEvent")(
            stamp=self._clock.now().to_msg(),
            node=self.fully_qualified,
            new_parameters=[p.to_parameter_msg() for p in new],
            changed_parameters=[p.to_parameter_msg() for p in changed],
            deleted_parameters=[p.to_parameter_msg() for p in deleted],
        )
        self._events.publish(event)

    # --- graph -------------------------------------------------------------------------------

    def record(self) -> NodeRecord:
        """This node as discovery announces it."""
        entities: list[Publisher | Subscription | Service | Client] = [
            *self.publishers, *self.subscriptions, *self.services, *self.clients
        ]  # fmt: skip
        endpoints = [e.record() for e in entities if not e.destroyed]
        return NodeRecord(
            self._name, self._namespace, self.participant.sender, self.index, tuple(endpoints)
        )

    def count_publishers(self, topic_name: str) -> int:
        """Publishers on a topic in the graph."""
        return self.participant.graph.count(PUBLISHER, self.resolve_topic_name(topic_name))

    def count_subscribers(self, topic_name: str) -> int:
        """Subscriptions on a topic in the graph."""
        return self.participant.graph.count(SUBSCRIPTION, self.resolve_topic_name(topic_name))

    def get_topic_names_and_types(self, no_demangle: bool = False) -> list[tuple[str, list[str]]]:
        """Every topic in the graph with its types."""
        del no_demangle
        return list(self.participant.graph.topics().items())

    def get_service_names_and_types(self) -> list[tuple[str, list[str]]]:
        """Every service in the graph with its types."""
        return list(self.participant.graph.services().items())

    def get_node_names(self) -> list[str]:
        """Names of the nodes in the graph."""
        return [n.name for n in self.participant.graph.nodes()]

    def get_node_names_and_namespaces(self) -> list[tuple[str, str]]:
        """(name, namespace) of the nodes in the graph."""
        return [(n.name, n.namespace) for n in self.participant.graph.nodes()]

    def get_publishers_info_by_topic(self, topic_name: str) -> list[Any]:
        """Endpoint records of a topic's publishers."""
        return self.participant.graph.endpoints(PUBLISHER, self.resolve_topic_name(topic_name))

    def get_subscriptions_info_by_topic(self, topic_name: str) -> list[Any]:
        """Endpoint records of a topic's subscriptions."""
        return self.participant.graph.endpoints(SUBSCRIPTION, self.resolve_topic_name(topic_name))

    def wait_for_node(self, fully_qualified_node_name: str, timeout: float) -> bool:
        """Block until a node with that name is in the graph."""
        graph = self.participant.graph
        return graph.wait_for(lambda: bool(graph.find_node(fully_qualified_node_name)), timeout)

    def __repr__(self) -> str:
        return f"<rosl Node {self.fully_qualified}>"


def _message_class(msg_type: Any) -> type[Message]:
    if isinstance(msg_type, str):
        from rosl.idl.registry import get_message_class

        return get_message_class(msg_type)
    if not (isinstance(msg_type, type) and issubclass(msg_type, Message)):
        raise TypeError(f"expected a message class such as std_msgs.msg.String, got {msg_type!r}")
    return msg_type


def _service_class(srv_type: Any) -> type[ServiceType]:
    if isinstance(srv_type, str):
        from rosl.idl.registry import get_service_class

        return get_service_class(srv_type)
    if not (isinstance(srv_type, type) and issubclass(srv_type, ServiceType)):
        raise TypeError(f"expected a service class such as std_srvs.srv.Trigger, got {srv_type!r}")
    return srv_type


__all__ = ["Duration", "Node"]
