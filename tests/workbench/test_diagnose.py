"""diagnose names hidden effects, stays quiet on noise, reports structure the catalogue lacks."""

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from navlib.workbench.diagnose import diagnose

from navlib.workbench.trials import detection_rates, hidden_effect_study, hidden_effect_trial
from navlib.workbench.fit import fit_model, simulate
from navlib.data.gyro_tables import drift_measurements
from navlib.paths import data_path


@pytest.mark.parametrize(
    "system,noises,n",
    [("compass", (0.05, 0.3), None), ("drift", (1e-4, 4e-4), 16), ("drift", (2e-4,), 40)],
)
@pytest.mark.slow
def test_hidden_effects_are_named_and_noise_is_noise(system, noises, n):
    study = hidden_effect_study(
        system, ratios=(3.0, 8.0), noises=noises, seeds=range(6), n=n, none_seeds=range(60)
    )
    rates = detection_rates(study)
    named = rates[rates.rate == "correctly named"]
    assert len(named) == 4
    assert (named["value"] >= 0.95).all(), named
    assert rates.loc["(none)", "value"] <= 0.05


def test_small_tables_do_not_raise_false_alarms():
    study = hidden_effect_study(
        "drift", ratios=(), noises=(3e-4,), seeds=range(0), n=6, none_seeds=range(120)
    )
    assert detection_rates(study).loc["(none)", "value"] <= 0.05


def test_a_trial_reports_what_it_did():
    row = hidden_effect_trial("compass", "temperature", 5.0, 0.1, seed=3)
    assert row["named"] == "temperature" and row["correct"] and not row["consistent_with_noise"]


def test_structure_outside_the_catalogue_is_reported_compass():
    """A third heading harmonic (e.g. sensor nonlinearity) is in no catalogued effect."""
    data = simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2}, noise=0.05, seed=0)
    data["measured_heading_deg"] = np.mod(
        data.measured_heading_deg + 0.4 * np.sin(np.radians(3 * data.true_heading_deg)), 360
    )
    d = diagnose(
        fit_model("compass", data, ["misalignment", "hard_iron", "soft_iron", "temperature"])
    )
    assert d.missing is None and not d.consistent_with_noise
    found = [s.what for s in d.structure if s.significant]
    assert any("heading harmonic 3" in w for w in found)
    assert "not noise" in d.message


def test_structure_outside_the_catalogue_is_reported_drift():
    data = simulate("drift", {"earth_rate_gain": 1.0}, n=30, noise=1e-4, seed=1)
    x = data.latitude_error_deg
    data["drift_deg_h"] += 2.0 * (x**2 - np.mean(x**2))  # curvature: not in the catalogue
    d = diagnose(
        fit_model("drift", data, ["earth_rate", "bias", "temperature", "temperature_change"])
    )
    assert [s.what for s in d.structure if s.significant] == ["curvature in latitude_error_deg"]


def test_permutation_test_on_six_rows_is_exact():
    data = simulate(
        "drift",
        {"earth_rate_gain": 1.0, "temperature_change_coef_deg_h_per_c": 1e-4},
        n=6,
        noise=1e-5,
        seed=2,
    )
    d = diagnose(fit_model("drift", data, ["earth_rate"]))
    c = {c.effect: c for c in d.candidates}
    assert c["temperature_change"].test == "permutation"
    assert c["temperature_change"].p_value == pytest.approx(
        np.round(c["temperature_change"].p_value * 720) / 720
    )
    assert c["bias"].test == "F"  # a constant cannot be permuted


def test_paper_c_tables_point_to_temperature_change():
    """On paper C's measured hot and cold tests together, the cold starts lack temperature_change."""
    d = diagnose(fit_model("drift", drift_measurements(), ["earth_rate", "bias"]))
    assert d.missing == "temperature_change"
    cold = diagnose(fit_model("drift", drift_measurements("cold"), ["earth_rate", "bias"]))
    assert cold.missing is None and "only 6 rows" in cold.message


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "navlib", *args], capture_output=True, text=True)


def test_cli_diagnose_compass_json(tmp_path):
    p = tmp_path / "c.csv"
    data = simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.04}, noise=0.1, seed=0)
    data["extra"] = "ignored"
    data.to_csv(p, index=False)
    r = run_cli("diagnose", "compass", str(p), "--model", "misalignment,hard_iron", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["model"] == ["misalignment", "hard_iron"] and out["missing"] == "soft_iron"
    assert out["rms"] > 1.0
    assert out["candidates"][0]["effect"] == "soft_iron" and out["candidates"][0]["rms"] < 0.2
    assert {"effect", "rms"} <= set(out["candidates"][0])


def test_cli_diagnose_drift_table_and_json():
    path = str(data_path("gyro_drift_measurements.csv"))
    r = run_cli("diagnose", "drift", path, "--model", "earth_rate", "--json")
    out = json.loads(r.stdout)
    assert out["missing"] == "temperature_change" and out["unit"] == "deg/h"
    text = run_cli("diagnose", "drift", path, "--model", "earth_rate")
    assert text.returncode == 0 and "add 'temperature_change'" in text.stdout


@pytest.mark.parametrize(
    "args,expect",
    [
        (["--model", "magic"], "unknown drift effect 'magic'"),
        (["--model", "earth_rate", "--alpha", "2"], "alpha"),
    ],
)
def test_cli_bad_arguments_exit_2(args, expect):
    r = run_cli("diagnose", "drift", str(data_path("gyro_drift_measurements.csv")), *args)
    assert r.returncode == 2 and expect in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


def test_cli_bad_files_exit_2(tmp_path):
    bad = tmp_path / "bad.csv"
    pd.DataFrame({"latitude_error_deg": [0.01, "x"], "drift_deg_h": [0.001, 0.002]}).to_csv(
        bad, index=False
    )
    r = run_cli("diagnose", "drift", str(bad))
    assert r.returncode == 2 and "column 'latitude_error_deg', row 2" in r.stderr
    few = tmp_path / "few.csv"
    pd.DataFrame(
        {
            "latitude_error_deg": [0.01, 0.02],
            "drift_deg_h": [0.001, 0.002],
            "temperature_c": [20, 30],
        }
    ).to_csv(few, index=False)
    r = run_cli("diagnose", "drift", str(few), "--model", "earth_rate,bias,temperature")
    assert r.returncode == 2 and "rows cannot determine" in r.stderr
    r = run_cli("diagnose", "compass", str(few))
    assert r.returncode == 2 and "missing column 'true_heading_deg'" in r.stderr
    for rr in (r,):
        assert len(rr.stderr.strip().splitlines()) == 1
