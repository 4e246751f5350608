"""The whole workbench loop as one function: diagnose, add the named effect, repeat until the residuals are
consistent with noise or nothing more can be named.  The CLI command ``loop`` and the notebooks call
:func:`loop`; :meth:`LoopResult.to_dict` is the ``--json`` schema and :func:`write_report` the
``--report DIR`` output.
"""

from __future__ import annotations

import textwrap

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import special

from ..angles import wrap_deg
from ..errors import InputError, check_param
from .. import plotstyle as rs
from ..plotstyle import DPI
from .diagnose import Diagnosis, diagnose
from .effects import Effect, get_system
from .fit import Fit, fit_model
from .screen import Screening, screen
from ..threads import one_blas_thread


@dataclass
class LoopResult:
    """The loop's steps: ``fits[i]`` was diagnosed as ``diagnoses[i]``; the last one ends the loop.
    ``screening``: what the screen before the first test found (outliers set aside, noise model)."""

    fits: list
    diagnoses: list
    screening: Screening | None = None

    @property
    def outliers(self) -> list[dict]:
        """The observations set aside before the first test: ``{"row", "column", "residual",
        "robust_z"}`` (row 1-based among the data rows)."""
        return [o.to_dict() for o in self.screening.outliers] if self.screening is not None else []

    @property
    def final(self) -> Fit:
        return self.fits[-1]

    @property
    def final_diagnosis(self) -> Diagnosis:
        return self.diagnoses[-1]

    @property
    def unexplained(self) -> list[dict]:
        """Significant structure left at the end that no effect explains."""
        return [
            {
                "structure": s.what,
                "amplitude": float(s.amplitude),
                "p_value": float(s.p_value) if np.isfinite(s.p_value) else None,
            }
            for s in self.final_diagnosis.structure
            if s.significant
        ]

    @property
    def untested(self) -> list[dict]:
        """Effects (catalogued or the user's) the loop could not test on these data, with the reason (a
        needed column absent, not numbers or constant; too few rows for one more parameter): every one any
        step could not test, unless the final model holds it."""
        why = {}
        for d in self.diagnoses:
            for name, reason in d.untestable.items():
                if name not in self.final.effects:
                    why.setdefault(name, reason)
        return [{"effect": k, "why": v} for k, v in why.items()]

    @property
    def consistent_with_noise(self) -> bool:
        return bool(self.final_diagnosis.consistent_with_noise)

    def steps_table(self) -> pd.DataFrame:
        unit = self.final.unit
        return pd.DataFrame(
            [
                {
                    "step": i,
                    "model": " + ".join(f.effects) or "(none)",
                    f"rms ({unit})": f.rms,
                    f"held-out rms ({unit})": f.loo_rms,
                    "named": d.missing or "-",
                }
                for i, (f, d) in enumerate(zip(self.fits, self.diagnoses))
            ]
        ).set_index("step")

    def remaining(self) -> tuple[pd.DataFrame, str] | None:
        """What the final residuals still hold, by the factors the system knows (its ``remaining`` hook,
        e.g. :func:`navlib.workbench.magnetometer_free.remaining_structure`), or None."""
        hook = get_system(self.final.system).remaining
        return None if hook is None else hook(self.final)

    def outcome(self) -> str:
        if self.consistent_with_noise:
            return "consistent with noise"
        return "unexplained structure: " + "; ".join(u["structure"] for u in self.unexplained)

    def to_dict(self) -> dict:
        """The ``--json`` schema: ``{"steps": [{"model", "rms", "loo_rms", "missing"}], "final": {"model",
        "rms", "loo_rms", "consistent_with_noise", "unexplained"}, "untested": [{"effect", "why"}],
        "outliers": [{"row", "column", "residual", "robust_z"}], "rows", "rows_used", "noise": {...}, ...}``
        (rms and residuals in the system's unit; ``untested``: :attr:`untested`; the screen's fields:
        :meth:`navlib.workbench.screen.Screening.to_dict`)."""
        f = self.final
        out = {
            "system": f.system,
            "unit": f.unit,
            "steps": [
                {
                    "model": list(fi.effects),
                    "rms": fi.rms,
                    "loo_rms": fi.loo_rms,
                    "missing": d.missing,
                }
                for fi, d in zip(self.fits, self.diagnoses)
            ],
            "final": {
                "model": list(f.effects),
                "rms": f.rms,
                "loo_rms": f.loo_rms,
                "consistent_with_noise": self.consistent_with_noise,
                "unexplained": self.unexplained,
                "message": self.final_diagnosis.message,
            },
            "untested": self.untested,
            "outliers": self.outliers,
        }
        rem = self.remaining()
        if rem is not None:
            out["remaining"] = {"by_factor": rem[0].to_dict(orient="records"), "reading": rem[1]}
        if self.screening is not None:
            extra = self.screening.to_dict()
            extra.pop("outliers")
            out.update(extra)
        return out


@one_blas_thread
def loop(
    system,
    data: pd.DataFrame,
    start_model=(),
    *,
    user_effects: tuple[Effect, ...] = (),
    alpha: float | None = None,
    max_steps: int = 8,
) -> LoopResult:
    """Run the workbench loop on ``data``.

    Starting from ``start_model`` (effect names), fit, :func:`~navlib.workbench.diagnose.diagnose`, add the
    named effect, refit (from the previous parameters and the linearised start), and repeat until the
    diagnosis names nothing (consistent with noise, or structure no effect explains) or ``max_steps``.
    The data are screened once, before the first test (:func:`navlib.workbench.screen.screen`): outlying
    rows are set aside (listed in ``outliers``) and every step is fitted and tested without them, with the
    noise model (serial correlation) the screen estimated.

    Parameters
    ----------
    system : str or System
        ``"compass"``, ``"drift"``, ``"magnetometer"`` or any registered system.
    data : DataFrame
        A validated measurement frame (the system's ``load``).
    start_model : sequence of str
        Effects in the first model.
    user_effects : tuple of Effect
        Extra effects (:func:`~navlib.workbench.effects.load_effects`) the loop may add.
    alpha : float
        Family-wise false-alarm level of each diagnosis.
    max_steps : int
        At most this many effects are added.

    Returns
    -------
    LoopResult

    Examples
    --------
    A simulated compass (two sweeps of 121 readings, 0.05 deg of noise) with hard and soft iron hidden;
    the loop starts from no effect and adds what the residuals ask for:

    >>> from navlib.workbench.fit import simulate
    >>> from navlib.workbench.loop import loop, step_labels
    >>> data = simulate("compass", {"hard_x": 0.05, "soft_e": 0.02}, noise=0.05, seed=1)
    >>> result = loop("compass", data)
    >>> step_labels(result)
    ['start (none)', '+ hard_iron', '+ soft_iron']
    >>> result.outcome()
    'consistent with noise'

    From the command line, on a CSV file: ``python -m navlib loop compass FILE --report out/``.
    """
    check_param("max_steps", max_steps, lo=0, integer=True)
    first = fit_model(system, data, list(start_model), user_effects=tuple(user_effects))
    sc = screen(first)
    fits = [sc.refit(first)]
    diagnoses = [diagnose(fits[0], alpha=alpha, screen=sc)]
    while diagnoses[-1].missing is not None and len(fits) <= max_steps:
        fits.append(fits[-1].add(diagnoses[-1].missing))
        diagnoses.append(diagnose(fits[-1], alpha=alpha, screen=sc))
    return LoopResult(fits, diagnoses, sc)


def step_labels(result: LoopResult) -> list[str]:
    """One label per step of the loop: ``"start: <model>"`` (``"start (none)"``) for the first fit, then
    ``"+ <effect>"`` with the effect that step added (the one the previous diagnosis named; a fit lists
    its effects in catalogue order, so the last one listed is not necessarily the one added)."""
    fits = result.fits
    out = ["start: " + " + ".join(fits[0].effects) if fits[0].effects else "start (none)"]
    for prev, f in zip(fits[:-1], fits[1:]):
        added = [e for e in f.effects if e not in prev.effects]
        out.append("+ " + " + ".join(added) if added else "(refit)")
    return out


def _chi2_ppf(q: float, dof: int) -> float:
    """The ``q`` quantile of chi-squared with ``dof`` degrees of freedom, ``2 P^-1(dof/2, q)`` (the
    inverse regularised lower incomplete gamma function): ``scipy.stats.chi2.ppf``'s own formula, without
    importing ``scipy.stats`` (0.6 s at the command line's start)."""
    return float(2.0 * special.gammaincinv(dof / 2.0, q))


def noise_band(result: LoopResult, level: float = 0.95) -> tuple[float, float] | None:
    """The noise floor as a band: the ``level`` interval of the noise standard deviation from the
    residuals of the screen's richest model (every testable effect),
    ``sqrt(RSS / chi2_{(1+level)/2}(n - p)) .. sqrt(RSS / chi2_{(1-level)/2}(n - p))`` with ``n``
    observations and ``p`` parameters (white noise assumed; never below the data's numerical floor).
    None when the screen fitted no richer model or it leaves no degrees of freedom."""
    sc = result.screening
    rich = None if sc is None else sc.rich
    if rich is None:
        return None
    dof = rich.n - rich.n_params
    if dof < 1 or not np.isfinite(rich.rss):
        return None
    tail = (1.0 - level) / 2.0
    lo = float(np.sqrt(rich.rss / _chi2_ppf(1.0 - tail, dof)))
    hi = float(np.sqrt(rich.rss / _chi2_ppf(tail, dof)))
    lo, hi = max(lo, sc.floor), max(hi, sc.floor)
    return (lo, hi) if hi > 0 else None


def known_noise_band(
    sigma: float, n: int, n_params: int, level: float = 0.95
) -> tuple[float, float]:
    """Where the rms of a correct model's residuals lies when the noise is known: white noise of standard
    deviation ``sigma`` on ``n`` observations and ``p = n_params`` fitted parameters give
    ``rms^2 = sigma^2 chi2(n - p) / n``; the band is its central ``level`` interval."""
    check_param("sigma", sigma, lo=0, lo_open=True)
    check_param("n_params", n_params, lo=0, hi=n - 1, integer=True)
    tail, dof = (1.0 - level) / 2.0, n - n_params
    return (
        float(sigma * np.sqrt(_chi2_ppf(tail, dof) / n)),
        float(sigma * np.sqrt(_chi2_ppf(1 - tail, dof) / n)),
    )


#: Characters per line of a staircase's title (the loop's outcome can be long): it stays within the column.
TITLE_WIDTH = 70


@dataclass(frozen=True)
class Staircase:
    """What a staircase shows of one loop, small enough to send back from a worker process: the step
    labels (:func:`step_labels`), the rms and held-out rms after each step (``held_out`` None for a loop
    without a held-out set; NaN where a step has none), the band (``floor``, ``(low, high)`` or None), its
    label, the unit and a title.  :func:`staircase_of` makes one from a :class:`LoopResult`."""

    labels: tuple
    rms: tuple
    held_out: tuple | None
    floor: tuple | None
    floor_label: str
    unit: str
    title: str
    outcome: str = ""


def staircase_of(
    result: LoopResult,
    title: str | None = None,
    floor: tuple[float, float] | None = None,
    floor_label: str | None = None,
) -> Staircase:
    """The :class:`Staircase` of a loop: the band is ``floor`` when the noise is known (e.g.
    :func:`known_noise_band` for simulated data), else :func:`noise_band` from the data, called the noise
    floor when the loop ended consistent with noise and the richest model's residual otherwise (it then
    holds the structure no effect explains).  The title defaults to ``"<system>: <outcome>"``."""
    if floor is None:
        floor = noise_band(result)
        floor_label = floor_label or (
            "noise floor (95 %)"
            if result.consistent_with_noise
            else "richest model's residual (95 %)"
        )
    held = [f.loo_rms for f in result.fits]
    held = (
        None if not np.any(np.isfinite(np.asarray(held, float))) else tuple(float(v) for v in held)
    )
    return Staircase(
        tuple(step_labels(result)),
        tuple(float(f.rms) for f in result.fits),
        held,
        None if floor is None else (float(floor[0]), float(floor[1])),
        floor_label or "noise floor (95 %)",
        result.final.unit,
        title if title is not None else f"{result.final.system}: {result.outcome()}",
        result.outcome(),
    )


def staircase_figure(
    result,
    ax=None,
    title: str | None = None,
    floor: tuple[float, float] | None = None,
    floor_label: str | None = None,
    legend: bool = True,
):
    """The loop as a picture, full column width: a staircase with one step per effect added (labelled
    with the effect), the rms after each step on a log axis, the held-out rms as a marker (none for a loop
    without a held-out set) and the noise floor as a band (:func:`navlib.plotstyle.staircase`).
    ``result`` is a :class:`LoopResult` (the band as in :func:`staircase_of`) or a :class:`Staircase`
    (``title`` then replaces its title).  Draws on ``ax`` if given (``legend=False``: no legend, e.g. for
    :func:`staircase_grid`); returns the figure."""

    st = (
        result if isinstance(result, Staircase) else staircase_of(result, title, floor, floor_label)
    )
    own = ax is None
    if own:
        fig, ax = rs.panels(1, panel_height_in=3.6)
    rs.staircase(
        ax,
        list(st.labels),
        list(st.rms),
        None if st.held_out is None else list(st.held_out),
        floor=st.floor,
        floor_label=st.floor_label,
        unit=st.unit,
        title=textwrap.fill(title if title is not None else st.title, TITLE_WIDTH),
    )
    ticks = ax.get_xticklabels()
    lines = max(t.get_text().count("\n") + 1 for t in ticks)
    extra = 1.3 if any(t.get_rotation() for t in ticks) else 0.2 * max(0, lines - 2)
    if own and extra:  # a figure of its own: room for the labels
        w, h = ax.figure.get_size_inches()
        ax.figure.set_size_inches(w, h + extra)
    if legend:
        rs.legend_below(ax, ncol=3)
    return ax.figure


#: Characters per line of a small-multiple staircase's title.
GRID_TITLE_WIDTH = 30


def staircase_grid(staircases, ncols: int = 2, panel_height_in: float = 2.6):
    """Small multiples: one staircase (:func:`staircase_figure`) per loop, ``staircases`` a mapping of
    panel title to :class:`Staircase` or :class:`LoopResult` (e.g. one per trial), ``ncols`` panels a row
    across the column width, one legend below the grid; tick labels are the effects added (without the
    ``+``), slanted where they do not fit.  Returns the figure."""
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: matplotlib only for figures; the CLI's loop runs without it

    items = [
        (k, v if isinstance(v, Staircase) else staircase_of(v)) for k, v in dict(staircases).items()
    ]
    if not items:
        raise InputError("staircase_grid: no loop to draw")
    check_param("ncols", ncols, lo=1, hi=3, integer=True)
    ncols = min(ncols, len(items))
    nrows = -(-len(items) // ncols)
    fig, axes = plt.subplots(
        nrows,
        ncols,
        figsize=(rs.MAX_WIDTH_IN, panel_height_in * nrows + 0.5),
        layout="constrained",
        squeeze=False,
    )
    handles, bands = {}, {st.floor_label for _, st in items if st.floor is not None}
    band = bands.pop() if len(bands) == 1 else "noise floor or richest model's residual (95 %)"
    for ax, (name, st) in zip(axes.ravel(), items):
        short = Staircase(
            tuple(
                lab.replace("+ ", "").replace("start (none)", "none").replace("start: ", "")
                for lab in st.labels
            ),
            st.rms,
            st.held_out,
            st.floor,
            st.floor_label,
            st.unit,
            st.title,
            st.outcome,
        )
        title = name if not st.outcome else f"{name}: {st.outcome}"
        staircase_figure(
            short,
            ax=ax,
            title=textwrap.shorten(title, 2 * GRID_TITLE_WIDTH, placeholder=" ..."),
            legend=False,
        )
        ax.title.set_text(textwrap.fill(ax.title.get_text(), GRID_TITLE_WIDTH))
        ax.set_xlabel("")
        for h, lab in zip(*ax.get_legend_handles_labels()):
            key = "band" if lab == st.floor_label else lab
            handles.setdefault(key, (h, band if key == "band" else lab))
    for ax in axes.ravel()[len(items) :]:
        ax.set_axis_off()
    hs, ls = zip(*handles.values())
    fig.legend(hs, ls, loc="outside lower center", ncol=3)
    return fig


def report_figure(result: LoopResult):
    """The ``--report`` picture, one column of full-width panels: the staircase
    (:func:`staircase_figure`) on top; below it the measurement against the start and final models, and
    below that the residuals at each step (legends below each panel, short labels: the steps are named on
    the staircase)."""
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: matplotlib only for figures; the CLI's loop runs without it

    with plt.rc_context(rs.RC):
        fig = plt.figure(figsize=(rs.MAX_WIDTH_IN, 10.6), layout="constrained")
        top, bottom = fig.subfigures(2, 1, height_ratios=[1.0, 1.45])
        staircase_figure(result, ax=top.subplots())
        a1, a2 = bottom.subplots(2, 1)
        _measurement_panel(a1, result, short=True)
        for i, f in enumerate(result.fits):
            a2.plot(f.residuals, ".", ms=2, label=f"step {i}")
        a2.set(
            xlabel="observation",
            ylabel=f"residual ({result.final.unit})",
            title="residuals after each step",
        )
        rs.legend_below(a1, ncol=3, markerscale=4)
        rs.legend_below(a2, ncol=min(4, len(result.fits)), markerscale=4)
    return fig


def _measurement_panel(ax, result: LoopResult, short: bool = False) -> None:
    """Measured against the start and final models; ``short``: the models labelled "start model (step
    0)" and "final model (step n)" instead of their effects."""
    fits, unit = result.fits, result.final.unit
    data = fits[0].data

    def label(i, f):
        if short:
            return "start model (step 0)" if i == 0 else f"final model (step {len(fits) - 1})"
        return f"model: {' + '.join(f.effects) or '(none)'}"

    if fits[0].system == "compass":
        h = data["true_heading_deg"].to_numpy(float)
        ax.plot(
            h,
            wrap_deg(data["measured_heading_deg"].to_numpy(float) - h),
            "k.",
            ms=3,
            label="measured",
        )
        for i, (f, style) in enumerate(((fits[0], "r."), (result.final, "b."))):
            ax.plot(h, wrap_deg(f.predict(data) - h), style, ms=2, label=label(i, f))
        ax.set(xlabel="true heading (deg)", ylabel="heading error (deg)")
    else:
        obs = fits[0].residuals + np.ravel(fits[0].predict(data))
        for i, (f, style) in enumerate(((fits[0], "r."), (result.final, "b."))):
            ax.plot(np.ravel(f.predict(data)), obs, style, ms=2, label=label(i, f))
        lim = [float(np.min(obs)), float(np.max(obs))]
        ax.plot(lim, lim, "k-", lw=0.8, label="measured = model")
        ax.set(xlabel=f"model ({unit})", ylabel=f"measured ({unit})")
    ax.set_title("measurement against model")


def loop_figure(result: LoopResult):
    """Three panels: measurement against the start and final models, residuals at each step, the error
    falling (rms and held-out rms per step)."""
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: matplotlib only for figures; the CLI's loop runs without it

    fits, unit = result.fits, result.final.unit
    fig, axes = plt.subplots(1, 3, figsize=(12, 4))
    ax = axes[0]
    _measurement_panel(ax, result)
    ax.legend(fontsize=9)
    for i, f in enumerate(fits):
        axes[1].plot(f.residuals, ".", ms=2, label=f"step {i}")
    axes[1].set(
        xlabel="observation (file order)",
        ylabel=f"residual ({unit})",
        title="residuals at each step",
    )
    axes[1].legend(fontsize=9)
    k = np.arange(len(fits))
    axes[2].semilogy(k, [f.rms for f in fits], "ko-", label="rms")
    axes[2].semilogy(k, [f.loo_rms for f in fits], "bs--", label="held-out rms")
    axes[2].set_xticks(k, [t.replace(": ", "\n")[:40] for t in step_labels(result)], fontsize=9)
    axes[2].set(ylabel=f"error ({unit})", title="the error falling")
    axes[2].legend(fontsize=9)
    for a in axes:
        a.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def check_report_folder(folder) -> tuple[Path, Path]:
    """The report's two files in ``folder``, checked before any work: InputError if ``folder`` (or the
    nearest part of its path that exists) is a file, if either file exists (nothing is ever overwritten), or
    if nothing can be written there (the nearest existing folder is tried with a temporary file, removed at
    once; the report folder itself is created only when the report is written)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder}: is a file, expected a folder for the report")
    png, md = folder / "loop.png", folder / "loop.md"
    for p in (png, md):
        if p.exists() or p.is_symlink():
            raise InputError(
                f"{p}: already exists; not overwritten (choose another --report folder)"
            )
    base = folder
    while not base.exists() and base != base.parent:
        base = base.parent
    if not base.is_dir():
        raise InputError(
            f"{folder}: cannot be created, '{base}' is a file (choose another --report folder)"
        )
    try:
        with tempfile.TemporaryFile(dir=base):
            pass
    except OSError as err:
        raise InputError(
            f"{folder}: cannot write the report there (creating a file in {base} failed: "
            f"{err.strerror or type(err).__name__}); choose another --report folder"
        ) from None
    return png, md


def write_report(result: LoopResult, folder, source: str = "") -> tuple[Path, Path]:
    """Write ``loop.png`` (:func:`report_figure`: the staircase, the measurement against the models, the
    residuals; 750 px wide) and ``loop.md`` (steps and outcome) into ``folder``; never over an existing
    file (InputError)."""
    folder = Path(folder)
    png, md = check_report_folder(folder)
    folder.mkdir(parents=True, exist_ok=True)
    import matplotlib.pyplot as plt  # noqa: PLC0415  # lazy: matplotlib only for figures; the CLI's loop runs without it

    fig = report_figure(result)
    fig.savefig(png, dpi=DPI)
    plt.close(fig)
    unit = result.final.unit
    lines = [
        f"# Workbench loop: {result.final.system}" + (f" on `{source}`" if source else ""),
        "",
        f"| step | model | rms ({unit}) | held-out rms ({unit}) | named |",
        "|---|---|---|---|---|",
    ]
    for i, (f, d) in enumerate(zip(result.fits, result.diagnoses)):
        lines.append(
            f"| {i} | {' + '.join(f.effects) or '(none)'} | {f.rms:.4g} | {f.loo_rms:.4g} | "
            f"{d.missing or '-'} |"
        )
    lines += [""] + [f"Not tested: {u['effect']} ({u['why']})." for u in result.untested]
    sc = result.screening
    if sc is not None and sc.outliers:
        lines += ["", f"**Outliers:** {sc.outlier_line(unit)}."]
    if sc is not None and sc.noise.series is not None:
        lines += ["", f"**Noise:** {sc.noise.describe()}."]
    lines += [
        "",
        f"**Outcome:** {result.outcome()}.",
        "",
        result.final_diagnosis.message.split("\n")[-1],
    ]
    rem = result.remaining()
    if rem is not None and not rem[0].empty:
        lines += [
            "",
            "**What remains** (a description, not a test; the factors overlap: a pause is a cell of time, "
            f"turn rate and acceleration at once): {rem[1]}.",
            "",
            f"| invariant | factor | cells | share of variance | rms of cell means ({unit}) | largest cell | "
            f"its mean ({unit}) |",
            "|---|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r.invariant} | {r.factor} | {r.cells} | {100 * r.share:.0f} % | {r.amplitude_ut:.3g} | "
            f"{r.largest_cell} | {r.largest_mean_ut:+.3g} |"
            for r in rem[0].itertuples()
        ]
    lines += ["", f"![the loop]({png.name})", ""]
    md.write_text("\n".join(lines))
    return png, md
