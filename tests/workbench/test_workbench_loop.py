"""The loop, user effects, the magnetometer system, robust refits and the CLI (issue 9)."""

import json
import subprocess
import sys

import numpy as np
import pytest

from navlib.errors import InputError, UserCodeError
from navlib.workbench import Effect, load_effects
from navlib.workbench.diagnose import diagnose
from navlib.workbench.effects import CATALOGUES
from navlib.workbench.fit import fit_model, simulate
from navlib.workbench.loop import loop
from navlib.workbench.magnetometer import field_summary, load_magnetometer, simulate_magnetometer
from navlib.workbench.trials import out_of_catalogue_trial
from navlib.paths import ROOT

QUAD = ROOT / "notebooks" / "quadrantal_effect.py"


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "navlib", *args], capture_output=True, text=True)


def three_cycle(amplitude=0.5, seed=0):
    data = simulate(
        "compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.03}, noise=0.05, seed=seed
    )
    data["measured_heading_deg"] = np.mod(
        data.measured_heading_deg + amplitude * np.sin(np.radians(3 * data.true_heading_deg) + 0.4),
        360,
    )
    return data


def test_refit_from_the_linearised_start_reaches_the_noise_floor():
    """The real-data failure: a large one-cycle error, hard iron added to a misalignment-only model."""
    data = simulate(
        "compass", {"yaw_deg": -2.0, "hard_x": 0.12, "hard_y": -0.05}, noise=0.05, seed=3
    )
    f0 = fit_model("compass", data, ["misalignment"])
    d = diagnose(f0)
    c = {c.effect: c for c in d.candidates}["hard_iron"]
    assert d.missing == "hard_iron" and c.variance_explained > 0.99 and c.rms < 0.08
    assert f0.add("hard_iron").params["hard_x"] == pytest.approx(0.12, abs=0.005)


@pytest.mark.parametrize("seed", range(6))
def test_structure_amplitudes_are_bounded_by_the_residual(seed):
    data = simulate(
        "compass", {"yaw_deg": 1.0, "hard_x": 0.1, "soft_f": 0.02}, noise=0.1, seed=seed
    )
    d = diagnose(fit_model("compass", data, ["misalignment", "hard_iron", "soft_iron"]))
    assert max(s.amplitude for s in d.structure) <= 3 * d.rms


@pytest.mark.slow
def test_loop_json_schema_and_report(tmp_path):
    p = tmp_path / "c.csv"
    simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.04}, noise=0.1, seed=0).to_csv(
        p, index=False
    )
    r = run_cli(
        "loop",
        "compass",
        str(p),
        "--model",
        "misalignment",
        "--json",
        "--report",
        str(tmp_path / "rep"),
    )
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    named = [s["missing"] for s in out["steps"]]
    assert sorted(named[:2]) == ["hard_iron", "soft_iron"] and named[2] is None
    assert set(out["steps"][0]) == {"model", "rms", "loo_rms", "missing"}
    assert out["final"]["model"] == ["misalignment", "hard_iron", "soft_iron"]
    assert out["final"]["consistent_with_noise"] and out["final"]["unexplained"] == []
    assert out["final"]["rms"] < 0.15 < out["steps"][0]["rms"]
    md = (tmp_path / "rep" / "loop.md").read_text()
    assert (
        "| 2 | misalignment + hard_iron + soft_iron |" in md
        and (tmp_path / "rep" / "loop.png").stat().st_size > 1000
    )
    png = (tmp_path / "rep" / "loop.png").read_bytes()
    assert (
        int.from_bytes(png[16:20], "big") == 750
    )  # drawn for the book's column (7.5 in at 100 dpi)
    again = run_cli(
        "loop", "compass", str(p), "--model", "misalignment", "--report", str(tmp_path / "rep")
    )
    assert (
        again.returncode == 2
        and "already exists" in again.stderr
        and len(again.stderr.strip().splitlines()) == 1
    )
    assert (tmp_path / "rep" / "loop.md").read_text() == md


@pytest.mark.slow
def test_user_effect_is_named_and_explains_the_structure(tmp_path):
    data = three_cycle()
    without = loop("compass", data, ["misalignment", "hard_iron", "soft_iron"])
    assert without.final.effects == ("misalignment", "hard_iron", "soft_iron")
    assert any("heading harmonic 3" in u["structure"] for u in without.unexplained)
    users = load_effects(QUAD, "compass", CATALOGUES["compass"])
    with_it = loop("compass", data, ["misalignment", "hard_iron", "soft_iron"], user_effects=users)
    assert with_it.diagnoses[0].missing == "quadrantal" and with_it.consistent_with_noise
    amp = np.hypot(with_it.final.params["q3_sin_deg"], with_it.final.params["q3_cos_deg"])
    assert amp == pytest.approx(0.5, abs=0.03)
    p = tmp_path / "c.csv"
    data.to_csv(p, index=False)
    r = run_cli(
        "loop",
        "compass",
        str(p),
        "--model",
        "misalignment,hard_iron,soft_iron",
        "--effects",
        str(QUAD),
        "--json",
    )
    assert json.loads(r.stdout)["steps"][0]["missing"] == "quadrantal"


@pytest.mark.slow
def test_effect_definitions_are_checked(tmp_path):
    with pytest.raises(InputError, match="one unit per parameter"):
        Effect("x", ("a", "b"), ("deg",), "m", system="compass", contribution=lambda p, d: 0)
    f = tmp_path / "e.py"
    f.write_text(
        "from navlib.workbench.effects import Effect\n"
        "hard_iron = Effect('hard_iron', ('a',), ('deg',), 'm', system='compass', contribution=lambda p, d: 0)\n"
    )
    with pytest.raises(InputError, match="already in the compass catalogue"):
        load_effects(f, "compass", CATALOGUES["compass"])
    assert (
        run_cli("loop", "compass", str(f), "--effects", str(tmp_path / "none.py")).returncode == 2
    )


def test_diagnose_lets_a_bug_in_an_effect_through():
    """Only expected errors (InputError) make a candidate untestable; a bug in a user's effect propagates,
    named (UserCodeError, not an InputError), with the user's exception as its cause."""
    bad = Effect("broken", ("k",), ("deg",), "m", system="compass", contribution=lambda p, d: 1 / 0)
    f = fit_model(
        "compass",
        simulate("compass", {"yaw_deg": 1.0}, noise=0.1),
        ["misalignment"],
        user_effects=(bad,),
    )
    with pytest.raises(
        UserCodeError, match="effect 'broken': contribution raised ZeroDivisionError"
    ) as err:
        diagnose(f)
    assert not isinstance(err.value, InputError) and isinstance(
        err.value.__cause__, ZeroDivisionError
    )


@pytest.mark.slow
def test_debug_flag_shows_the_traceback(tmp_path):
    bad = tmp_path / "b.csv"
    bad.write_text("true_heading_deg,measured_heading_deg\n1,x\n")
    plain = run_cli("diagnose", "compass", str(bad))
    debug = run_cli("--debug", "diagnose", "compass", str(bad))
    assert (
        plain.returncode == 2
        and "Traceback" not in plain.stderr
        and len(plain.stderr.strip().splitlines()) == 1
    )
    assert debug.returncode != 0 and "Traceback" in debug.stderr and "InputError" in debug.stderr


@pytest.mark.slow
@pytest.mark.parametrize(
    "kind", ["three-cycle error", "four-cycle error", "step between sweeps", "drift in time"]
)
def test_errors_outside_the_catalogue_name_nothing_but_are_not_noise(kind):
    rows = [out_of_catalogue_trial(kind, 6.0, 0.1, seed) for seed in range(4)]
    assert all(r["quiet"] and r["detected"] for r in rows), rows


def test_magnetometer_loop_recovers_hard_iron_and_the_field():
    params = {
        "hard_x_ut": 12.0,
        "hard_y_ut": -5.0,
        "hard_z_ut": 3.0,
        "soft_xx": 0.03,
        "soft_xy": -0.02,
    }
    data = simulate_magnetometer(params, n=300, noise_ut=0.1, seed=1)
    res = loop("magnetometer", data, [])
    assert res.diagnoses[0].missing == "hard_iron"
    assert res.final.effects == ("hard_iron", "soft_iron") and res.consistent_with_noise
    for k, v in params.items():
        assert res.final.params[k] == pytest.approx(v, abs=0.05 if "soft" not in k else 0.003)
    f = field_summary(res.final)
    assert f["dip (deg)"] == pytest.approx(
        np.degrees(np.arctan2(40.8, np.hypot(15.2, 0.3))), abs=0.1
    )


def test_magnetometer_time_lag_is_found_from_the_rate():
    data = simulate_magnetometer({"time_lag_s": 0.02}, n=300, noise_ut=0.05, seed=2)
    res = loop("magnetometer", data, [])
    assert res.final.effects == ("time_lag",)
    assert res.final.params["time_lag_s"] == pytest.approx(0.02, abs=0.002)


def write(tmp_path, frame, name="m.csv"):
    p = tmp_path / name
    frame.to_csv(p, index=False)
    return p


@pytest.mark.slow
def test_magnetometer_bad_input(tmp_path):
    good = simulate_magnetometer({}, n=60, seed=0)
    assert len(load_magnetometer(write(tmp_path, good))) == 60
    with pytest.raises(InputError, match="m.csv: missing column 'q_w'"):
        load_magnetometer(write(tmp_path, good.drop(columns=["q_w"])))
    g = good.copy()
    g.loc[4, ["q_w", "q_x"]] = [0.3, 0.2]
    with pytest.raises(
        InputError, match=r"m.csv: column 'q_w..q_z', row 5 \(file line 6\): quaternion norm"
    ):
        load_magnetometer(write(tmp_path, g))
    g = good.astype(object)
    g.loc[7, "mag_y_ut"] = "nan"
    with pytest.raises(InputError, match="column 'mag_y_ut', row 8"):
        load_magnetometer(write(tmp_path, g))
    level = good.copy()
    yaw = np.radians(np.linspace(0, 40, len(level)))
    level[["q_w", "q_x", "q_y", "q_z"]] = np.column_stack(
        [np.cos(yaw / 2), 0 * yaw, 0 * yaw, np.sin(yaw / 2)]
    )
    with pytest.raises(InputError, match="distinct orientations"):
        load_magnetometer(write(tmp_path, level))
    r = run_cli("diagnose", "magnetometer", str(write(tmp_path, level, "lvl.csv")))
    assert (
        r.returncode == 2
        and "lvl.csv: columns q_w..q_z" in r.stderr
        and len(r.stderr.strip().splitlines()) == 1
    )


def test_a_user_effect_works_for_the_drift_system_too():
    data = simulate("drift", {"earth_rate_gain": 1.0}, n=30, noise=1e-4, seed=1)
    x = data.latitude_error_deg.to_numpy()
    data["drift_deg_h"] += 2.0 * (x**2 - np.mean(x**2))
    curv = Effect(
        "curvature",
        ("c_deg_h_per_deg2",),
        ("deg/h/deg^2",),
        "quadratic in the latitude error",
        system="drift",
        contribution=lambda p, d: (
            p["c_deg_h_per_deg2"]
            * (d.latitude_error_deg.to_numpy() ** 2 - np.mean(d.latitude_error_deg.to_numpy() ** 2))
        ),
    )
    res = loop("drift", data, ["earth_rate"], user_effects=(curv,))
    assert "curvature" in res.final.effects and res.consistent_with_noise
    assert res.final.params["c_deg_h_per_deg2"] == pytest.approx(2.0, rel=0.1)


# ------------------------------------------------------------------------------------ trial seeds (issue 19)
@pytest.mark.slow
def test_every_trial_of_a_study_has_its_own_seed():
    from navlib.workbench.trials import hidden_effect_study, out_of_catalogue_study

    st = hidden_effect_study(
        "drift", ratios=(3.0, 10.0), noises=(1e-4, 3e-4), seeds=range(2), n=6, none_seeds=range(3)
    )
    assert st.seed.is_unique and len(st) == 2 * (4 * 2 * 2 + 3)
    ooc = out_of_catalogue_study(
        ratios=(5.0, 5.5), noises=(0.1,), seeds=range(1)
    )  # int(ratio) collided
    assert ooc.seed.is_unique and len(ooc) == 4 * 2


def test_trial_seeds_are_spawn_keys_not_arithmetic():
    from navlib.workbench.trials import trial_seed

    a, b = (
        trial_seed("hidden effect", 0, 16, 0, 1, 0, 0),
        trial_seed("hidden effect", 0, 16, 0, 1, 1, 0),
    )
    assert isinstance(a, np.random.SeedSequence) and a.spawn_key[1:] == (0, 16, 0, 1, 0, 0)
    draws = [
        np.random.default_rng(trial_seed("out of catalogue", *k)).random(4)
        for k in ((0, 0, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1), (1, 0, 0, 0))
    ]
    assert len({tuple(d) for d in draws}) == 4
    assert not np.allclose(np.random.default_rng(a).random(4), np.random.default_rng(b).random(4))
    with pytest.raises(InputError):
        trial_seed("hidden effect", -1)
    with pytest.raises(InputError):
        trial_seed("other study", 0)
