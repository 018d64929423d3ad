"""Replaying a bag into a ROS 2 graph (:mod:`.player`): the one part of bag handling that talks
to ROS. The schedule is ROS-free and tested with a fake clock; the sink imports rclpy when made.
"""
