"""The command line, run as a user would: ``python -m rvdyn ...`` in a subprocess."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
import warnings

import pytest

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "rvdyn", *args], capture_output=True,
                          text=True, timeout=300, cwd=cwd)


def test_info_json_has_the_numbers():
    r = run("info", "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    kin = d["kinematics"]
    assert kin["ratio"] == 57.0
    assert kin["speeds"]["sun"]["deg_s"] == pytest.approx(8328.0, rel=1e-14)
    assert kin["speeds"]["carrier"]["deg_s"] == pytest.approx(146.105, abs=1e-3)
    for body in ("sun", "crank_absolute", "crank_relative", "disc_spin", "disc_orbit",
                 "carrier"):
        v = kin["speeds"][body]
        assert v["rad_s"] == pytest.approx(v["deg_s"] * 3.141592653589793 / 180, rel=1e-14)
    op = d["operating_point"]
    assert op["input_torque_Nm"] == pytest.approx(770.6, abs=0.1)
    assert op["output_torque_Nm"] == pytest.approx(43.92e3, abs=10)
    assert op["paper_printed_output_torque_Nm"] == 4024.9
    assert op["paper_printed_output_torque_consistent"] is False
    assert op["paper_printed_output_power_W"] == pytest.approx(10.26e3, abs=10)
    cyc = d["geometry"]["cycloid"]
    assert cyc["k1"] == pytest.approx(0.72, abs=1e-12)
    assert cyc["min_convex_radius_m"] == pytest.approx(20.75e-3, abs=0.01e-3)
    assert cyc["pitch_radius_m"] == pytest.approx(0.1035, abs=1e-12)
    assert cyc["root_curvature_radius_m"] == pytest.approx(-10.72e-3, abs=0.005e-3)
    assert cyc["disc_mass_kg"] == pytest.approx(14.7, rel=0.02)
    assert cyc["disc_inertia_kg_m2"] == pytest.approx(0.163, rel=0.02)
    assert d["geometry"]["involute"]["contact_ratio"] == pytest.approx(1.63, abs=0.005)
    st = d["stiffness"]
    assert st["r1_m"] == 0.010 and st["r2_m"] == 0.1035
    for cond, paper in (("convex-convex", 3.988e5), ("convex-concave", 5.093e5)):
        e = st["conditions"][cond]
        assert e["paper_maximum_N_per_mm1_5"] == paper
        assert e["k_at_5mm_N_per_mm1_5"] == pytest.approx(
            e["k_at_5mm_N_per_m1_5"] / 1000**1.5, rel=1e-14)
        # Errata corrected: no maximum over physical widths (reported, not hidden).
        assert e["maximum"] is None and "no interior maximum" in e["maximum_note"]
        assert e["formal_maximum"]["width_m"] < 1e-6
    assert st["conditions"]["convex-convex"]["k_at_5mm_N_per_mm1_5"] == \
        pytest.approx(28408.99, rel=1e-6)


def test_info_text():
    r = run("info")
    assert r.returncode == 0, r.stderr
    for fragment in ("ratio i", "= 57", "146.105 deg/s", "770.55 N m", "43.92 kN m",
                     "INCONSISTENT", "10.3 kW", "K1 = 0.7200", "convex-concave"):
        assert fragment in r.stdout, fragment
    # The presets' table: each column starts where its heading does, one blank column at
    # least before it (an entry longer than its column used to run into the next).
    lines = r.stdout.splitlines()
    top = lines.index("Presets side by side (rated load)")
    head = lines[top + 1]
    cols = [head.index("paper"), head.index("physical")]
    body = lines[top + 2:top + 10]
    assert body[0].strip().startswith("pin contact law") and body[-1].strip().startswith("torsional stiffness")
    # The physical preset's lives are the LTCA's (LtcaResult.bearing_life), s0 with them.
    import rvdyn
    from rvdyn.analysis import ARCMIN, compliance_budget

    life = rvdyn.ltca(rvdyn.Scene.physical("rated")).bearing_life()
    assert f"eccentric {life['eccentric']['l10_hours']:.1f} h (s0 {life['eccentric']['static_safety']:.2f})" in body[-2]
    # The stiffness and its largest part are the compliance budget's.
    b = compliance_budget(rvdyn.Scene.physical("rated")).grouped()
    top_part = b.table()[0]
    assert f"{b.torsional_stiffness[0] * ARCMIN:.0f} N m/arcmin: {top_part['part']} {100 * top_part['share']:.0f} %" in body[-1]
    for line in body:
        for c in cols:
            assert line[c - 2:c] == "  " and line[c] != " ", (line, c)


@pytest.mark.parametrize("command, name", [("plot-geometry", "geometry.png"),
                                           ("plot-stiffness", "stiffness.png")])
def test_plot_commands_write_pngs(tmp_path, command, name):
    out = tmp_path / "figs"
    r = run(command, "--out", str(out))
    assert r.returncode == 0, r.stderr
    png = out / name
    data = png.read_bytes()
    assert data.startswith(PNG_SIGNATURE) and len(data) > 10_000
    assert str(png) in r.stdout


def test_plot_geometry_options_and_default_folder(tmp_path):
    r = run("plot-geometry", "--psi", "0.7", "--disc", "front", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "rvdyn-out" / "geometry.png").stat().st_size > 10_000


def test_paper_command(tmp_path):
    if importlib.util.find_spec("rvdyn.paper") is None:
        # Before the paper job exists the command says so and exits with the usage code.
        r = run("paper", "--t-end", "0.1")
        assert r.returncode == 2
        assert "not available in this version" in r.stderr
        return
    # The wiring only (rvdyn.paper has its own tests): a short idle run writes its summary.
    # 0.3 s is several crank revolutions (the averaging window needs at least one).
    out = tmp_path / "paper"
    r = run("paper", "--t-end", "0.3", "--load", "idle", "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert (out / "summary.json").stat().st_size > 0


def test_usage_errors_and_help():
    assert run("--help").returncode == 0
    r = run()
    assert r.returncode == 2 and "usage" in r.stderr
    r = run("info", "--bogus")
    assert r.returncode == 2
    r = run("paper", "--load", "heavy")
    assert r.returncode == 2 and "invalid choice" in r.stderr
    r = run("--version")
    assert r.returncode == 0 and "rvdyn" in r.stdout


def test_command_line_mistakes_are_caught_before_the_work(tmp_path):
    # An outside review of the CLI: each of these worked badly.
    # A negative number in scientific notation was read as an option ("expected one argument").
    r = run("analyze", "--preset", "paper", "--torque", "-4.39e4", "--angles", "6", "--loop-points", "9",
            "--out", str(tmp_path / "neg"))
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "neg" / "summary.json").read_text())["torque_Nm"] == pytest.approx(-4.39e4)
    # --angles 1 failed only after the LTCA, with an API argument's name.
    r = run("analyze", "--angles", "1", "--out", str(tmp_path / "a"))
    assert r.returncode == 1 and "--angles must be at least 2" in r.stderr
    assert not (tmp_path / "a").exists()
    # --out "" wrote into the current folder (analyze) or failed late (modes).
    for cmd in ("analyze", "modes"):
        r = run(cmd, "--out", "", cwd=tmp_path)
        assert r.returncode == 2 and "must not be empty" in r.stderr
    # A missing study spec: one prefix, not two.
    r = run("study", str(tmp_path / "nonexist.toml"))
    assert r.returncode == 1 and r.stderr.count("ParameterError") == 1, r.stderr


def test_warnings_are_one_line_each_and_once(tmp_path):
    # They came with the source path and code line, in the middle of the progress line, and
    # the contact-pressure warning twice.
    r = run("analyze", "--preset", "paper", "--torque", "2e5", "--angles", "6", "--loop-points", "9",
            "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    warn = [line for line in r.stderr.splitlines() if "warning:" in line]
    assert warn and all(line.startswith("rvdyn analyze: warning: ") for line in warn)
    assert len(warn) == len(set(warn))
    assert "cli.py" not in r.stderr and ".py:" not in r.stderr
    # In the command's option names.
    r = run("analyze", "--angles", "30", "--loop-points", "9", "--out", str(tmp_path / "b"))
    assert "use --angles >= 84" in r.stderr and "use points" not in r.stderr, r.stderr


def test_analyze_gives_the_bearings_static_safety_and_the_crank_layout(tmp_path):
    r = run("analyze", "--angles", "12", "--loop-points", "9", "--crank-layout", "-0.06", "0.06", "-0.09",
            "-0.02", "0.02", "--out", str(tmp_path / "rows"))
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "rows" / "summary.json").read_text())["bearing_static_safety"]
    assert sorted(s) == ["crank_a", "crank_b", "eccentric"]
    # The LTCA's own numbers at the same angles (the CLI only reports them).
    import numpy as np

    import rvdyn

    scene = rvdyn.Scene.physical("rated")
    angles = rvdyn.ltca(scene, crank_angles=[0.0]).mesh_period * np.arange(12) / 12
    layout = rvdyn.CrankLayout(bearings=(-0.06, 0.06), planet=-0.09, discs=(-0.02, 0.02))
    with pytest.warns(RuntimeWarning, match="crank_a"):
        want = rvdyn.ltca(scene, crank_angles=angles).bearing_safety(layout)
    for name in s:
        assert s[name]["static_safety"] == pytest.approx(want[name]["static_safety"], rel=1e-9)
    assert "rvdyn analyze: warning: bearing_safety: the crank_a bearings' peak load" in r.stderr
    assert "crank a peak" in (tmp_path / "rows" / "summary.md").read_text()
    lives = json.loads((tmp_path / "rows" / "summary.json").read_text())["bearing_life"]
    with pytest.warns(RuntimeWarning, match="crank_a"):
        want_life = rvdyn.ltca(scene, crank_angles=angles).bearing_life(crank_layout=layout)
    assert sorted(lives) == ["crank_a", "crank_b", "crank_pair", "eccentric"]
    for name in lives:
        assert lives[name]["l10_hours"] == pytest.approx(want_life[name]["l10_hours"], rel=1e-9)
    assert "crank pair" in (tmp_path / "rows" / "summary.md").read_text()
    assert str(tmp_path / "rows" / "bearing_loads.png") in json.loads((tmp_path / "rows" / "summary.json").read_text())["files"]
    assert (tmp_path / "rows" / "bearing_loads.png").stat().st_size > 0
    # Too few positions, or a scene without roller crank bearings: refused before the work.
    r = run("analyze", "--crank-layout", "0", "1", "2", "--out", str(tmp_path / "few"))
    assert r.returncode == 1 and "at least 4 positions" in r.stderr and not (tmp_path / "few").exists()
    r = run("analyze", "--preset", "paper", "--crank-layout", "0", "1", "2", "3", "--out", str(tmp_path / "paper"))
    assert r.returncode == 1 and "crank bearing built from rollers" in r.stderr
    assert not (tmp_path / "paper").exists()
    # The same layout carried by the scene file (field crank_layout, 20 mm rollers): taken
    # without the option, and named in the summaries.
    path = scene.replace(crank_layout={"bearings": [-0.06, 0.06], "planet": -0.09, "discs": [-0.02, 0.02],
                                       "roller_length": 0.02}).save(tmp_path / "laid_out.toml")
    r = run("analyze", str(path), "--angles", "12", "--loop-points", "9", "--out", str(tmp_path / "carried"))
    assert r.returncode == 0, r.stderr
    summary = json.loads((tmp_path / "carried" / "summary.json").read_text())
    assert summary["crank_layout"] == {"bearings": [-0.06, 0.06], "discs": [-0.02, 0.02], "planet": -0.09,
                                       "roller_length": 0.02}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        want = rvdyn.ltca(scene, crank_angles=angles).bearing_safety(
            rvdyn.CrankLayout(bearings=(-0.06, 0.06), planet=-0.09, discs=(-0.02, 0.02), roller_length=0.02))
    for name in ("crank_a", "crank_b", "eccentric"):
        assert summary["bearing_static_safety"][name]["static_safety"] == pytest.approx(
            want[name]["static_safety"], rel=1e-9)
    assert "from the scene's crank_layout, each with rollers of 20 mm" in (tmp_path / "carried" / "summary.md").read_text()
