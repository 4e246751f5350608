"""``navlib apply`` refuses calibrations that would give confident nonsense (issue 35, item 1): every key it
reads is checked by name (missing, wrong type or shape, text for a number, NaN, infinity), A must be
well conditioned (``COND_LIMIT``), and the corrected data must show the calibration's expected field
strength (``FIELD_WARN_REL``: a warning line; ``FIELD_REFUSE_REL``: refused, nothing written)."""

import copy
import json

import numpy as np
import pandas as pd
import pytest

from navlib.cli import main
from navlib.errors import InputError
from navlib.workbench import calibration as C
from navlib.workbench import free_simulation as FS
from navlib.workbench import magnetometer_free as MF

TRUE = {"hard_x_ut": 6.0, "hard_y_ut": -4.0, "hard_z_ut": 2.5, "scale_x": 0.03, "soft_xy": 0.015}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A simulated recording and its calibration (written by ``navlib calibrate``)."""
    folder = tmp_path_factory.mktemp("apply")
    data = FS.simulate_free(TRUE, duration_s=20.0, noise_ut=0.3, seed=np.random.SeedSequence(35))
    src = folder / "sim.csv"
    data.drop(columns=list(MF.DERIVED)).to_csv(src, index=False)
    cal = folder / "cal.json"
    assert main(["calibrate", "magnetometer", str(src), "--out", str(cal)]) == 0
    return src, cal, json.loads(cal.read_text())


def _apply(tmp_path, capsys, cal: dict, src, name="edited.json"):
    capsys.readouterr()
    path = tmp_path / name
    path.write_text(json.dumps(cal, allow_nan=True))
    out = tmp_path / f"{name}.csv"
    rc = main(["apply", str(path), str(src), "--out", str(out)])
    return rc, capsys.readouterr().err.strip(), out


def test_a_good_calibration_applies_quietly(files, tmp_path, capsys):
    src, _, cal = files
    rc, err, out = _apply(tmp_path, capsys, cal, src)
    assert rc == 0 and err == "" and out.is_file()


def _set(path, value):
    def edit(cal):
        node = cal
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value

    return edit


def _drop(*path):
    def edit(cal):
        node = cal
        for k in path[:-1]:
            node = node[k]
        del node[path[-1]]

    return edit


@pytest.mark.parametrize(
    "edit, says",
    [
        (
            _set(("magcal", "A"), [[1, 0, 0], [0, 1, 0], [0, 0, 0]]),
            "key 'magcal.A': condition number infinite",
        ),
        (
            _set(("magcal", "A"), [[1, 2, 3], [2, 4, 6], [1, 1, 1]]),
            "key 'magcal.A': condition number infinite",
        ),
        (
            _set(("magcal", "A"), [[1, 0, 0], [0, 1, 0], [0, 0, 0.05]]),
            "condition number 20 (the limit is 10)",
        ),
        (_set(("magcal", "A"), [[1, 0, 0], [0, 1, 0]]), "key 'magcal.A' must be a 3x3 array"),
        (
            _set(("magcal", "A"), [[1, 0, 0], [0, 1, "0"], [0, 0, 1]]),
            "key 'magcal.A[1][2]' = \"0\" is not a number",
        ),
        (
            _set(("magcal", "A"), [[1, 0, 0], [0, 1, float("nan")], [0, 0, 1]]),
            "key 'magcal.A[1][2]' = NaN is not a finite",
        ),
        (
            _set(("magcal", "A"), [[True, 0, 0], [0, 1, 0], [0, 0, 1]]),
            "key 'magcal.A[0][0]' = true is not a number",
        ),
        (_set(("magcal", "A"), "identity"), "key 'magcal.A' must be a 3x3 array"),
        (
            _set(("magcal", "b_ut"), [float("inf"), 0, 0]),
            "key 'magcal.b_ut[0]' = Infinity is not a finite number",
        ),
        (_set(("magcal", "b_ut"), [1, 2]), "key 'magcal.b_ut' must be 3 numbers, got [1, 2]"),
        (_set(("magcal", "b_ut"), None), "key 'magcal.b_ut' must be 3 numbers, got null"),
        (_drop("magcal", "b_ut"), "key 'magcal.b_ut' is missing"),
        (_drop("magcal"), "key 'magcal' is missing"),
        (_set(("magcal",), [1, 2]), "key 'magcal' must be a JSON object"),
        (
            _set(("magcal", "expected_field_strength_ut"), "43.5"),
            "key 'magcal.expected_field_strength_ut' = \"43.5\"",
        ),
        (
            _set(("magcal", "expected_field_strength_ut"), -43.5),
            "must be a positive field strength",
        ),
        (
            _set(("expected_field_strength_ut", "value"), 50.0),
            "differs from 'magcal.expected_field_strength_ut'",
        ),
        (
            _set(("temperature",), {"centre_c": "warm", "coef_ut_per_c": [0, 0, 0]}),
            "key 'temperature.centre_c' = \"warm\" is not a number",
        ),
        (_set(("temperature",), {"centre_c": 20.0}), "key 'temperature.coef_ut_per_c' is missing"),
        (
            _set(("to_accelerometer_axes",), [[1, 0], [0, 1]]),
            "key 'to_accelerometer_axes' must be a 3x3 array",
        ),
        (
            _set(("to_accelerometer_axes",), [[2, 0, 0], [0, 1, 0], [0, 0, 1]]),
            "is not a rotation matrix",
        ),
        (_set(("columns", "field"), ["mx", "my", "mz"]), "key 'columns.field'"),
        (_set(("version",), True), "calibration format version True"),
        (_set(("system",), "compass"), "a calibration of the system 'compass'"),
    ],
)
def test_every_hand_edited_key_is_checked_by_name(files, tmp_path, capsys, edit, says):
    src, _, cal = files
    bad = copy.deepcopy(cal)
    edit(bad)
    rc, err, out = _apply(tmp_path, capsys, bad, src)
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert err.startswith("navlib apply: error: edited.json: ") and says in err, err
    assert "internal error" not in err and not out.exists()


def test_a_calibration_that_is_not_an_object_is_refused(files, tmp_path, capsys):
    src, _, _ = files
    rc, err, out = _apply(tmp_path, capsys, [1, 2, 3], src)
    assert rc == 2 and "not a navlib calibration file" in err and not out.exists()


def test_huge_a_is_refused_by_the_field_strength_it_gives(files, tmp_path, capsys):
    """1e300 x I is well conditioned; the corrected field it gives is not the expected one."""
    src, _, cal = files
    bad = copy.deepcopy(cal)
    bad["magcal"]["A"] = (1e300 * np.eye(3)).tolist()
    rc, err, out = _apply(tmp_path, capsys, bad, src)
    assert (
        rc == 2 and len(err.splitlines()) == 1 and "sim.csv: the corrected field strength" in err
    ), err
    assert "expected_field_strength_ut" in err and "more than 25 %" in err and not out.exists()
    # an offset that overflows the corrected field: not finite, named by row
    bad["magcal"]["b_ut"] = [1.7e308, 0.0, 0.0]
    bad["magcal"]["A"] = [[-1.5, 0, 0], [0, 1, 0], [0, 0, 1]]
    rc, err, out = _apply(tmp_path, capsys, bad, src, "overflow.json")
    assert rc == 2 and "sim.csv: row 1 " in err and "is not finite" in err and not out.exists(), err


def test_the_field_strength_of_another_sensor_is_refused_and_a_nearby_one_warned(
    files, tmp_path, capsys
):
    """Data of a stronger field (x 1.33: 58 uT where the calibration expects 43.5) are refused; x 1.15 is
    written with one warning line on stderr."""
    src, _, cal = files
    data = pd.read_csv(src)
    for factor, refused in ((1.33, True), (1.15, False), (0.7, True)):
        other = data.copy()
        other[list(MF.MAG)] = other[list(MF.MAG)] * factor
        p = tmp_path / f"other_{factor}.csv"
        other.to_csv(p, index=False)
        rc, err, out = _apply(tmp_path, capsys, cal, p, f"cal_{factor}.json")
        assert len(err.splitlines()) == 1, err
        assert f"cal_{factor}.json's expected_field_strength_ut" in err, err
        if refused:
            assert rc == 2 and "error:" in err and "more than 25 %" in err and not out.exists(), err
        else:
            assert rc == 0 and "warning:" in err and "more than 10 %" in err and out.is_file(), err


def test_the_limits_are_the_stated_constants(files):
    _, _, cal = files
    good = copy.deepcopy(cal)
    s = np.sqrt(C.COND_LIMIT)
    good["magcal"]["A"] = np.diag([s, 1.0, 1.0 / s * 1.0001]).tolist()  # cond just under the limit
    assert C.check_calibration(good, "x")["A"].shape == (3, 3)
    good["magcal"]["A"] = np.diag([s, 1.0, 1.0 / s * 0.999]).tolist()  # just over
    with pytest.raises(InputError, match="the limit is 10"):
        C.check_calibration(good, "x")
    u = np.tile([1.0, 0.0, 0.0], (5, 1)) * cal["magcal"]["expected_field_strength_ut"]
    for rel, outcome in (
        (0.9 * C.FIELD_WARN_REL, "quiet"),
        (1.1 * C.FIELD_WARN_REL, "warn"),
        (1.1 * C.FIELD_REFUSE_REL, "refuse"),
    ):
        frame = pd.DataFrame(u * (1 + rel), columns=list(MF.MAG))
        if outcome == "refuse":
            with pytest.raises(InputError, match="nothing written"):
                C.check_corrected(cal, frame, "cal.json", "data.csv")
        else:
            assert len(C.check_corrected(cal, frame, "cal.json", "data.csv")) == (outcome == "warn")
