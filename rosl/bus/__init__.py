"""The bus: datagrams between the processes of one domain, behind one transport seam.

Owns sockets, the datagram header, fragmentation and reassembly, the domain's addressing
(which group and port each channel uses) and loss counting. It knows nothing of nodes,
message types or the graph; payloads are opaque bytes. Imports only ``rosl.errors``.
``transport.py`` is the seam node/ and graph/ use (send, receivers that join channels and
poll whole deliveries, wake-ups); ``multicast.py`` is the default transport and
``inprocess.py`` a one-process transport for tests. ``ROSL_TRANSPORT=zenoh`` picks
``zenoh_transport.py``: the same seam over Zenoh in ROS 2's rmw_zenoh wire format
(``zenoh_wire.py``: keys, tokens, QoS strings, attachments, GIDs; ``zenoh_graph.py``: liveliness
tokens and other implementations' nodes; ``zenoh_config.py``: sessions, routers, settings;
``zenoh_history.py``: transient local through publication caches; ``zenoh_identity.py``: GIDs
back to rosl's process and endpoint ids).
Large messages between processes of one host take shared memory beside multicast: ``shm.py``
(when, ring names, the host identity, cleanup of crashed processes' rings) over
``shm_ring.py`` (the ring file, its writer, the readers' checked copies).

How topics map to the network (documented here because users and tools rely on it):

* A domain ``D`` (``ROSL_DOMAIN_ID``, else ``ROS_DOMAIN_ID``, else 0) uses UDP port
  ``17400 + D`` and the multicast groups ``239.255.D.0`` to ``239.255.D.64``.
* Group ``.0`` carries discovery (node announcements and graph queries).
* Every topic and service name hashes (FNV-1a, 64 bit) to one of 64 *channels*, groups
  ``.1`` to ``.64``. A process joins only the channels of the topics and services it uses,
  so heavy traffic on other topics never reaches it; the kernel filters by group. Topics
  that share a channel are told apart by the 64-bit topic hash in each datagram's header,
  checked before any payload is touched.
* By default everything leaves through 127.0.0.1 with TTL 0: nothing leaves the host.
  ``ROSL_INTERFACE=<name or address>`` sends and joins on that interface with TTL 1 instead.
* ``probe.py`` is ROS 2's multicast check (``rosl multicast send|receive``): one datagram to
  225.0.0.1:49150, in the same scope (loopback unless ``ROSL_INTERFACE`` names one).
"""
