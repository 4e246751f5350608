"""The book's figure style: the layout decision, legends outside the data, the loop staircase and its step
labels, the shrunk-figure check of the screenshots, readable table labels."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from navbook import report, tables  # noqa: E402
from navlib import plotstyle as rs  # noqa: E402
from navbook.screenshots import shrunk_figures  # noqa: E402
from navlib.errors import InputError  # noqa: E402
from navlib.workbench.fit import fit_model, simulate  # noqa: E402
from navlib.workbench.loop import (
    LoopResult,
    loop,
    loop_figure,
    noise_band,
    staircase_figure,
    step_labels,
)  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.mark.parametrize(
    "n, width, expected",
    [
        (1, 7.5, (1, 1)),
        (2, 7.5, (1, 2)),
        (3, 7.5, (3, 1)),
        (4, 7.5, (2, 2)),
        (5, 7.5, (5, 1)),
        (3, 10.2, (1, 3)),
        (2, 6.0, (2, 1)),
    ],
)
def test_panels_are_stacked_when_side_by_side_they_would_be_too_narrow(n, width, expected):
    rows, cols = rs.panel_grid(n, width)
    assert (rows, cols) == expected
    assert rows * cols >= n and (cols == 1 or width / cols >= rs.MIN_PANEL_IN)


def test_panel_grid_rejects_bad_input_naming_the_parameter():
    with pytest.raises(InputError, match="n_panels"):
        rs.panel_grid(0)
    with pytest.raises(InputError, match="width_in"):
        rs.panels(2, width_in=12)


def test_style_fits_the_column_and_the_legend_sits_below_the_data(monkeypatch):
    monkeypatch.setattr(tables, "READABLE_TABLES", False)  # restored after the test
    with plt.rc_context():
        report.use_style()
        assert (
            plt.rcParams["font.size"] >= 11 and plt.rcParams["figure.figsize"][0] <= rs.MAX_WIDTH_IN
        )
        assert rs.MAX_WIDTH_IN * rs.DPI <= rs.COLUMN_PX
        fig, axes = rs.panels(2)
        for ax in axes:
            ax.plot([0, 1], [0, 1], label="a line with a long label")
            ax.plot([0, 1], [1, 0], label="another")
            ax.set_xlabel("x (unit)")
        leg = rs.legend_below(axes[0])
        fig.canvas.draw()
        r = fig.canvas.get_renderer()
        box, ticks = leg.get_window_extent(r), axes[0].get_tightbbox(r)
        label = axes[0].xaxis.label.get_window_extent(r)
        assert box.y1 < axes[0].get_window_extent(r).y0 and box.y1 <= label.y0  # under the x label
        assert fig.get_size_inches()[0] <= rs.MAX_WIDTH_IN and ticks.y0 >= 0
    assert tables.READABLE_TABLES  # use_style turned readable tables on


@pytest.fixture(scope="module")
def out_of_order():
    """Hard iron added after soft iron: the fits list effects in catalogue order (hard before soft)."""
    data = simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.04}, noise=0.1, seed=0)
    f0 = fit_model("compass", data, ["misalignment"])
    f1 = f0.add("soft_iron")
    f2 = f1.add("hard_iron")
    assert f2.effects[-1] == "soft_iron"  # the trap the old labels fell into
    return LoopResult([f0, f1, f2], [None, None, None])


def test_each_step_is_labelled_with_the_effect_it_added(out_of_order):
    assert step_labels(out_of_order) == ["start: misalignment", "+ soft_iron", "+ hard_iron"]
    ticks = [t.get_text() for t in loop_figure(out_of_order).axes[2].get_xticklabels()]
    assert ticks[1:] == ["+ soft_iron", "+ hard_iron"]


def test_the_staircase_shows_every_step_on_a_log_axis_with_the_noise_band():
    data = simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.04}, noise=0.1, seed=0)
    res = loop("compass", data, ["misalignment"])
    lo, hi = noise_band(res)
    rich = res.screening.rich
    assert lo < np.sqrt(rich.rss / (rich.n - rich.n_params)) < hi < 1.3 * lo  # 95 %, 240 readings
    assert lo < res.final.loo_rms < hi  # the loop ends at the noise floor
    fig = staircase_figure(res)
    ax = fig.axes[0]
    assert ax.get_yscale() == "log" and fig.get_size_inches()[0] <= rs.MAX_WIDTH_IN
    assert [t.get_text() for t in ax.get_xticklabels()] == step_labels(res)
    assert ax.get_legend() is not None and {"rms", "held-out rms", "noise floor (95 %)"} <= {
        t.get_text() for t in ax.get_legend().get_texts()
    }
    heights = ax.patches[0].get_data().values  # the stairs
    assert np.allclose(heights, [f.rms for f in res.fits])
    assert all(t.get_rotation() == 0 for t in ax.get_xticklabels())  # three steps: labels fit
    long = staircase_figure(res, title="compass: unexplained structure: heading harmonic 3; " * 3)
    lines = (
        long.axes[0].get_title().splitlines()
    )  # a long outcome wraps: the figure stays in the column
    assert len(lines) > 1 and max(map(len, lines)) <= 70


def test_staircase_slants_labels_that_do_not_fit_their_step():
    fig, ax = rs.panels(1)
    rs.staircase(
        ax, ["start: bias"] + [f"+ effect_number_{i}" for i in range(9)], np.geomspace(1, 0.1, 10)
    )
    assert {t.get_rotation() for t in ax.get_xticklabels()} == {30.0}
    assert ax.get_xticklabels()[1].get_text() == "+ effect_number_0"


def test_staircase_rejects_what_a_log_axis_cannot_show():
    fig, ax = plt.subplots()
    with pytest.raises(InputError, match="rms"):
        rs.staircase(ax, ["a", "b"], [1.0, 0.0])
    with pytest.raises(InputError, match="floor"):
        rs.staircase(ax, ["a"], [1.0], floor=(0.0, 1.0))


@pytest.mark.parametrize("shown, flagged", [(750, False), (563, False), (562, True), (300, True)])
def test_a_figure_shown_below_three_quarters_of_its_width_is_flagged(shown, flagged):
    found = shrunk_figures(
        [
            {"src": "a.png", "natural_px": 750, "shown_px": shown, "heading": "Fig"},
            {"src": "logo.png", "natural_px": 0, "shown_px": 0},
        ]
    )
    assert [f["src"] for f in found] == (["a.png"] if flagged else [])
    if flagged:
        assert found[0]["share"] == round(shown / 750, 3) and found[0]["heading"] == "Fig"


def test_readable_labels_units_flat_rows_no_index_name_no_negative_zero():
    assert report.label("median_rms_deg") == "median RMS (deg)"
    assert report.label("drift_deg_h") == "drift (deg/h)"
    assert report.label("temperature_c") == "temperature (degC)"
    assert (
        report.label("RMS (deg/h)") == "RMS (deg/h)" and report.label(("a", "b_ug")) == "a b (ug)"
    )
    assert [report.no_negative_zero(t) for t in ("-0.000", "-0", "+0.00", "-0.001", "-10")] == [
        "0.000",
        "0",
        "+0.00",
        "-0.001",
        "-10",
    ]
    df = pd.DataFrame(
        {"rms_ug": [1.0, -0.0001]},
        index=pd.MultiIndex.from_tuples([("compass", "a"), ("compass", "b")]),
    )
    text = repr(report.table(df, {"rms_ug": "{:.2f}"}, readable=True))
    assert "RMS (ug)" in text and "compass: a" in text and "-0.00" not in text and "0.00" in text
    named = pd.DataFrame({"value": [1.0]}, index=pd.Index(["k"], name="quantity"))
    lines = repr(report.table(named, readable=True)).splitlines()
    assert len(lines) == 2 and lines[0].split() == ["quantity", "value"]  # no index-name row
    assert len(repr(report.table(named)).splitlines()) == 3  # the old table had one
    steps = pd.DataFrame(
        {"rms_deg": [0.5]}, index=pd.Index([0], name="step")
    )  # a numeric index level
    assert repr(report.table(steps, readable=True)).splitlines()[1].split() == ["0", "0.5"]
    with pytest.raises(InputError, match="RMS"):
        report.readable(pd.DataFrame({"rms_deg": [1], "RMS (deg)": [2]}))


def test_step_labels_wrap_after_spaces_and_underscores_only():
    assert rs.wrap_label("+ scale_factor_temperature", 13) == "+ scale_\nfactor_\ntemperature"
    assert rs.wrap_label("misalignment", 5) == "misalignment"  # a word stays whole
    assert rs.wrap_label("start: bias", 20) == "start: bias"


def test_known_noise_band_holds_95_percent_of_correct_models_rms():
    from navlib.workbench.loop import known_noise_band

    rng = np.random.default_rng(7)
    n, p, sigma = 60, 4, 0.3
    X = rng.normal(size=(n, p))
    lo, hi = known_noise_band(sigma, n, p)
    y = (X @ rng.normal(size=p))[:, None] + sigma * rng.normal(
        size=(n, 2000)
    )  # 2000 noisy data sets
    resid = y - X @ np.linalg.lstsq(X, y, rcond=None)[0]
    rms = np.sqrt(np.mean(resid**2, axis=0))
    share = np.mean((rms >= lo) & (rms <= hi))
    assert 0.93 < share < 0.97
    with pytest.raises(InputError, match="n_params"):
        known_noise_band(sigma, 5, 5)


def test_unit_loop_names_the_units_it_has():
    from navlib.workbench.accelerometer import unit_loop

    frame = pd.DataFrame({"unit": ["A", "B"], "output_mg": [0.0, 0.0]})
    with pytest.raises(InputError, match="unit='C'.*A, B"):
        unit_loop(frame, "C")


def test_a_staircase_summary_draws_the_same_picture_and_pickles():
    """The Staircase a worker sends back draws what the LoopResult draws; a loop without a held-out set
    draws no markers; small multiples keep one legend below the grid."""
    import pickle

    from navlib.workbench.loop import Staircase, staircase_grid, staircase_of

    data = simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.04}, noise=0.1, seed=0)
    res = loop("compass", data, ["misalignment"])
    st = pickle.loads(pickle.dumps(staircase_of(res)))
    assert st.labels == tuple(step_labels(res)) and st.floor == pytest.approx(noise_band(res))
    assert st.outcome == res.outcome() and st.floor_label == "noise floor (95 %)"
    a, b = staircase_figure(res).axes[0], staircase_figure(st).axes[0]
    assert np.allclose(a.patches[0].get_data().values, b.patches[0].get_data().values)
    assert [t.get_text() for t in a.get_xticklabels()] == [
        t.get_text() for t in b.get_xticklabels()
    ]
    assert len(b.lines) == 1  # the held-out markers
    bare = Staircase(st.labels, st.rms, None, None, "", st.unit, "no held-out set")
    ax = staircase_figure(bare).axes[0]
    assert len(ax.lines) == 0 and {t.get_text() for t in ax.get_legend().get_texts()} == {"rms"}
    grid = staircase_grid({"trial one": res, "trial two": st, "trial three": bare})
    axes = [x for x in grid.axes if x.get_visible() and x.axison]
    assert len(axes) == 3 and grid.get_size_inches()[0] <= rs.MAX_WIDTH_IN
    assert grid.get_size_inches()[1] <= 2 * 2.6 + 0.5 + 1e-9  # two rows: panels do not grow it
    assert all(x.get_legend() is None for x in axes) and len(grid.legends) == 1
    assert (
        axes[0].get_title().startswith("trial one")
        and "+" not in axes[0].get_xticklabels()[1].get_text()
    )
    with pytest.raises(InputError, match="no loop"):
        staircase_grid({})


def test_report_figure_panels_span_the_column():
    """The --report picture: staircase, measurement and residual panels one above the other, each as wide
    as the column allows (short legend labels below them)."""
    from navlib.workbench.loop import report_figure

    data = simulate("compass", {"yaw_deg": 1.0, "hard_x": 0.2, "soft_e": 0.04}, noise=0.1, seed=0)
    res = loop("compass", data, [])
    fig = report_figure(res)
    fig.draw_without_rendering()
    boxes = [ax.get_position() for ax in fig.axes]
    assert len(boxes) == 3 and fig.get_size_inches()[0] <= rs.MAX_WIDTH_IN
    assert all(b.width > 0.8 for b in boxes)  # stacked, not side by side
    labels = [t.get_text() for ax in fig.axes[1:] for t in ax.get_legend().get_texts()]
    assert max(map(len, labels)) <= 22 and "step 0" in labels
