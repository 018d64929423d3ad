"""Recording runs (:class:`BagWriter`), reading bags (:func:`open_bag`), repairing a killed
recording (:func:`repair_bag`), with ``mcap`` and ``rosbags``, no ROS import (docs/bags.md)."""

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
