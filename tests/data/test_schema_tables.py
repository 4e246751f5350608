"""The data dictionary of every workbench system (``columns_table``) lists exactly what its loader requires:
each required column, dropped from a valid file, is refused by name; a file holding only the required columns
loads."""

import numpy as np
import pandas as pd
import pytest

from navlib.data.tables import Column, read_table, schema_table
from navlib.data.tumble import TUMBLE_FILE
from navlib.errors import InputError
from navlib.paths import data_path
from navlib.workbench import SYSTEMS, get_system
from navlib.workbench.effects import columns_table
from navlib.workbench.magnetometer import simulate_magnetometer
from navlib.workbench.free_simulation import simulate_free


def _valid_frame(system: str) -> pd.DataFrame:
    """A file each loader accepts: the shipped files, or the systems' own simulators."""
    if system == "compass":
        return pd.read_csv(data_path("compass_sweeps.csv"))
    if system == "drift":
        return pd.read_csv(data_path("gyro_drift_measurements.csv"))
    if system == "accelerometer":
        t = pd.read_csv(TUMBLE_FILE)
        return t[t["unit"] == "A"].reset_index(drop=True)
    if system == "magnetometer":
        d = simulate_magnetometer({"hard_x_ut": 3.0}, n=120, seed=4)
        d["time_s"] = 0.1 * np.arange(len(d))
        return d
    if system == "magnetometer_free":
        return simulate_free({"hard_x_ut": 3.0}, duration_s=20.0, seed=np.random.SeedSequence(5))
    raise AssertionError(f"no valid file for {system}")


@pytest.mark.parametrize("system", sorted(SYSTEMS))
def test_table_lists_exactly_what_the_loader_requires(system, tmp_path):
    table = columns_table(system)
    assert list(table.columns) == ["column", "unit", "required", "limits", "meaning"]
    assert table["column"].is_unique and (table["meaning"].str.len() > 0).all()
    required = table.loc[table.required == "yes", "column"].tolist()
    assert required
    frame = _valid_frame(system)
    load = get_system(system).load
    path = tmp_path / "ok.csv"
    frame.to_csv(path, index=False)
    load(path)  # the valid file loads
    for col in required:
        p = tmp_path / f"without_{col}.csv"
        frame.drop(columns=[col]).to_csv(p, index=False)
        with pytest.raises(InputError) as err:
            load(p)
        assert f"'{col}'" in str(err.value) and "missing column" in str(err.value)
    only = tmp_path / "required_only.csv"
    one = frame[frame["sweep"] == 1] if "sweep" in frame else frame  # without 'sweep': one sweep
    one[required].to_csv(only, index=False)
    load(only)  # nothing else is required


def test_the_table_is_the_loaders_own_schema():
    """Derived from the Column list, not typed twice: a new column shows up in the table."""
    cols = (
        Column("a_deg", "deg", lo=0, hi=360, meaning="an angle"),
        Column("n", "", required=False, lo=0, integer=True, meaning="a count"),
        Column("who", required=True, text=True, meaning="a name"),
        Column("x", "uT", required=False, checked=False, meaning="information"),
    )
    t = schema_table(cols)
    assert t["column"].tolist() == ["a_deg", "n", "who", "x"]
    assert t["required"].tolist() == ["yes", "no", "yes", "no"]
    assert t["unit"].tolist() == ["deg", "-", "text", "uT"]
    assert t["limits"].tolist() == ["0..360", "0.., whole", "text, not empty", "not checked"]


def test_text_column_kept_as_text_and_required(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("v,who\n1,alpha\n2,007\n")
    cols = [Column("v"), Column("who", text=True, meaning="a name")]
    f = read_table(p, cols)
    assert f["who"].tolist() == ["alpha", "007"]
    q = tmp_path / "u.csv"
    q.write_text("v\n1\n")
    with pytest.raises(InputError, match=r"u.csv: missing column 'who' \(a name\)"):
        read_table(q, cols)


def test_system_without_schema_is_named():
    from dataclasses import replace
    from navlib.workbench.effects import register_system, SYSTEMS as REG

    s = replace(get_system("drift"), name="drift_noschema", columns=())
    register_system(s)
    try:
        with pytest.raises(InputError, match="drift_noschema"):
            columns_table("drift_noschema")
    finally:
        REG.pop("drift_noschema")


# ------------------------------------------------------------------- the largest table (issue 34)
def test_a_table_over_the_row_limit_is_refused_before_it_is_parsed(tmp_path, monkeypatch):
    """Every workbench step is linear in the rows, but 2,000,000 rows would still take hours and tens of GB:
    a file over MAX_ROWS is refused by name, its line count and the limit, before any parsing."""
    import navlib.data.tables as T
    from navlib.errors import InputError

    cols = [T.Column("x", "-", "a number")]
    ok, big = tmp_path / "ok.csv", tmp_path / "big.csv"
    ok.write_text("x\n" + "1\n" * 50)
    big.write_text("x\n" + "1\n" * 51)
    monkeypatch.setattr(T, "_parse", lambda *a: (_ for _ in ()).throw(AssertionError("parsed")))
    with pytest.raises(
        InputError, match=r"big.csv: 51 lines after the header; navlib reads at most 50 rows"
    ):
        T.read_table(big, cols, max_rows=50)
    monkeypatch.undo()
    assert len(T.read_table(ok, cols, max_rows=50)) == 50
    assert len(T.read_table(big, cols, max_rows=None)) == 51
    no_newline = tmp_path / "last.csv"
    no_newline.write_text("x\n" + "1\n" * 49 + "1")  # 50 rows, no final newline
    assert len(T.read_table(no_newline, cols, max_rows=50)) == 50
    utf16 = tmp_path / "u16.csv"
    utf16.write_bytes(("x\n" + "1\n" * 51).encode("utf-16"))
    with pytest.raises(InputError, match="51 lines"):
        T.read_table(utf16, cols, max_rows=50)
    assert T.MAX_ROWS >= 100_000  # the 100k-row compass benchmark still loads


def test_the_cli_refuses_a_two_million_row_file_in_one_line(tmp_path):
    import subprocess
    import sys
    from navlib.paths import ROOT

    p = tmp_path / "huge.csv"
    with open(p, "w") as fh:
        fh.write("mag_x_ut,mag_y_ut,mag_z_ut\n")
        fh.write("20.0,1.0,40.0\n" * 2_000_000)
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "navlib",
            "calibrate",
            "magnetometer",
            str(p),
            "--out",
            str(tmp_path / "cal.json"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin", "OPENBLAS_NUM_THREADS": "1"},
    )
    assert r.returncode == 2 and r.stderr.count("\n") == 1
    assert "huge.csv: 2,000,000 lines after the header; navlib reads at most" in r.stderr
    assert not (tmp_path / "cal.json").exists()
