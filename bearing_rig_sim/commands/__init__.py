"""Sub-commands of ``bearing-rig``.

One module per sub-command, listed in :data:`bearing_rig_sim.cli.COMMANDS`. Each module exposes::

    def register(subparsers: argparse._SubParsersAction) -> None:
        parser = subparsers.add_parser("name", help="...")
        ...
        parser.set_defaults(func=run)      # run(args: argparse.Namespace) -> int

and keeps its heavy imports inside ``run`` so that ``bearing-rig --help`` stays fast.
"""
