"""Reducer scenes: a validated, serialisable description of one reducer and its load case.

A :class:`Scene` wraps a nested dictionary whose schema is defined (and validated) by the Rust
core; every value is SI (m, kg, s, N, rad). Fields are addressed by dotted paths, with list
indices as numbers: ``"load.torque"``, ``"discs.1.d_rrp"``, ``"cycloid.pin_radius"``.

Top-level fields: ``name``; ``stage1`` (involute stage or ``None``); ``cycloid`` (pins,
eccentricity, pin_circle_radius, pin_radius, face_width, d_rp, d_rrp, d_delta); ``discs`` (one
or two ``{phase, d_rp, d_rrp, d_delta}``, the modifications overriding ``cycloid``'s);
``cranks``; ``pin_errors`` (``position`` (zp, 2) [m], ``radius`` (zp,) [m]); ``density``;
``inertias`` (``sun``/``crank``/``disc``/``carrier``: ``{mass, inertia}`` or ``None`` =
computed from the geometry; ``load_inertia``); ``joints`` (``{"kind": "rigid"}``);
``contact`` (``pin`` and ``mesh`` laws: ``{"kind": "impact", stiffness [N/m^e], exponent,
max_damping [N s/m], damping_depth [m]}`` or ``{"kind": "palmgren", max_damping,
damping_depth}``); ``drive`` (``{"kind": "speed", speed [rad/s], start: "step"|"ramp",
ramp_time [s]}`` or ``{"kind": "torque", torque [N m], ramp_time}``); ``load`` (``idle``,
``constant`` {torque}, ``step`` {before, after, time}, ``table`` {points: [[t, torque], ...]});
``initial`` (``"rest"`` or ``"steady"``).
"""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

from . import _core
from .errors import SceneError

__all__ = ["Scene"]


def _split(path: str) -> list[str | int]:
    if not isinstance(path, str) or not path:
        raise SceneError(f"a scene field path must be a non-empty string like 'load.torque', got {path!r}")
    return [int(p) if p.isdigit() else p for p in path.split(".")]


class Scene:
    """One reducer with its drive, load and initial state (validated on construction).

    Build one with :meth:`Scene.paper` and change fields with :meth:`replace`; scenes are
    immutable values (``replace`` returns a new, validated scene).

    >>> s = Scene.paper("rated").replace(**{"cycloid.d_rrp": 2e-5, "initial": "steady"})
    >>> s["load.torque"]  # N m
    43922.7...
    """

    __slots__ = ("_data",)

    def __init__(self, data: dict[str, Any]):
        if not isinstance(data, dict):
            raise SceneError(f"a scene is built from a dict, got {type(data).__name__}")
        try:
            text = json.dumps(data, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise SceneError(f"scene values must be numbers, strings, lists or dicts without NaN/inf: {exc}") from None
        self._data: dict[str, Any] = json.loads(_core.scene_validate(text))

    @classmethod
    def paper(cls, load: str = "paper", /, **changes: Any) -> "Scene":
        """The default scene (design.md section 7) at 8328 deg/s with a step start from rest.

        ``load``: ``"idle"``, ``"paper"`` (the printed 4024.9 N m on the output) or
        ``"rated"`` (43.9 kN m = 57 x 770.6 N m, consistent with 112 kW). ``changes``: dotted
        field paths and values, as for :meth:`replace`.
        """
        scene = cls(json.loads(_core.scene_paper(load)))
        return scene.replace(**changes) if changes else scene

    def with_compliant_joints(self, eccentric_bearing: dict[str, float] | None = None,
                              crank_bearing: dict[str, float] | str | None = None) -> "Scene":
        """This scene with compliant joints: spring-damper bearings between each eccentric and
        its disc hole and between each crank and the carrier (``{stiffness [N/m], damping
        [N s/m], clearance [m]}``, changes to the defaults); the discs and crank centres then
        move freely. ``crank_bearing="rigid"`` keeps the crank bearings ideal (the crank centres
        stay in their seats) with compliant eccentric bearings. Defaults are the assumed values
        of ``rvdyn._core.default_compliant_joints()`` (eccentric needle bearing 1e9 N/m,
        1e4 N s/m; crank bearing 2e9 N/m, 1e4 N s/m; no clearance)."""
        joints = json.loads(_core.default_compliant_joints())
        if eccentric_bearing:
            joints["eccentric_bearing"].update(eccentric_bearing)
        if crank_bearing == "rigid":
            joints["crank_bearing"] = None
        elif isinstance(crank_bearing, str):
            raise SceneError(f"crank_bearing must be a dict of changes or 'rigid', got {crank_bearing!r}")
        elif crank_bearing:
            joints["crank_bearing"].update(crank_bearing)
        return self.replace(joints=joints)

    def to_dict(self) -> dict[str, Any]:
        """A deep copy of the scene as a plain dictionary (SI values)."""
        return copy.deepcopy(self._data)

    def to_json(self) -> str:
        """The scene as JSON text."""
        return json.dumps(self._data, indent=2)

    def __getitem__(self, path: str) -> Any:
        """Value of a dotted field path, e.g. ``scene["load.torque"]``."""
        node: Any = self._data
        for key in _split(path):
            try:
                node = node[key]
            except (KeyError, IndexError, TypeError):
                raise SceneError(f"scene has no field {path!r} (at {key!r})") from None
        return copy.deepcopy(node)

    def replace(self, **changes: Any) -> "Scene":
        """A new scene with fields changed; keys are dotted paths (pass them with ``**{...}``).

        Setting a whole sub-dictionary (e.g. ``load={"kind": "constant", "torque": 1e3}``)
        replaces it. The result is validated: a wrong value raises :class:`SceneError` or
        :class:`GeometryError` naming the field.
        """
        data = self.to_dict()
        for path, value in changes.items():
            keys = _split(path)
            node: Any = data
            for key in keys[:-1]:
                try:
                    node = node[key]
                except (KeyError, IndexError, TypeError):
                    raise SceneError(f"scene has no field {path!r} (at {key!r})") from None
            last = keys[-1]
            if isinstance(node, dict) or (isinstance(node, list) and isinstance(last, int) and last < len(node)):
                node[last] = copy.deepcopy(value)
            else:
                raise SceneError(f"scene has no field {path!r}")
        return Scene(data)

    def save(self, path: str | Path) -> Path:
        """Write the scene to ``path``: TOML for ``.toml``, JSON otherwise. Returns the path."""
        p = Path(path)
        text = _core.scene_to_toml(json.dumps(self._data)) if p.suffix == ".toml" else self.to_json()
        p.write_text(text, encoding="utf-8")
        return p

    @classmethod
    def load(cls, path: str | Path) -> "Scene":
        """Read a scene written by :meth:`save` (TOML for ``.toml``, JSON otherwise)."""
        p = Path(path)
        try:
            text = p.read_text(encoding="utf-8")
        except OSError as exc:
            raise SceneError(f"cannot read scene file {str(p)!r}: {exc.strerror}") from None
        if p.suffix == ".toml":
            return cls(json.loads(_core.scene_from_toml(text)))
        try:
            return cls(json.loads(text))
        except json.JSONDecodeError as exc:
            raise SceneError(f"scene file {str(p)!r} is not valid JSON: {exc}") from None

    def model_info(self) -> dict[str, Any]:
        """Mass properties the model uses (computed ones included) [kg, kg m^2], the
        generalised masses of (carrier, crank, sun), crank radius [m], ratio and DOF count."""
        return dict(_core.scene_model_info(json.dumps(self._data)))

    @property
    def ratio(self) -> float:
        """Transmission ratio input speed / output speed (57 for the paper)."""
        return float(self.model_info()["ratio"])

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and self._data == other._data

    def __hash__(self) -> int:
        return hash(json.dumps(self._data, sort_keys=True))

    def __repr__(self) -> str:
        load = self._data.get("load", {})
        return f"Scene(name={self._data.get('name')!r}, load={load}, joints={self._data.get('joints', {}).get('kind')!r})"
