"""Reducer scenes: a validated, serialisable description of one reducer and its load case.

A :class:`Scene` owns a scene compiled by the Rust core (``rvdyn._core.CompiledScene``): the
schema exists once, in Rust, and is validated once, when the scene is built; :func:`simulate`
and :func:`sweep` take the compiled scene as it is. Every value is SI (m, kg, s, N, rad).
Fields are addressed by dotted paths, with list indices as numbers: ``"load.torque"``,
``"discs.1.d_rrp"``, ``"cycloid.pin_radius"``. Every field, with its unit, default and rule, is
listed in ``docs/scene.md`` (generated from the code).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, NoReturn, final

from . import _core
from .errors import SceneError

__all__ = ["Scene"]



def _plain(value: Any) -> Any:
    """numpy scalars and arrays as Python numbers and lists (for JSON)."""
    if hasattr(value, "tolist") and callable(value.tolist):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not a number, string, list or dict")


def _json_value(path: str, value: Any) -> str:
    try:
        return json.dumps(value, allow_nan=False, default=_plain)
    except RecursionError as exc:
        raise SceneError(f"scene field {path!r}: the value is nested too deeply to be a scene value") from exc
    except (TypeError, ValueError) as exc:
        raise SceneError(
            f"scene field {path!r}: values must be numbers, strings, lists or dicts without NaN/inf ({exc})"
        ) from None


@final
class Scene:
    """One reducer with its drive, load and initial state, validated on construction.

    Build one with :meth:`Scene.paper`, from a dict (``Scene(data)``), or from a file
    (:meth:`load`, :meth:`from_json`, :meth:`from_toml`); change fields with :meth:`replace`.
    Scenes are immutable values: equal scenes compare and hash equal, and they pickle.

    >>> s = Scene.paper("rated").replace(**{"cycloid.d_rrp": 2e-5, "initial": "steady"})
    >>> round(s["load.torque"], 1)  # N m
    43921.3
    >>> s == Scene.from_json(s.to_json())
    True
    """

    __slots__ = ("_compiled",)
    _compiled: _core.CompiledScene

    def __init__(self, data: dict[str, Any]):
        if not isinstance(data, dict):
            raise SceneError(f"a scene is built from a dict, got {type(data).__name__}")
        object.__setattr__(self, "_compiled", _core.CompiledScene.from_json(_json_value("scene", data)))

    @classmethod
    def _wrap(cls, compiled: _core.CompiledScene) -> Scene:
        scene = cls.__new__(cls)
        object.__setattr__(scene, "_compiled", compiled)
        return scene

    def __setattr__(self, name: str, value: object) -> NoReturn:
        raise AttributeError("Scene is immutable: use scene.replace(...) for a changed copy")

    def __delattr__(self, name: str) -> NoReturn:
        raise AttributeError("Scene is immutable")

    # ------------------------------------------------------------------ construction
    @classmethod
    def paper(cls, load: str = "paper", /, **changes: Any) -> Scene:
        """The default scene (``docs/model.md#default-scene``) at 8328 deg/s with a step start
        from rest.

        ``load``: ``"idle"``, ``"paper"`` (the printed 4024.9 N m on the output) or
        ``"rated"`` (43.9 kN m = 57 x 770.6 N m, consistent with 112 kW); positional, or as
        the keyword ``load=``. ``changes``: dotted field paths and values, as for
        :meth:`replace`.

        >>> Scene.paper(load="rated") == Scene.paper("rated")
        True
        """
        if "load" in changes and not isinstance(changes["load"], dict):
            # Scene.paper(load="rated"): the load case given by keyword, not a field change.
            if load != "paper":
                raise SceneError(
                    "give the load case once: Scene.paper('rated') or Scene.paper(load='rated')"
                )
            load = changes.pop("load")
        if not isinstance(load, str):
            raise SceneError(
                f"the load case must be 'idle', 'paper' or 'rated' (Scene.paper('rated')), got {load!r}; "
                "to set a load law use Scene.paper().replace(load={'kind': 'constant', 'torque': ...})"
            )
        scene = cls._wrap(_core.CompiledScene.paper(load))
        return scene.replace(**changes) if changes else scene

    @classmethod
    def physical(cls, load: str = "rated", /, **changes: Any) -> Scene:
        """The physical preset: the paper's reducer with its physics derived from geometry and
        materials (``docs/model.md``, "The physical preset"): line-contact pins (Johnson, local
        profile curvature), ISO 6336-1 meshes varying along the line of action, needle and
        roller bearings built from their rollers with clearance (compliant joints),
        stiffness-proportional damping with ratio 0.05 at 1790 Hz (the main torsional mode at
        rated load; other modes in proportion to their frequency), and a 50 ms ramp from rest
        to the paper's input speed (use ``drive.start="step"`` with ``initial="steady"``).

        ``load``: ``"idle"``, ``"paper"`` or ``"rated"`` as for :meth:`paper`; ``changes``:
        dotted field paths and values, as for :meth:`replace`.

        >>> Scene.physical("rated")["contact.pin.kind"]
        'line'
        """
        if not isinstance(load, str):
            raise SceneError(f"the load case must be 'idle', 'paper' or 'rated', got {load!r}")
        scene = cls._wrap(_core.CompiledScene.physical(load))
        return scene.replace(**changes) if changes else scene

    @classmethod
    def from_json(cls, text: str) -> Scene:
        """A scene from JSON text (the schema of ``docs/scene.md``; unknown fields are errors)."""
        return cls._wrap(_core.CompiledScene.from_json(text))

    @classmethod
    def from_toml(cls, text: str) -> Scene:
        """A scene from TOML text."""
        return cls._wrap(_core.CompiledScene.from_toml(text))

    def with_compliant_joints(self, eccentric_bearing: dict[str, float] | None = None,
                              crank_bearing: dict[str, float] | str | None = None) -> Scene:
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

    def replace(self, **changes: Any) -> Scene:
        """A new scene with fields changed; keys are dotted paths (pass them with ``**{...}``).

        Setting a whole sub-dictionary (e.g. ``load={"kind": "constant", "torque": 1e3}``)
        replaces it. The result is validated (in Rust): a wrong value or an unknown field
        raises :class:`SceneError` or :class:`GeometryError` naming the field.
        """
        if not changes:
            return self
        items = [(path, _json_value(path, value)) for path, value in changes.items()]
        return Scene._wrap(self._compiled.replace(items))

    # ------------------------------------------------------------------ reading
    def __getitem__(self, path: str) -> Any:
        """Value of a dotted field path, e.g. ``scene["load.torque"]`` (a copy)."""
        if not isinstance(path, str):
            raise SceneError(f"a scene field path must be a string like 'load.torque', got {path!r}")
        return json.loads(self._compiled.get(path))

    def to_dict(self) -> dict[str, Any]:
        """The scene as a plain dictionary (SI values; a copy)."""
        data: dict[str, Any] = json.loads(self._compiled.to_json(indent=False))
        return data

    def to_json(self) -> str:
        """The scene as JSON text."""
        return self._compiled.to_json()

    def to_toml(self) -> str:
        """The scene as TOML text."""
        return self._compiled.to_toml()

    def save(self, path: str | Path) -> Path:
        """Write the scene to ``path``: TOML for ``.toml`` (any case), JSON otherwise. Returns the path."""
        p = Path(path)
        text = self.to_toml() if p.suffix.lower() == ".toml" else self.to_json()
        p.write_text(text, encoding="utf-8")
        return p

    @classmethod
    def load(cls, path: str | Path) -> Scene:
        """Read a scene written by :meth:`save` (TOML for ``.toml`` in any case, JSON otherwise)."""
        p = Path(path)
        try:
            text = p.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise SceneError(f"cannot read scene file {str(p)!r}: {exc}") from exc
        try:
            return cls.from_toml(text) if p.suffix.lower() == ".toml" else cls.from_json(text)
        except SceneError as exc:
            raise SceneError(f"scene file {str(p)!r}: {exc}") from exc

    def model_info(self) -> dict[str, Any]:
        """Mass properties the model uses (computed ones included) [kg, kg m^2], the
        generalised masses of the rigid model's (carrier, crank, sun, load, motor) [kg m^2] (the
        load and motor entries are coordinates only with ``shafts.output`` / ``shafts.input``;
        without them the load inertia is in the carrier's and the motor inertia in the sun's;
        a scene without a first stage has no sun: its mass and entry are 0), crank radius [m],
        ratio and DOF count."""
        return dict(self._compiled.model_info())

    @property
    def ratio(self) -> float:
        """Transmission ratio input speed / output speed [-] (57 for the paper). Negative
        without a first stage (``-zc``: the output turns against the cranks)."""
        return float(self.model_info()["ratio"])

    @property
    def nominal_mesh_force(self) -> float | None:
        """Nominal tangential force of one sun/planet mesh [N] at the load's largest torque
        magnitude: ``2 T_sun / (d_sun planets)`` with ``T_sun`` that torque over the ratio
        (ISO 6336-1 clause 6; 9.5 kN for ``Scene.paper("rated")``). 0 for an idle scene, None
        without a first stage."""
        return self._compiled.nominal_mesh_force()

    @property
    def light_load(self) -> bool:
        """Whether the load is light: idle, or a :attr:`nominal_mesh_force` below 10 N (below
        about 1e-3 of the paper's rated torque). Its contact forces are a few newtons, which the
        loaded scenes' default integrators do not resolve: such a scene runs ``IDLE_DEFAULT``
        (docs/validation.md, "Idle rattle and light loads"). A scene without a first stage is
        light only when idle."""
        return self._compiled.is_light_load()

    # ------------------------------------------------------------------ value semantics
    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and self._compiled == other._compiled

    def __hash__(self) -> int:
        return hash(self._compiled)

    def __reduce__(self) -> tuple[Any, tuple[str]]:
        return (Scene.from_json, (self._compiled.to_json(indent=False),))

    def __repr__(self) -> str:
        d = self.to_dict()
        return f"Scene(name={d.get('name')!r}, load={d.get('load')}, joints={d.get('joints', {}).get('kind')!r})"
