"""The accelerometer as a workbench system: catalogue fits, diagnose/loop on tumble files, bad input, trials."""

import subprocess
import sys

import pandas as pd
import pytest

from navlib.data.tumble import TUMBLE_FILE
from navlib.errors import InputError
from navlib.workbench import get_system
from navlib.workbench import accelerometer as A
from navlib.workbench.diagnose import diagnose
from navlib.workbench.fit import fit_model

TRUE = {
    "k0_mg": 0.8,
    "k1_mg_g": -0.5,
    "bias_t1_mg_c": 0.015,
    "bias_t2_mg_c2": 5e-5,
    "sf_t1_mg_g_c": -0.04,
    "sf_t2_mg_g_c2": 1e-4,
    "k2_mg_g2": 0.02,
    "k2_t_mg_g2_c": -0.002,
    "kip_mg_g2": 0.03,
    "delta_o_mg": 0.2,
}


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "navlib", *args], capture_output=True, text=True)


def test_registered_with_its_catalogue():
    s = get_system("accelerometer")
    assert s.unit == "mg" and list(s.catalogue) == list(A.ACCELEROMETER_EFFECTS)


def test_full_catalogue_recovers_the_parameters_noise_free():
    data = A.simulate_catalogue(TRUE, noise_ug=0.0)
    f = fit_model("accelerometer", data, tuple(A.ACCELEROMETER_EFFECTS))
    for k, v in TRUE.items():
        assert f.params[k] == pytest.approx(v, rel=1e-6, abs=1e-12)
    assert f.rms < 1e-9


def test_diagnose_names_a_hidden_effect_and_stays_quiet_without_one():
    data = A.simulate_catalogue(TRUE, noise_ug=3.0, seed=4)
    cat = tuple(A.ACCELEROMETER_EFFECTS)
    d = diagnose(fit_model("accelerometer", data, tuple(e for e in cat if e != "cross_coupling")))
    assert d.missing == "cross_coupling"
    d0 = diagnose(fit_model("accelerometer", data, cat))
    assert d0.consistent_with_noise


def test_trials_and_table():
    st = A.hidden_effect_study(ratios=(10.0,), seeds=range(1), none_seeds=range(2))
    assert len(st) == len(A.ACCELEROMETER_EFFECTS) + 2
    tab = A.detection_table(st)
    assert set(tab["rate"]) == {"correctly named", "false alarms"}
    assert tab.loc[tab["rate"] == "correctly named", "value"].mean() >= 0.75
    with pytest.raises(InputError, match="unknown accelerometer effect"):
        A.hidden_effect_trial("k3", 1.0, 3.0, 0)


def _one_unit(tmp_path, temps=None):
    d = pd.read_csv(TUMBLE_FILE)
    d = d[d["unit"] == "A"]
    if temps is not None:
        d = d[d["set_point_c"].isin(temps)]
    p = tmp_path / "unit_a.csv"
    d.to_csv(p, index=False)
    return p


def test_cli_diagnose_and_loop_on_a_tumble_file(tmp_path):
    p = _one_unit(tmp_path)
    r = run_cli("diagnose", "accelerometer", str(p), "--model", "bias,scale_factor")
    assert r.returncode == 0, r.stderr
    assert "add 'scale_factor_temperature'" in r.stdout
    r = run_cli("loop", "accelerometer", str(p), "--model", "bias")
    assert r.returncode == 0, r.stderr
    assert "cubic in temperature" in r.stdout  # the simulator's cubic + step bias is not catalogued


def test_cli_bad_input_exit_2(tmp_path):
    r = run_cli("diagnose", "accelerometer", str(TUMBLE_FILE), "--model", "bias")
    assert r.returncode == 2 and "names 2 accelerometers (A, B)" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    p = _one_unit(tmp_path, temps=[25.0, 55.0])
    with pytest.raises(
        InputError, match="has 2 temperatures; effect 'bias_temperature' needs at least 3"
    ):
        fit_model("accelerometer", A.load_accelerometer(p), ("bias", "bias_temperature"))
    bad = tmp_path / "bad.csv"
    d = pd.read_csv(p)
    d.loc[3, "position_deg"] = 7.5
    d.to_csv(bad, index=False)
    r = run_cli("diagnose", "accelerometer", str(bad), "--model", "bias")
    assert (
        r.returncode == 2
        and "column 'position_deg', row 4 (file line 5): 7.5 is not on" in r.stderr
    )


@pytest.mark.slow
def test_unit_picks_one_accelerometer_of_a_file_that_holds_several(tmp_path):
    both = A.load_accelerometer(TUMBLE_FILE, unit="B")
    assert set(both["unit"]) == {"B"} and len(both) == int(
        (pd.read_csv(TUMBLE_FILE)["unit"] == "B").sum()
    )
    one = _one_unit(tmp_path)
    assert A.load_accelerometer(one).equals(A.load_accelerometer(TUMBLE_FILE, unit="A"))
    with pytest.raises(InputError, match=r"no rows of unit 'C' in column 'unit' \(it names A, B\)"):
        A.load_accelerometer(TUMBLE_FILE, unit="C")
    with pytest.raises(InputError, match="choose it with --unit"):
        A.load_accelerometer(TUMBLE_FILE)
    r = run_cli(
        "diagnose", "accelerometer", str(TUMBLE_FILE), "--model", "bias", "--unit", "A", "--json"
    )
    assert r.returncode == 0, r.stderr
    assert (
        r.stdout.strip()
        == run_cli(
            "diagnose", "accelerometer", str(one), "--model", "bias", "--json"
        ).stdout.strip()
    )
    for args, says in ((("--unit", "C"), "no rows of unit 'C'"), ((), "choose it with --unit")):
        r = run_cli("loop", "accelerometer", str(TUMBLE_FILE), "--model", "bias", *args)
        assert r.returncode == 2 and says in r.stderr and len(r.stderr.strip().splitlines()) == 1
    r = run_cli("loop", "compass", str(TUMBLE_FILE), "--unit", "A")
    assert r.returncode == 2 and "only the accelerometer system has units" in r.stderr
