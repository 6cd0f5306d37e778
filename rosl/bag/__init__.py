"""Recordings: everything on the bus to a rosbag2 folder of MCAP files, and back.

Owns recording (exact wire bytes, receive and send times, service traffic as service
events), the rosbag2 ``metadata.yaml``, reading bags (folders, single MCAP files, unfinished
ones), ``info``, ``reindex``, playback, diffs and trimming. Imports ``rosl.node`` (for a
participant and the type registry) but never the CLI, launch or sim.
"""
