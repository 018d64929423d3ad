"""Recording runs to rosbag2 bags with MCAP storage (:class:`BagWriter`), reading them back with
MCAP or SQLite 3 storage (:func:`open_bag`), repairing a killed recording (:func:`repair_bag`);
the types are ROS 2 Jazzy's plus ``bearing_rig_msgs`` (:func:`rig_typestore`). No ROS import:
bags are written and read with ``mcap`` and ``rosbags``.
"""

from bearing_rig_sim.bags.errors import BagError, BagWarning
from bearing_rig_sim.bags.layout import RUN_METADATA_RECORD
from bearing_rig_sim.bags.qos import QOS_PROFILES, QosSpec
from bearing_rig_sim.bags.reader import BagMessage, BagReader, TopicInfo, open_bag
from bearing_rig_sim.bags.repair import FileRepair, RepairReport, repair_bag
from bearing_rig_sim.bags.typestore import msg_definition_text, rig_typestore
from bearing_rig_sim.bags.writer import PROJECT_VERSION_KEY, BagWriter

__all__ = [
    "QOS_PROFILES", "PROJECT_VERSION_KEY", "RUN_METADATA_RECORD", "BagError", "BagMessage", "BagReader", "BagWarning", "BagWriter",
    "FileRepair", "QosSpec", "RepairReport", "TopicInfo", "msg_definition_text", "open_bag", "repair_bag", "rig_typestore",
]  # fmt: skip
