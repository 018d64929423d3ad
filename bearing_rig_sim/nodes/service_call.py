"""A service request asked again until it is answered, within a bound (no ROS import).

Right after the graph shows a service ready, its server's response writer may not have matched
the client's response reader yet (Fast DDS): a response sent before that match is lost, and a
client that asked once waits for ever. The rig's own clients therefore ask an idempotent request
again every :data:`RETRY_S` of wall time until one of its answers comes (any answer counts, to
the first request or to a repeat), and give up after the caller's guard. Only requests whose
repetition does no harm are retried: a set-point (``/rig/axial_load/set``: the same value
twice), the clutch (engage twice), a lifecycle transition (a repeat of one already made is
refused, and the caller then reads the node's state: the lifecycle manager does).

:class:`RetriedCall` never blocks: :meth:`RetriedCall.poll` is called from a timer or a spin
loop; the client is anything with ``call_async(request)`` returning a future (``done()``,
``result()``), so the logic is tested with fakes.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

__all__ = ["RETRY_S", "RetriedCall"]

RETRY_S = 1.0
"""Wall time between two askings of an unanswered request, s: a discovery race resolves within
tens of milliseconds on one host, and a busy server answers a first request well within a
second; asking more often would only queue repeats behind a slow answer."""


class RetriedCall:
    """One request, asked until answered (see the module docstring).

    Args:
        client: has ``call_async(request)`` returning a future.
        request: the request (idempotent).
        guard_s: wall time after the first asking at which it gives up, s (> 0).
        retry_s: wall time between askings, s (> 0).
        clock: the wall clock, s (monotonic).

    Raises:
        ValueError: ``guard_s`` or ``retry_s`` not > 0.
    """

    def __init__(
        self,
        client: Any,
        request: Any,
        guard_s: float,
        *,
        retry_s: float = RETRY_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if not (guard_s > 0.0 and retry_s > 0.0) or math.isnan(guard_s) or math.isinf(retry_s):
            raise ValueError(f"guard_s and retry_s must be > 0 (retry finite), got {guard_s!r} and {retry_s!r}")
        self.client = client
        self.request = request
        self.guard_s = float(guard_s)
        self.retry_s = float(retry_s)
        self._clock = clock
        self._futures: list[Any] = []
        self._first = clock()
        self._last = self._first
        self.response: Any = None
        """The first answer that came (None until then)."""
        self._ask()

    @property
    def attempts(self) -> int:
        """How many times the request was sent."""
        return len(self._futures)

    @property
    def answered(self) -> bool:
        """An answer came (:attr:`response`)."""
        return self.response is not None

    @property
    def timed_out(self) -> bool:
        """No answer within ``guard_s`` of the first asking (checked by :meth:`poll`)."""
        return not self.answered and self._clock() - self._first > self.guard_s

    def _ask(self) -> None:
        self._futures.append(self.client.call_async(self.request))
        self._last = self._clock()

    def poll(self) -> bool:
        """Take an answer if one came, else ask again when :attr:`retry_s` has passed since the
        last asking (never after the guard). Returns True once done: answered or timed out."""
        if self.answered:
            return True
        for future in self._futures:
            if future.done() and future.result() is not None:
                self.response = future.result()
                self.cancel()
                return True
        now = self._clock()
        if now - self._first > self.guard_s:
            self.cancel()
            return True
        if now - self._last >= self.retry_s:
            self._ask()
        return False

    def cancel(self) -> None:
        """Forget the requests still unanswered (their late answers are dropped)."""
        for future in self._futures:
            if not future.done():
                future.cancel()
                remove = getattr(self.client, "remove_pending_request", None)
                if remove is not None:
                    remove(future)
