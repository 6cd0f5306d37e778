"""``import sensor_msgs_py`` under rosl: ROS 2's PointCloud2 helpers (``point_cloud2``)."""
