"""The physical preset's figures at rated load quoted in docs/model.md ("The physical preset",
"Load rating, life and friction torque") and docs/validation.md: its main torsional mode, the
quasi-static wind-up, pin and bearing loads, the ISO 76 / ISO 281 bearing figures, and the
dynamic peaks, lives and efficiencies.

    python benches/physical_figures.py [--json PATH]

About 1-3 minutes on a 2-core machine (the 0.13 s dopri5 run takes most of it). Prints one
line per figure; ``--json`` also writes them to a file.
"""

from __future__ import annotations

import argparse
import json
import math
import warnings

import numpy as np

import rvdyn
from rvdyn import _core

ARCMIN = math.pi / (180.0 * 60.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", help="also write the figures to this JSON file")
    args = ap.parse_args()
    out: dict[str, float] = {}

    def say(key: str, value: float, unit: str) -> None:
        out[key] = float(value)
        print(f"{key:48s} {value:.6g} {unit}")

    rated = rvdyn.Scene.physical("rated")
    torque = float(rated["load.torque"])
    for load in ("rated", "paper"):
        m = rvdyn.modes(rvdyn.Scene.physical(load), crank_angle=0.0)
        say(f"main mode {load}: frequency", m.frequency[0], "Hz")
        say(f"main mode {load}: damping ratio", m.damping_ratio[0], "")

    # Quasi-static: one mesh period at 90 (the default) and 360 crank angles.
    res90 = rvdyn.ltca(rated, torque)
    say("LTCA peak pin force, 90 angles", res90.peak_pin_force, "N")
    angles = np.arange(360) * res90.mesh_period / 360.0
    res = rvdyn.ltca(rated, torque, angles)
    say("LTCA peak pin force", res.peak_pin_force, "N")
    say("LTCA loaded pins min", res.loaded_pins.min(), "")
    say("LTCA loaded pins max", res.loaded_pins.max(), "")
    say("LTCA wind-up (mean -TE), roller bearings", -np.mean(res.transmission_error) / ARCMIN, "arcmin")
    rigid = rated.replace(**{"joints": {"kind": "rigid"}})
    say("LTCA wind-up (mean -TE), rigid joints", -np.mean(rvdyn.ltca(rigid, torque, angles).transmission_error) / ARCMIN,
        "arcmin")
    ecc = float(np.linalg.norm(res.eccentric_bearing_force, axis=-1).max())
    crank = float(np.linalg.norm(res.crank_bearing_force, axis=-1).max())
    compiled = _core.CompiledScene.from_json(json.dumps(rated.to_dict()))
    (c_e, c_c), (s_e, s_c) = compiled.bearing_ratings(), compiled.bearing_ratings("static")
    say("ISO 281 rating C_r eccentric", c_e, "N")
    say("ISO 281 rating C_r crank", c_c, "N")
    say("ISO 76 rating C0r eccentric", s_e, "N")
    say("ISO 76 rating C0r crank", s_c, "N")
    say("LTCA peak eccentric bearing load", ecc, "N")
    say("LTCA peak crank bearing load", crank, "N")
    say("LTCA static safety eccentric", s_e / ecc, "")
    say("LTCA static safety crank", s_c / crank, "")

    # Dynamic, started at the kinematic speeds (the preset's ramp meets the load as a step).
    steady = rated.replace(**{"drive.start": "step", "initial": "steady"})
    r = rvdyn.simulate(steady, 0.06, "dopri5", progress=False)
    i0 = int(np.searchsorted(r.t, 0.01))
    say("dynamic 60 ms: peak pin force", np.max(r.pin_force[i0:]), "N")
    say("dynamic 60 ms: peak eccentric bearing load", np.linalg.norm(r.eccentric_bearing_force[i0:], axis=-1).max(), "N")
    say("dynamic 60 ms: peak crank bearing load", np.linalg.norm(r.crank_bearing_force[i0:], axis=-1).max(), "N")
    long = rvdyn.simulate(steady, 0.13, "dopri5", progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        life = long.bearing_life()
    w0 = int(np.searchsorted(long.t, long.steady_window()[0]))
    each = np.linalg.norm(long.eccentric_bearing_force[w0:], axis=-1)
    say("dynamic 0.13 s: smallest eccentric bearing load", each.min(axis=0).min(), "N")
    say("dynamic 0.13 s: largest eccentric bearing load", each.max(), "N")
    for fam in ("eccentric", "crank"):
        say(f"dynamic 0.13 s: {fam} equivalent load", life[fam]["equivalent_load"], "N")
        say(f"dynamic 0.13 s: {fam} L10", life[fam]["l10_million_revolutions"], "million rev")
        say(f"dynamic 0.13 s: {fam} L10 hours", life[fam]["l10_hours"], "h")
        say(f"dynamic 0.13 s: {fam} static safety", life[fam]["static_safety"], "")
    for mu_pin, mu_mesh in ((0.05, 0.05), (0.1, 0.05)):
        f = rvdyn.simulate(steady.replace(**{"friction.pin": mu_pin, "friction.mesh": mu_mesh}), 0.06, "dopri5",
                           progress=False)
        j0 = int(np.searchsorted(f.t, 0.02))
        tag = f"friction pins {mu_pin} teeth {mu_mesh}"
        say(f"{tag}: efficiency", f.efficiency(0.02), "")
        say(f"{tag}: peak pin force", np.max(f.pin_force[j0:]), "N")
        say(f"{tag}: peak eccentric bearing load", np.linalg.norm(f.eccentric_bearing_force[j0:], axis=-1).max(), "N")
        for part, watts in f.friction_power_means(0.02).items():
            say(f"{tag}: friction power {part}", watts, "W")
    start = rvdyn.simulate(rated, 0.01, "dopri5", progress=False)
    k = int(np.argmax(np.max(start.pin_force.reshape(len(start.t), -1), axis=1)))
    say("from rest: first peak pin force", np.max(start.pin_force[k]), "N")
    say("from rest: time of the first peak", start.t[k], "s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
