"""Transcription checks for paper C's Tables 2-5 and validation of drift tables."""

import numpy as np
import pandas as pd
import pytest

from navlib.errors import InputError
from navlib.data.gyro_tables import (
    COLUMNS,
    TABLE_FILES,
    load_cold_test,
    load_cold_train,
    load_hot_test,
    load_hot_train,
    load_table,
    load_user_drift,
)
from navlib.data.gyro_tables import LOCAL_LATITUDE_DEG
from navlib.paths import data_path


def test_row_counts():
    assert len(load_hot_train()) == 16
    assert len(load_hot_test()) == 3
    assert len(load_cold_train()) == 6
    assert len(load_cold_test()) == 3


def test_exact_values_table2():
    t = load_hot_train().set_index("sample")
    assert t.loc[1, "latitude_deg"] == 28.2274 and t.loc[1, "drift_deg_h"] == 0.0007
    assert (t.loc[2, "temperature_min_c"], t.loc[2, "temperature_max_c"]) == (28, 39)
    assert t.loc[3, "temperature_min_c"] == t.loc[3, "temperature_max_c"] == 55  # single value
    assert t.loc[7, "latitude_deg"] == 28.2474 and t.loc[7, "drift_deg_h"] == 0.0034
    assert t.loc[9, "latitude_deg"] == 28.2032 and t.loc[9, "drift_deg_h"] == -0.00253
    assert t.loc[10, "drift_deg_h"] == -0.00339
    assert t.loc[16, "latitude_deg"] == 28.1978 and t.loc[16, "drift_deg_h"] == -0.00301
    assert t["drift_deg_h"].sum() == pytest.approx(
        -0.01737, abs=1e-12
    )  # summed by hand from the paper
    assert t["latitude_deg"].sum() == pytest.approx(451.4218, abs=1e-9)
    assert t.loc[7, "latitude_error_deg"] == pytest.approx(0.0254, abs=1e-12)


def test_exact_values_table3_and_error_sign_convention():
    t = load_hot_test().set_index("test")
    assert t.loc[1].tolist()[:8] == [28.1959, 44, 45, -0.00324, -0.0034, -0.00016, 8, 0.5]
    assert t.loc[3, "paper_rbf_drift_deg_h"] == 0.0020 and t.loc[3, "true_drift_deg_h"] == 0.0022
    assert t.loc[2, "paper_pos_error_before_nmi_72h"] == 1.4
    # the printed error column is true - RBF on every row (the book's convention too)
    np.testing.assert_allclose(
        t["true_drift_deg_h"] - t["paper_rbf_drift_deg_h"], t["paper_error_deg_h"], atol=1e-12
    )


def test_exact_values_tables4_5():
    t = load_cold_train().set_index("sample")
    assert t.loc[
        1, ["align_temp_min_c", "align_temp_max_c", "calib_temp_min_c", "calib_temp_max_c"]
    ].tolist() == [12, 35, 25, 35]
    assert t.loc[3, "latitude_deg"] == 28.2028 and t.loc[3, "true_drift_deg_h"] == -0.0033
    assert (
        t.loc[6, "paper_hot_rbf_drift_deg_h"] == -0.0031 and t.loc[5, "true_drift_deg_h"] == 0.00013
    )
    c = load_cold_test().set_index("test")
    assert c.loc[1, ["align_temp_change_c", "calib_temp_change_c"]].tolist() == [32, 17]
    assert c["paper_pos_error_hot_net_nmi_72h"].tolist() == [1.8, 1.7, 1.3]
    assert c["paper_pos_error_cold_net_nmi_72h"].tolist() == [0.8, 0.9, 0.75]


def test_data_dictionary_documents_every_column_with_units():
    md = data_path("gyro_tables.md").read_text(encoding="utf-8")
    assert "28.222" in md and "true - identified" in md
    for n, fname in TABLE_FILES.items():
        assert fname in md
        header = pd.read_csv(data_path(fname), nrows=0).columns
        assert [c.name for c in COLUMNS[n]] == list(header)  # every CSV column is validated
        for col in COLUMNS[n]:
            assert f"`{col.name}`" in md, col.name
            unit = {"degC": "degC", "deg/h": "deg/h", "deg": "deg", "nmi/72h": "nmi/72h", "": "-"}[
                col.unit
            ]
            row = [ln for ln in md.splitlines() if f"`{col.name}`" in ln and ln.startswith("|")][0]
            assert f"| {unit} |" in row, (col.name, row)
    assert LOCAL_LATITUDE_DEG == 28.222


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def _table2_with(tmp_path, row7):
    lines = data_path(TABLE_FILES[2]).read_text().splitlines()
    lines[7] = row7
    return _write(tmp_path, "t2.csv", "\n".join(lines) + "\n")


@pytest.mark.parametrize(
    "row7, pattern",
    [
        (
            "7,28.2474,48,49,0.0O34",
            r"t2\.csv: column 'drift_deg_h', row 7 \(file line 8\): '0\.0O34' is not a number",
        ),
        (
            "7,82.2474,48,49,0.0034",
            r"t2\.csv: column 'latitude_deg', row 7 .*outside 28\.\.28\.5 deg",
        ),
        (
            "7,28.2474,49,48,0.0034",
            r"t2\.csv: column 'temperature_min_c', row 7 .*above temperature_max_c",
        ),
        ("7,28.2474,48,49,", r"t2\.csv: column 'drift_deg_h', row 7 .*is empty"),
        ("6,28.2474,48,49,0.0034", r"t2\.csv: column 'sample', row 7 .*appears twice"),
        ("7,28.2474,48,49,0.34", r"t2\.csv: column 'drift_deg_h', row 7 .*outside"),
    ],
)
def test_table2_typos_are_caught(tmp_path, row7, pattern):
    with pytest.raises(InputError, match=pattern) as e:
        load_table(2, _table2_with(tmp_path, row7))
    assert "\n" not in str(e.value)


def test_table4_inconsistent_temperature_change(tmp_path):
    lines = data_path(TABLE_FILES[4]).read_text().splitlines()
    lines[2] = lines[2].replace("42,54,12,", "42,54,13,")
    p = _write(tmp_path, "t4.csv", "\n".join(lines) + "\n")
    with pytest.raises(
        InputError, match=r"t4\.csv: column 'align_temp_change_c', row 2 .*not align_temp_max_c"
    ):
        load_table(4, p)


def test_missing_column_and_missing_file(tmp_path):
    p = _write(tmp_path, "t3.csv", "test,latitude,temperature_min_c\n1,28.2,4\n")
    with pytest.raises(InputError, match=r"t3\.csv: missing column 'latitude_deg'"):
        load_table(3, p)
    with pytest.raises(InputError, match="no such file"):
        load_table(2, tmp_path / "nope.csv")
    with pytest.raises(InputError, match="tables 2, 3, 4 and 5"):
        load_table(1)


def test_user_drift_loader(tmp_path):
    p = _write(
        tmp_path,
        "mine.csv",
        "latitude_error_deg,drift_deg_h,temperature_c\n0.01,0.0015,40\n-0.02,-0.003,41\n",
    )
    d = load_user_drift(p)
    assert d["drift_deg_h"].tolist() == [0.0015, -0.003] and "temperature_change_c" not in d
    q = _write(tmp_path, "ident.csv", "latitude_error_deg\n0.01\n")
    assert len(load_user_drift(q, require_drift=False)) == 1
    with pytest.raises(InputError, match=r"ident\.csv: missing column 'drift_deg_h'"):
        load_user_drift(q)
    r = _write(
        tmp_path, "bad.csv", "latitude_error_deg,drift_deg_h,temperature_change_c\n0.01,0.001,x\n"
    )
    with pytest.raises(
        InputError, match=r"bad\.csv: column 'temperature_change_c', row 1 \(file line 2\)"
    ):
        load_user_drift(r)
