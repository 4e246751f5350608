"""Paper C's cold-state protocol in simulated thermal worlds that are not the rate baseline's own.

- the study: :func:`cold_thermal_study` (gyros of :mod:`navlib.sensors.thermal_gyro`, draws on
  :mod:`navlib.engine`, cached per parameter set) and its
  summary per world, :func:`cold_thermal_summary`;
- the worlds' stated ranges: :func:`thermal_worlds_table` (the worlds themselves:
  :data:`navlib.studies.gyro.parameters.THERMAL_WORLDS`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pandas as pd

from navlib import engine, seeding, verdicts
from navlib.angles import to_arcmin
from navlib.data.gyro_tables import load_cold_test, load_cold_train, load_hot_train
from navlib.methods.rbf import InputScaler, newrb
from navlib.sensors import ins, thermal_gyro

from .cold_state import _cold_history
from .measured import _maxabs, _rms
from .networks import _table2_net, design_cold_net, design_hot_net, rate_coefficient
from .parameters import HotNetSettings, StudyParams, ThermalWorld, fact


#: The methods each draw of :func:`cold_thermal_study` scores.
COLD_STUDY_METHODS = ("hot net", "hot + rate corr.", "cold net (z-scored)", "cold net (raw units)")


@lru_cache(maxsize=1)
def _k_r_table4() -> float:
    """``k_R`` fitted on the real Table 4 with the paper's hot net (default settings)."""
    t4 = load_cold_train()
    hot4 = _table2_net(HotNetSettings()).predict(t4["latitude_error_deg"].to_numpy(float))
    return rate_coefficient(
        hot4 - t4["true_drift_deg_h"].to_numpy(float),
        t4["calib_temp_change_c"].to_numpy(float) / fact("identify_h"),
    )


@lru_cache(maxsize=4)
def _cold_fixed(dt_column: str, procedure: ins.Procedure) -> dict:
    """The fixed arrays of :func:`_cold_draw` (tables loaded once per process)."""
    t2, t4, t5 = load_hot_train(), load_cold_train(), load_cold_test()
    out = {"y2": t2["drift_deg_h"].to_numpy(float), "y4": t4["true_drift_deg_h"].to_numpy(float)}
    for name, t in (("4", t4), ("5", t5)):
        out[f"knots{name}"] = [
            thermal_gyro.cold_start_knots(_cold_history(r, 0.0, procedure)) for r in t.itertuples()
        ]
        out[f"rate{name}"] = t["calib_temp_change_c"].to_numpy(float) / procedure.identify_h
        out[f"temp{name}"] = t["calib_temp_max_c"].to_numpy(float)
        out[f"dt{name}"] = t[dt_column].to_numpy(float)
    return out


def _cold_draw(params: StudyParams, world: int, draw: int, k_r: float) -> dict:
    """One draw of one world of :func:`cold_thermal_study` (an engine task; seeds from
    ``seeding.sequence(seed, 0, draw)`` for the residual errors and test drifts, common to every world, and
    ``seeding.sequence(seed, 1, world, draw)`` for the gyro)."""
    s, proc, earth = params.sim, params.sim.procedure(), params.earth
    cs = params.thermal
    m = thermal_gyro.identification_map(earth, proc, ins.Rotation())
    fx = _cold_fixed(params.cold.dt_column, proc)
    y2, y4 = fx["y2"], fx["y4"]
    n2, n4, n5 = y2.size, y4.size, fx["rate5"].size
    rng = np.random.default_rng(seeding.sequence(s.seed, 0, draw))
    zero = np.zeros(m.axial.size)
    resid = []
    for _ in range(n2 + n4 + n5):
        imu, init = ins.random_test(rng, axial_drift_deg_h=0.0, **s.error_sd())
        resid.append(float(m.latitude_error_deg(zero, imu, init, rng.standard_normal())[0]))
    resid = np.array(resid)
    half = s.cold_drift_half_range_deg_h
    y5 = rng.uniform(-half, half, n5)
    gyro = cs.worlds[world].draw(
        np.random.default_rng(seeding.sequence(s.seed, 1, world, draw)), k_r
    )

    def cold_lat(knots, finals, res):
        return np.array(
            [
                float(m.axial @ gyro.axial_drift_deg_h(m.t_mid_h, kt, kc, float(f))) + r
                for (kt, kc), f, r in zip(knots, finals, res)
            ]
        )

    lat2 = y2 * float(m.axial.sum()) + resid[:n2]
    lat4 = cold_lat(fx["knots4"], y4, resid[n2 : n2 + n4])
    lat5 = cold_lat(fx["knots5"], y5, resid[n2 + n4 :])
    hot_net = design_hot_net(lat2, y2, params.hot)
    hot5 = hot_net.predict(lat5)
    k_fit = rate_coefficient(hot_net.predict(lat4) - y4, fx["rate4"])
    X4 = np.c_[to_arcmin(lat4), fx["temp4"], fx["dt4"]]
    X5 = np.c_[to_arcmin(lat5), fx["temp5"], fx["dt5"]]
    z = design_cold_net(X4, y4, params)
    raw = newrb(
        X4,
        y4,
        goal=params.hot.goal,
        spread=cs.raw_spread,
        goal_kind=params.hot.goal_kind,
        scaler=InputScaler.identity(X4.shape[1]),
    )
    est = dict(
        zip(COLD_STUDY_METHODS, (hot5, hot5 - k_fit * fx["rate5"], z.predict(X5), raw.predict(X5)))
    )
    out = {
        "world": cs.worlds[world].name,
        "draw": draw,
        "k_T (deg/h per C)": gyro.temp_coeff_deg_h_per_c,
        "k_G tau (deg/h per C/h)": gyro.rate_coeff_deg_h_per_c_h,
        "tau (h)": gyro.lag_h,
    }
    for name, e in est.items():
        err = y5 - e
        out[f"{name} RMS (deg/h)"] = _rms(err)
        out[f"{name} max (deg/h)"] = _maxabs(err)
    return out


_COLD_STUDIES: dict = {}


def cold_thermal_study(
    params: StudyParams = StudyParams(), workers: int = 1, scheduler: str | None = None
) -> pd.DataFrame:
    """Paper C's cold-state protocol in simulated worlds that are not the rate baseline's own.

    Per world (:data:`~navlib.studies.gyro.parameters.THERMAL_WORLDS`, ``params.thermal``) and draw: one gyro
    (:class:`navlib.sensors.thermal_gyro.ThermalGyro`, parameters drawn in the world's ranges); 16 hot tests
    with Table 2's drifts at a constant temperature train the hot net; 6 cold tests with Table 4's temperature
    histories and true drifts train the cold nets (z-scored inputs with SPREAD ``params.cold.spread_sd`` in
    standard deviations, and raw inputs in arcmin, C, C with SPREAD ``params.thermal.raw_spread``) and fit the
    rate coefficient of the "hot + rate correction" baseline (:func:`~navlib.studies.gyro.networks.rate_coefficient` on
    the hot net's errors); 3 tests with Table 5's histories and final drifts uniform in
    +-``cold_drift_half_range_deg_h`` are identified by every method.  Each test draws its residual errors
    (:func:`navlib.sensors.ins.random_test`); its 12 h latitude error comes from the exact linear map of the
    identification run (:func:`navlib.sensors.thermal_gyro.identification_map`).  Draws run on :mod:`navlib.engine`,
    batched ``params.thermal.batch_size`` per task; the residual errors and test drifts of draw ``d`` are the same in
    every world.

    Parameters
    ----------
    params : StudyParams
    workers : int
        Engine worker processes (1: in this process); results do not depend on it.
    scheduler : str, optional
        Address of an existing dask scheduler.

    Returns
    -------
    pandas.DataFrame
        One row per (world, draw): the gyro's parameters and per method the RMS and largest ``|final drift -
        identified|`` over the 3 test runs (deg/h).
    """
    if params not in _COLD_STUDIES:  # results do not depend on workers or scheduler (engine)
        k_r = _k_r_table4()
        cs = params.thermal
        items = [(params, w, d, k_r) for w in range(len(cs.worlds)) for d in range(cs.n_draws)]
        rows = engine.run_batches(
            _cold_draw,
            items,
            cs.batch_size,
            workers=workers,
            scheduler=scheduler,
            label="paper C cold worlds",
        )
        _COLD_STUDIES.clear()
        _COLD_STUDIES[params] = pd.DataFrame(rows)
    return _COLD_STUDIES[params]


def cold_thermal_summary(study: pd.DataFrame) -> pd.DataFrame:
    """Per world, the median over draws of each method's RMS drift error on the 3 test runs (deg/h), and the
    median paired difference cold net - hot net with its 95 % interval (:func:`navlib.verdicts.paired_difference`).

    Parameters
    ----------
    study : pandas.DataFrame
        From :func:`cold_thermal_study`.

    Returns
    -------
    pandas.DataFrame
        One row per world.
    """
    rows = []
    for world, g in study.groupby("world", sort=False):
        row = {"world": world, "draws": len(g)}
        for m in COLD_STUDY_METHODS:
            row[m] = float(g[f"{m} RMS (deg/h)"].median())
        for m in COLD_STUDY_METHODS[2:]:
            e = verdicts.paired_difference(g[f"{m} RMS (deg/h)"], g["hot net RMS (deg/h)"])
            row[f"{m} - hot"] = f"{e.value:+.5f} [{e.lo:+.5f}, {e.hi:+.5f}]"
        rows.append(row)
    return pd.DataFrame(rows)


def _world_text(w: ThermalWorld, k_r: float) -> str:
    return (
        f"k_T {w.temp_coeff_deg_h_per_c[0]:g}..{w.temp_coeff_deg_h_per_c[1]:g} deg/h per C, k_G tau "
        f"{w.rate_coeff_in_k_r[0] * k_r:.5f}..{w.rate_coeff_in_k_r[1] * k_r:.5f} (deg/h) per (C/h), tau "
        f"{w.lag_h[0]:g}..{w.lag_h[1]:g} h"
    )


def thermal_worlds_table(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """The stated parameter ranges of every thermal world of :func:`cold_thermal_study` (each draw takes its
    gyro uniformly within them); ``k_G tau`` in (deg/h) per (C/h), from the world's multiples of ``k_R``.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    pandas.DataFrame
        One row per world.
    """
    k_r = _k_r_table4()
    return pd.DataFrame(
        [
            {
                "world": w.name,
                "k_T low (deg/h per C)": w.temp_coeff_deg_h_per_c[0],
                "k_T high": w.temp_coeff_deg_h_per_c[1],
                "k_G tau low ((deg/h)/(C/h))": w.rate_coeff_in_k_r[0] * k_r,
                "k_G tau high": w.rate_coeff_in_k_r[1] * k_r,
                "tau low (h)": w.lag_h[0],
                "tau high (h)": w.lag_h[1],
            }
            for w in params.thermal.worlds
        ]
    )
