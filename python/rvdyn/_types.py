"""Small result types returned by the compiled core (``rvdyn._core``).

They are plain named tuples: unpack them, index them, or read the fields by name.
"""

from __future__ import annotations

from typing import NamedTuple, Union

import numpy as np
from numpy.typing import NDArray

__all__ = ["GapResult", "LineContact", "OperatingPoint"]

FloatOrArray = Union[float, NDArray[np.float64]]


class GapResult(NamedTuple):
    """Exact gap between one pin and a cycloid disc (fixed frame, SI units).

    Attributes
    ----------
    gap : float
        Signed normal gap between the pin circle and the profile [m]; negative = penetration.
    point : numpy.ndarray, shape (2,)
        Contact point on the disc profile [m].
    normal : numpy.ndarray, shape (2,)
        Unit outward normal of the profile at the contact (from the disc towards the pin).
    phi : float
        Curve parameter of the contact in [0, 2 pi) [rad].
    curvature_radius : float
        Signed radius of curvature of the profile at the contact [m] (positive convex).
    """

    gap: float
    point: NDArray[np.float64]
    normal: NDArray[np.float64]
    phi: float
    curvature_radius: float


class LineContact(NamedTuple):
    """Hertz line contact of two parallel cylinders (SI units).

    Each field is a float for scalar inputs, else an array of the broadcast input shape.

    Attributes
    ----------
    half_width : float or numpy.ndarray
        Half width a of the contact strip [m].
    peak_pressure : float or numpy.ndarray
        Peak (central) pressure p0 [Pa].
    mean_pressure : float or numpy.ndarray
        Mean pressure (pi/4) p0 [Pa].
    approach : float or numpy.ndarray
        Approach of the two cylinder axes [m] (Johnson's 2-D formula, a model value).
    """

    half_width: FloatOrArray
    peak_pressure: FloatOrArray
    mean_pressure: FloatOrArray
    approach: FloatOrArray


class OperatingPoint(NamedTuple):
    """Lossless operating point (SI units).

    Attributes
    ----------
    power : float
        Transmitted power [W].
    input_speed : float
        Input (sun) speed [rad/s].
    output_speed : float
        Output (carrier) speed [rad/s] = input_speed / ratio.
    input_torque : float
        Input torque [N m] = power / input_speed.
    output_torque : float
        Output torque [N m] = ratio * input_torque.
    ratio : float
        Transmission ratio [-].
    """

    power: float
    input_speed: float
    output_speed: float
    input_torque: float
    output_torque: float
    ratio: float


def _document_fields(cls: type) -> None:
    """Give each field of ``cls`` the description its class docstring's Attributes section
    gives it (with the unit), instead of the named tuple's "Alias for field number N"."""
    lines = (cls.__doc__ or "").splitlines()
    docs: dict[str, list[str]] = {}
    name = None
    for line in lines:
        text = line.strip()
        head = text.split(" : ", 1)[0]
        if " : " in text and head in cls._fields:  # type: ignore[attr-defined]
            name = head
            docs[name] = [text.split(" : ", 1)[1] + ":"]
        elif name is not None and text and line.startswith(" " * 8):
            docs[name].append(text)
        elif name is not None and not text:
            name = None
    for field_name, words in docs.items():
        getattr(cls, field_name).__doc__ = " ".join(words)


for _cls in (GapResult, LineContact, OperatingPoint):
    _document_fields(_cls)
