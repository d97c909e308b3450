"""Analyses of scenes and results: loaded tooth contact analysis (LTCA), transmission error in both
drive directions, the torque-twist loop (rigidity, lost motion, backlash), the compliance budget
(:mod:`.budget`: which parts the torsional compliance comes from) and contact loads for FEA;
order spectra of dynamic runs (:mod:`.spectrum`), modes about the loaded equilibrium
(:mod:`.modes`) and Campbell diagrams (:mod:`.campbell`). The equilibria are computed by the
Rust core (``rvdyn._core``); docs/model.md, "Quasi-static analysis", gives the formulation and
conventions.

Units are SI: N m, rad, m, N, Pa; results also offer arcmin/arcsec conversions.

Every analysis is callable under its own name here (``rvdyn.analysis.modes(scene)``, as
``rvdyn.modes``): the function takes the name of the submodule that holds it, as ``ltca`` does.
"""

from __future__ import annotations

from .budget import ComplianceBudget, compliance_budget
from .campbell import CampbellDiagram, Crossing, campbell, travel_to_input_speed
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
from .modes import MeshSweep, Modes, modes, modes_at, modes_over_mesh
from .spectrum import ExcitationOrder, OrderSpectrum, SpectrumPeak, excitation_orders, order_spectrum

__all__ = [
    "ARCMIN",
    "ComplianceBudget",
    "compliance_budget",
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
    "Modes",
    "MeshSweep",
    "modes",
    "modes_at",
    "modes_over_mesh",
    "CampbellDiagram",
    "Crossing",
    "campbell",
    "travel_to_input_speed",
    "ExcitationOrder",
    "OrderSpectrum",
    "SpectrumPeak",
    "excitation_orders",
    "order_spectrum",
]
