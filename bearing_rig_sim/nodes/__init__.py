"""ROS 2 nodes of the rig: thin shells around the ROS-free cores (see nodes/common.py)."""
