"""Issue 18, the input half: the workbench refuses what it cannot use, in one line, instead of giving a
confident wrong answer -- duplicate or overflowing columns, implausible units and frames, stuck sensors,
broken user effects -- and ignores what it does not use; the CLI is quiet on a closed pipe and checks the
--report folder before the fit."""

import gzip
import json
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from navlib import cli
from navlib.data.compass_sweeps import load_sweeps
from navlib.data.gyro_tables import drift_measurements
from navlib.data.tables import Column, read_table
from navlib.data.tumble import TUMBLE_FILE, read_tumble
from navlib.errors import InputError
from navlib.paths import ROOT, data_path
from navlib.studies.workbench import REALDATA
from navlib.workbench import Effect, get_system, load_effects
from navlib.workbench.effects import CATALOGUES
from navlib.workbench.fit import fit_model, simulate
from navlib.workbench.loop import check_report_folder, loop
from navlib.workbench.magnetometer import (
    GYR,
    MAG,
    QUAT,
    load_magnetometer,
    predict_field,
    simulate_magnetometer,
)

ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def run_cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "navlib", *map(str, args)], capture_output=True, text=True, env=ENV
    )


def in_process(capsys, *args):
    """The CLI's ``main`` in this process: (status, stdout, stderr)."""
    status = cli.main([str(a) for a in args])
    out = capsys.readouterr()
    return status, out.out, out.err


def one_line(text):
    lines = text.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in text, text
    return lines[0]


def refused(fn, *args):
    with pytest.raises(InputError) as err:
        fn(*args)
    return one_line(str(err.value))


@pytest.fixture
def compass(tmp_path):
    data = simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.04}, noise=0.1, seed=0)
    path = tmp_path / "c.csv"
    data.to_csv(path, index=False)
    return data, path


@pytest.fixture
def mag():
    return simulate_magnetometer({"hard_x_ut": 5.0, "soft_xy": 0.02}, n=200, noise_ut=0.1, seed=1)


def write(tmp_path, frame, name):
    p = tmp_path / name
    frame.to_csv(p, index=False)
    return p


# ---------------------------------------------------------------------------------------- reading files
def test_a_repeated_column_is_refused_though_pandas_would_rename_it(tmp_path, compass):
    data, _ = compass
    twice = data.copy()
    twice.insert(3, "x", data["measured_heading_deg"] + 5)
    p = tmp_path / "twice.csv"
    p.write_text(twice.to_csv(index=False).replace(",x,", ",measured_heading_deg,", 1))
    assert (
        pd.read_csv(p).columns[3] == "measured_heading_deg.1"
    )  # what pandas would have used silently
    assert refused(load_sweeps, p) == (
        "twice.csv: column 'measured_heading_deg' appears more than once in the "
        "header (columns 2 and 4); remove or rename one"
    )
    r = run_cli("loop", "compass", p, "--model", "misalignment")
    assert r.returncode == 2 and "appears more than once" in one_line(r.stderr)
    spaced = tmp_path / "spaced.csv"
    spaced.write_text(
        data.to_csv(index=False).replace(",temperature_c,", ", true_heading_deg ,", 1)
    )
    assert "column 'true_heading_deg' appears more than once" in refused(load_sweeps, spaced)


@pytest.mark.parametrize(
    "column,value,expect",
    [
        ("time_s", "1e300", "column 'time_s', row 6 (file line 7): 1e300 is outside 0..1e+09 s"),
        (
            "time_s",
            "1e400",
            "column 'time_s', row 6 (file line 7): '1e400' overflows a floating-point number",
        ),
        (
            "temperature_c",
            "-inf",
            "column 'temperature_c', row 6 (file line 7): '-inf' is not a finite number",
        ),
        (
            "measured_heading_deg",
            "1e300",
            "column 'measured_heading_deg', row 6 (file line 7): 1e300 is outside 0..360",
        ),
    ],
)
def test_huge_and_overflowing_values_in_used_columns_are_named(
    tmp_path, compass, column, value, expect
):
    data, _ = compass
    bad = data.astype(object)
    bad.loc[5, column] = value
    assert refused(load_sweeps, write(tmp_path, bad, "big.csv")).startswith("big.csv: " + expect)


def test_a_field_of_1e300_exits_2_not_internal_error(tmp_path, mag):
    """On main, 1e300 in a magnetometer file ended in numpy warnings and 'internal error', exit 1."""
    bad = mag.copy()
    bad.loc[7, "mag_y_ut"] = 1e300
    r = run_cli("loop", "magnetometer", write(tmp_path, bad, "m.csv"))
    assert r.returncode == 2
    assert one_line(r.stderr).endswith(
        "m.csv: column 'mag_y_ut', row 8 (file line 9): 1e+300 is outside -1e+06..1e+06 uT"
    )


def test_every_checked_column_has_a_finite_limit(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("value\n1\n1e300\n")
    assert (
        refused(read_table, p, [Column("value")])
        == "t.csv: column 'value', row 2 (file line 3): 1e300 is outside -1e+12..1e+12"
    )
    assert read_table(p, [])["value"].tolist() == ["1", "1e300"]  # not described: not checked


@pytest.mark.slow
def test_ignored_columns_are_really_ignored(tmp_path, compass):
    """NaN, text and bytes that are not UTF-8 in columns no model uses change nothing."""
    data, clean = compass
    extra = data.copy()
    extra["note"] = ["nan" if i % 5 == 0 else "ok" for i in range(len(extra))]
    extra["mag_x_ut"] = ["abc" if i % 7 == 0 else 20.0 for i in range(len(extra))]  # informational
    text = extra.to_csv(index=False).encode().replace(b",ok,", b",\xb0\xff,", 3)
    p = tmp_path / "extra.csv"
    p.write_bytes(text)
    frame = load_sweeps(p)
    assert frame["mag_x_ut"].isna().sum() == (len(frame) + 6) // 7 and "\ufffd" in "".join(
        frame["note"]
    )
    a, b = (
        loop("compass", load_sweeps(clean), ["misalignment"]),
        loop("compass", frame, ["misalignment"]),
    )
    assert a.final.effects == b.final.effects and a.final.rms == b.final.rms
    r = run_cli("loop", "compass", p, "--model", "misalignment", "--json")
    assert r.returncode == 0 and json.loads(r.stdout)["final"]["rms"] == pytest.approx(
        a.final.rms, rel=1e-12
    )


def test_informational_magnetometer_columns_are_not_refused(tmp_path, mag):
    m = mag.copy()
    m["moving"] = "yes"
    m["att_blur"] = np.nan
    m["acc_x_ms2"] = "-"
    frame = load_magnetometer(write(tmp_path, m, "m.csv"))
    assert frame["moving"].isna().all() and frame["acc_x_ms2"].isna().all()


def test_bytes_that_are_not_utf8_in_a_used_cell_are_named(tmp_path, compass):
    _, p = compass
    lines = p.read_bytes().split(b"\n")
    fields = lines[4].split(b",")
    fields[1] = fields[1].replace(b".", b"\xb0", 1)
    lines[4] = b",".join(fields)
    p.write_bytes(b"\n".join(lines))
    assert "column 'measured_heading_deg', row 4 (file line 5)" in refused(load_sweeps, p)
    assert "\\xb0" in refused(load_sweeps, p) and "not UTF-8" in refused(load_sweeps, p)


def test_file_lines_count_blank_lines_and_quoted_breaks(tmp_path):
    p = tmp_path / "b.csv"
    p.write_text(
        'true_heading_deg,measured_heading_deg,note\n0,1,a\n\n10,11,"two\nlines"\n20,21,b\n30,x,c\n'
    )
    assert (
        refused(load_sweeps, p)
        == "b.csv: column 'measured_heading_deg', row 4 (file line 7): 'x' is not a number"
    )


def test_files_that_are_not_csv_text(tmp_path, compass):
    data, p = compass
    gz = tmp_path / "c.csv.gz"
    gz.write_bytes(gzip.compress(p.read_bytes()))
    assert "is gzip-compressed" in refused(load_sweeps, gz)
    if os.path.exists("/dev/zero"):
        assert (
            refused(load_sweeps, "/dev/zero")
            == "/dev/zero: is not a regular file, expected a CSV compass sweep"
        )
    binary = tmp_path / "b.csv"
    binary.write_bytes(b"true_heading_deg\x00\x01\x02")
    assert "is a binary file" in refused(load_sweeps, binary)
    for name, encoding in (("u16.csv", "utf-16"), ("bom.csv", "utf-8-sig")):
        other = tmp_path / name
        other.write_bytes(p.read_text().encode(encoding))
        assert load_sweeps(other).equals(load_sweeps(p))
    semi = tmp_path / "semi.csv"
    semi.write_text(p.read_text().replace(",", ";"))
    assert "the file seems to use ';' as the separator" in refused(load_sweeps, semi)
    wide = tmp_path / "wide.csv"
    wide.write_text(p.read_text().replace("\n", ",7\n", 3).replace(",7\n", "\n", 1))
    assert refused(load_sweeps, wide).startswith("wide.csv: line 2: 6 fields, the header has 5")


# ------------------------------------------------------------------------------ plausibility of units
@pytest.mark.parametrize(
    "factor,unit", [(0.01, "gauss"), (10.0, "mG"), (1000.0, "nT"), (1e-3, "mT"), (1e-6, "T")]
)
def test_a_field_in_another_unit_is_named(tmp_path, mag, factor, unit):
    m = mag.copy()
    m[list(MAG)] *= factor
    msg = refused(load_magnetometer, write(tmp_path, m, "m.csv"))
    assert msg.startswith(
        "m.csv: columns mag_x_ut, mag_y_ut, mag_z_ut: the field that follows the attitude"
    )
    assert f"these look like {unit}" in msg and f"(multiply by {1 / factor:g} for uT)" in msg


def test_a_field_in_gauss_exits_2_from_the_cli(tmp_path, mag):
    m = mag.copy()
    m[list(MAG)] /= 100
    r = run_cli("loop", "magnetometer", write(tmp_path, m, "g.csv"))
    assert r.returncode == 2 and "look like gauss" in one_line(r.stderr)


@pytest.mark.parametrize(
    "axes,expect",
    [
        ((1, -1, -1), "mag_y_ut holds -y and mag_z_ut holds -z (FLU"),
        ((1, 1, -1), "mag_z_ut holds -z"),
        ("swap", "mag_x_ut holds y and mag_y_ut holds x"),
    ],
)
def test_axes_in_another_frame_are_named(tmp_path, mag, axes, expect):
    m = mag.copy()
    v = m[list(MAG)].to_numpy()
    m[list(MAG)] = v[:, [1, 0, 2]] if axes == "swap" else v * np.array(axes)
    msg = refused(load_magnetometer, write(tmp_path, m, "m.csv"))
    assert "the axes are not FRD" in msg and expect in msg


def test_a_stuck_or_unrelated_magnetometer_is_refused(tmp_path, mag):
    stuck = mag.copy()
    stuck["mag_z_ut"] = 12.5
    assert refused(load_magnetometer, write(tmp_path, stuck, "s.csv")).startswith(
        "s.csv: column 'mag_z_ut' is 12.5 in all 200 rows"
    )
    shuffled = mag.copy()
    shuffled[list(MAG)] = mag[list(MAG)].to_numpy()[np.random.default_rng(3).permutation(len(mag))]
    assert "the reference attitude explains only" in refused(
        load_magnetometer, write(tmp_path, shuffled, "u.csv")
    )


def test_a_few_spikes_are_not_taken_for_a_unit(tmp_path, mag):
    """Spikes are left to the outlier screening: the plausibility fits set them aside."""
    m = mag.copy()
    m.loc[[3, 50, 120], "mag_x_ut"] = [1e6, -1e6, 300.0]
    assert len(load_magnetometer(write(tmp_path, m, "spikes.csv"))) == 200
    m[list(MAG)] /= 100
    assert "look like gauss" in refused(load_magnetometer, write(tmp_path, m, "gauss.csv"))
    a = read_tumble(TUMBLE_FILE)
    a = a[
        (a["unit"] == "A") & (a["set_point_c"] == a["set_point_c"].iloc[0])
    ].copy()  # 24 positions
    a.loc[a.index[[0, 7]], "output_mg"] = -5000.0
    assert len(get_system("accelerometer").load(write(tmp_path, a, "a.csv"))) == 24


def test_gyro_rates_in_another_unit_are_named(tmp_path):
    """A turning trajectory (a constant body rate about a fixed axis, 10 Hz): the gyro must agree with the
    rate at which the reference attitude turns."""
    t = 0.1 * np.arange(600)
    w = np.array([40.0, 25.0, 60.0])
    q = Rotation.from_rotvec(np.radians(np.outer(t, w))).as_quat()[:, [3, 0, 1, 2]]
    f = pd.DataFrame(q, columns=list(QUAT))
    f[list(GYR)] = w
    f["time_s"] = t
    f[list(MAG)] = predict_field({"field_n_ut": 15.2, "field_e_ut": -0.3, "field_d_ut": 40.8}, f)
    assert len(load_magnetometer(write(tmp_path, f, "deg.csv"))) == 600
    f[list(GYR)] = np.radians(w)
    assert "these look like rad/s (multiply by 57.2958 for deg/s)" in refused(
        load_magnetometer, write(tmp_path, f, "rad.csv")
    )


def tumble_unit(tmp_path, change=None, name="a.csv"):
    t = read_tumble(TUMBLE_FILE)
    a = t[t["unit"] == "A"].copy()
    if change:
        change(a)
    return write(tmp_path, a, name)


@pytest.mark.parametrize(
    "change,expect",
    [
        (
            lambda a: a.__setitem__("output_mg", a["output_mg"] / 1000),
            "the output looks like g (multiply by 1000 for mg)",
        ),
        (
            lambda a: a.__setitem__("output_mg", a["output_mg"] * 9.80665e-3),
            "the output looks like m/s^2",
        ),
        (lambda a: a.__setitem__("output_mg", -a["output_mg"]), "the input axis is reversed"),
        (lambda a: a.__setitem__("output_mg", 2.0), "column 'output_mg' is 2 in all 552 rows"),
        (
            lambda a: a.__setitem__("position_deg", np.radians(a["position_deg"])),
            "these look like radians",
        ),
    ],
)
def test_accelerometer_units_are_checked(tmp_path, change, expect):
    get_system("accelerometer").load(tumble_unit(tmp_path))  # the unit as recorded passes
    assert expect in refused(
        get_system("accelerometer").load, tumble_unit(tmp_path, change, "bad.csv")
    )


def test_compass_headings_that_do_not_follow_are_refused(tmp_path, compass):
    data, _ = compass
    ccw = data.copy()
    ccw["measured_heading_deg"] = np.mod(360.0 - data["measured_heading_deg"], 360.0)
    assert "the headings run the other way" in refused(load_sweeps, write(tmp_path, ccw, "ccw.csv"))
    shuffled = data.copy()
    shuffled["measured_heading_deg"] = data["measured_heading_deg"].to_numpy()[
        np.random.default_rng(0).permutation(len(data))
    ]
    assert "does not follow 'true_heading_deg'" in refused(
        load_sweeps, write(tmp_path, shuffled, "sh.csv")
    )
    stuck = data.copy()
    stuck["measured_heading_deg"] = 42.0
    assert "column 'measured_heading_deg' is 42 in all 242 rows" in refused(
        load_sweeps, write(tmp_path, stuck, "st.csv")
    )


@pytest.mark.parametrize(
    "change,expect",
    [
        (
            lambda d: d.__setitem__("drift_deg_h", d["drift_deg_h"] / 3600),
            "drift_deg_h in deg/s (multiply by 3600)",
        ),
        (
            lambda d: d.__setitem__("latitude_error_deg", d["latitude_error_deg"] * np.pi / 180),
            "latitude_error_deg in radians",
        ),
        (
            lambda d: d.__setitem__("latitude_error_deg", -d["latitude_error_deg"]),
            "the drift falls as the 12 h latitude",
        ),
        (
            lambda d: d.__setitem__("drift_deg_h", 0.001),
            "column 'drift_deg_h' is 0.001 in all 25 rows",
        ),
    ],
)
def test_drift_units_are_checked(tmp_path, change, expect):
    d = drift_measurements()[
        ["latitude_error_deg", "drift_deg_h", "temperature_c", "temperature_change_c"]
    ]
    get_system("drift").load(write(tmp_path, d, "d.csv"))
    change(d)
    assert expect in refused(get_system("drift").load, write(tmp_path, d, "bad.csv"))


def real_files():
    files = [
        ("compass", data_path("compass_sweeps.csv")),
        ("drift", data_path("gyro_drift_measurements.csv")),
    ]
    files += [("compass", p) for p in sorted((REALDATA / "broad" / "level").glob("*.csv"))]
    files += [("magnetometer", p) for p in sorted((REALDATA / "broad" / "3d").glob("*.csv"))]
    return files


@pytest.mark.parametrize("system,path", real_files(), ids=lambda x: getattr(x, "name", x))
def test_real_and_committed_data_pass_every_check(system, path):
    frame = get_system(system).load(path)
    assert len(frame) >= 25 and not frame.attrs.get("line_jumps")


def test_both_committed_accelerometers_pass(tmp_path):
    t = read_tumble(TUMBLE_FILE)
    for unit, part in t.groupby("unit"):
        assert len(get_system("accelerometer").load(write(tmp_path, part, f"{unit}.csv"))) == len(
            part
        )


# -------------------------------------------------------------------------------------- user effects
HEAD = """import sys
import numpy as np
from navlib.workbench.effects import Effect


def good(p, d):
    h = np.radians(d["true_heading_deg"].to_numpy(float))
    return p["a_deg"] * np.sin(3 * h) + p["b_deg"] * np.cos(3 * h)


def effect(contribution=good, name="q", params=("a_deg", "b_deg"), **kw):
    return Effect(name, params, ("deg",) * len(params), "three-cycle", system="compass", contribution=contribution, **kw)

"""

BROKEN = {
    "import_error": (
        "import nosuchmodule_xyz\n",
        "e.py: line 14: ModuleNotFoundError: No module named 'nosuchmodule_xyz'",
    ),
    "exception_at_import": (
        "q = effect()\nraise RuntimeError('boom')\n",
        "e.py: line 15: RuntimeError: boom",
    ),
    "bad_effect_definition": (
        "q = Effect('q', ('a',), ('deg', 'deg'), 'm', system='compass')\n",
        "e.py: line 14: InputError: effect 'q': give one unit per parameter",
    ),
    "exit_at_import": ("q = effect()\nsys.exit(0)\n", "e.py: calls sys.exit(0) while it is loaded"),
    "syntax_error": ("q = effect(\n", "e.py: line 14: '(' was never closed"),
    "two_with_one_name": (
        "q = effect()\nr = effect(params=('c_deg',))\n",
        "e.py: two effects are named 'q' (variables 'q' and 'r')",
    ),
    "parameter_of_the_catalogue": (
        "q = effect(params=('yaw_deg', 'b_deg'))\n",
        "e.py: effect 'q': parameter 'yaw_deg' is already a parameter of the catalogue's",
    ),
    "another_system": (
        "q = Effect('q', ('a',), ('deg',), 'm', system='compas', contribution=good)\n",
        "e.py: defines no Effect with system='compass' (its effects are for system 'compas')",
    ),
    "raises": (
        "q = effect(lambda p, d: 1 / 0)\n",
        "e.py: effect 'q': contribution raised ZeroDivisionError",
    ),
    "exits": (
        "q = effect(lambda p, d: sys.exit(3))\n",
        "e.py: effect 'q': contribution called sys.exit(3)",
    ),
    "nan": (
        "q = effect(lambda p, d: good(p, d) * np.nan)\n",
        "e.py: effect 'q': contribution returned nan at row 1",
    ),
    "inf": (
        "q = effect(lambda p, d: good(p, d) + np.where(d.index == 9, np.inf, 0.0))\n",
        "e.py: effect 'q': contribution returned inf at row 10",
    ),
    "text": (
        "q = effect(lambda p, d: np.array(['x'] * len(d)))\n",
        "e.py: effect 'q': contribution returned text",
    ),
    "none": ("q = effect(lambda p, d: None)\n", "e.py: effect 'q': contribution returned None"),
    "scalar": (
        "q = effect(lambda p, d: p['a_deg'])\n",
        "e.py: effect 'q': contribution returned shape (), the measurement",
    ),
    "short": (
        "q = effect(lambda p, d: good(p, d)[:-1])\n",
        "e.py: effect 'q': contribution returned shape (241,)",
    ),
    "writes_the_data": (
        "def w(p, d):\n    d['true_heading_deg'].to_numpy()[:] = 0\n    return good(p, d)\nq = effect(w)\n",
        "e.py: effect 'q': contribution raised ValueError: assignment destination is read-only",
    ),
}


def effects_file(tmp_path, body, name="e.py"):
    p = tmp_path / name
    p.write_text(HEAD + body)
    return p


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_every_broken_effects_file_exits_2_naming_file_and_effect(tmp_path, compass, capsys, case):
    body, expect = BROKEN[case]
    _, data = compass
    status, out, err = in_process(
        capsys,
        "loop",
        "compass",
        data,
        "--model",
        "misalignment,hard_iron,soft_iron",
        "--effects",
        effects_file(tmp_path, body),
        "--json",
    )
    assert status == 2 and out == ""
    assert expect in one_line(err), err


@pytest.mark.slow
@pytest.mark.parametrize("case", ["import_error", "exit_at_import", "raises", "nan"])
def test_broken_effects_exit_2_from_a_real_process(tmp_path, compass, case):
    """Through ``python -m navlib`` (on main: 'internal error' exit 1, or exit 0 with no output)."""
    body, expect = BROKEN[case]
    r = run_cli(
        "loop",
        "compass",
        compass[1],
        "--model",
        "misalignment",
        "--effects",
        effects_file(tmp_path, body),
    )
    assert r.returncode == 2 and expect in one_line(r.stderr) and r.stdout == ""


def test_an_effect_that_assigns_to_the_data_does_not_change_the_answer(tmp_path, compass):
    data, _ = compass
    data = data.copy()
    data["measured_heading_deg"] = np.mod(
        data["measured_heading_deg"] + 0.5 * np.sin(np.radians(3 * data["true_heading_deg"])), 360
    )
    plain = load_effects(
        effects_file(tmp_path, "q = effect()\n", "p.py"), "compass", CATALOGUES["compass"]
    )
    rude = load_effects(
        effects_file(
            tmp_path,
            "def w(p, d):\n    out = good(p, d)\n"
            "    d['true_heading_deg'] = d['true_heading_deg'] + 90\n"
            "    d.loc[:, 'measured_heading_deg'] = 0.0\n    return out\n"
            "q = effect(w)\n",
            "r.py",
        ),
        "compass",
        CATALOGUES["compass"],
    )
    before = data.copy()
    a = loop("compass", data, ["misalignment", "hard_iron", "soft_iron"], user_effects=plain)
    b = loop("compass", data, ["misalignment", "hard_iron", "soft_iron"], user_effects=rude)
    assert a.final.effects == b.final.effects and "q" in a.final.effects
    assert a.final.params == b.final.params and data.equals(before)


def test_an_effect_the_data_cannot_test_is_listed(tmp_path, compass, capsys):
    data, path = compass
    e = effects_file(tmp_path, "q = effect(columns=('wind_m_s',))\n")
    status, out, _ = in_process(
        capsys, "loop", "compass", path, "--model", "misalignment", "--effects", e, "--json"
    )
    assert status == 0 and json.loads(out)["untested"] == [
        {"effect": "q", "why": "no column 'wind_m_s'"}
    ]
    status, out, _ = in_process(
        capsys, "loop", "compass", path, "--model", "misalignment", "--effects", e
    )
    assert status == 0 and "not tested: q (no column 'wind_m_s')" in out.splitlines()
    no_temp = write(tmp_path, data.drop(columns="temperature_c"), "nt.csv")
    status, out, _ = in_process(
        capsys, "diagnose", "compass", no_temp, "--model", "misalignment", "--json"
    )
    assert {"effect": "temperature", "why": "no column 'temperature_c'"} in json.loads(out)[
        "untested"
    ]
    text = data.astype(object)
    text["wind_m_s"] = ["calm" if i == 3 else 1.0 + i % 4 for i in range(len(text))]
    status, out, _ = in_process(
        capsys,
        "loop",
        "compass",
        write(tmp_path, text, "w.csv"),
        "--model",
        "misalignment",
        "--effects",
        e,
        "--json",
    )
    assert json.loads(out)["untested"] == [
        {"effect": "q", "why": "'wind_m_s' row 4 is 'calm', not a number"}
    ]


def test_effects_given_to_the_api_are_checked_too(compass):
    data, _ = compass
    a = Effect(
        "q",
        "a_deg",
        "deg",
        "m",
        system="compass",
        contribution=lambda p, d: p["a_deg"] * np.ones(len(d)),
    )
    assert a.params == ("a_deg",) and a.units == ("deg",)  # a lone name, not its letters
    with pytest.raises(InputError, match="effect 'q' is given twice"):
        fit_model("compass", data, ["misalignment"], user_effects=(a, a))
    clash = Effect("r", ("yaw_deg",), ("deg",), "m", system="compass", contribution=a.contribution)
    with pytest.raises(
        InputError, match="parameter 'yaw_deg' is already a parameter of effect 'misalignment'"
    ):
        fit_model("compass", data, ["misalignment"], user_effects=(clash,))


def test_prints_of_an_effects_file_do_not_spoil_the_json(tmp_path, compass, capsys):
    e = effects_file(tmp_path, "print('loading my effects')\nq = effect()\n")
    status, out, err = in_process(
        capsys, "loop", "compass", compass[1], "--model", "misalignment", "--effects", e, "--json"
    )
    assert status == 0 and json.loads(out)["system"] == "compass" and "loading my effects" in err


# ----------------------------------------------------------------------------------------------- CLI
@pytest.mark.slow
def test_a_closed_pipe_ends_quietly(compass):
    """``loop ... | head -1`` printed "error: : Broken pipe"; the reader here is gone before anything is
    written, so the write fails for certain."""
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "navlib",
            "loop",
            "compass",
            str(compass[1]),
            "--model",
            "misalignment",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=ENV,
    )
    p.stdout.close()
    err = p.stderr.read().decode()
    p.wait()
    assert err == "" and p.returncode == cli.BROKEN_PIPE
    shell = subprocess.run(
        f"{sys.executable} -m navlib loop compass {compass[1]} --model misalignment | head -1",
        shell=True,
        capture_output=True,
        text=True,
        env=ENV,
    )
    assert shell.stderr == "" and shell.stdout.split() == [
        "step",
        "model",
        "rms",
        "(deg)",
        "held-out",
        "rms",
        "(deg)",
        "named",
    ]


@pytest.mark.slow
def test_the_report_folder_is_refused_before_the_fit(tmp_path, compass):
    """The report check comes first: it wins over a data file that would only fail later, in the fit."""
    _, path = compass
    late = effects_file(tmp_path, "q = effect(lambda p, d: 1 / 0)\n")
    inside_a_file = tmp_path / "c.csv" / "rep"
    r = run_cli(
        "loop",
        "compass",
        path,
        "--model",
        "misalignment",
        "--effects",
        late,
        "--report",
        inside_a_file,
    )
    assert (
        r.returncode == 2
        and "cannot be created, " in one_line(r.stderr)
        and "is a file" in r.stderr
    )
    taken = tmp_path / "rep"
    taken.mkdir()
    (taken / "loop.png").write_bytes(b"mine")
    r = run_cli(
        "loop", "compass", path, "--model", "misalignment", "--effects", late, "--report", taken
    )
    assert r.returncode == 2 and "loop.png: already exists" in one_line(r.stderr)
    assert (taken / "loop.png").read_bytes() == b"mine" and not (taken / "loop.md").exists()


@pytest.mark.skipif(
    not os.path.isdir("/proc/self"), reason="needs /proc (a folder nobody can write to)"
)
def test_an_unwritable_report_folder_is_refused_and_not_created():
    with pytest.raises(InputError, match=r"/proc/navlib_report: cannot write the report there"):
        check_report_folder("/proc/navlib_report")
    assert not os.path.exists("/proc/navlib_report")
