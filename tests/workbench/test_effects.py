"""Named-effect models: catalogue, exact fits, identifiability, one-call add, comparison."""

import numpy as np
import pandas as pd
import pytest

from navlib.sensors.compass import CompassErrors, SweepConfig, simulate_sweep
from navlib.workbench.trials import random_params
from navlib.workbench.effects import CATALOGUES, catalogue_table, check_effects
from navlib.workbench.fit import compare, effect_rms, fit_model, load, simulate
from navlib.errors import InputError
from navlib.data.gyro_tables import drift_measurements
from navlib.paths import data_path


@pytest.mark.parametrize("system", ["compass", "drift"])
def test_each_effect_alone_is_recovered_by_its_own_parameters(system):
    """Every catalogued effect's declared parameters are the ones its model uses: data made with that effect
    alone are fitted exactly by it, and the table lists each parameter with its unit."""
    table = catalogue_table(system)
    for name, effect in CATALOGUES[system].items():
        p = random_params(system, np.random.default_rng(1), [name])
        assert set(p) == set(effect.params)
        data = simulate(system, p, n=30, noise=0.0, seed=2)
        fit = fit_model(system, data, [name])
        assert fit.rms < 1e-6, name
        for k in effect.params:
            assert fit.params[k] == pytest.approx(p[k], rel=1e-4, abs=1e-9)
            assert f"{k} [" in table.loc[name, "parameters"]


def test_needed_columns_are_enforced():
    """An effect that needs a column is untestable without it and cannot be put in a model."""
    from navlib.workbench.effects import testable

    data = simulate("compass", {"yaw_deg": 1.0}, noise=0.1).drop(columns=["temperature_c"])
    ok, why = testable(CATALOGUES["compass"], data)
    assert "temperature" not in ok and why["temperature"] == "no column 'temperature_c'"
    with pytest.raises(InputError, match="needs the column 'temperature_c'"):
        fit_model("compass", data, ["temperature"])
    d = simulate("drift", {}, n=10)
    d["temperature_change_c"] = 5.0
    with pytest.raises(InputError, match="'temperature_change_c' to vary"):
        fit_model("drift", d, ["temperature_change"])


@pytest.mark.parametrize("system", ["compass", "drift"])
def test_full_model_is_exact_on_noiseless_data(system):
    rng = np.random.default_rng(4)
    p = random_params(system, rng, CATALOGUES[system])
    data = simulate(system, p, n=30, noise=0.0, seed=1)
    fit = fit_model(system, data, CATALOGUES[system])
    assert fit.rms < (1e-7 if system == "compass" else 1e-12)
    for k, v in p.items():
        assert fit.params[k] == pytest.approx(v, rel=1e-4, abs=1e-9)


def test_compass_model_is_exact_for_the_physical_simulator_with_warming():
    """The 3-D simulator with hard iron drifting with temperature is explained exactly by the catalogue."""
    err = CompassErrors(hard_iron_tc_ut_per_c=(0.05, -0.08, 0.02), noise_ut=0.0)
    d = simulate_sweep(err, config=SweepConfig(temperature_rate_c_per_point=0.15))
    fit = fit_model("compass", d, CATALOGUES["compass"])
    assert fit.rms < 1e-6
    assert fit_model("compass", d, ["misalignment", "hard_iron", "soft_iron"]).rms > 0.3


def test_adding_an_effect_is_one_call_and_lowers_the_residual():
    p = random_params("compass", np.random.default_rng(0), CATALOGUES["compass"])
    data = simulate("compass", p, noise=0.1, seed=2)
    f0 = fit_model("compass", data, ["misalignment", "hard_iron"])
    f1 = f0.add("soft_iron")
    assert f1.effects == ("misalignment", "hard_iron", "soft_iron")
    assert f1.rms < f0.rms / 2 and f1.loo_rms < f0.loo_rms
    table = compare(f0, f1, f1.add("temperature"))
    assert list(table.index) == [
        "misalignment + hard_iron",
        "misalignment + hard_iron + soft_iron",
        "misalignment + hard_iron + soft_iron + temperature",
    ]
    assert table["rms (deg)"].is_monotonic_decreasing
    with pytest.raises(InputError, match="already in the model"):
        f1.add("soft_iron")


def test_misalignment_and_soft_iron_never_explain_the_same_residual():
    data = simulate("compass", {"yaw_deg": 2.0}, noise=0.0)
    fit = fit_model("compass", data, ["misalignment", "soft_iron"])
    assert fit.params["yaw_deg"] == pytest.approx(2.0, abs=1e-7)
    assert abs(fit.params["soft_e"]) < 1e-8 and abs(fit.params["soft_f"]) < 1e-8
    data = simulate("compass", {"soft_e": 0.05, "soft_f": -0.02}, noise=0.0)
    fit = fit_model("compass", data, ["misalignment", "soft_iron"])
    assert abs(fit.params["yaw_deg"]) < 1e-6


def test_earth_rate_adds_no_constant():
    frame = pd.DataFrame(
        {"latitude_error_deg": [0.01, 0.02, 0.03, 0.04], "drift_deg_h": [1e-3] * 4}
    )
    fit = fit_model("drift", frame, ["earth_rate"])
    assert fit.rms > 1e-4  # a pure bias is not explained...
    assert fit_model("drift", frame, ["earth_rate", "bias"]).rms < 1e-15  # ...until bias is added
    zero = pd.DataFrame({"latitude_error_deg": [0.0] * 3, "drift_deg_h": [1.0, 2.0, 3.0]})
    assert np.allclose(fit_model("drift", zero, ["earth_rate"]).predict(zero), 0.0)


def test_earth_rate_gain_one_is_table1():
    from navlib.sensors.ins import drift_from_latitude_error

    frame = pd.DataFrame({"latitude_error_deg": [0.005, -0.02, 0.013]})
    frame["drift_deg_h"] = drift_from_latitude_error(frame.latitude_error_deg)
    assert fit_model("drift", frame, ["earth_rate"]).params["earth_rate_gain"] == pytest.approx(1.0)


def test_effect_rms():
    data = simulate("drift", {}, n=50, seed=0)
    assert effect_rms("drift", data, {"bias_deg_h": 2e-4}, "bias") == pytest.approx(2e-4)
    data = simulate("compass", {}, noise=0.0)
    assert effect_rms("compass", data, {"yaw_deg": 1.5}, "misalignment") == pytest.approx(1.5)


def test_effect_validation():
    data = simulate("drift", {}, n=5, seed=0)
    with pytest.raises(InputError, match="unknown drift effect 'tilt'"):
        check_effects("drift", ["tilt"])
    with pytest.raises(InputError, match="twice"):
        check_effects("drift", ["bias", "bias"])
    with pytest.raises(InputError, match="needs the column 'temperature_c'"):
        fit_model("drift", data.drop(columns="temperature_c"), ["temperature"])
    with pytest.raises(InputError, match="constant"):
        fit_model("drift", data.assign(temperature_c=20.0), ["temperature"])
    with pytest.raises(InputError, match="5 rows cannot determine 5|at least"):
        fit_model(
            "drift", data.iloc[:4], ["earth_rate", "bias", "temperature", "temperature_change"]
        )
    with pytest.raises(InputError, match="unknown system"):
        fit_model("gravity", data, [])


def test_stored_drift_file_is_generated_by_code():
    stored = load("drift", data_path("gyro_drift_measurements.csv"))
    fresh = drift_measurements()
    assert len(stored) == 25 == len(fresh)
    for col in ("latitude_error_deg", "drift_deg_h", "temperature_c", "temperature_change_c"):
        assert np.allclose(stored[col], fresh[col].round(6), atol=1e-12)
    assert list(stored.state.value_counts().sort_index()) == [6, 19]
