"""Three of paper C's statements of *why* its method works, judged on its printed tables and on the error
model: C14 (Sec. 1), C16 (Sec. 2.1) and C18 (introduction, abstract).

- :func:`centre_basis_errors`, :func:`centre_claims`: C14, "what influences the network's performance more
  is the choice of the centres".  Leave-one-out over Table 2, each fold's ``newrb`` net (``params.hot``)
  fixes the number of neurons ``m`` and the width ``b``; then the basis function is changed at newrb's
  centres (Gaussian, multiquadric, inverse multiquadric, thin-plate spline, as in C13) and, with the
  Gaussian, the centres are changed (newrb's orthogonal least squares, k-means with ``m`` centres, random
  subsets of ``m`` data rows); output weights and bias always refitted by least squares.  The statistic::

      D = ptp_c RMS_c - ptp_f RMS_f                                           (eq. c14)

  ``RMS`` the leave-one-out RMS error over Table 2 (deg/h), ``ptp`` the spread (max - min) across the
  centre choices ``c`` (OLS, k-means, the median over the random subsets) or across the basis functions
  ``f``; percentile bootstrap over Table 2's rows (the leave-one-out errors resampled together, paired);
  the claim holds above 0.
- :func:`latitude_share`, :func:`latitude_share_claims`: C16, "the 12 h latitude error is mainly caused by
  the axial drift".  On the measured hot tests (Table 2), the latitude error's part due to the axial drift
  through Table 1's own 12 h gain ``k = (cos L / W)(1 - cos 12 W)``, against the rest::

      S = 100 sum_i (k eps_i)^2 / (sum_i (k eps_i)^2 + sum_i (dL_i - k eps_i)^2)
                                                                       (eq. c16)

  ``dL_i`` the printed 12 h latitude less the printed local latitude, ``eps_i`` the printed "true" drift;
  bootstrap over the rows; the claim holds above 50 %.  The simulated hot tests give the same share, but
  there it is set by the residual error sizes the book's simulator draws (a row true by construction).
- :func:`rotation_responses`, :func:`rotation_shares`, :func:`rotation_claims`: C18, "single-axis rotation
  cancels the errors perpendicular to the axis, so the accuracy is mainly the axial drift".  With the
  rotation on, the worst 72 h position error ``P`` of each source alone (the axial drift; both horizontal
  gyros; both horizontal accelerometers), and the axial share::

      s = 100 P_axial / (P_axial + P_gyros + P_accels)                         (eq. c18)

  median over runs that draw the horizontal instruments' signs and the rotation phase; the claim holds
  above 50 %.  The error model is :mod:`navlib.sensors.ins` (static base, psi-angle equations, body-frame
  errors turned by the rotation about the vertical); :func:`rotation_responses` propagates its unit
  responses for every phase at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pandas as pd

from navlib import verdicts
from navlib.claims import Claim
from navlib.errors import InputError, check_param
from navlib.methods.rbf import radbas
from navlib.sensors import ins

from .measured import _hot_xy
from .networks import BASIS_FUNCTIONS, design_hot_net, swap_basis
from .parameters import (
    HotNetSettings,
    StudyParams,
    _experiment_children,
    bootstrap_seed,
    fact,
)
from .simulation import _simulated_hot_tests

CLAIM_C14 = "the choice of centres matters more than the basis function"
CLAIM_C16 = "after 4 h alignment the 12 h latitude error is mainly due to the axial drift"
CLAIM_C18 = "a single-axis rotation INS's accuracy is set by the axial gyro drift"
#: C14's basis functions at newrb's centres: the Gaussian and C13's others.
BASES = ("gaussian", *BASIS_FUNCTIONS)


# ---------------------------------------------------------------------------------------------------- C14
def kmeans_centres(xs, m: int, n_iter: int = 100) -> np.ndarray:
    """Lloyd's k-means with ``m`` centres on the rows of ``xs`` (scaled inputs), started deterministically
    at the rows of evenly spaced ranks of the first column (for the hot net's one input: evenly spaced
    quantiles); a cluster left empty keeps its centre.

    Parameters
    ----------
    xs : array_like
        (q, n) points.
    m : int
        Number of centres, 1 <= m <= q.
    n_iter : int
        Most iterations (it stops when the assignment no longer changes).

    Returns
    -------
    numpy.ndarray
        (m, n) centres.
    """
    x = np.asarray(xs, float)
    x = x[:, None] if x.ndim == 1 else x
    q = x.shape[0]
    check_param("m", m, lo=1, hi=q, integer=True)
    order = np.argsort(x[:, 0], kind="stable")
    c = x[order[np.round(np.linspace(0, q - 1, m)).astype(int)]].copy()
    lab = None
    for _ in range(int(n_iter)):
        new = np.argmin(((x[:, None, :] - c[None, :, :]) ** 2).sum(axis=2), axis=1)
        if lab is not None and np.array_equal(new, lab):
            break
        lab = new
        for j in range(m):
            if np.any(lab == j):
                c[j] = x[lab == j].mean(axis=0)
    return c


def _gauss_design(xs, centres, b) -> np.ndarray:
    """``[radbas(b |x - c_j|), 1]`` for stacks: ``centres`` (..., m, n) -> (..., q, m + 1)."""
    d = np.sqrt(((xs[..., :, None, :] - centres[..., None, :, :]) ** 2).sum(axis=-1))
    a = radbas(b * d)
    return np.concatenate([a, np.ones(a.shape[:-1] + (1,))], axis=-1)


@dataclass(frozen=True)
class CentreBasisErrors:
    """Leave-one-out errors (true - predicted, deg/h) over Table 2's rows: ``basis`` (q, 4) for
    :data:`BASES` at newrb's centres; ``kmeans`` (q,) and ``random`` (q, R) for the Gaussian at other
    centres (newrb's own centres are ``basis[:, 0]``); ``neurons`` per fold."""

    basis: np.ndarray
    kmeans: np.ndarray
    random: np.ndarray
    neurons: np.ndarray

    def matrix(self, include_random: bool = True) -> np.ndarray:
        """Columns: the bases, k-means, then (``include_random``) the random subsets."""
        cols = [self.basis, self.kmeans[:, None]]
        if include_random:
            cols.append(self.random)
        return np.hstack(cols)


def centre_basis_errors(
    hot: HotNetSettings, n_subsets: int = 200, seed: np.random.SeedSequence | int = 0
) -> CentreBasisErrors:
    """Leave-one-out over Table 2 of the basis-function and centre choices of eq. c14 (module docstring).

    Parameters
    ----------
    hot : HotNetSettings
        newrb's settings: each fold's net fixes ``m`` and ``b``.
    n_subsets : int
        Random subsets of ``m`` training rows per fold (subset ``r`` of every fold together is one
        design rule, "random centres", whose leave-one-out RMS is one value).
    seed : numpy.random.SeedSequence or int

    Returns
    -------
    CentreBasisErrors
    """
    check_param("n_subsets", n_subsets, lo=1, hi=100000, integer=True)
    x2, y2, _, _ = _hot_xy()
    q = x2.size
    rng = np.random.default_rng(seed)
    basis = np.empty((q, len(BASES)))
    km = np.empty(q)
    rnd = np.empty((q, int(n_subsets)))
    neurons = np.empty(q, int)
    for i in range(q):
        keep = np.arange(q) != i
        xk, yk, xi = x2[keep], y2[keep], x2[i : i + 1]
        net = design_hot_net(xk, yk, hot)
        m, b = net.n_neurons, net.b
        neurons[i] = m
        for j, f in enumerate(BASES):
            basis[i, j] = y2[i] - float(swap_basis(net, xk, yk, f)(xi)[0])
        xs, xsi = net.scaler.transform(xk), net.scaler.transform(xi)
        ck = kmeans_centres(xs, m)
        sol, *_ = np.linalg.lstsq(_gauss_design(xs, ck, b), yk, rcond=None)
        km[i] = y2[i] - float((_gauss_design(xsi, ck, b) @ sol)[0])
        pick = np.argsort(rng.random((int(n_subsets), q - 1)), axis=1)[:, :m]
        cents = xs[pick]  # (R, m, n)
        design = _gauss_design(np.broadcast_to(xs, (pick.shape[0],) + xs.shape), cents, b)
        w = np.linalg.pinv(design) @ yk  # (R, m + 1), least squares per subset
        rnd[i] = y2[i] - np.einsum("rk,rk->r", _gauss_design(xsi[None], cents, b)[:, 0, :], w)
    return CentreBasisErrors(basis, km, rnd, neurons)


def spread_difference(errors, n_bases: int = len(BASES), random_from: int | None = None):
    """Eq. c14 on a leave-one-out error matrix (rows: Table 2's rows).

    Parameters
    ----------
    errors : array_like
        (q, k) columns: ``n_bases`` basis functions (the first, the Gaussian at newrb's centres, is also
        the OLS centre choice), then the other centre choices; from column ``random_from`` on, random
        subsets, which count as one choice through the median of their RMS.
    n_bases : int
    random_from : int or None
        First random column, or None (no random choice).

    Returns
    -------
    float
        Spread over centre choices less spread over bases, deg/h.
    """
    e = np.asarray(errors, float)
    return _spread_difference_rms(np.sqrt(np.mean(e * e, axis=0)), n_bases, random_from)


def _spread_difference_rms(rms, n_bases, random_from) -> float:
    cut = rms.size if random_from is None else random_from
    centres = list(rms[n_bases:cut]) + [rms[0]]
    if random_from is not None:
        centres.append(np.median(rms[random_from:]))
    b = rms[:n_bases]
    return float(max(centres) - min(centres) - (b.max() - b.min()))


@lru_cache(maxsize=4)
def _c14_runs(params: StudyParams) -> dict:
    h = params.hot
    readings = {
        "primary": h,
        "deg": HotNetSettings(
            spread=h.spread, goal=h.goal, goal_kind=h.goal_kind, input_unit="deg"
        ),
        "rss": HotNetSettings(
            spread=h.spread, goal=h.goal**2, goal_kind="sse", input_unit=h.input_unit
        ),
    }
    seeds = _experiment_children(params.sim.seed, "centre_subsets", len(readings))
    return {k: centre_basis_errors(v, seed=s) for (k, v), s in zip(readings.items(), seeds)}


def centre_claims(params: StudyParams = StudyParams()) -> list[Claim]:
    """C14's rows (eq. c14): the primary reading (input and goal from ``params.hot``; OLS, k-means and
    random subsets), the input in deg, the goal read as an RMS, and the centre choices without the random
    subsets.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    list of navlib.claims.Claim
    """
    runs = _c14_runs(params)
    seed = bootstrap_seed(params.sim.seed, "centres_vs_basis")
    h = params.hot
    nb = len(BASES)
    out = []
    for key, run, with_random, reading in (
        (
            "gyro_centres",
            runs["primary"],
            True,
            "newrb OLS, k-means and random data subsets against four bases, leave-one-out over Table 2",
        ),
        (
            "gyro_centres_deg",
            runs["deg"],
            True,
            "the same with the input in deg",
        ),
        (
            "gyro_centres_rss_goal",
            runs["rss"],
            True,
            "the same with the goal read as a root-sum-square (more neurons)",
        ),
        (
            "gyro_centres_no_random",
            runs["primary"],
            False,
            "centre choices newrb OLS and k-means only (no random subsets)",
        ),
    ):
        e = run.matrix(include_random=with_random)
        rf = nb + 1 if with_random else None
        e2 = e * e

        def stat(idx, e2=e2, rf=rf):
            return _spread_difference_rms(np.sqrt(e2[np.asarray(idx, int)].mean(axis=0)), nb, rf)

        rows = np.arange(e.shape[0])
        rms = np.sqrt(np.mean(e * e, axis=0))
        cen = f"OLS {rms[0]:.5f}, k-means {rms[nb]:.5f}"
        if with_random:
            cen += f", random median {np.median(rms[nb + 1 :]):.5f}"
        unit = "deg" if key.endswith("_deg") else h.input_unit
        goal = "RSS" if key.endswith("rss_goal") else h.goal_kind.upper()
        out.append(
            Claim.of(
                "C14",
                CLAIM_C14,
                "centres c_i influence performance more than Phi(.)",
                reading=reading,
                statistic="spread (max - min) of the leave-one-out RMS over Table 2 across centre choices "
                "- its spread across basis functions at newrb's centres (bootstrap over the rows), deg/h",
                estimate=verdicts.bootstrap([rows], stat, seed=seed),
                decided_by=(
                    f"input in {unit}, goal as {goal}; each fold's newrb fixes the neurons "
                    f"({int(run.neurons.min())}-{int(run.neurons.max())}) and the width",
                    "weights and bias refitted by least squares for every choice; k-means started at "
                    "evenly spaced quantiles; random subsets: the median RMS of "
                    f"{run.random.shape[1]} draws",
                ),
                ours=f"centres: {cen}; bases: " + ", ".join(f"{rms[j]:.5f}" for j in range(nb)),
                key=key,
                spec="{:.5f}",
            )
        )
    return out


# ---------------------------------------------------------------------------------------------------- C16
def latitude_share(latitude_error_deg, drift_deg_h, gain_deg_per_deg_h: float) -> float:
    """Eq. c16: the axial drift's share (%) of the summed squared 12 h latitude errors.

    Parameters
    ----------
    latitude_error_deg : array_like
        12 h latitude errors, deg.
    drift_deg_h : array_like
        The axial drifts, deg/h.
    gain_deg_per_deg_h : float
        The 12 h latitude error per deg/h of axial drift (Table 1).

    Returns
    -------
    float
        %.
    """
    dl, eps = np.asarray(latitude_error_deg, float), np.asarray(drift_deg_h, float)
    if dl.shape != eps.shape or dl.size < 1:
        raise InputError(f"latitude_share: {dl.size} latitude errors for {eps.size} drifts")
    a = gain_deg_per_deg_h * eps
    sa, so = float(a @ a), float((dl - a) @ (dl - a))
    if sa + so == 0:
        raise InputError("latitude_share: every latitude error and drift is zero")
    return 100.0 * sa / (sa + so)


def _per_row_shares(dl, eps, k) -> np.ndarray:
    a = k * np.asarray(eps, float)
    o = np.asarray(dl, float) - a
    with np.errstate(invalid="ignore"):
        s = 100.0 * a * a / (a * a + o * o)
    return np.where(np.isfinite(s), s, 0.0)


def latitude_share_claims(params: StudyParams = StudyParams()) -> list[Claim]:
    """C16's rows (eq. c16): Table 2 (primary), the median per-test share, Tables 2 and 3 together, the
    local latitude moved by half its last printed digit (the worse way), and the simulated hot tests (true
    by construction: their other sources are the sizes our simulator draws).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    list of navlib.claims.Claim
    """
    identify_h = fact("identify_h")
    k = ins.latitude_error_per_drift(identify_h, params.earth)
    x2, y2, x3, y3 = _hot_xy()
    seed = bootstrap_seed(params.sim.seed, "latitude_share")
    lat_text = f"{fact('local_latitude'):g}"
    half = 0.5 * 10.0 ** -(len(lat_text.split(".")[1]) if "." in lat_text else 0)

    def share(dl, eps):
        return latitude_share(dl, eps, k)

    def worse_shift(dl, eps):
        return min(latitude_share(dl + s, eps, k) for s in (-half, half))

    common = (
        f"Table 1's 12 h axial-drift gain {k:.3f} deg per deg/h (the paper's own propagation)",
        "the printed 'true' drift read as the axial drift; the rest of the latitude error charged to the "
        "other sources",
        f"latitude error = printed latitude - local {lat_text} deg (+-{half:g} in the shifted row)",
    )
    rows = [
        (
            "Table 2's 16 hot tests, pooled (eq. c16)",
            verdicts.bootstrap([x2, y2], share, seed=seed),
            "gyro_latitude_share",
            "real",
            (),
        ),
        (
            "median over Table 2's tests of each test's share",
            verdicts.bootstrap(
                [x2, y2], lambda dl, eps: float(np.median(_per_row_shares(dl, eps, k))), seed=seed
            ),
            "gyro_latitude_share_median",
            "real",
            (),
        ),
        (
            "Tables 2 and 3 together (19 hot tests), pooled",
            verdicts.bootstrap([np.r_[x2, x3], np.r_[y2, y3]], share, seed=seed),
            "gyro_latitude_share_t23",
            "real",
            (),
        ),
        (
            "local latitude moved by half its last printed digit, the worse way",
            verdicts.bootstrap([x2, y2], worse_shift, seed=seed),
            "gyro_latitude_share_shift",
            "real",
            (),
        ),
    ]
    sim = _simulated_hot_tests(params)
    sdl = np.array([r.latitude_error_12h_deg for r in sim])
    seps = np.array([r.final_drift_deg_h for r in sim])
    rows.append(
        (
            f"{sdl.size} simulated hot tests with Table 2's drifts and the chapter's residual errors",
            verdicts.bootstrap([sdl, seps], share, seed=seed),
            "gyro_latitude_share_sim",
            "simulated",
            ("residual errors drawn with the chapter's standard deviations (SimulationSettings)",),
        )
    )
    out = []
    for reading, est, key, data, extra in rows:
        sim_row = data == "simulated"
        out.append(
            Claim.of(
                "C16",
                CLAIM_C16,
                "12 h latitude error mainly caused by the axial drift",
                reading=reading,
                statistic="axial drift's share of the summed squared 12 h latitude errors, Table 1 gain "
                "times drift against the rest (bootstrap over the tests), %",
                estimate=est,
                by_construction=sim_row,
                why=(
                    "in simulation the other sources' part is set by the residual error sizes the book "
                    "chose for its simulator (horizontal gyro and accelerometer biases, tilt, azimuth, "
                    "gyro noise), not by anything measured; the measured Tables 2 and 3 decide"
                    if sim_row
                    else ""
                ),
                decided_by=common + extra,
                ours=f"{est.value:.1f} % over {est.n} tests",
                key=key,
                spec="{:.1f}",
            )
        )
    return out


# ---------------------------------------------------------------------------------------------------- C18
#: C18's horizontal unit sources, in the order of :func:`rotation_responses`' second axis.
HORIZONTAL_SOURCES = ("gyro x", "gyro y", "accel x", "accel y")


@dataclass(frozen=True)
class RotationResponses:
    """North and east position errors (m) over the navigation, per unit source: ``axial`` (2, K+1) for
    1 deg/h of axial drift; ``horizontal`` (P, 4, 2, K+1) per rotation phase (``P`` phases a step apart
    over one rotation cycle) and per :data:`HORIZONTAL_SOURCES` (1 deg/h of gyro drift, 1 ug of
    accelerometer bias, body frame)."""

    axial: np.ndarray
    horizontal: np.ndarray
    t_h: np.ndarray


def _cycle_s(rotation: ins.Rotation) -> float:
    if rotation.kind == "indexing":
        return len(rotation.positions_deg) * rotation.dwell_s
    if rotation.kind == "continuous" and rotation.rate_deg_s != 0:
        return 360.0 / abs(rotation.rate_deg_s)
    return 0.0


def rotation_responses(
    rotation: ins.Rotation = ins.Rotation(),
    *,
    earth: ins.Earth = ins.Earth(),
    duration_h: float = 72.0,
    start_h: float = 16.0,
    step_s: float = 60.0,
) -> RotationResponses:
    """Unit responses of :func:`navlib.sensors.ins.simulate` (zero initial errors, no noise), every phase and
    source propagated at once with the same exact step (``Phi``, ``Gamma`` of the augmented matrix
    exponential) and the same step-averaged rotation ``Rz(theta)``: body errors ``e^b`` enter as
    ``e^n = Rz(theta(t)) e^b``, the axial drift unmodulated.

    Parameters
    ----------
    rotation : navlib.sensors.ins.Rotation
    earth : navlib.sensors.ins.Earth
    duration_h : float
        Navigation time, h.
    start_h : float
        Hours since power-on at which the navigation starts (the rotation's phase there).
    step_s : float

    Returns
    -------
    RotationResponses
    """
    check_param("duration_h", duration_h, lo=0, lo_open=True)
    n = int(round(duration_h * 3600.0 / step_s))
    if n < 1:
        raise InputError(f"parameter duration_h={duration_h!r}: shorter than one step")
    cyc = _cycle_s(rotation)
    n_ph = max(1, int(round(cyc / step_s)))
    Phi, Gam = ins._discrete(earth, float(step_s))
    g, a = ins.DEG_H, ins.UG
    cols = []
    for p in range(n_ph):
        cs, sn = rotation.mean_cos_sin(start_h * 3600.0 + p * step_s, n, step_s)
        z = np.zeros(n)
        cols += [
            (cs * g, sn * g, z, z, z),
            (-sn * g, cs * g, z, z, z),
            (z, z, z, cs * a, sn * a),
            (z, z, z, -sn * a, cs * a),
        ]
    one = np.ones(n)
    cols.append((0 * one, 0 * one, g * one, 0 * one, 0 * one))
    u = np.stack([np.stack(c, axis=1) for c in cols])  # (C, n, 5)
    forced = u @ Gam.T  # (C, n, 7)
    x = np.zeros((u.shape[0], 7))
    pos = np.empty((n + 1, u.shape[0], 2))
    pos[0] = 0.0
    for k in range(n):
        x = x @ Phi.T + forced[:, k]
        pos[k + 1] = x[:, 5:7]
    ne = np.stack(
        [pos[..., 0] * earth.radius_m, pos[..., 1] * earth.radius_m * math.cos(earth.lat_rad)],
        axis=-1,
    )  # (n+1, C, 2)
    ne = np.moveaxis(ne, 0, -1)  # (C, 2, n+1)
    return RotationResponses(
        axial=ne[-1],
        horizontal=ne[:-1].reshape(n_ph, 4, 2, n + 1),
        t_h=np.arange(n + 1) * step_s / 3600,
    )


def rotation_shares(
    resp: RotationResponses,
    gyro_deg_h: float,
    accel_ug: float,
    n_runs: int,
    seed: np.random.SeedSequence | int,
) -> pd.DataFrame:
    """Eq. c18 per run: each run draws the rotation phase (uniform over the cycle's steps) and the signs of
    the two horizontal gyro drifts (size ``gyro_deg_h``, the axial drift's) and the two accelerometer
    biases (size ``accel_ug``).

    Parameters
    ----------
    resp : RotationResponses
    gyro_deg_h : float
        Size of the axial and of each horizontal gyro drift, deg/h.
    accel_ug : float
        Size of each horizontal accelerometer bias, ug.
    n_runs : int
    seed : numpy.random.SeedSequence or int

    Returns
    -------
    pandas.DataFrame
        One row per run: worst 72 h error (nmi) of the axial drift, the horizontal gyros and the
        accelerometers, each alone, and the axial share (%).
    """
    check_param("gyro_deg_h", gyro_deg_h, lo=0, lo_open=True)
    check_param("accel_ug", accel_ug, lo=0)
    check_param("n_runs", n_runs, lo=1, integer=True)
    rng = np.random.default_rng(seed)
    ph = rng.integers(0, resp.horizontal.shape[0], int(n_runs))
    sg = rng.choice([-1.0, 1.0], size=(int(n_runs), 4))
    h = resp.horizontal[ph]  # (runs, 4, 2, K+1)

    def worst(i, j, size):
        ne = sg[:, i, None, None] * h[:, i] + sg[:, j, None, None] * h[:, j]
        return size * np.hypot(ne[:, 0], ne[:, 1]).max(axis=1) / ins.NMI

    p_ax = np.full(int(n_runs), gyro_deg_h * np.hypot(*resp.axial).max() / ins.NMI)
    p_g, p_a = worst(0, 1, gyro_deg_h), worst(2, 3, accel_ug)
    return pd.DataFrame(
        {
            "axial drift (nmi)": p_ax,
            "horizontal gyros (nmi)": p_g,
            "accelerometers (nmi)": p_a,
            "axial share (%)": 100.0 * p_ax / (p_ax + p_g + p_a),
        }
    )


N_ROTATION_RUNS = 50


@lru_cache(maxsize=8)
def _responses(rotation: ins.Rotation, earth: ins.Earth, duration_h, start_h, step_s):
    return rotation_responses(
        rotation, earth=earth, duration_h=duration_h, start_h=start_h, step_s=step_s
    )


def equal_harm_accel_ug(params: StudyParams = StudyParams()) -> float:
    """The accelerometer bias (ug, both horizontal accelerometers, same signs) whose worst 72 h error
    *without* rotation equals that of the axial drift of ``params.sim.gyro_bias_sd_deg_h``: sources of the
    same size measured by the harm they do unmodulated."""
    p = params.sim.procedure()
    r = _responses(ins.Rotation(kind="none"), params.earth, p.navigate_h, 16.0, p.step_s)
    d = params.sim.gyro_bias_sd_deg_h
    acc = r.horizontal[0, 2] + r.horizontal[0, 3]
    return float(d * np.hypot(*r.axial).max() / np.hypot(*acc).max())


def rotation_claims(params: StudyParams = StudyParams()) -> list[Claim]:
    """C18's rows (eq. c18, median over ``N_ROTATION_RUNS`` runs): the chapter's indexing rotation with
    accelerometer biases at the chapter's budget ratio (primary); accelerometer biases of equal harm
    without rotation (:func:`equal_harm_accel_ug`); continuous rotation.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    list of navlib.claims.Claim
    """
    p = params.sim.procedure()
    start = p.align_h + p.identify_h
    d = params.sim.gyro_bias_sd_deg_h
    budget = params.sim.accel_bias_sd_ug
    seeds = _experiment_children(params.sim.seed, "rotation_share", 3)
    idx = ins.Rotation()
    cont = ins.Rotation(kind="continuous")
    out = []
    for (reading, rot, acc, key, extra), s in zip(
        (
            (
                "4-position indexing; horizontal gyros of the axial drift's size, accelerometers at the "
                "chapter's residual budget ratio",
                idx,
                budget,
                "gyro_rotation_axial",
                "accelerometer size: the ratio of the chapter's residual standard deviations (ours)",
            ),
            (
                "4-position indexing; accelerometers of equal harm without rotation",
                idx,
                equal_harm_accel_ug(params),
                "gyro_rotation_axial_equal_harm",
                "accelerometer size: the bias that, unrotated, does the axial drift's harm over 72 h",
            ),
            (
                "continuous rotation; accelerometers at the chapter's residual budget ratio",
                cont,
                budget,
                "gyro_rotation_axial_continuous",
                "accelerometer size: the chapter's residual budget ratio (ours)",
            ),
        ),
        seeds,
    ):
        r = _responses(rot, params.earth, p.navigate_h, start, p.step_s)
        df = rotation_shares(r, d, acc, N_ROTATION_RUNS, s)
        med = df.median()
        out.append(
            Claim.of(
                "C18",
                CLAIM_C18,
                "accuracy mainly determined by the axial gyro drift",
                reading=reading,
                statistic="axial drift's share of the summed worst 72 h position errors of the axial "
                "drift, the horizontal gyros and the accelerometers, each alone, rotation on (median over "
                "runs), %",
                estimate=verdicts.median_ci(df["axial share (%)"].to_numpy()),
                decided_by=(
                    "static-base error model (navlib.sensors.ins), zero initial errors, no noise; runs "
                    "draw the rotation phase and the horizontal instruments' signs",
                    extra,
                    f"sizes: each gyro {d:g} deg/h, each accelerometer {acc:.3g} ug; rotation "
                    f"{rot.kind}",
                ),
                ours=f"median worst 72 h: axial {med['axial drift (nmi)']:.2f}, gyros "
                f"{med['horizontal gyros (nmi)']:.3f}, accels {med['accelerometers (nmi)']:.3f} nmi",
                key=key,
                spec="{:.1f}",
            )
        )
    return out


def mechanism_claims(params: StudyParams = StudyParams()) -> list[Claim]:
    """C14, C16 and C18's rows (:func:`centre_claims`, :func:`latitude_share_claims`,
    :func:`rotation_claims`)."""
    return centre_claims(params) + latitude_share_claims(params) + rotation_claims(params)
