"""The simulator: pymunk worlds, diff-drive robots with 2D LiDAR, and the sim node.

``worldfile.py`` reads world and robot files (line-numbered errors), ``world.py`` builds the
pymunk space and the ray-casting geometry, ``robot.py`` drives a robot, ``lidar.py`` casts
rays, ``simulation.py`` steps everything on an integer-nanosecond clock (no bus), and
``sim_node.py`` is the only module that talks to the bus. Imports ``rosl.node`` and below,
``rosl.bag`` for ``--record``; never the CLI or launch.
"""
