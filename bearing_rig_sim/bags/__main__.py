"""``python -m bearing_rig_sim.bags repair BAG...``: the bag repair from a shell, until the
``bearing-rig`` command has its ``bag repair`` sub-command."""

import sys

from bearing_rig_sim.bags.repair import main

if len(sys.argv) < 2 or sys.argv[1] != "repair":
    print("usage: python -m bearing_rig_sim.bags repair BAG [BAG ...]", file=sys.stderr)
    sys.exit(2)
sys.exit(main(sys.argv[2:]))
