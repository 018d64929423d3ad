"""Deterministic offline analysis of a rig bag: the monitor's verdicts without a ROS graph.

::

    result = analyse_bag("bags/20250612T093015Z-validation", csv_dir="reports/run")
    print(result.final_status.state, [s.final_state for s in result.segments])

The two fibre-optic pulse topics are read in log-time order and fed through the same
:class:`~bearing_rig_sim.monitoring.StatusSchedule` and
:class:`~bearing_rig_sim.monitoring.SlipMonitor` the monitor node runs, so the slip windows,
verdicts and the moments of the statuses offline are the node's (one status row per status the
node would publish, plus a last one after the last pulse). With the ``axial_load`` criterion the
load cell's force is fed too. The criterion is the run's test program's ``stability_criterion``
when the bag records the program. Nothing depends on a wall clock: two runs over one bag give
bit-identical results.

**What is read.** Only the topics the analysis uses, as raw CDR, in one pass over the bag's
chunks (:meth:`~bearing_rig_sim.bags.reader.BagReader.ordered_batches`: each chunk decompressed
once, its messages as arrays): the pulses decoded as arrays
(:func:`~bearing_rig_sim.bags.cdr.decode_pulses`; other encodings through the reader's general
decoder, one by one); the load cell, recorded statuses and spindle commands one by one; the 1 kHz
speeds and the other sampled topics (:data:`SAMPLED_TOPICS`) not message by message: a chunk of
them is kept and only the message a status row samples is decoded (the speeds' and the truth's
fields by hand, :func:`~bearing_rig_sim.bags.cdr.decode_joint_velocities` and
:func:`~bearing_rig_sim.bags.cdr.decode_truth_speeds`: a status row samples both; the recorded
statuses' likewise, :func:`~bearing_rig_sim.bags.cdr.decode_status_fields`). Memory does not grow with
the bag's length: rows and windows stream to CSV files as they are made, and only a decimated
copy of the rows (at most ``max_points``) and the state changes are kept for plots.

**The topics** (:data:`PULSE_TOPICS` required, :data:`CONTEXT_TOPICS` used when present; the
bench records the same contract, and bags without the simulator's truth are analysed alike):

* ``/rig/spindle/pulses``, ``/rig/cage/pulses``: ``bearing_rig_msgs/msg/FibreOpticPulse``;
* ``/rig/speeds``: ``sensor_msgs/msg/JointState`` (``velocity`` of ``inner_ring`` and ``cage``);
* ``/rig/truth``: ``bearing_rig_msgs/msg/SimulatorTruth`` (twin only);
* ``/rig/slip_status``: ``bearing_rig_msgs/msg/SlipStatus`` (the monitor's recorded verdicts);
* ``/rig/spindle/command``: ``bearing_rig_msgs/msg/SpindleCommand`` (program segments; a
  command is recorded when sent, which may be ahead of its stamp, the time it takes effect: it
  starts its segment when the bag's timeline reaches that stamp);
* ``/rig/axial_load/state`` (``bearing_rig_msgs/msg/AxialLoadState``),
  ``/rig/axial_load/setpoint`` (``std_msgs/msg/Float64``), ``/rig/axial_load/force`` and
  ``/rig/bearing/axial_force`` (``geometry_msgs/msg/WrenchStamped``, ``force.z``).

**Segments** (:mod:`.segments`): program segments from the spindle commands when the bag has
them, else constant-speed stretches found in the monitor's windows.

Units: SI inside (s, rad/s, N), slip in percent; the CSV files speak rpm, percent and N.
"""

from __future__ import annotations

import bisect
import dataclasses
from collections import deque
import functools
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from collections.abc import Callable

import numpy as np


from bearing_rig_sim import interfaces as contract
from bearing_rig_sim.analysis.stability import LoadSweepVerdict
from bearing_rig_sim.config import ConfigError, parse_yaml, ros_parameters
from bearing_rig_sim.monitoring import DIAGNOSTIC_NAME as MONITOR_DIAGNOSTIC_NAME
from bearing_rig_sim.monitoring import (
    NODE_NAME,
    PARAMETER_KEY_PREFIX,
    MonitorSettings,
    MonitorStatus,
    SlipMonitor,
    StampOrder,
    StatusSchedule,
    shipped_parameters,
    unstamped,
)
from bearing_rig_sim.bags.cdr import decode_pulse as pulse_fields
from bearing_rig_sim.bags.cdr import decode_joint_velocities, decode_pulses, decode_status_fields, decode_truth_speeds, make_decoder, make_field_decoder
from bearing_rig_sim.bags.errors import BagError, BagWarning
from bearing_rig_sim.bags.mcapfile import ChunkBatch
from bearing_rig_sim.bags.reader import BagReader, open_bag
from bearing_rig_sim.offline.segments import (
    SEGMENTS_CSV,
    SegmentSummary,
    SegmentTracker,
    program_criterion,
    program_segment_names,
    write_segments_csv,
)
from bearing_rig_sim.offline.series import (
    STATUS_CSV,
    WINDOWS_CSV,
    CsvWriter,
    RowDecimator,
    SlipWindowRow,
    StatusRow,
    csv_columns,
)
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.monitoring.load_sweep import sweep_key
from bearing_rig_sim import picklable

PULSE_TYPE = contract.CAGE_PULSES.msgtype
STATUS_TYPE = contract.SLIP_STATUS.msgtype
DIAGNOSTICS = contract.DIAGNOSTICS.name
"""Where the monitor publishes the parameters its statuses are judged by."""
PULSE_TOPICS: dict[str, str] = {shaft: t.name for shaft, t in contract.PULSE_TOPICS.items()}
"""Shaft -> pulse topic: what the analysis cannot do without."""

SPEEDS, TRUTH, STATUS, COMMAND = (t.name for t in (contract.SPEEDS, contract.TRUTH, contract.SLIP_STATUS, contract.SPINDLE_COMMAND))
LOAD_STATE, LOAD_SETPOINT, LOAD_CELL, BEARING_FORCE = (
    t.name for t in (contract.AXIAL_LOAD_STATE, contract.AXIAL_LOAD_SETPOINT, contract.AXIAL_LOAD_FORCE, contract.BEARING_AXIAL_FORCE)
)
OUTER_RING_TEMPERATURE, HOUSING_TORQUE = contract.OUTER_RING_TEMPERATURE.name, contract.HOUSING_TORQUE.name
CONTEXT_TOPICS: dict[str, str] = {
    t.name: t.msgtype
    for t in (
        contract.SPEEDS,
        contract.TRUTH,
        contract.SLIP_STATUS,
        contract.SPINDLE_COMMAND,
        contract.AXIAL_LOAD_STATE,
        contract.AXIAL_LOAD_SETPOINT,
        contract.AXIAL_LOAD_FORCE,
        contract.BEARING_AXIAL_FORCE,
        contract.OUTER_RING_TEMPERATURE,
        contract.HOUSING_TORQUE,
    )
}
"""Topics read when present, with the type they must carry."""
SAMPLED_TOPICS = frozenset((SPEEDS, TRUTH, LOAD_STATE, LOAD_SETPOINT, BEARING_FORCE, OUTER_RING_TEMPERATURE, HOUSING_TORQUE))
"""Context topics only sampled by the status rows (their latest value): read a chunk at a time
as arrays beside the pulses, never message by message (the 1 kHz speeds would be most of the
messages of the bag)."""

MONITOR_PARAMETERS_KEY = f"parameters/{NODE_NAME}"
"""Run-context key holding the monitor's parameter file of the run."""

PLAUSIBLE_STAMP_S = 10.0
"""A recorded status or command stamped further than this from the pulse clock was stamped on
another clock (s); see :meth:`OfflineAnalysis._decoded`."""
MAX_TRANSITIONS = 20_000
"""State changes kept per source; further ones are counted, not kept (1)."""
DEFAULT_MAX_POINTS = 2000
"""Rows kept for plots (1)."""

_NAN = math.nan


# ---------------------------------------------------------------------------------------------
# Pulses: a decoder of the fields the monitor uses
# ---------------------------------------------------------------------------------------------
def decode_pulse(data: bytes | memoryview) -> Pulse:
    """A little-endian CDR ``FibreOpticPulse`` as a :class:`Pulse` (:func:`bearing_rig_sim.bags.cdr.decode_pulse`).

    Raises:
        BagError: not little-endian CDR, or the bytes end before the message does.
    """
    return Pulse(*pulse_fields(data))


def _pulses_of(batch: ChunkBatch) -> list[Pulse | None]:
    """The pulses of a batch (topic positions 0 and 1), decoded as arrays
    (:func:`~bearing_rig_sim.bags.cdr.decode_pulses`); None for the other messages and for
    pulses to decode alone (not little-endian CDR, or malformed)."""
    found: list[Pulse | None] = [None] * len(batch.log_times)
    where = np.flatnonzero(batch.channel_ids < 2)
    if not where.size:
        return found
    fields = decode_pulses(batch.data, batch.starts[where], batch.ends[where])
    columns = (fields.time.tolist(), fields.strip_id.tolist(), fields.strip_count.tolist(), fields.revolution.tolist(), fields.pulse_index.tolist())
    for k, valid, time, strip_id, strip_count, revolution, pulse_index, sensor in zip(where.tolist(), fields.valid.tolist(), *columns, fields.sensor_id):
        if valid:
            found[k] = Pulse(time, strip_id, strip_count, revolution, pulse_index, sensor)
    return found


def _pulse_from_message(message: Any) -> Pulse:
    stamp = message.header.stamp
    return Pulse(
        stamp.sec + stamp.nanosec * 1e-9,
        int(message.strip_id),
        int(message.strip_count),
        int(message.revolution),
        int(message.pulse_index),
        str(message.sensor_id),
    )


# ---------------------------------------------------------------------------------------------
# The result
# ---------------------------------------------------------------------------------------------
@dataclass
class OfflineResult:
    """Everything the offline analysis of one bag found (see :func:`analyse_bag`)."""

    path: Path
    run_metadata: dict[str, str]
    topics: dict[str, tuple[str, int]]
    """Every topic of the bag: name -> (type, message count)."""
    complete: bool
    """False when the bag was damaged or truncated: the results cover what could be read."""
    problems: list[str]
    """Every problem met (the reader's and the analysis'), one line each."""
    settings_source: str
    """Where the monitor's parameters came from."""
    stable_confidence: float
    """The monitor's ``stable_confidence`` the time to stable was judged at (1)."""
    segment_source: str
    """``"program"`` (spindle commands) or ``"stretches"`` (detected constant speeds)."""
    bag_start: float
    bag_end: float
    """Log-time range of the bag, s."""
    first_time: float = _NAN
    last_time: float = _NAN
    """Rig time of the first and last pulse analysed, s."""
    pulses: dict[str, int] = field(default_factory=lambda: dict.fromkeys(PULSE_TOPICS, 0))
    windows: int = 0
    status_rows: int = 0
    recorded_statuses: int = 0
    state_durations: dict[int, float] = field(default_factory=dict)
    """Rig seconds spent in each offline state (between status rows)."""
    final_status: MonitorStatus | None = None
    final_recorded_state: int = -1
    rows: list[StatusRow] = field(default_factory=list)
    """Decimated status rows (at most ``max_points``, evenly spread, the last one included)."""
    transitions: list[tuple[float, int]] = field(default_factory=list)
    """Offline state changes (rig time, state), the first row included."""
    recorded_transitions: list[tuple[float, int]] = field(default_factory=list)
    """State changes of the recorded ``/rig/slip_status`` (stamp on the pulse clock, state)."""
    transitions_dropped: int = 0
    segments: list[SegmentSummary] = field(default_factory=list)
    csv_files: list[Path] = field(default_factory=list)
    sweeps: list[LoadSweepVerdict] = field(default_factory=list)
    """The offline monitor's load-sweep verdict per spindle speed (``axial_load`` criterion)."""
    recorded_sweeps: dict[int, str] = field(default_factory=dict)
    """The recorded statuses' latest load-sweep verdict per speed (rpm rounded to 10 -> text)."""


# ---------------------------------------------------------------------------------------------
# Helpers
# ---------------------------------------------------------------------------------------------
class _Decoding:
    """Decodes the message a row asks for once (a message that does not decode is counted in
    :attr:`failed` and leaves the value unknown)."""

    def __init__(self, decode: Callable[[bytes], Any]) -> None:
        self._decode = decode
        self._decoded: tuple[int, bytes, Any] | None = None
        self._bad: set[int] = set()  # keys of messages that did not decode
        self.failed = 0

    def _value(self, entry: tuple[int, bytes] | None) -> Any:
        """The decoded message of ``entry`` = (key, raw bytes); None for no entry or a bad one."""
        if entry is None or entry[0] in self._bad:
            return None
        if self._decoded is not None and self._decoded[:2] == entry:
            return self._decoded[2]
        try:
            value = self._decode(entry[1])
        except BagError:
            self.failed += 1
            self._bad.add(entry[0])
            return None
        self._decoded = (*entry, value)
        return value


class _Latest(_Decoding):
    """The latest message of a topic, decoded only when asked for (a message that does not
    decode is counted in :attr:`failed` and leaves the value unknown); :meth:`get` ``before`` a
    message's place in the bag gives the latest read before it (a status is computed on pulses
    put in stamp order, which may be released after later context messages were read)."""

    KEPT = 4096
    """Messages kept for :meth:`get` before an earlier place (1)."""

    def __init__(self, decode: Callable[[bytes], Any]) -> None:
        super().__init__(decode)
        self._kept: deque[tuple[int, bytes]] = deque(maxlen=self.KEPT)  # (place read, raw)

    def put(self, place: int, raw: bytes) -> None:
        """The message read ``place``-th in the bag."""
        self._kept.append((place, raw))

    def get(self, before: int | None = None) -> Any:
        """The latest message, or the latest read before the ``before``-th (of the last
        :attr:`KEPT`); None if none (or it does not decode)."""
        entry = None
        for kept in reversed(self._kept):  # the pulses are held briefly: a few steps back at most
            if before is None or kept[0] < before:
                entry = kept
                break
        return self._value(entry)


class _Sampled(_Decoding):
    """A context topic read only where a status row samples it: its messages arrive a chunk at a
    time as arrays (:meth:`.BagReader.batches`: no message handled one by one) and only the one a
    row asks for is decoded (a message that does not decode is counted in :attr:`failed` and
    leaves the value unknown)."""

    def __init__(self, decode: Callable[[bytes], Any]) -> None:
        super().__init__(decode)
        self._current: ChunkBatch | None = None
        self._times: list[int] = []  # the current batch's log times (a list: bisected at every row)
        self._entry: tuple[int, tuple[int, bytes]] | None = None  # (position, entry) last asked for
        self._before: tuple[int, bytes] | None = None  # the last message of the batches left behind

    def take(self, batch: ChunkBatch) -> None:
        """The topic's next batch (later than the ones before)."""
        current = self._current
        if current is not None:
            self._before = (int(current.log_times[-1]), current.data[int(current.starts[-1]) : int(current.ends[-1])])
        self._current, self._times, self._entry = batch, batch.log_times.tolist(), None

    def get(self, at_ns: int) -> Any:
        """The latest message taken logged at or before ``at_ns`` (ns), decoded; None if none
        (or it does not decode)."""
        entry = self._before
        current = self._current
        if current is not None:
            k = bisect.bisect_right(self._times, at_ns) - 1
            if k >= 0:
                if self._entry is None or self._entry[0] != k:
                    self._entry = (k, (self._times[k], current.data[int(current.starts[k]) : int(current.ends[k])]))
                entry = self._entry[1]
        return self._value(entry)


class _SampledTopics:
    """The sampled context topics (:data:`SAMPLED_TOPICS`) of a bag, given a chunk at a time as
    the bag is read (:meth:`push`, a chunk ahead of the messages read one by one) and taken
    when the time asked for reaches them: times asked for may go back a little (pulses released
    in stamp order), not before the chunk the latest time reached."""

    def __init__(self, bag: BagReader, names: list[str]) -> None:
        by_hand = {SPEEDS: decode_joint_velocities, TRUTH: decode_truth_speeds}  # sampled by every row
        self.topics = {
            name: _Sampled(
                make_field_decoder(bag.typestore, CONTEXT_TOPICS[name], by_hand[name]) if name in by_hand else make_decoder(bag.typestore, CONTEXT_TOPICS[name])
            )
            for name in names
        }
        self._pending: deque[tuple[int, dict[str, ChunkBatch]]] = deque()  # (first log time, batches)

    def push(self, batches: dict[str, ChunkBatch]) -> None:
        """The topics' messages of the next chunk (each in log-time order; none empty)."""
        if batches:
            self._pending.append((min(int(b.log_times[0]) for b in batches.values()), batches))

    def get(self, at_ns: int) -> dict[str, Any]:
        """Each topic's latest message logged at or before ``at_ns`` (ns), decoded (None if none)."""
        pending = self._pending
        while pending and pending[0][0] <= at_ns:
            for name, batch in pending.popleft()[1].items():
                self.topics[name].take(batch)
        return {name: topic.get(at_ns) for name, topic in self.topics.items()}


def monitor_settings_from_run(run_metadata: dict[str, str], source: str) -> MonitorSettings | None:
    """The monitor's parameters of the run: the parameter file recorded in the run context
    (:data:`MONITOR_PARAMETERS_KEY`) over the shipped defaults, as the node reads them; None when
    the bag records none.

    Raises:
        ConfigError: the recorded parameters are invalid (naming the key).
    """
    text = run_metadata.get(MONITOR_PARAMETERS_KEY)
    if not text:
        return None
    doc = parse_yaml(text, source)
    if not isinstance(doc, dict):
        raise ConfigError(source, "", "top level must be a mapping")
    recorded = ros_parameters(doc, NODE_NAME, source)
    return MonitorSettings.from_values({**shipped_parameters(), **recorded}, source)


def monitor_published_parameters(bag: BagReader) -> dict[str, str]:
    """The parameter values the running monitor published on its ``/diagnostics`` status
    (:meth:`~bearing_rig_sim.monitoring.MonitorSettings.published_parameters`), from the first such
    status recorded in the bag; {} when it has none (a bag of another recorder, an older monitor)."""
    if DIAGNOSTICS not in bag.topics or not bag.topics[DIAGNOSTICS].decodable:
        return {}
    try:
        for _topic, _log_time_ns, _msgtype, message in bag.messages([DIAGNOSTICS]):
            for status in getattr(message, "status", ()):  # diagnostic_msgs/DiagnosticArray
                if status.name == MONITOR_DIAGNOSTIC_NAME:
                    values = {kv.key: kv.value for kv in status.values if kv.key.startswith(PARAMETER_KEY_PREFIX)}
                    if values:
                        return values
    except BagError:
        return {}
    return {}


# ---------------------------------------------------------------------------------------------
# The analysis
# ---------------------------------------------------------------------------------------------
class OfflineAnalysis:
    """One pass over a bag (see the module documentation); use :func:`analyse_bag`."""

    def __init__(
        self,
        bag: BagReader,
        settings: MonitorSettings | None,
        *,
        csv_dir: Path | None,
        max_points: int,
        on_row: Callable[[StatusRow], None] | None,
        on_window: Callable[[SlipWindowRow], None] | None,
    ) -> None:
        self.bag = bag
        self._problems: list[str] = []
        self._check_topics()
        source = "given"
        if settings is None:
            settings, source = self._run_settings()
        criterion = program_criterion(bag.run_metadata)
        if source != "given" and criterion and criterion != settings.criterion:
            settings = settings.replace(criterion=criterion)
            source += f", criterion {criterion!r} from the run's test program"
        self.settings = settings
        self.monitor = SlipMonitor(settings.kinematics(), settings)
        self.schedule = StatusSchedule(self.monitor)
        topics = bag.topics
        self.result = OfflineResult(
            path=bag.path,
            run_metadata=bag.run_metadata,
            topics={n: (t.msgtype, t.message_count) for n, t in sorted(topics.items())},
            complete=bag.complete,
            problems=[],
            settings_source=source,
            stable_confidence=settings.stable_confidence,
            segment_source="program" if topics.get(COMMAND) and topics[COMMAND].message_count else "stretches",
            bag_start=bag.start_ns * 1e-9,
            bag_end=bag.end_ns * 1e-9,
        )
        self._rows = RowDecimator(max_points)
        self._on_row, self._on_window = on_row, on_window
        self._latest = {
            name: _Latest(
                make_field_decoder(bag.typestore, STATUS_TYPE, decode_status_fields) if name == STATUS else make_decoder(bag.typestore, CONTEXT_TOPICS[name])
            )
            for name in self._context
            if name not in SAMPLED_TOPICS
        }
        self._sampled = _SampledTopics(bag, [name for name in self._context if name in SAMPLED_TOPICS])
        self._decode_pulse_message = make_decoder(bag.typestore, PULSE_TYPE)
        self._bad_pulses = 0
        self._unstamped = 0
        self._shaft_of = {topic: shaft for shaft, topic in PULSE_TOPICS.items()}
        self._last_row: StatusRow | None = None
        self._recorded: Any = None
        self._segments = SegmentTracker(self.result.segment_source == "program", program_segment_names(self.result.run_metadata), settings)
        self._order = StampOrder()
        """The pulses in stamp order, not the log's reception order (a held-up recorder)."""
        self._read = 0
        """Messages read from the bag so far."""
        self._read_at: dict[int, tuple[int, int]] = {}
        """Place in the bag and log time (ns) of each pulse held in :attr:`_order`, by id."""
        self._context_before: int | None = None
        """Statuses take the context read before this place (the pulse computing them); None: all."""
        self._context_time = 0
        """... and the sampled topics' messages logged at or before this time, ns."""
        self._log_ns = 0
        """Log time of the last message read, ns."""
        self._commands_ahead: list[tuple[float, Any]] = []
        """Spindle commands read before their stamp: (stamp s, message), in order."""
        self._sinks: list[CsvWriter] = []
        self._csv_dir = csv_dir
        if csv_dir is not None:
            csv_dir.mkdir(parents=True, exist_ok=True)
            self._status_csv = CsvWriter(csv_dir / STATUS_CSV, csv_columns(StatusRow))
            self._windows_csv = CsvWriter(csv_dir / WINDOWS_CSV, csv_columns(SlipWindowRow))
            self._sinks = [self._status_csv, self._windows_csv]

    # -- set-up --------------------------------------------------------------------------------
    def _report(self, problem: str) -> None:
        self._problems.append(problem)
        warnings.warn(problem, BagWarning, stacklevel=4)

    def _check_topics(self) -> None:
        topics = self.bag.topics
        missing = [t for t in PULSE_TOPICS.values() if t not in topics]
        if missing:
            raise BagError(
                f"{self.bag.path}: no fibre-optic pulse topic {' nor '.join(missing)} ({PULSE_TYPE}) in the bag, "
                f"so no slip can be computed (the bag has: {', '.join(sorted(topics)) or 'no topics'})"
            )
        for topic in PULSE_TOPICS.values():
            if topics[topic].msgtype != PULSE_TYPE:
                raise BagError(f"{self.bag.path}: topic {topic} carries {topics[topic].msgtype}, not {PULSE_TYPE}")
            if not topics[topic].message_count:
                self._report(f"{self.bag.path.name}: topic {topic} has no messages: no slip window can be formed")
        self._context = []
        for name, msgtype in CONTEXT_TOPICS.items():
            info = topics.get(name)
            if info is None:
                continue
            if info.msgtype != msgtype:
                self._report(f"{self.bag.path.name}: topic {name} carries {info.msgtype}, not {msgtype}; not used")
            else:
                self._context.append(name)

    def _run_settings(self) -> tuple[MonitorSettings, str]:
        source = f"{self.bag.path} run context {MONITOR_PARAMETERS_KEY}"
        try:
            recorded = monitor_settings_from_run(self.bag.run_metadata, source)
        except ConfigError as exc:
            self._report(f"{exc}; using the shipped config/monitor.yaml")
            recorded = None
        settings, source = (
            (recorded, "the bag's run context (parameters/monitor)")
            if recorded is not None
            else (
                MonitorSettings.from_yaml(),
                "the shipped config/monitor.yaml (the bag records none)",
            )
        )
        published = monitor_published_parameters(self.bag)
        if published:
            settings, problem = settings.with_published(published, f"{self.bag.path.name}: {DIAGNOSTICS}")
            if problem:
                self._report(f"{self.bag.path.name}: the monitor's recorded parameters: {problem}; the file's values kept")
            else:
                source += f", over it the values the running monitor published on {DIAGNOSTICS}"
        return settings, source

    # -- the pass ------------------------------------------------------------------------------
    def run(self) -> OfflineResult:
        """Read the bag once and return the result; CSV files are closed whatever happens."""
        sampled = list(self._sampled.topics)
        topics = [*PULSE_TOPICS.values(), *self._latest, *sampled]  # pulses first: positions 0 and 1
        handlers: list[Callable[[int, bytes], None]] = [functools.partial(self._on_pulse, t) for t in PULSE_TOPICS.values()]
        for name in self._latest:
            handler = {STATUS: self._on_recorded_status, COMMAND: self._on_command, LOAD_CELL: self._on_load_cell}.get(name)
            handlers.append(handler if handler is not None else functools.partial(self._on_context, name))
        read_whole = list(range(len(handlers)))
        try:
            ahead: ChunkBatch | None = None
            for batch in self.bag.ordered_batches(topics):  # each chunk decompressed once for every topic
                parts = {name: batch.of_channels([len(handlers) + k]) for k, name in enumerate(sampled)}
                self._sampled.push({name: part for name, part in parts.items() if part.log_times.size})
                if ahead is not None:  # the sampled topics a chunk ahead of the messages read one by one
                    self._take_batch(ahead, handlers)
                ahead = batch.of_channels(read_whole)
            if ahead is not None:
                self._take_batch(ahead, handlers)
            self._finish()
        finally:
            for sink in self._sinks:
                sink.close()
        result = self.result
        if self._bad_pulses > 1:
            self._report(f"{self.bag.path.name}: {self._bad_pulses} pulses could not be decoded in all")
        failures = {name: latest.failed for name, latest in self._latest.items()} | {name: topic.failed for name, topic in self._sampled.topics.items()}
        for name, failed in failures.items():
            if failed:
                self._report(f"{self.bag.path.name}: topic {name}: {failed} message(s) could not be decoded; not used")
        result.complete = self.bag.complete and not self._problems
        result.problems = list(dict.fromkeys(self.bag.problems + self._problems))
        result.rows = self._rows.result()
        if self._csv_dir is not None:
            result.csv_files = [sink.path for sink in self._sinks] + [write_segments_csv(self._csv_dir / SEGMENTS_CSV, result.segments)]
        return result

    def _take_batch(self, batch: ChunkBatch, handlers: list[Callable[[int, bytes], None]]) -> None:
        """A batch of the messages read one by one (:meth:`.BagReader.ordered_batches`: topic
        positions 0 and 1 the pulses, decoded here as arrays), in the bag's order."""
        codes, times = batch.channel_ids.tolist(), batch.log_times.tolist()
        starts, ends, data = batch.starts.tolist(), batch.ends.tolist(), batch.data
        pulses = _pulses_of(batch)
        topics = list(PULSE_TOPICS.values())
        for k, code in enumerate(codes):
            log_time_ns = times[k]
            while self._commands_ahead and self._commands_ahead[0][0] <= log_time_ns * 1e-9:
                start, command = self._commands_ahead.pop(0)
                for shaft, held in self._order.release_until(start):
                    self._feed(shaft, held)
                for scheduled in self.schedule.advance_to(start):  # the ticks of the ending segment
                    self._emit(scheduled.time, scheduled.reason, scheduled.status)
                self._start_segment(start, command)
            self._read += 1
            self._log_ns = log_time_ns
            pulse = pulses[k] if code < 2 else None
            if pulse is not None:
                self._take_pulse(topics[code], log_time_ns, pulse)
            else:  # another topic, or a pulse that needs the general decoder (or does not decode)
                handlers[code](log_time_ns, data[starts[k] : ends[k]])

    def _on_pulse(self, topic: str, log_time_ns: int, data: bytes) -> None:
        try:
            pulse = decode_pulse(data) if data[:2] == b"\x00\x01" else _pulse_from_message(self._decode_pulse_message(data))
        except BagError as exc:
            self._bad_pulses += 1
            if self._bad_pulses == 1:
                self._report(f"{self.bag.path.name}: topic {topic}: {exc}; such pulses are skipped")
            return
        self._take_pulse(topic, log_time_ns, pulse)

    def _take_pulse(self, topic: str, log_time_ns: int, pulse: Pulse) -> None:
        if pulse.time == 0.0 and unstamped(pulse.time, log_time_ns * 1e-9):  # a counter that does not stamp: the reception time
            self._unstamped += 1
            if self._unstamped == 1:
                self._report(
                    f"{self.bag.path.name}: topic {topic}: pulses with a zero header stamp; their log (reception) "
                    "times are used, whose delivery jitter scatters the slip"
                )
            pulse = dataclasses.replace(pulse, time=log_time_ns * 1e-9)
        shaft = self._shaft_of[topic]
        self.result.pulses[shaft] += 1
        self._read_at[id(pulse)] = (self._read, log_time_ns)
        for ordered in self._order.push(shaft, pulse):
            self._feed(*ordered)

    def _feed(self, shaft: str, pulse: Pulse) -> None:
        """One pulse, in stamp order, through the schedule; its statuses take the context read
        before it (a failure ends the analysis: no later status takes that context)."""
        self._context_before, self._context_time = self._read_at.pop(id(pulse), (None, self._log_ns))
        for scheduled in self.schedule.on_pulse(shaft, pulse):
            if scheduled.reason == "window":
                latest = self.monitor.latest_window
                assert latest is not None
                window = SlipWindowRow(latest.start_time, latest.end_time, latest.inner_ring_speed, latest.cage_speed, latest.slip_rate)
                self.result.windows += 1
                if self._sinks:
                    self._windows_csv.write(window)
                if self._on_window is not None:
                    self._on_window(window)
            self._emit(scheduled.time, scheduled.reason, scheduled.status)
        clock = self.schedule.clock
        if math.isfinite(clock):
            if not math.isfinite(self.result.first_time):
                self.result.first_time = clock
            self.result.last_time = clock
        self._context_before, self._context_time = None, self._log_ns

    def _on_load_cell(self, log_time_ns: int, data: bytes) -> None:
        """The load cell's force, for the axial-load criterion (and the rows)."""
        message, stamp = self._decoded(LOAD_CELL, log_time_ns, data)
        if message is not None:
            self.monitor.add_load(stamp, float(message.wrench.force.z))

    def _finish(self) -> None:
        for shaft, pulse in self._order.flush():
            self._feed(shaft, pulse)
        final = self.schedule.finish()
        if final is not None:
            self._emit(final.time, final.reason, final.status)
            self.result.final_status = final.status
        self.result.segments = self._segments.finish()
        self.result.sweeps = list(self.monitor.sweep.verdicts)

    # -- context topics ------------------------------------------------------------------------
    def _decoded(self, topic: str, log_time_ns: int, data: bytes) -> tuple[Any, float]:
        """The message (None if it does not decode) and its time on the pulse clock, s: its
        ``header.stamp``, unless that lies more than :data:`PLAUSIBLE_STAMP_S` from the pulse
        clock (or, before the first pulse, from the log time): a stamp on another clock, such as
        the monitor's status before its first window. The pulse clock (or log time) is used then."""
        latest = self._latest[topic]
        latest.put(self._read, data)
        message = latest.get()
        if message is None:
            return None, _NAN
        stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
        clock = self._pulse_clock()
        reference = clock if math.isfinite(clock) else log_time_ns * 1e-9
        return message, stamp if abs(stamp - reference) <= PLAUSIBLE_STAMP_S else reference

    def _pulse_clock(self) -> float:
        """The latest pulse stamp read, held in :class:`StampOrder` or not, s (-inf before any)."""
        return max(self.schedule.clock, self._order.clock)

    def _on_context(self, name: str, _log_time_ns: int, data: bytes) -> None:
        self._latest[name].put(self._read, data)

    def _on_recorded_status(self, log_time_ns: int, data: bytes) -> None:
        message, stamp = self._decoded(STATUS, log_time_ns, data)
        if message is None:
            return
        state = int(message.state)
        result = self.result
        result.recorded_statuses += 1
        if result.final_recorded_state != state:
            self._transition(result.recorded_transitions, stamp, state)
        result.final_recorded_state = state
        self._recorded = message
        verdict, speed = getattr(message, "sweep_verdict", ""), float(getattr(message, "sweep_speed", _NAN))
        if verdict and math.isfinite(speed):
            result.recorded_sweeps[sweep_key(speed)] = verdict
        self._segments.recorded(stamp, float(message.cage_speed), state, float(message.confidence), float(message.inner_ring_speed))

    def _on_command(self, log_time_ns: int, data: bytes) -> None:
        """A spindle command; one stamped ahead of the bag's timeline (sent ahead of its start by
        the session) waits until the timeline reaches its stamp. One never reached (an
        interrupted run) started no segment."""
        command, start = self._decoded(COMMAND, log_time_ns, data)
        if command is None:
            return
        if start > log_time_ns * 1e-9:
            self._commands_ahead.append((start, command))
            return
        self._start_segment(start, command)

    def _start_segment(self, start: float, command: Any) -> None:
        window = self.monitor.latest_window
        self._segments.command(
            start,
            float(command.target_speed),
            int(command.profile),
            float(command.ramp_time),
            float(command.acceleration),
            window.inner_ring_speed if window is not None else 0.0,
        )

    def _transition(self, where: list[tuple[float, int]], time: float, state: int) -> None:
        if len(where) < MAX_TRANSITIONS:
            where.append((time, state))
        else:
            self.result.transitions_dropped += 1

    # -- rows ----------------------------------------------------------------------------------
    def _context_values(self) -> dict[str, Any]:
        """The context topics' latest values read before the pulse computing the status."""
        values: dict[str, Any] = {}
        before = self._context_before
        get = {name: latest.get(before) for name, latest in self._latest.items() if name not in (STATUS, COMMAND)}
        get.update(self._sampled.get(self._context_time if before is not None else self._log_ns))
        speeds = get.get(SPEEDS)
        if speeds is not None:
            velocity = dict(zip(speeds.name, speeds.velocity))
            values["counter_inner_ring_speed"] = float(velocity.get("inner_ring", _NAN))
            values["counter_cage_speed"] = float(velocity.get("cage", _NAN))
        truth = get.get(TRUTH)
        if truth is not None:
            values.update(
                truth_inner_ring_speed=float(truth.inner_ring_speed),
                truth_cage_speed=float(truth.cage_speed),
                truth_slip_rate=float(truth.slip_rate),
                truth_axial_load=float(truth.axial_load),
            )
        state = get.get(LOAD_STATE)
        if state is not None:
            values.update(
                axial_load_setpoint=float(state.setpoint),
                load_cell_force=float(state.load_cell_force),
                bearing_force=float(state.bearing_force),
            )
        if get.get(LOAD_SETPOINT) is not None:
            values["axial_load_setpoint"] = float(get[LOAD_SETPOINT].data)
        if get.get(LOAD_CELL) is not None:
            values["load_cell_force"] = float(get[LOAD_CELL].wrench.force.z)
        if get.get(BEARING_FORCE) is not None:
            values["bearing_force"] = float(get[BEARING_FORCE].wrench.force.z)
        if get.get(OUTER_RING_TEMPERATURE) is not None:
            values["outer_ring_temperature"] = float(get[OUTER_RING_TEMPERATURE].temperature)
        if get.get(HOUSING_TORQUE) is not None:
            values["housing_torque"] = float(get[HOUSING_TORQUE].wrench.torque.z)
        if self._recorded is not None:
            values["recorded_state"] = int(self._recorded.state)
            values["recorded_slip_rate"] = float(self._recorded.slip_rate)
        return values

    def _emit(self, time: float, reason: str, status: MonitorStatus) -> None:
        row = StatusRow(
            time=time,
            reason=reason,
            state=int(status.state),
            window_end=_NAN if status.time is None else status.time,
            window_start=_NAN if status.window_start is None else status.window_start,
            inner_ring_speed=status.inner_ring_speed,
            cage_speed=status.cage_speed,
            theoretical_cage_speed=status.theoretical_cage_speed,
            slip_rate=status.slip_rate,
            kinematic_slip_rate=status.kinematic_slip_rate,
            loaded_contact_angle=status.loaded_contact_angle,
            fitted_slope=status.fitted_slope,
            confidence=status.confidence,
            windows=status.windows,
            detail=status.detail,
            **self._context_values(),
        )
        result = self.result
        previous = self._last_row
        if previous is None or previous.state != row.state:
            self._transition(result.transitions, time, row.state)
        if previous is not None:
            result.state_durations[previous.state] = result.state_durations.get(previous.state, 0.0) + (time - previous.time)
        result.status_rows += 1
        self._last_row = row
        self._rows.offer(row)
        if self._sinks:
            self._status_csv.write(row)
        if self._on_row is not None:
            self._on_row(row)
        self._segments.row(row)


def analyse_bag(
    path: str | Path,
    *,
    settings: MonitorSettings | None = None,
    csv_dir: str | Path | None = None,
    max_points: int = DEFAULT_MAX_POINTS,
    on_row: Callable[[StatusRow], None] | None = None,
    on_window: Callable[[SlipWindowRow], None] | None = None,
) -> OfflineResult:
    """Run the monitor offline over a bag's pulses (see the module documentation).

    Args:
        path: bag directory or ``.mcap`` file.
        settings: the monitor's parameters; default: those recorded in the bag's run context
            (``parameters/monitor``), else the shipped ``config/monitor.yaml``.
        csv_dir: when given, every status row and slip window is written there as it is made
            (:data:`STATUS_CSV`, :data:`WINDOWS_CSV`).
        max_points: status rows kept in memory for plots (>= 2).
        on_row / on_window: called with every status row / slip window, in order.

    Raises:
        BagError: not a bag, or a bag without both pulse topics (the message names the missing
            topics); damage is warned about (:class:`BagWarning`) and the result covers what
            could be read (``result.complete`` False).
        ConfigError: the given settings file is invalid.
    """
    with open_bag(path) as bag:
        analysis = OfflineAnalysis(
            bag,
            settings,
            csv_dir=None if csv_dir is None else Path(csv_dir),
            max_points=max_points,
            on_row=on_row,
            on_window=on_window,
        )
        return analysis.run()


picklable.by_fields(OfflineResult)
