"""TF: coordinate frames over time, as tf2, tf2_ros and tf2_geometry_msgs provide them.

Owns the transform math (``transform``), each edge's history (``cache``), the frame tree and
its lookups (``tree``; tf2_py's ``BufferCore`` over messages in ``core``), the waiting
``Buffer``, ``TransformListener``, the broadcasters, the geometry_msgs conversions
(``geometry``) and the tf2_ros programs (``static_publisher``, ``echo``, ``monitor``).
``rosl tf`` reads the same tree. ``import tf2_ros`` / ``tf2_py`` / ``tf2_geometry_msgs``
are served from here through ``rosl.compat``.

Sits beside launch, bag and sim: uses ``rosl.node`` (and ``rosl.idl`` for messages); must
not import ``rosl.cli``, ``rosl.introspection``, launch, bag or sim.
"""
