"""Live views of the rig's topics (no ROS): :mod:`.foxglove` serves them to the Foxglove app
over its WebSocket protocol, from the session's recorder or from a replay."""
