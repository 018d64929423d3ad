"""The Fast DDS profile every process of the rig uses unless its user gives one (no ROS import).

Two things in it matter to the rig's streams, measured on a two-core host:

* **Shared memory with deep buffers**: an 8 MiB segment and 8192 descriptors per port instead of
  Fast DDS's 512 KiB and 512 (about 0.1 s of the rig's traffic). With the defaults a node's
  receive thread held up for a few hundred milliseconds on a busy host let the writer's segment
  or the reader's port fill, and every reader lost 100-600 ms stretches of every topic.
* **A writer heartbeat every** :data:`HEARTBEAT_PERIOD_S` instead of Fast DDS's 3 s. A reliable
  reader acknowledges what it received only when a heartbeat asks, and a reliable writer keeps
  at most its history (5000 samples on the rig's streams) for readers that have not: without
  real time the simulator publishes some 4000 ``/clock`` samples a second, so with 3 s between
  heartbeats samples left the history unacknowledged, and a sample lost in transport could no
  longer be sent again. The heartbeat also lets the simulator pace itself on its readers'
  acknowledgements (:mod:`bearing_rig_sim.nodes.simulator`) within a few tens of milliseconds.

UDPv4 stays on for discovery and other hosts. The profile is read through the environment
variable ``FASTRTPS_DEFAULT_PROFILES_FILE``: a session writes it to ``<run-id>/logs/`` for its
nodes (:func:`apply_rig_profile`); a node, the player or the shadow node started on its own
writes it to the system temp folder (:func:`use_rig_profile`). A profile the user names in
``FASTRTPS_DEFAULT_PROFILES_FILE`` or ``FASTDDS_DEFAULT_PROFILES_FILE`` is always kept.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import MutableMapping
from pathlib import Path

__all__ = ["HEARTBEAT_PERIOD_S", "PROFILE_VARIABLES", "RIG_PROFILE_XML", "apply_rig_profile", "use_rig_profile"]

HEARTBEAT_PERIOD_S = 0.05
"""Period of a reliable writer's heartbeat in the rig's profile, s (Fast DDS's default: 3 s)."""

PROFILE_VARIABLES = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE")
"""Environment variables through which a user gives Fast DDS a profile of their own."""

RIG_PROFILE_XML = f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- Fast DDS profile of the bearing rig's processes (bearing_rig_sim.dds_profile): shared memory
     with an 8 MiB segment and 8192 descriptors per port (about 2 s of the rig's traffic), UDPv4
     for discovery and other hosts, and a reliable writer's heartbeat every
     {HEARTBEAT_PERIOD_S * 1e3:g} ms instead of 3 s. -->
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
    <transport_descriptor>
      <transport_id>rig_shm</transport_id>
      <type>SHM</type>
      <segment_size>8388608</segment_size>
      <port_queue_capacity>8192</port_queue_capacity>
    </transport_descriptor>
    <transport_descriptor>
      <transport_id>rig_udp</transport_id>
      <type>UDPv4</type>
    </transport_descriptor>
  </transport_descriptors>
  <participant profile_name="bearing_rig_participant" is_default_profile="true">
    <rtps>
      <userTransports>
        <transport_id>rig_shm</transport_id>
        <transport_id>rig_udp</transport_id>
      </userTransports>
      <useBuiltinTransports>false</useBuiltinTransports>
    </rtps>
  </participant>
  <data_writer profile_name="bearing_rig_writer" is_default_profile="true">
    <times>
      <heartbeatPeriod><sec>0</sec><nanosec>{round(HEARTBEAT_PERIOD_S * 1e9)}</nanosec></heartbeatPeriod>
    </times>
  </data_writer>
</profiles>
"""
"""The profile's text (Fast DDS 2.14 XML)."""


def _user_profile(env: MutableMapping[str, str]) -> bool:
    return any(env.get(name, "").strip() for name in PROFILE_VARIABLES)


def _write(path: Path) -> None:
    """Write the profile to ``path`` unless it holds it already (atomically: readers never see
    half a file)."""
    try:
        if path.read_text(encoding="utf-8") == RIG_PROFILE_XML:
            return
    except OSError:
        pass
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.{os.getpid()}")
    partial.write_text(RIG_PROFILE_XML, encoding="utf-8")
    os.replace(partial, path)


def apply_rig_profile(env: MutableMapping[str, str], directory: str | Path) -> Path | None:
    """Unless ``env`` names a Fast DDS profile already, write :data:`RIG_PROFILE_XML` to
    ``directory/fastdds_profile.xml`` and name it in ``env``; returns the file, or None."""
    if _user_profile(env):
        return None
    profile = Path(directory) / "fastdds_profile.xml"
    _write(profile)
    env["FASTRTPS_DEFAULT_PROFILES_FILE"] = str(profile)
    return profile


def use_rig_profile() -> Path | None:
    """For this process (before ``rclpy.init``): unless the environment names a profile, write
    :data:`RIG_PROFILE_XML` to the system temp folder (one file per user) and name it in
    ``os.environ``; returns the file, or None. A temp folder that cannot be written leaves Fast
    DDS's defaults (the node still runs)."""
    try:
        return apply_rig_profile(os.environ, Path(tempfile.gettempdir()) / f"bearing_rig_sim-{os.getuid()}")
    except OSError:
        return None
