"""The celestial notebook's parameters cell into the study's spec in one call: ``StudySpec.from_notebook``."""

import ast
import json
from dataclasses import replace

import pytest

from navlib.errors import InputError
from navlib.paths import NOTEBOOK_DIR
from navlib.studies import celestial
from navlib.studies.celestial import NOTEBOOK_DEFAULTS, RUN_KEYS, StudySpec


def notebook_cell() -> dict:
    """The defaults of ``notebooks/celestial.ipynb``'s parameters cell, name -> value, in the cell's order."""
    nb = json.loads((NOTEBOOK_DIR / "celestial.ipynb").read_text(encoding="utf-8"))
    cell = next(c for c in nb["cells"] if "parameters" in c.get("metadata", {}).get("tags", []))
    tree = ast.parse("".join(cell["source"]))
    return {
        node.targets[0].id: ast.literal_eval(node.value)
        for node in tree.body
        if isinstance(node, ast.Assign)
    }


def test_the_defaults_are_the_notebooks_parameters_cell():
    cell = notebook_cell()
    assert list(NOTEBOOK_DEFAULTS) == list(cell) and NOTEBOOK_DEFAULTS == cell
    assert set(RUN_KEYS) < set(cell)


def test_the_notebooks_defaults_give_the_spec_its_mapping_cell_builds():
    p = notebook_cell()
    expected = StudySpec(
        duration_s=p["duration_s"],
        imu_rate_hz=p["imu_rate_hz"],
        star_rate_hz=p["star_rate_hz"],
        star_cross_arcsec=p["star_cross_arcsec"],
        star_boresight_arcsec=p["star_boresight_arcsec"],
        gyro_drift_deg_h=p["gyro_drift_deg_h"],
        gyro_arw_deg_rt_h=p["gyro_arw_deg_rt_h"],
        gyro_scale_ppm=p["gyro_scale_ppm"],
        accel_bias_ug=p["accel_bias_ug"],
        accel_noise_ug_rt_hz=p["accel_noise_ug_rt_hz"],
        yaw_amplitude_deg=p["yaw_amplitude_deg"],
        turn_period_s=p["turn_period_s"],
        n_hidden=p["n_hidden"],
        epochs=p["epochs"],
        n_train_runs=p["n_train_runs"],
        n_test_runs=p["n_test_runs"],
        n_repeats=p["n_repeats"],
        n_timings=p["n_timings"],
        timing_epochs=p["timing_epochs"],
        lm_timings=p["lm_timings"],
        sweep_ppm=tuple(p["sweep_ppm"]),
        sweep_repeats=p["sweep_repeats"],
        latency_ms_levels=tuple(p["latency_ms_levels"]),
        smear_levels_arcsec_per_deg_s=tuple(p["smear_levels_arcsec_per_deg_s"]),
        quiet_repeats=p["quiet_repeats"],
        seed=p["seed"],
    )
    assert StudySpec.from_notebook(**p) == expected
    assert StudySpec.from_notebook() == expected  # a name not given: the cell's default
    assert celestial.StudySpec.from_notebook(**p) == expected
    assert (
        expected.sweep_repeats == 4 != StudySpec().sweep_repeats
    )  # the cell's default, not the spec's


@pytest.mark.parametrize(
    "name, value, field, stored",
    [
        ("gyro_scale_ppm", 50.0, "gyro_scale_ppm", 50.0),
        ("n_repeats", 6, "n_repeats", 6),
        ("star_rate_hz", 5.0, "star_rate_hz", 5.0),
        ("seed", 7, "seed", 7),
        (
            "sweep_ppm",
            [0.0, 100.0],
            "sweep_ppm",
            (0.0, 100.0),
        ),  # papermill passes lists: tuples here
        ("latency_ms_levels", [20.0], "latency_ms_levels", (20.0,)),
        ("smear_levels_arcsec_per_deg_s", [3.0], "smear_levels_arcsec_per_deg_s", (3.0,)),
    ],
)
def test_one_parameter_changes_its_field_alone(name, value, field, stored):
    base = StudySpec.from_notebook()
    got = StudySpec.from_notebook(**{name: value})
    assert got == replace(base, **{field: stored}) and got != base
    assert isinstance(getattr(got, field), type(stored))


def test_run_settings_are_accepted_and_change_nothing():
    assert (
        StudySpec.from_notebook(n_workers=1, scheduler="tcp://127.0.0.1:8786")
        == StudySpec.from_notebook()
    )


def test_an_unknown_parameter_stops_with_its_name():
    with pytest.raises(InputError, match="gyro_scale_pm") as err:
        StudySpec.from_notebook(gyro_scale_pm=50.0)
    assert "\n" not in str(err.value)
    with pytest.raises(InputError, match="settle_s"):  # a spec field, but not in the cell
        StudySpec.from_notebook(settle_s=5.0)


def test_a_bad_value_stops_in_the_spec():
    with pytest.raises(InputError, match="star_rate_hz"):
        StudySpec.from_notebook(star_rate_hz=3.0)
