"""navlib.studies.gyro.parameters: paper C's facts, the settings, the seeds, and the notebook's parameters."""

import dataclasses
import json

import numpy as np
import pytest

from navlib.errors import InputError
from navlib.paths import NOTEBOOK_DIR, data_path
from navlib.sensors import ins
from navlib.studies import gyro


# ------------------------------------------------------------------------------------------------------ facts
def test_paper_facts_match_their_quotes_and_the_simulator():
    f = gyro.paper_facts()
    assert set(gyro.FACT_KEYS) <= set(f.index)
    for key in (
        "claimed_accuracy",
        "required_accuracy",
        "training_goal",
        "spread",
        "local_latitude",
        "hot_state_max_temp_change",
        "cold_state_min_temp_change",
    ):
        assert f"{f.loc[key, 'value']:g}" in f.loc[key, "quote"], (
            key
        )  # the number is in the sentence
    assert gyro.fact("claimed_accuracy") == 0.0003 and gyro.fact("spread") == 2.0
    assert gyro.fact("local_latitude") == ins.LOCAL_LATITUDE_DEG
    p = ins.Procedure()
    assert (gyro.fact("align_h"), gyro.fact("identify_h"), gyro.fact("navigate_h")) == (
        p.align_h,
        p.identify_h,
        p.navigate_h,
    )
    assert set(f["kind"]) == {"claim", "setting"}
    assert "paper_c_facts.csv" in data_path("README.md").read_text(encoding="utf-8")
    with pytest.raises(InputError, match="no such fact"):
        gyro.fact("accuracy")


def test_paper_facts_reject_a_missing_or_duplicated_key(tmp_path):
    lines = data_path(gyro.FACTS_FILE).read_text(encoding="utf-8").splitlines()
    p = tmp_path / "facts.csv"
    p.write_text(
        "\n".join(ln for ln in lines if not ln.startswith("spread,")) + "\n", encoding="utf-8"
    )
    with pytest.raises(InputError, match="facts.csv: no row for key 'spread'"):
        gyro.paper_facts(p)
    p.write_text("\n".join(lines + [lines[1]]) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match="appears twice"):
        gyro.paper_facts(p)
    p.write_text(
        "\n".join(lines).replace("0.0003,deg/h,claim", "x,deg/h,claim", 1) + "\n", encoding="utf-8"
    )
    with pytest.raises(InputError, match="column 'value', row 1"):
        gyro.paper_facts(p)


# --------------------------------------------------------------------------------------------------- settings
def test_settings_take_the_papers_values_and_validate():
    h = gyro.HotNetSettings()
    assert (h.spread, h.goal) == (2.0, 0.0003)
    assert gyro.HotNetSettings(spread=4.0).spread == 4.0
    for make, frag in [
        (lambda: gyro.HotNetSettings(spread=0.0), "spread"),
        (lambda: gyro.HotNetSettings(goal=-1.0), "goal"),
        (lambda: gyro.HotNetSettings(goal_kind="rms"), "goal_kind"),
        (lambda: gyro.HotNetSettings(input_unit="rad"), "input_unit"),
        (lambda: gyro.ColdNetSettings(spread_sd=-1.0), "cold_spread"),
        (lambda: gyro.ColdNetSettings(dt_column="x"), "cold_dt_column"),
        (lambda: gyro.SimulationSettings(step_s=7.0), "sim_step_s"),
        (lambda: gyro.SimulationSettings(n_seeds=0), "n_seeds"),
        (lambda: gyro.SimulationSettings(tilt_sd_arcsec=-1.0), "sim_tilt_sd_arcsec"),
        (lambda: gyro.StudyParams(hot=gyro.ColdNetSettings()), "hot"),
    ]:
        with pytest.raises(InputError, match=frag):
            make()
    s = gyro.SimulationSettings()
    assert s.procedure().step_s == s.step_s
    imu, _ = ins.random_test(np.random.default_rng(0), axial_drift_deg_h=0.001, **s.error_sd())
    assert imu.gyro_arw_deg_rt_h == s.gyro_arw_deg_rt_h


def test_thermal_settings_reject_bad_input():
    with pytest.raises(InputError, match="lag_h"):
        gyro.ThermalWorld("w", lag_h=(2.0, 1.0))
    with pytest.raises(InputError, match="n_cold_draws"):
        gyro.ColdStudySettings(n_draws=2)
    with pytest.raises(InputError, match="width"):
        gyro.HotNetSettings(width="cauchy")
    with pytest.raises(InputError, match="thermal"):
        gyro.StudyParams(thermal=3)


# ------------------------------------------------------------------------------------------------------ seeds
def test_experiment_seeds_follow_the_seedsequence_convention():
    a = gyro.experiment_seeds(2012, "fig3", 3)
    ref = np.random.SeedSequence(2012).spawn(6)[3].spawn(3)
    assert a == [int(c.generate_state(1)[0]) for c in ref]
    assert gyro.experiment_seeds(2012, "fig3", 3) == a
    every = [
        s
        for e in (
            "fig1",
            "hot_reference",
            "cold_training",
            "fig3",
            "table5",
            "table5_drifts",
            "rounding",
            "bootstrap",
        )
        for s in gyro.experiment_seeds(2012, e, 3)
    ]
    assert len(set(every)) == len(every)  # no two experiments share a draw
    with pytest.raises(InputError, match="experiment"):
        gyro.experiment_seeds(1, "fig9", 1)


def test_bootstrap_seeds_are_children_of_the_bootstrap_experiment():
    ss = [gyro.bootstrap_seed(2012, b) for b in gyro.BOOTSTRAPS]
    ref = np.random.SeedSequence(2012).spawn(8)[7].spawn(len(gyro.BOOTSTRAPS))
    assert [tuple(a.generate_state(2)) for a in ss] == [tuple(b.generate_state(2)) for b in ref]
    assert len({tuple(a.generate_state(2)) for a in ss}) == len(ss)
    with pytest.raises(InputError, match="statistic"):
        gyro.bootstrap_seed(2012, "loo_rad")


# ---------------------------------------------------------------------------------- the notebook's parameters
def _cell() -> dict:
    """The gyro notebook's ``parameters`` cell, run: its names and default values."""
    nb = json.loads((NOTEBOOK_DIR / "gyro.ipynb").read_text(encoding="utf-8"))
    cell = next(
        c
        for c in nb["cells"]
        if c["cell_type"] == "code" and "parameters" in c.get("metadata", {}).get("tags", [])
    )
    ns: dict = {}
    exec("".join(cell["source"]), ns)
    return {k: v for k, v in ns.items() if not k.startswith("__")}


def test_from_notebook_builds_what_the_notebooks_mapping_cell_builds():
    cell = _cell()
    assert set(cell) == set(gyro.NOTEBOOK_PARAMETERS)
    # the notebook's mapping cell, as it stood before from_notebook
    expected = gyro.StudyParams(
        hot=gyro.HotNetSettings(
            spread=cell["spread"],
            goal=cell["goal"],
            goal_kind=cell["goal_kind"],
            input_unit=cell["input_unit"],
        ),
        cold=gyro.ColdNetSettings(spread_sd=cell["cold_spread"], dt_column=cell["cold_dt_column"]),
        sim=gyro.SimulationSettings(
            n_tests=cell["n_sim_tests"],
            n_seeds=cell["n_seeds"],
            seed=cell["sim_seed"],
            step_s=cell["sim_step_s"],
            gyro_arw_deg_rt_h=cell["sim_gyro_arw_deg_rt_h"],
            gyro_bias_sd_deg_h=cell["sim_gyro_bias_sd_deg_h"],
            accel_bias_sd_ug=cell["sim_accel_bias_sd_ug"],
            tilt_sd_arcsec=cell["sim_tilt_sd_arcsec"],
            azimuth_sd_arcsec=cell["sim_azimuth_sd_arcsec"],
        ),
        thermal=gyro.ColdStudySettings(
            n_draws=cell["n_cold_draws"], raw_spread=cell["cold_raw_spread"]
        ),
    )
    assert gyro.StudyParams.from_notebook(**cell) == expected
    assert (
        gyro.StudyParams.from_notebook() == expected == gyro.StudyParams()
    )  # the cell's defaults are theirs


#: One changed value per parameter of the cell (each valid).
CHANGED = {
    "spread": 3.0,
    "goal": 0.001,
    "goal_kind": "sse",
    "input_unit": "deg",
    "cold_spread": 1.0,
    "cold_dt_column": "align_temp_change_c",
    "n_sim_tests": 4,
    "n_seeds": 3,
    "sim_seed": 7,
    "sim_step_s": 30.0,
    "sim_gyro_arw_deg_rt_h": 0.0001,
    "sim_gyro_bias_sd_deg_h": 0.001,
    "sim_accel_bias_sd_ug": 10.0,
    "sim_tilt_sd_arcsec": 2.0,
    "sim_azimuth_sd_arcsec": 5.0,
    "n_cold_draws": 50,
    "cold_raw_spread": 3.0,
}


@pytest.mark.parametrize("key", sorted(CHANGED))
def test_from_notebook_one_parameter_changes_its_field(key):
    cell = _cell()
    base = gyro.StudyParams.from_notebook(**cell)
    got = gyro.StudyParams.from_notebook(**(cell | {key: CHANGED[key]}))
    group, name = gyro.NOTEBOOK_PARAMETERS[key]
    assert getattr(getattr(got, group), name) == CHANGED[key]
    assert got == dataclasses.replace(
        base, **{group: dataclasses.replace(getattr(base, group), **{name: CHANGED[key]})}
    )


def test_from_notebook_sets_n_workers_aside_and_rejects_unknown_keys():
    cell = _cell()
    assert set(CHANGED) | {"n_workers"} == set(cell)
    assert gyro.StudyParams.from_notebook(
        **(cell | {"n_workers": 2})
    ) == gyro.StudyParams.from_notebook(**cell)
    with pytest.raises(
        InputError, match="parameter spreads: the gyro notebook has no such parameter"
    ):
        gyro.StudyParams.from_notebook(**(cell | {"spreads": 2.0}))
    with pytest.raises(InputError, match="n_seeds"):  # values are checked by the dataclasses
        gyro.StudyParams.from_notebook(n_seeds=0)
