"""Every bad input gets one line that names the file, column and row (or the parameter)."""

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from navlib.data.compass_sweeps import load_sweeps

from navlib.sensors.compass import simulate_train_test
from navlib.methods.bpnet import AdamParams
from navlib.methods.de import DEParams
from navlib.methods.lm import LMParams
from navlib.studies.compass import StudyParams
from navlib.errors import InputError
from navlib.data.tables import write_new_csv


@pytest.fixture
def good(tmp_path):
    d = simulate_train_test()[["true_heading_deg", "measured_heading_deg", "sweep"]]
    return d


def write(tmp_path, frame, name="sweep.csv"):
    p = tmp_path / name
    frame.to_csv(p, index=False)
    return p


def one_line(err):
    msg = str(err.value)
    assert "\n" not in msg
    return msg


def test_good_file_loads(tmp_path, good):
    d = load_sweeps(write(tmp_path, good))
    assert len(d) == 242 and set(d.sweep) == {1, 2}


def test_missing_column(tmp_path, good):
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, good.drop(columns="measured_heading_deg")))
    assert "sweep.csv: missing column 'measured_heading_deg'" in one_line(e)


def test_misnamed_column_gets_a_suggestion(tmp_path, good):
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, good.rename(columns={"true_heading_deg": "true_heading"})))
    msg = one_line(e)
    assert "missing column 'true_heading_deg'" in msg and "'true_heading'" in msg


def test_non_numeric_value_names_row(tmp_path, good):
    g = good.astype(object)
    g.loc[6, "measured_heading_deg"] = "12.3deg"
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, g))
    assert one_line(e) == (
        "sweep.csv: column 'measured_heading_deg', row 7 (file line 8): '12.3deg' is not a number"
    )


@pytest.mark.parametrize("value,expect", [(np.nan, "is empty"), ("nan", "not a finite number")])
def test_nan_names_row(tmp_path, good, value, expect):
    g = good.astype(object)
    g.loc[10, "true_heading_deg"] = value
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, g))
    msg = one_line(e)
    assert "column 'true_heading_deg', row 11" in msg and expect in msg


def test_heading_outside_range(tmp_path, good):
    g = good.copy()
    g.loc[3, "measured_heading_deg"] = 365.0
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, g))
    assert (
        "column 'measured_heading_deg', row 4 (file line 5): 365.0 is outside 0..360 deg"
        in one_line(e)
    )
    g.loc[3, "measured_heading_deg"] = -3.0
    with pytest.raises(InputError, match="row 4 .*outside"):
        load_sweeps(write(tmp_path, g))


def test_radians_are_detected(tmp_path, good):
    g = good.copy()
    g["true_heading_deg"] = np.radians(g["true_heading_deg"])
    g["measured_heading_deg"] = np.radians(g["measured_heading_deg"])
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, g))
    assert "look like radians" in one_line(e) and "'true_heading_deg'" in one_line(e)


def test_duplicated_reading(tmp_path, good):
    g = good.copy()
    g.loc[5, "true_heading_deg"] = g.loc[4, "true_heading_deg"]
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, g))
    assert (
        "column 'true_heading_deg', row 6 (file line 7): heading 12 is repeated in sweep 1"
        in one_line(e)
    )


def test_too_few_readings(tmp_path, good):
    with pytest.raises(InputError) as e:
        load_sweeps(write(tmp_path, good.iloc[:5]))
    assert "5 data rows" in one_line(e) and "at least 8" in one_line(e)
    g = pd.concat([good[good.sweep == 1], good[good.sweep == 2].iloc[:4]])
    with pytest.raises(InputError, match="sweep 2 has 4 readings"):
        load_sweeps(write(tmp_path, g))


def test_missing_file_and_not_csv(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_sweeps(tmp_path / "nope.csv")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(InputError, match="empty.csv: file is empty"):
        load_sweeps(tmp_path / "empty.csv")


def test_write_never_overwrites(tmp_path, good):
    p = write(tmp_path, good, "mine.csv")
    before = p.read_bytes()
    with pytest.raises(InputError, match="already exists"):
        write_new_csv(good.iloc[:3], p)
    assert p.read_bytes() == before


def test_csv_and_results_writers_share_one_overwrite_rule(tmp_path, good):
    """write_new_csv and report.write_results both create their file through tables.write_new: an existing
    path, even a symbolic link to a file not there yet, is refused with each writer's own one line."""
    from navbook import report
    from navlib import verdicts

    claim = report.Claim(
        "c", "p", statistic="x, deg", estimate=verdicts.exact(0.5), boundary=1.0, holds_when="below"
    )
    for name, call, says in [
        ("s.csv", lambda f: write_new_csv(good, f), "already exists; not overwritten"),
        (
            "demo.json",
            lambda f: report.write_results("demo", claims=[claim], folder=f.parent),
            "a results file is already there",
        ),
    ]:
        link, target = tmp_path / name, tmp_path / f"target_of_{name}"
        link.symlink_to(target)  # dangling: target does not exist
        with pytest.raises(InputError, match=says) as err:
            call(link)
        assert str(err.value).startswith(str(link)) and not target.exists()
        link.unlink()
        assert call(link) == link and link.stat().st_size > 0  # a new file is written


@pytest.mark.parametrize(
    "make,name",
    [
        (lambda: StudyParams(de=DEParams(pop_size=3)), "NP"),
        (lambda: DEParams(f=0), "F"),
        (lambda: DEParams(f=2.1), "F"),
        (lambda: DEParams(f_max=3), "F"),
        (lambda: DEParams(cr=-0.1), "CR"),
        (lambda: StudyParams(n_hidden=0), "n_hidden"),
        (lambda: StudyParams(network_target="x"), "network_target"),
        (lambda: StudyParams(hybrid_target="deg"), "hybrid_target"),
        (lambda: LMParams(mu_inc=0.5), "mu_inc"),
        (lambda: LMParams(max_fail=0), "max_fail"),
        (lambda: AdamParams(lr=0), "lr"),
        (lambda: StudyParams(de={"pop_size": 95}), "de"),
    ],
)
def test_bad_notebook_parameters(make, name):
    with pytest.raises(InputError, match=name) as err:
        make()
    assert "\n" not in str(err.value)


def test_negative_noise_parameter():
    from dataclasses import replace

    from navlib.sensors.compass import CompassErrors

    with pytest.raises(InputError, match="noise_ut=-0.1"):
        replace(CompassErrors(), noise_ut=-0.1)


@pytest.mark.slow
def test_cli_refuses_to_overwrite_and_exits_2(tmp_path):
    out = tmp_path / "s.csv"
    ok = subprocess.run(
        [sys.executable, "-m", "navlib", "simulate-compass", str(out)],
        capture_output=True,
        text=True,
    )
    assert ok.returncode == 0 and out.exists()
    again = subprocess.run(
        [sys.executable, "-m", "navlib", "simulate-compass", str(out), "--noise-ut", "-1"],
        capture_output=True,
        text=True,
    )
    assert again.returncode == 2
    assert len(again.stderr.strip().splitlines()) == 1 and "Traceback" not in again.stderr
