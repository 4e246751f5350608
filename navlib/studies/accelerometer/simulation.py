"""The chapter's data: both units' simulated tumble tests for one seed (:mod:`navlib.sensors.accelerometer`;
the paper publishes no data), each seed's draws by part (:func:`sim_seed`), the samples ``[(T, N), Nc]``
and the split into training, checking and test readings (by whole temperatures, or at random)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...errors import InputError, check_param
from ...seeding import child, sequence
from ...sensors.accelerometer import AccelCoefficients, T_REF_C, simulate_tumble
from .parameters import SIM_ENTROPY, SIM_PARTS, PaperDParams


def sim_seed(seed: int, part: str) -> np.random.SeedSequence:
    """The draw of one part (:data:`~navlib.studies.accelerometer.parameters.SIM_PARTS`) of seed ``seed``:
    ``SeedSequence(SIM_ENTROPY, spawn_key=(seed, part))``."""
    check_param("seed", seed, lo=0, integer=True)
    return sequence(SIM_ENTROPY, seed, SIM_PARTS[part])


def unit_b_coefficients(
    params: PaperDParams, seed: int, spread_rel: float | None = None
) -> AccelCoefficients:
    """Unit B of seed ``seed``: unit A's coefficients scaled by ``1 + spread z`` (``spread`` defaults to
    ``params.batch_spread_rel``), ``z`` drawn from :func:`sim_seed` ``(seed, "batch_b")``: no seed is picked,
    every seed draws its own second unit, and the same seed gives the same ``z`` at every spread."""
    spread = params.batch_spread_rel if spread_rel is None else spread_rel
    return params.coefficients.batch_member(spread, sim_seed(seed, "batch_b"))


def simulate(params: PaperDParams, seed: int) -> pd.DataFrame:
    """Both units' tumble tests for one seed: unit A with noise :func:`sim_seed` ``(seed, "noise_a")``,
    unit B (:func:`unit_b_coefficients`, drawn afresh for every seed) with noise ``(seed, "noise_b")``."""
    exp = params.experiment
    return pd.concat(
        [
            simulate_tumble(params.coefficients, exp, sim_seed(seed, "noise_a"), "A"),
            simulate_tumble(unit_b_coefficients(params, seed), exp, sim_seed(seed, "noise_b"), "B"),
        ],
        ignore_index=True,
    )


def samples(df: pd.DataFrame, unit: str = "A", reference_c: float = T_REF_C) -> pd.DataFrame:
    """Samples ``[(T, N), Nc]`` of one unit: each reading with the same position's reading at the
    reference set point as target (``Nc``, measured) and its noise-free value (``Nc_true``)."""
    g = df[df["unit"] == unit]
    if g.empty:
        raise InputError(f"tumble data: no rows for unit {unit!r}")
    ref = g[np.isclose(g["set_point_c"], reference_c)].set_index("position_deg")
    if ref.empty:
        raise InputError(
            f"tumble data: unit {unit} has no readings at the reference {reference_c:g} degC"
        )
    missing = sorted(set(g["position_deg"]) - set(ref.index))
    if missing:
        raise InputError(
            f"tumble data: unit {unit} has no reference reading at position {missing[0]:g} deg"
        )
    out = g[["set_point_c", "temperature_c", "position_deg", "output_mg"]].reset_index(drop=True)
    out["target_mg"] = ref.loc[out["position_deg"], "output_mg"].to_numpy()
    if "true_output_mg" in g.columns:
        out["target_true_mg"] = ref.loc[out["position_deg"], "true_output_mg"].to_numpy()
    return out


def split(s: pd.DataFrame, params: PaperDParams) -> pd.Series:
    """``train`` / ``check`` / ``test`` label of every sample, by whole set-point temperatures."""
    lab = pd.Series("train", index=s.index)
    lab[np.isin(np.round(s["set_point_c"], 6), np.round(params.check_c, 6))] = "check"
    lab[np.isin(np.round(s["set_point_c"], 6), np.round(params.held_out_c, 6))] = "test"
    return lab


def random_split(
    s: pd.DataFrame, params: PaperDParams, seed: int | np.random.SeedSequence
) -> pd.Series:
    """The random-split reading: ``train`` / ``check`` / ``test`` labels drawn at random over all readings,
    with as many ``test`` and ``check`` readings as :func:`split` by whole temperatures gives (one random
    permutation of the rows; ``seed``: an integer seed of the study, drawn from :func:`sim_seed`
    ``(seed, "split")``, or a ``SeedSequence``).  Deterministic from the seed; the three sets are disjoint
    and cover every row."""
    by_t = split(s, params)
    n_test, n_check = int((by_t == "test").sum()), int((by_t == "check").sum())
    ss = seed if isinstance(seed, np.random.SeedSequence) else sim_seed(seed, "split")
    perm = np.random.default_rng(child(ss)).permutation(len(s))
    lab = np.full(len(s), "train", dtype=object)
    lab[perm[:n_test]] = "test"
    lab[perm[n_test : n_test + n_check]] = "check"
    return pd.Series(lab, index=s.index)
