"""A lumped linear thermal network, integrated exactly over each step.

Nodes i carry a heat capacity C_i (J/K) and a temperature T_i (degC); conductances G_ij (W/K)
join two nodes or a node and a boundary held at a fixed temperature (ambient, oil inlet). With
heat inputs q_i (W) held constant over a step of length h:

    C dT/dt = -L T + G_b T_b + q,      L = the conductance Laplacian plus the boundary conductances

This is a small linear ODE dT/dt = A T + b, A = -C^-1 L, b = C^-1 (G_b T_b + q). Over a step
with constant q its exact solution is

    T(t + h) = Phi T(t) + Psi_1 b,   int_t^(t+h) T = Psi_1 T(t) + Psi_2 b,

Phi = expm(A h), Psi_1 = int_0^h expm(A s) ds, Psi_2 = int_0^h int_0^s expm(A r) dr ds, the
three blocks of one exponential of the block matrix [[A, I, 0], [0, 0, I], [0, 0, 0]] h (Van
Loan 1978). It is unconditionally stable at any h (Phi's eigenvalues are exp(-h / tau_k) in
(0, 1]), needs no inverse of L (a node insulated from every boundary integrates too: its heat
stays in it), and the heat leaving through the boundaries over the step is exact too: the
energy account (heat in = stored + out) closes to rounding. The blocks are cached per step
length.

The time constants are tau_k = 1 / lambda_k, lambda_k the eigenvalues of C^-1 L
(:meth:`ThermalNetwork.time_constants`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from collections.abc import Mapping, Sequence

import numpy as np
from scipy.linalg import expm

from bearing_rig_sim.errors import RigError


class ThermalNetworkError(RigError):
    """A network that cannot be built or a heat input that cannot be applied."""


@dataclass(frozen=True)
class Node:
    """A lumped body: name, heat capacity (J/K) and where the capacity comes from."""

    name: str
    capacity: float
    source: str


@dataclass(frozen=True)
class Conductance:
    """A thermal conductance (W/K) between two nodes or a node and a boundary, with its source."""

    a: str
    b: str
    value: float
    source: str


class ThermalNetwork:
    """Lumped network of :class:`Node` joined by :class:`Conductance`, with fixed-temperature
    boundaries.

    Args:
        nodes: the bodies (capacity > 0).
        conductances: each joins two of ``nodes`` or a node and a boundary (value >= 0).
        boundaries: boundary name -> temperature, degC.
        initial: start temperature of every node, degC (default: the first boundary's).
        insulated: accept nodes with no conductive path to a boundary (a transient with no
            steady state: :meth:`steady` then raises); default False refuses them.

    Raises:
        ThermalNetworkError: an unknown node, a non-positive capacity, a negative or non-finite
            conductance, a node with no path to a boundary (no steady state) unless
            ``insulated``.
    """

    def __init__(
        self,
        nodes: Sequence[Node],
        conductances: Sequence[Conductance],
        boundaries: Mapping[str, float],
        initial: float | None = None,
        *,
        insulated: bool = False,
    ) -> None:
        self.nodes = tuple(nodes)
        self.conductances = tuple(conductances)
        self.names = tuple(n.name for n in self.nodes)
        self.boundary_names = tuple(boundaries)
        self.boundary_temperatures = np.array([float(boundaries[b]) for b in self.boundary_names])
        index = {n: i for i, n in enumerate(self.names)}
        bindex = {b: i for i, b in enumerate(self.boundary_names)}
        n = len(self.nodes)
        self.capacity = np.array([nd.capacity for nd in self.nodes], dtype=float)
        if not np.all(np.isfinite(self.capacity)) or np.any(self.capacity <= 0.0):
            raise ThermalNetworkError(f"heat capacities must be finite and > 0 J/K: {dict(zip(self.names, self.capacity))}")
        lap = np.zeros((n, n))
        gb = np.zeros((n, len(self.boundary_names)))
        for c in self.conductances:
            if not math.isfinite(c.value) or c.value < 0.0:
                raise ThermalNetworkError(f"conductance {c.a}-{c.b} must be finite and >= 0 W/K, got {c.value!r}")
            ia, ib = index.get(c.a), index.get(c.b)
            if ia is None:
                ia, ib, other = index.get(c.b), None, c.a
            else:
                other = c.b
            if ia is None:
                raise ThermalNetworkError(f"conductance {c.a}-{c.b} names no node of the network")
            if ib is None:
                ib = index.get(other)
            if ib is not None:
                lap[ia, ia] += c.value
                lap[ib, ib] += c.value
                lap[ia, ib] -= c.value
                lap[ib, ia] -= c.value
            elif other in bindex:
                lap[ia, ia] += c.value
                gb[ia, bindex[other]] += c.value
            else:
                raise ThermalNetworkError(f"conductance {c.a}-{c.b}: {other!r} is neither a node nor a boundary")
        self.laplacian = lap
        self.boundary_conductance = gb
        self._lap_inv: np.ndarray | None = None
        if np.linalg.cond(lap) <= 1e14:
            try:
                self._lap_inv = np.linalg.inv(lap)
            except np.linalg.LinAlgError:
                self._lap_inv = None
        if self._lap_inv is not None and not np.all(np.isfinite(self._lap_inv)):
            self._lap_inv = None
        if self._lap_inv is None and not insulated:
            raise ThermalNetworkError("a node has no conductive path to a boundary: no steady state")
        self._a = -lap / self.capacity[:, None]
        self._cache: dict[float, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        t0 = float(self.boundary_temperatures[0]) if initial is None else float(initial)
        self.temperatures = np.full(n, t0)
        self.initial_temperatures = self.temperatures.copy()
        self.heat_in = 0.0
        """Heat put into the nodes since the start, J."""
        self.heat_out = 0.0
        """Heat that left through the boundaries since the start, J."""
        self.time = 0.0
        """Integrated time, s."""

    # -- queries -------------------------------------------------------------------------------
    def index(self, name: str) -> int:
        """Position of node ``name``."""
        try:
            return self.names.index(name)
        except ValueError:
            raise ThermalNetworkError(f"no node {name!r}; nodes: {', '.join(self.names)}") from None

    def heat_vector(self, heat: Mapping[str, float]) -> np.ndarray:
        """The heat inputs by node name (W) as a vector (unnamed nodes 0)."""
        q = np.zeros(len(self.nodes))
        for name, value in heat.items():
            if not math.isfinite(value):
                raise ThermalNetworkError(f"heat into {name} must be finite, got {value!r}")
            q[self.index(name)] += value
        return q

    def steady(self, heat: Mapping[str, float] | np.ndarray) -> np.ndarray:
        """Steady temperatures (degC) under constant heat inputs (W): L^-1 (G_b T_b + q)."""
        q = heat if isinstance(heat, np.ndarray) else self.heat_vector(heat)
        if self._lap_inv is None:
            raise ThermalNetworkError("a node has no conductive path to a boundary: no steady state")
        return np.asarray(self._lap_inv @ (self.boundary_conductance @ self.boundary_temperatures + q))

    def time_constants(self) -> np.ndarray:
        """The network's time constants, s, longest first (1 / eigenvalues of C^-1 L)."""
        lam = np.linalg.eigvals(-self._a).real
        return np.sort(1.0 / lam)[::-1]

    def stored_energy(self) -> float:
        """Heat stored since the start, J: sum C_i (T_i - T_i,0)."""
        return float(self.capacity @ (self.temperatures - self.initial_temperatures))

    def temperature(self, name: str) -> float:
        """Temperature of node ``name``, degC."""
        return float(self.temperatures[self.index(name)])

    # -- integration ---------------------------------------------------------------------------
    def _propagators(self, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        key = round(h, 12)
        got = self._cache.get(key)
        if got is None:
            n = len(self.nodes)
            block = np.zeros((3 * n, 3 * n))
            block[:n, :n] = self._a * h
            block[:n, n : 2 * n] = np.eye(n) * h
            block[n : 2 * n, 2 * n :] = np.eye(n) * h
            e = expm(block)
            if len(self._cache) > 16:
                self._cache.clear()
            got = self._cache[key] = (e[:n, :n], e[:n, n : 2 * n], e[:n, 2 * n :])
        return got

    def step(self, heat: Mapping[str, float] | np.ndarray, h: float) -> np.ndarray:
        """Advance by ``h`` seconds (> 0) with the heat inputs (W) held constant; returns the new
        temperatures (degC) and books the heat in and out."""
        if not math.isfinite(h) or h <= 0.0:
            raise ThermalNetworkError(f"step must be finite and > 0 s, got {h!r}")
        q = heat if isinstance(heat, np.ndarray) else self.heat_vector(heat)
        phi, psi1, psi2 = self._propagators(h)
        gb = self.boundary_conductance
        b = (gb @ self.boundary_temperatures + q) / self.capacity
        integral = psi1 @ self.temperatures + psi2 @ b
        self.heat_out += float(np.sum(gb.sum(axis=1) * integral) - np.sum(gb @ self.boundary_temperatures) * h)
        self.heat_in += float(np.sum(q)) * h
        self.temperatures = phi @ self.temperatures + psi1 @ b
        self.time += h
        return self.temperatures

    def energy_residual(self) -> float:
        """heat in - stored - out since the start, J (zero up to rounding)."""
        return self.heat_in - self.stored_energy() - self.heat_out
