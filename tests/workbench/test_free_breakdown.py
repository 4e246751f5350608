"""The reference-free loop's breakdown of what remains (issue 34): each factor finds the structure built
into it, the sentence names the one that holds the most, and the loop's outputs carry it."""

import json

import numpy as np
import pytest

from navlib.workbench import free_breakdown as fb
from navlib.workbench.loop import loop, write_report
from navlib.workbench.free_simulation import simulate_free
from navlib.workbench.magnetometer_free import DERIVED

RNG = np.random.default_rng(5)
N = 2000
T = np.arange(N) * 0.05
U = RNG.normal(size=(N, 3)) * 30
ACC = np.column_stack(
    [
        np.zeros(N),
        np.zeros(N),
        9.81 + np.abs(RNG.normal(size=N)) * np.r_[np.zeros(N // 2), np.ones(N // 2) * 3],
    ]
)
RATE = np.abs(RNG.normal(size=N)) * 40


def _table(resid):
    return fb.breakdown(resid, ["magnitude", "dip"][: resid.shape[1]], fb.factors(T, RATE, U, ACC))


def test_shares_are_between_cell_variance():
    """share = between-cell sum of squares / total; amplitude = sqrt(between / n): by hand for one factor."""
    r = RNG.normal(size=(N, 1))
    t = _table(r).set_index("factor").loc["time"]
    cell = fb.factors(T)["time"][0]
    x = r[:, 0] - r[:, 0].mean()
    means = np.array([x[cell == c].mean() for c in range(10)])
    between = sum(np.sum(cell == c) * means[c] ** 2 for c in range(10))
    assert t["share"] == pytest.approx(between / (x @ x))
    assert t["amplitude_ut"] == pytest.approx(np.sqrt(between / N))


@pytest.mark.parametrize(
    "factor, make, invariant",
    [
        ("time", lambda: np.where(T > T[-1] * 0.7, 1.0, 0.0), "magnitude"),
        ("orientation", lambda: np.where(np.argmax(np.abs(U), axis=1) == 2, 1.0, 0.0), "magnitude"),
        ("acceleration", lambda: np.abs(np.linalg.norm(ACC, axis=1) - 9.81), "dip"),
        ("turn rate", lambda: RATE / 40, "dip"),
    ],
)
def test_the_factor_built_in_is_named(factor, make, invariant):
    r = RNG.normal(size=(N, 2)) * 0.2
    r[:, ["magnitude", "dip"].index(invariant)] += make()
    tab = _table(r)
    top = tab.loc[tab["share"].idxmax()]
    assert (top["factor"], top["invariant"]) == (factor, invariant)
    assert top["share"] > 0.3
    sentence = fb.reading(tab)
    assert sentence.startswith(factor) and fb._POINTS_AT[(invariant, factor)] in sentence


def test_noise_alone_names_no_factor():
    tab = _table(RNG.normal(size=(N, 2)))
    assert tab["share"].max() < fb.CLEAR_SHARE
    assert fb.reading(tab).startswith("no single factor")


def test_rate_from_the_field_when_no_gyro():
    """Without gyro columns the turn rate is the corrected field's turn between samples over the time step."""
    ang = np.radians(np.cumsum(np.r_[0.0, np.full(N - 1, 2.0)]))  # 2 deg per 0.05 s: 40 deg/s
    u = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(N)]) * 40
    cell, labels = fb.factors(T, None, u)["turn rate"]
    assert all(lab.startswith("40-40") or lab.startswith("40 ") for lab in labels.values())


def test_no_columns_no_factors():
    assert fb.reading(fb.breakdown(RNG.normal(size=(N, 1)), ["magnitude"], {})).startswith(
        "no factor"
    )


def test_loop_report_and_json_carry_the_breakdown(tmp_path):
    """A field that steps by 3 uT half-way through a simulated recording: the loop cannot take it up; the
    breakdown puts it in time, in the JSON and in the report."""
    d = simulate_free({"hard_x_ut": 5.0}, duration_s=60.0, seed=3).drop(columns=list(DERIVED))
    step = np.where(d["time_s"] > 30, 3.0, 0.0)
    m = d[["mag_x_ut", "mag_y_ut", "mag_z_ut"]].to_numpy(float)
    d[["mag_x_ut", "mag_y_ut", "mag_z_ut"]] = m * (1 + step / np.linalg.norm(m, axis=1))[:, None]
    res = loop("magnetometer_free", d)
    table, sentence = res.remaining()
    top = table.loc[table["share"].idxmax()]
    assert (top["factor"], top["invariant"]) == ("time", "magnitude") and top["share"] > 0.5
    out = res.to_dict()
    assert out["remaining"]["reading"] == sentence
    json.dumps(out, allow_nan=False)
    _, md = write_report(res, tmp_path / "rep")
    text = md.read_text()
    assert "**What remains**" in text and "| magnitude | time |" in text


def test_other_systems_have_no_breakdown():
    from navlib.workbench.fit import simulate

    res = loop("compass", simulate("compass", {"hard_x": 0.05}, noise=0.05, seed=1))
    assert res.remaining() is None and "remaining" not in res.to_dict()
