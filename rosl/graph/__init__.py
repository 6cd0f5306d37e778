"""Discovery: who is alive and what each node publishes, subscribes, serves and calls.

Every process announces its nodes (with their endpoints, types, QoS and loss counters) on
the discovery group once a second, at once when something changes, and immediately in answer
to a graph query; it says goodbye on shutdown, and a process not heard from for 3.5 s is
dropped (liveliness). Every process keeps a :class:`GraphCache` of what it heard, so a fresh
CLI learns the whole graph in one round trip, without a daemon. Imports ``rosl.bus`` only.
"""
