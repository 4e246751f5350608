"""The loop on the real BROAD recordings: the level compass sweeps, and the undisturbed 3-D trials with the
reference (the optical attitude) and without it (field and accelerometer only), trial by trial on
:mod:`navlib.engine`.
"""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from ... import engine
from ...errors import InputError, check_param
from ...workbench.fit import load
from ...workbench.loop import LoopResult, loop, staircase_of
from ...workbench.magnetometer import MAG
from ...workbench.magnetometer_free import ACC, SYSTEM as FREE, with_invariants
from .parameters import BROAD_SITE, FREE_ROW_STEP, LEVEL_DIR, MAG_DIR, MAX_ATT_BLUR, STATIONARY
from .tables import added


# ------------------------------------------------------------------------------------ real level sweeps
@dataclass
class LevelLoops:
    """The loop from ``misalignment`` on each level BROAD file: the results and a summary table."""

    results: dict
    summary: pd.DataFrame


def level_loops(start_model=("misalignment",), alpha: float | None = None) -> LevelLoops | None:
    """Run :func:`navlib.workbench.loop.loop` on every file in ``broad/level`` (None if absent).

    The summary has one row per file: rows, the effects added in order, final rms and held-out rms (deg),
    the outcome, and the largest unexplained structure amplitude as a multiple of the residual RMS."""
    if not LEVEL_DIR.is_dir():
        return None
    results, rows = {}, []
    for path in sorted(LEVEL_DIR.glob("*.csv")):
        res = loop("compass", load("compass", path), list(start_model), alpha=alpha)
        results[path.name] = res
        amp = max([u["amplitude"] for u in res.unexplained] + [0.0])
        rows.append(
            {
                "file": path.name,
                "rows": len(res.final.data),
                "effects added": added(res),
                "start rms (deg)": res.fits[0].rms,
                "final rms (deg)": res.final.rms,
                "final held-out rms (deg)": res.final.loo_rms,
                "outcome": res.outcome(),
                "largest structure / rms": amp / res.final.rms,
            }
        )
    return LevelLoops(results, pd.DataFrame(rows).set_index("file"))


# ------------------------------------------------------------------------------------ 3-D magnetometer
def load_trial(name: str, row_step: int = 1, attached_only: bool = False) -> pd.DataFrame:
    """A BROAD 3-D trial: blocks with attitude blur below 0.01, without the magnet being handled
    (``magnet_attached`` = -1), only the magnet-on blocks if ``attached_only``, and in motion for the
    stationary-magnet trials (the magnet is put down while the IMU rests); every ``row_step``-th block."""
    check_param("row_step", row_step, lo=1, integer=True)
    d = load("magnetometer", MAG_DIR / name)
    keep = (d["att_blur"] < MAX_ATT_BLUR) & (d["magnet_attached"] >= 0)
    if attached_only:
        keep &= d["magnet_attached"] == 1
    if name in STATIONARY:
        keep &= d["moving"] == 1
    return d[keep].iloc[:: int(row_step)].reset_index(drop=True)


def undisturbed_trials() -> list[str]:
    """The undisturbed BROAD 3-D trials (01-07 and 21), file names in order ([] if the data are absent)."""
    return sorted(p.name for p in MAG_DIR.glob("*undisturbed*.csv")) if MAG_DIR.is_dir() else []


def undisturbed_loop(name: str, row_step: int = 3, alpha: float | None = None) -> dict:
    """The loop from the local field alone on one undisturbed trial (:func:`load_trial`): what it ends
    with -- rows used and set aside as outliers, the noise model, the effects added, the final rms, the
    outcome and the largest unexplained structure -- and ``staircase``, the loop's
    :class:`navlib.workbench.loop.Staircase`."""
    data = load_trial(name, row_step)
    res = loop("magnetometer", data, [], alpha=alpha)
    noise = res.screening.noise
    amp = max([u["amplitude"] for u in res.unexplained] + [0.0])
    return {
        "trial": name.replace("broad_", "").replace(".csv", "").replace("_", " "),
        "rows": len(data),
        "rows set aside": len(res.screening.rows_set_aside),
        "noise model": f"AR({noise.order}), lag-1 {noise.lag1:.2f}"
        if noise.correlated
        else "independent",
        "effects added": added(res),
        "final rms (uT)": res.final.rms,
        "largest structure (uT)": amp,
        "outcome": res.outcome(),
        "staircase": staircase_of(res),
    }


def undisturbed_loops(
    row_step: int = 3, alpha: float | None = None, workers: int = 1, scheduler: str | None = None
) -> pd.DataFrame | None:
    """:func:`undisturbed_loop` on every undisturbed BROAD 3-D trial, one row each (None if the data are
    absent); ``workers``, ``scheduler``: where they run (:mod:`navlib.engine`, the largest files first; the
    workers read the files, so a remote cluster needs them at the same path)."""
    return _on_undisturbed(undisturbed_loop, row_step, alpha, workers, scheduler, "BROAD loops")


def _on_undisturbed(fn, row_step, alpha, workers, scheduler, label) -> pd.DataFrame | None:
    """``fn(name, row_step, alpha)`` on every undisturbed BROAD 3-D trial on the engine (the longest
    recordings first), one row each indexed by ``trial``; each row's ``staircase`` (a loop's
    :class:`navlib.workbench.loop.Staircase`) goes into ``attrs["staircases"]`` (trial -> Staircase), not
    into the table.  None if the data are absent."""
    names = undisturbed_trials()
    if not names:
        return None
    check_param("row_step", row_step, lo=1, integer=True)
    rows = engine.run(
        fn,
        [(n, row_step, alpha) for n in names],
        workers=workers,
        scheduler=scheduler,
        label=label,
        cost=[float((MAG_DIR / n).stat().st_size) for n in names],
    )
    stairs = {r["trial"]: st for r in rows if (st := r.pop("staircase", None)) is not None}
    out = pd.DataFrame(rows).set_index("trial")
    out.attrs["staircases"] = stairs
    return out


# ------------------------------------------------------------------------------------ without the reference
def _free_frame(d: pd.DataFrame) -> pd.DataFrame:
    return with_invariants(d[list(MAG) + list(ACC) + ["time_s"]])


def free_undisturbed_loop(
    name: str, row_step: int = FREE_ROW_STEP, alpha: float | None = None
) -> dict:
    """The reference-free loop (:mod:`navlib.workbench.magnetometer_free`: field and accelerometer only,
    the optical reference ignored) from the local field alone on one undisturbed BROAD trial, every
    ``row_step``-th block: what it ends with -- rows, rows set aside, the noise model, the effects added,
    the final rms, the outcome, and the local field it estimates (intensity and dip with their 95 %
    half-widths; the system's ``final_check`` without a site,
    :data:`~navlib.studies.workbench.parameters.BROAD_SITE`), and ``staircase`` (the
    loop's :class:`navlib.workbench.loop.Staircase`); a trial the system refuses (e.g. too few distinct
    orientations at this row step) says so in ``outcome`` and has no staircase."""
    data = _free_frame(load_trial(name, row_step))
    label = name.replace("broad_", "").replace(".csv", "").replace("_", " ")
    try:
        res = loop(FREE, data, [], alpha=alpha)
    except InputError as err:  # what the CLI would refuse (e.g. too few distinct orientations)
        return {
            "trial": label,
            "rows": len(data),
            "rows set aside": 0,
            "noise model": "-",
            "effects added": "-",
            "final rms (uT)": float("nan"),
            "outcome": "refused: " + str(err).split(": ", 1)[-1][:60],
            "field (uT)": float("nan"),
            "field 95% (uT)": float("nan"),
            "dip (deg)": float("nan"),
            "dip 95% (deg)": float("nan"),
            "what is left": "-",
        }
    check, _ = FREE.final_check(res, BROAD_SITE, None)
    noise = res.screening.noise
    return {
        "trial": label,
        "rows": len(data),
        "rows set aside": len(res.screening.rows_set_aside),
        "noise model": f"AR({noise.order}), lag-1 {noise.lag1:.2f}"
        if noise.correlated
        else "independent",
        "effects added": added(res),
        "final rms (uT)": res.final.rms,
        "outcome": res.outcome(),
        "field (uT)": check["intensity_ut"],
        "field 95% (uT)": 1.96 * check["intensity_std_ut"],
        "dip (deg)": check["dip_deg"],
        "dip 95% (deg)": 1.96 * check["dip_std_deg"],
        "what is left": "-" if res.consistent_with_noise else _top_factor(res),
        "staircase": staircase_of(res),
    }


def _top_factor(res: LoopResult) -> str:
    """The factor holding the largest share of the final residuals (:meth:`LoopResult.remaining`), short."""
    table, _ = res.remaining()
    if table.empty:
        return "-"
    top = table.loc[table["share"].idxmax()]
    return f"{top['factor']} ({'|m|' if top['invariant'] == 'magnitude' else 'dip'}) {100 * top['share']:.0f}%"


def free_undisturbed_loops(
    row_step: int = FREE_ROW_STEP,
    alpha: float | None = None,
    workers: int = 1,
    scheduler: str | None = None,
) -> pd.DataFrame | None:
    """:func:`free_undisturbed_loop` on every undisturbed BROAD 3-D trial, one row each (None if the data
    are absent)."""
    return _on_undisturbed(
        free_undisturbed_loop, row_step, alpha, workers, scheduler, "BROAD reference-free loops"
    )
