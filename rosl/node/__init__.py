"""Nodes in the rclpy style, and everything a node owns.

Node, publishers, subscriptions, timers, services, clients, action servers and clients (built
from those), parameters, clock and sim time, logging, names and ``--ros-args``.

Imports ``rosl.graph``, ``rosl.bus`` and ``rosl.idl``; never the CLI, launch, bag or sim.
"""
