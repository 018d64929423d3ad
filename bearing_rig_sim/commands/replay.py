"""``bearing-rig replay BAG``: republish a recorded bag into the ROS 2 graph with its original
timing, and ``/clock``.

Replaying some topics only, stopping: docs/guide.md, section ``bearing-rig replay``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from bearing_rig_sim.commands import describe
from bearing_rig_sim.commands.run import add_foxglove_argument
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import CLOCK


def register(subparsers: Any) -> None:
    """Add ``replay`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("replay", help=f"republish a bag into ROS 2 with its timing and {CLOCK.name}", description=describe(__doc__, "replay"))
    p.add_argument("bag", type=Path, metavar="BAG", help="bag directory (or a single .mcap file)")
    p.add_argument("--rate", type=float, default=1.0, help="bag seconds per wall second (default 1)")
    p.add_argument("--loop", action="store_true", help="start again at the end (the clock jumps back), until Ctrl-C")
    p.add_argument("--topics", nargs="+", metavar="T", default=None, help=f"topics to replay (default: all; {CLOCK.name} always)")
    p.add_argument("--start", type=float, default=0.0, metavar="S", help="start S seconds after the bag's first message")
    p.add_argument("--duration", type=float, default=None, metavar="D", help="replay D seconds of the bag (default: to the end)")
    p.add_argument(
        "--clock-hz", type=float, default=100.0, metavar="HZ", help=f"rate of the {CLOCK.name} made when the bag has none, per bag second (default 100)"
    )
    p.add_argument("--delay", type=float, default=0.5, metavar="S", help="wall seconds to wait before the first message, for discovery (default 0.5)")
    p.add_argument(
        "--wait-for-subscribers",
        action="store_true",
        help=f"start as soon as every replayed topic (except {CLOCK.name}) has a subscriber, waiting at most --delay seconds",
    )
    p.add_argument("--quiet", action="store_true", help="no summary line")
    add_foxglove_argument(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Replay the bag; returns the exit status."""
    from bearing_rig_sim.commands.bag import bag_warnings_as_lines
    from bearing_rig_sim.bags import open_bag
    from bearing_rig_sim.replay.player import ReplayOptions, RosReplaySink, check_topics, replay_bag

    if not args.delay >= 0.0:
        raise RigError(f"--delay must be >= 0 s, got {args.delay!r}")
    options = ReplayOptions(
        rate=args.rate,
        loop=args.loop,
        topics=None if args.topics is None else tuple(args.topics),
        start=args.start,
        duration=args.duration,
        clock_hz=args.clock_hz,
    )
    with bag_warnings_as_lines(), open_bag(args.bag) as bag:
        topics = check_topics(bag, options.topics)
        sink: Any = RosReplaySink(bag.topics)
        view = None
        if args.foxglove is not None:
            from bearing_rig_sim.bags import msg_definition_text
            from bearing_rig_sim.live.foxglove import FoxgloveLiveView, LiveReplaySink

            view = FoxgloveLiveView(args.foxglove, msg_definition_text)
            sink = LiveReplaySink(sink, view, {name: info.msgtype for name, info in bag.topics.items() if name in topics or name == CLOCK.name})
            print(f"Foxglove live view: {view.urls} (layout to import: config/foxglove/rig.json)", flush=True)
        try:
            if args.wait_for_subscribers:
                alone = sink.wait_for_subscribers([t for t in topics if t != CLOCK.name], args.delay)
                if alone:
                    print(f"bearing-rig: warning: no subscriber after {args.delay:g} s on {', '.join(alone)}; replaying anyway", file=sys.stderr)
            else:
                time.sleep(args.delay)
            stats = replay_bag(bag, sink, options)
        except KeyboardInterrupt:
            print("bearing-rig: replay interrupted", file=sys.stderr)
            return 130
        finally:
            (sink.inner if view is not None else sink).close()
            if view is not None:
                view.close()
    if not args.quiet:
        skipped = f"; skipped (type not installed): {', '.join(stats.skipped_topics)}" if stats.skipped_topics else ""
        print(f"{args.bag}: {stats.summary()}{skipped}")
    return 0
