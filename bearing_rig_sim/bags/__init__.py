"""Recording runs to rosbag2 bags with MCAP storage, reading them back, repairing them.

* :class:`BagWriter` (:mod:`.writer`): the recorder; raw CDR or rosbags message objects in,
  a rosbag2 v9 bag directory out (zstd chunks, ``ros2msg`` schemas, offered QoS, run context).
* :func:`open_bag` / :class:`BagReader` (:mod:`.reader`): topics, counts, time range, run context,
  messages decoded in time order, streamed; damaged bags read as far as they go, with warnings;
  MCAP (:mod:`.mcapfile`) or SQLite 3 (:mod:`.sqlite`) storage behind one seam (:mod:`.storage`).
* :func:`repair_bag` (:mod:`.repair`): restores the index of a bag whose recording was killed.
* :func:`rig_typestore` (:mod:`.typestore`): ROS 2 Jazzy types plus ``bearing_rig_msgs``.

No ROS import anywhere in this package: bags are written and read with ``mcap`` and ``rosbags``.
"""

from bearing_rig_sim.bags.errors import BagError, BagWarning
from bearing_rig_sim.bags.layout import RUN_METADATA_RECORD
from bearing_rig_sim.bags.qos import QOS_PROFILES, QosSpec
from bearing_rig_sim.bags.reader import BagMessage, BagReader, TopicInfo, open_bag
from bearing_rig_sim.bags.repair import FileRepair, RepairReport, repair_bag
from bearing_rig_sim.bags.typestore import msg_definition_text, rig_typestore
from bearing_rig_sim.bags.writer import PROJECT_VERSION_KEY, BagWriter

__all__ = [
    "QOS_PROFILES",
    "PROJECT_VERSION_KEY",
    "RUN_METADATA_RECORD",
    "BagError",
    "BagMessage",
    "BagReader",
    "BagWarning",
    "BagWriter",
    "FileRepair",
    "QosSpec",
    "RepairReport",
    "TopicInfo",
    "msg_definition_text",
    "open_bag",
    "repair_bag",
    "rig_typestore",
]
