"""What the introspection commands do, as library calls.

Topics, services, parameters, nodes, lifecycle states, the graph picture, TF frames and the
setup doctor.

``rosl topic|service|param|node|lifecycle|graph|tf|doctor`` are thin click layers over this package,
which uses ``rosl.node`` (a hidden CLI node when it must subscribe, publish or call) and
``rosl.graph`` (one complete graph query, no daemon). Nothing here prints; functions return
text or records for ``rosl.cli.render``. Must not import ``rosl.cli``, launch, bag or sim.
"""
