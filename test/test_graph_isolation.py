"""The test fixture's graph isolation: a process left on a domain is found, passed over by the
next lease, and killed at teardown (see ``conftest``)."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from conftest import DOMAIN_IDS, DomainLease, kill_processes_on_domain, lease_domain, processes_on_domain, time_left

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux /proc")


def test_a_process_on_a_domain_is_found_passed_over_and_killed() -> None:
    lease = lease_domain()
    orphan = subprocess.Popen(
        [sys.executable, "-c", "import time; time.sleep(120)"],
        env=dict(os.environ, ROS_DOMAIN_ID=str(lease.domain_id)),
    )
    try:
        deadline = time.monotonic() + 30.0  # until the child has exec'd its command line
        while orphan.pid not in processes_on_domain(lease.domain_id) and time.monotonic() < deadline:
            time.sleep(0.02)
        assert "time.sleep(120)" in processes_on_domain(lease.domain_id)[orphan.pid]
        lease.release()  # the id is free as a lock, but a process still talks on it
        others: list[DomainLease] = []
        try:
            while len(others) < len(DOMAIN_IDS):  # every id a lease will hand out now
                try:
                    others.append(lease_domain(timeout=0.0))
                except RuntimeError:
                    break
            assert others, "no domain id was free at all"
            assert lease.domain_id not in {o.domain_id for o in others}
        finally:
            for other in others:
                other.release()
        killed = kill_processes_on_domain(lease.domain_id)
        assert orphan.pid in killed
        assert orphan.wait(timeout=time_left()) == -9
        assert orphan.pid not in processes_on_domain(lease.domain_id)
    finally:
        lease.release()
        if orphan.poll() is None:
            orphan.kill()
            orphan.wait()
