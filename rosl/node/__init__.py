"""Nodes in the rclpy style, and everything a node owns.

Node, publishers, subscriptions, timers, services, clients, action servers and clients (built
from those), parameters, clock and sim time, logging, names and ``--ros-args``; QoS: profiles,
compatibility, events and overrides; managed (lifecycle) nodes and their state machine.

Imports ``rosl.graph``, ``rosl.bus`` and ``rosl.idl``; never the CLI, launch, bag or sim.
"""
