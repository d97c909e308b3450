"""Analyses of scenes and results: loaded tooth contact analysis (LTCA), transmission error in both
drive directions, the torque-twist loop (rigidity, lost motion, backlash) and contact loads for
FEA; order spectra of dynamic runs (:mod:`.spectrum`), modes about the loaded equilibrium
(:mod:`.modes`) and Campbell diagrams (:mod:`.campbell`). The equilibria are computed by the
Rust core (``rvdyn._core``); docs/model.md, "Quasi-static analysis", gives the formulation and
conventions.

Units are SI: N m, rad, m, N, Pa; results also offer arcmin/arcsec conversions.
"""

from __future__ import annotations

from .ltca import (
    ARCMIN,
    ARCSEC,
    LtcaResult,
    TeHarmonic,
    TransmissionError,
    TwistLoop,
    ltca,
    running_friction,
    tooth_mesh_angles,
    torque_twist,
    transmission_error,
)

__all__ = [
    "ARCMIN",
    "ARCSEC",
    "LtcaResult",
    "TeHarmonic",
    "TransmissionError",
    "TwistLoop",
    "ltca",
    "running_friction",
    "tooth_mesh_angles",
    "torque_twist",
    "transmission_error",
]
