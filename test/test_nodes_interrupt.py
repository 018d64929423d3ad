"""Ctrl-C ends a node through rclpy's shutdown, never as a Python ``KeyboardInterrupt``: raised
inside a callback the events executor runs from C++, pybind11 cannot carry it and the process
aborts ("terminate called after throwing an instance of 'pybind11::error_already_set'")."""

from __future__ import annotations

import os
import signal
import time

from bearing_rig_sim.nodes import common


def test_sigint_after_quiet_interrupt_raises_nothing_and_is_remembered() -> None:
    previous = signal.getsignal(signal.SIGINT)
    common.INTERRUPTED.clear()
    try:
        common.quiet_interrupt()
        os.kill(os.getpid(), signal.SIGINT)
        deadline = time.monotonic() + 60.0  # a guard against a hang only
        while not common.INTERRUPTED and time.monotonic() < deadline:
            time.sleep(0.01)  # Python runs the handler between bytecodes of the main thread
        assert common.INTERRUPTED == [True]
    finally:
        signal.signal(signal.SIGINT, previous)
        common.INTERRUPTED.clear()
