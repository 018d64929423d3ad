"""Thermal properties of the bearing's materials and the cavity's fluids (SI units).

Each value carries its source; all are handbook values at 20-100 degC, where they change by a
few percent, so they are held constant.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ThermalMaterial:
    """Specific heat c (J/(kg K)), thermal conductivity k (W/(m K)) and linear thermal expansion
    coefficient alpha (1/K; 0 where not needed) of a solid, with source."""

    name: str
    specific_heat: float
    conductivity: float
    source: str
    expansion: float = 0.0


BEARING_STEEL = ThermalMaterial(
    "AISI 52100 / GCr15 through-hardened bearing steel",
    475.0,
    46.6,
    "ASM Handbook vol. 1 (properties of AISI 52100; c 475 J/(kg K), k 46.6 W/(m K) at 20-100 degC, "
    "alpha 11.9e-6 1/K at 20-100 degC); Harris and Kotzalas, Essential Concepts, table of bearing "
    "steel properties (k 40-47 W/(m K)); bearing makers quote alpha 11-12.5e-6 1/K",
    11.9e-6,
)
POLYIMIDE = ThermalMaterial(
    "polyimide (cage)",
    1130.0,
    0.35,
    "DuPont Vespel SP-1 data sheet: c 1130 J/(kg K), k 0.29-0.35 W/(m K)",
)


@dataclass(frozen=True)
class Fluid:
    """A fluid's density (kg/m^3), specific heat (J/(kg K)), conductivity (W/(m K)) and kinematic
    viscosity (m^2/s) at the film temperature, for convection correlations."""

    density: float
    specific_heat: float
    conductivity: float
    kinematic_viscosity: float

    @property
    def prandtl(self) -> float:
        """Pr = rho c nu / k (1)."""
        return self.density * self.specific_heat * self.kinematic_viscosity / self.conductivity


AIR_40C = Fluid(1.127, 1007.0, 0.0271, 1.70e-5)
"""Dry air at 40 degC and 1 atm (Incropera and DeWitt, Fundamentals of Heat and Mass Transfer,
table A.4)."""
