"""Kalman filtering of the INS/star-sensor system (paper E eq. 1-7), its gain features for the BP network
(section 2.1), and the innovation test that names a missing error state.

- :func:`star_measurement` -- paper E eq. 5-6: the platform misalignment ``Z = -M (att_INS - att_star)``
  with ``M`` of :func:`navlib.sensors.trajectory.euler_rate_matrix` (attitude order pitch, roll, yaw);
- :func:`kalman_filter` -- the standard discrete KF (eq. 7), batched over runs in numpy, covariance
  update in Joseph form (as filterpy 2.0.0's ``KalmanFilter.update``; tested against it to 1e-12);
- :func:`run_filter` -- the open-loop 15-state filter (or 18-state with gyro scale factors) on an
  :class:`navlib.sensors.strapdown.InsRun`, returning the corrected attitude's Euler errors;
- :func:`qr_features` / :func:`gain_features` -- the 6 non-zero entries of ``R`` in ``K = Q R`` (diagonal
  made non-negative), the 45 raw entries, and the 6 + 3 angular-rate variant;
- :func:`innovation_glr` -- a generalised-likelihood-ratio test (Willsky and Jones 1976) of the filter's
  innovations against the signature of each candidate unmodelled effect;
- :func:`innovation_structure_test` -- the generalised test (innovations regressed on the body rates and their
  derivatives), which names no candidate;
- :func:`innovation_loop` -- the decision rule (the workbench's loop applied to the filter): name a candidate
  only when adding its state removes the structure, otherwise say that the candidates do not explain it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace as replace_spec
from typing import Literal

import numpy as np
import pandas as pd
from scipy import stats

from ..angles import ARCSEC, DEG
from ..errors import InputError, check_param
from ..sensors.ins15 import N_BASE, discretise, process_noise, system_matrix
from ..sensors.strapdown import InsRun, misalignment, rotvec_to_dcm
from ..sensors.trajectory import dcm_to_euler, euler_rate_matrix

UG = 9.80665e-6


def wrap_rad(a):
    """Wrap angles (rad) to [-pi, pi)."""
    return np.mod(np.asarray(a, float) + np.pi, 2 * np.pi) - np.pi


def star_measurement(att_ins, att_star):
    """Paper E's measurement: ``Z = phi = -M(att_INS) (att_INS - att_star)`` (rad), attitudes ordered
    (pitch, roll, yaw), yaw difference wrapped.  First-order equal to the direction-cosine route
    :func:`navlib.sensors.strapdown.misalignment` (tested below 1e-3 arcsec for 10-arcsec errors)."""
    d = np.asarray(att_ins, float) - np.asarray(att_star, float)
    d[..., 2] = wrap_rad(d[..., 2])
    return -np.einsum("...ij,...j->...i", euler_rate_matrix(att_ins), d)


@dataclass(frozen=True)
class FilterSpec:
    """Initial 1-sigma uncertainties of the filter (they also set ``P_0``) and whether to carry the three
    gyro scale-factor states (the augmented filter)."""

    phi_level_arcsec: float = 20.0
    phi_azimuth_arcsec: float = 60.0
    vel_m_s: float = 0.1
    pos_m: float = 10.0
    drift_deg_h: float = 0.02
    bias_ug: float = 100.0
    scale_ppm: float = 300.0
    scale_states: bool = False
    candidates: tuple = ()

    def __post_init__(self):
        for f in (
            "phi_level_arcsec",
            "phi_azimuth_arcsec",
            "vel_m_s",
            "pos_m",
            "drift_deg_h",
            "bias_ug",
            "scale_ppm",
        ):
            check_param(f, getattr(self, f), lo=0.0, lo_open=True)
        c = self.candidates
        if (
            not isinstance(c, tuple)
            or len(set(c)) != len(c)
            or any(n not in CANDIDATES for n in c)
            or (self.scale_states and any(n.startswith("gyro") for n in c))
        ):
            raise InputError(
                f"parameter candidates={c!r}: a tuple of distinct names of {', '.join(CANDIDATES)}"
                " (no gyro scale factor with scale_states=True)"
            )

    @property
    def n_states(self) -> int:
        return N_BASE + (3 if self.scale_states else 0) + len(self.candidates)

    def p0(self, lat_rad: float) -> np.ndarray:
        r = 6.371e6
        sd = (
            [self.phi_level_arcsec * ARCSEC] * 2
            + [self.phi_azimuth_arcsec * ARCSEC]
            + [self.vel_m_s] * 3
        )
        sd += [self.pos_m / r, self.pos_m / (r * np.cos(lat_rad)), self.pos_m]
        sd += [self.drift_deg_h * DEG / 3600] * 3 + [self.bias_ug * UG] * 3
        if self.scale_states:
            sd += [self.scale_ppm * 1e-6] * 3
        sd += [self.scale_ppm * 1e-6] * len(self.candidates)  # one dimensionless scale factor each
        return np.diag(np.square(sd))


def kalman_filter(phi, q, h, z, r, x0, p0):
    """Discrete Kalman filter (paper E eq. 7), batched over runs, predict then update at each epoch::

        x- = Phi x,  P- = Phi P Phi^T + Q,  S = H P- H^T + R,  K = P- H^T S^-1,
        x = x- + K (z - H x-),  P = (I - K H) P- (I - K H)^T + K R K^T   (Joseph form).

    Parameters
    ----------
    phi : (n_runs, n_steps, d, d) transition matrices
    q : (d, d) or (n_runs, n_steps, d, d) process noise
    h : (m, d) measurement matrix
    z : (n_runs, n_steps, m) measurements
    r : (n_runs, n_steps, m, m) measurement noise
    x0, p0 : (d,), (d, d) initial state and covariance (same for every run)

    Returns
    -------
    dict of arrays (n_runs, n_steps, ...): ``x`` posterior, ``P`` posterior, ``K`` gain (d, m),
    ``x_prior``, ``innov`` (z - H x-), ``S`` innovation covariance.
    """
    phi, z, r = np.asarray(phi, float), np.asarray(z, float), np.asarray(r, float)
    n, steps, d = phi.shape[0], phi.shape[1], phi.shape[-1]
    m = h.shape[0]
    q = np.asarray(q, float)
    x = np.broadcast_to(np.asarray(x0, float), (n, d)).copy()
    p = np.broadcast_to(np.asarray(p0, float), (n, d, d)).copy()
    out = {
        "x": np.empty((n, steps, d)),
        "P": np.empty((n, steps, d, d)),
        "K": np.empty((n, steps, d, m)),
        "x_prior": np.empty((n, steps, d)),
        "innov": np.empty((n, steps, m)),
        "S": np.empty((n, steps, m, m)),
    }
    eye = np.eye(d)
    ht = h.T
    for k in range(steps):
        f = phi[:, k]
        qk = q if q.ndim == 2 else q[:, k]
        x = np.einsum("rij,rj->ri", f, x)
        p = f @ p @ np.swapaxes(f, 1, 2) + qk
        s = h @ p @ ht + r[:, k]
        kg = np.swapaxes(np.linalg.solve(s, (p @ ht).swapaxes(1, 2)), 1, 2)
        nu = z[:, k] - x @ ht
        out["x_prior"][:, k] = x
        x = x + np.einsum("rij,rj->ri", kg, nu)
        ikh = eye - kg @ h
        p = ikh @ p @ np.swapaxes(ikh, 1, 2) + kg @ r[:, k] @ np.swapaxes(kg, 1, 2)
        out["x"][:, k], out["P"][:, k], out["K"][:, k] = x, p, kg
        out["innov"][:, k], out["S"][:, k] = nu, s
    return out


@dataclass(frozen=True)
class FilterResult:
    """Output of :func:`run_filter` over epochs 1..N (epoch 0 is the initial state).

    ``att_err_arcsec``: Euler-angle errors (pitch, roll, yaw) of the filter-corrected attitude,
    ``ins_err_arcsec`` those of the uncorrected INS; ``phi_err`` the misalignment estimation error
    ``phi_true - phi_hat`` (rad); the raw filter output in ``kf``; ``phi`` the transition matrices."""

    t_s: np.ndarray
    att_err_arcsec: np.ndarray
    ins_err_arcsec: np.ndarray
    phi_err: np.ndarray
    rate_deg_s: np.ndarray
    kf: dict
    phi: np.ndarray
    spec: FilterSpec


def attitude_error_arcsec(cbn_est, att_true):
    """Euler-angle errors (pitch, roll, yaw) of an attitude estimate, arcsec (yaw wrapped)."""
    d = dcm_to_euler(cbn_est) - att_true
    d[..., 2] = wrap_rad(d[..., 2])
    return d / ARCSEC


def run_filter(run: InsRun, spec: FilterSpec = FilterSpec()) -> FilterResult:
    """Run the open-loop Kalman filter on every run of ``run``: transition from the INS outputs at each
    epoch (:func:`navlib.sensors.ins15.system_matrix`, second-order discretisation), measurement noise
    ``R = C_b^n diag(s_c^2, s_c^2, s_b^2) C_n^b`` (the star sensor's body-frame noise in n), measurement
    :func:`star_measurement`.  The corrected attitude is ``exp([phi_hat x]) C_ins``.  Each name in
    ``spec.candidates`` adds one constant state ``theta`` (prior ``scale_ppm``), the candidate of
    :data:`CANDIDATES` entering the state derivative through its column ``b_k`` (gyro scale factor about
    axis i: ``-C_b^n e_i w_i`` on ``phi``; accelerometer scale factor: ``+C_b^n e_i f_i`` on ``dv``)."""
    t = run.t_s
    period = float(t[1] - t[0])
    sl = slice(1, None)
    cw = run.cw_b[:, sl] if spec.scale_states else None
    F = system_matrix(run.pos[:, sl], run.vn[:, sl], run.fn[:, sl], run.cbn[:, sl], cw)
    if spec.candidates:
        d0 = F.shape[-1]
        F = np.pad(F, [(0, 0)] * (F.ndim - 2) + [(0, len(spec.candidates))] * 2)
        for j, name in enumerate(spec.candidates):
            field, col, sgn, row = CANDIDATES[name]
            F[..., row : row + 3, d0 + j] = sgn * getattr(run, field)[:, sl, :, col]
    phi = discretise(F, period)
    q = process_noise(run.imu, period, spec.n_states)
    h = np.zeros((3, spec.n_states))
    h[:, :3] = np.eye(3)
    z = star_measurement(run.att[:, sl], run.star_att[:, sl])
    rb = np.diag(run.star.noise_rad**2)
    c = run.cbn[:, sl]
    r = c @ rb @ np.swapaxes(c, -1, -2)
    p0 = spec.p0(float(run.pos[0, 0, 0]))
    kf = kalman_filter(phi, q, h, z, r, np.zeros(spec.n_states), p0)
    phi_hat = kf["x"][..., :3]
    c_est = rotvec_to_dcm(phi_hat) @ c
    att_true = run.att_true[:, sl]
    return FilterResult(
        t_s=t[sl],
        att_err_arcsec=attitude_error_arcsec(c_est, att_true),
        ins_err_arcsec=attitude_error_arcsec(c, att_true),
        phi_err=misalignment(c, run.cbn_true[:, sl]) - phi_hat,
        rate_deg_s=run.rate_b[:, sl] / DEG,
        kf=kf,
        phi=phi,
        spec=spec,
    )


# ------------------------------------------------------------------------------------------- gain features
def qr_features(K):
    """The 6 non-zero entries of ``R`` in the QR decomposition ``K = Q R`` of the (15 x 3) gain (paper E
    eq. 8), signs fixed so that ``R``'s diagonal is non-negative: ``[R11, R12, R13, R22, R23, R33]``.
    Batched over leading axes.  ``R^T R = K^T K`` holds whatever the signs."""
    K = np.asarray(K, float)
    if K.shape[-2:] != (K.shape[-2], 3) or K.shape[-2] < 3:
        raise InputError(f"qr_features: gain of shape {K.shape}, expected (..., d >= 3, 3)")
    r = np.linalg.qr(K, mode="r")
    sign = np.where(np.diagonal(r, axis1=-2, axis2=-1) < 0, -1.0, 1.0)
    r = r * sign[..., :, None]
    iu = np.triu_indices(3)
    return r[..., iu[0], iu[1]]


def r_from_features(feat):
    """The upper-triangular 3x3 ``R`` from the 6 features of :func:`qr_features`."""
    feat = np.asarray(feat, float)
    r = np.zeros(feat.shape[:-1] + (3, 3))
    iu = np.triu_indices(3)
    r[..., iu[0], iu[1]] = feat
    return r


FeatureSet = Literal["raw45", "qr6", "qr6_rate", "residual3"]
N_INPUTS = {"raw45": 45, "qr6": 6, "qr6_rate": 9, "residual3": 3}


def gain_features(result: FilterResult, kind: FeatureSet) -> np.ndarray:
    """Network inputs per epoch, shape (n_runs, n_epochs, n_in): ``raw45`` the 45 entries of the 15x3 gain
    (base states only), ``qr6`` its QR features, ``qr6_rate`` those plus the INS angular rates (deg/s);
    ``residual3`` the filter residual (the innovation, arcsec), the features paper E tried and rejected."""
    if kind not in N_INPUTS:
        raise InputError(f"parameter features={kind!r}: must be one of {', '.join(N_INPUTS)}")
    if kind == "residual3":
        return result.kf["innov"] / ARCSEC
    K = result.kf["K"][..., :N_BASE, :]
    if kind == "raw45":
        return K.reshape(K.shape[:-2] + (45,))
    f = qr_features(K)
    if kind == "qr6_rate":
        f = np.concatenate([f, result.rate_deg_s], -1)
    return f


# ------------------------------------------------------------------------------------------- innovation test
#: The candidate unmodelled effects: name -> (``InsRun`` field of ``C_b^n diag(.)``, body axis, sign, first
#: state row it drives: 0 for the attitude, 3 for the velocity).
CANDIDATES = {
    "gyro scale factor x": ("cw_b", 0, -1.0, 0),
    "gyro scale factor y": ("cw_b", 1, -1.0, 0),
    "gyro scale factor z": ("cw_b", 2, -1.0, 0),
    "accelerometer scale factor x": ("cf_b", 0, 1.0, 3),
    "accelerometer scale factor y": ("cf_b", 1, 1.0, 3),
    "accelerometer scale factor z": ("cf_b", 2, 1.0, 3),
}


def innovation_signatures(run: InsRun, result: FilterResult) -> dict[str, np.ndarray]:
    """For each candidate effect (a constant ``theta`` entering the state derivative through the column
    ``b_k``: gyro scale factor ``-C_b^n diag(w_ib^b)``, accelerometer scale factor ``+C_b^n diag(f^b)``),
    the innovations' response to ``theta = 1`` through the filter:
    ``e_k- = Phi_k (I - K_{k-1} H) e_{k-1}- + b_k T``, signature ``g_k = H e_k-`` (n_runs, n_steps, 3)."""
    kf = result.kf
    K = kf["K"]
    n, steps, d, m = K.shape
    period = float(result.t_s[1] - result.t_s[0])
    names = list(CANDIDATES)
    src = np.zeros((n, steps, len(names), d))  # b_k T, every candidate at once
    for j, name in enumerate(names):
        field, col, sgn, row = CANDIDATES[name]
        src[:, :, j, row : row + 3] = getattr(run, field)[:, 1:, :, col] * (sgn * period)
    e = np.zeros((n, len(names), d))
    g = np.empty((n, len(names), steps, m))
    for k in range(steps):
        e = np.einsum("rij,rcj->rci", result.phi[:, k], e) + src[:, k]
        g[:, :, k] = e[..., :3]
        e = e - np.einsum("rij,rcj->rci", K[:, k], g[:, :, k])
    return {name: g[:, j] for j, name in enumerate(names)}


@dataclass(frozen=True)
class GlrResult:
    """GLR statistics per candidate (chi-square with 1 dof under 'no missing effect'), their p-values, the
    Bonferroni-corrected verdict and the named effect (None if nothing is significant)."""

    table: pd.DataFrame
    named: str | None
    alpha: float


def _glr(sig: dict, nu: np.ndarray, s: np.ndarray, alpha: float) -> GlrResult:
    """The GLR table of :func:`innovation_glr` from signatures, innovations and their covariances."""
    sinv_nu = np.linalg.solve(s, nu[..., None])[..., 0]
    rows = []
    for name, g in sig.items():
        sinv_g = np.linalg.solve(s, g[..., None])[..., 0]
        info = float(np.sum(g * sinv_g))
        num = float(np.sum(g * sinv_nu))
        testable = info > 1e-6
        chi2 = num**2 / info if testable else np.nan
        rows.append(
            {
                "candidate": name,
                "testable": testable,
                "chi2": chi2,
                "estimate": num / info if testable else np.nan,
                "p_value": float(stats.chi2.sf(chi2, 1)) if testable else np.nan,
            }
        )
    df = pd.DataFrame(rows)
    n_test = max(int(df["testable"].sum()), 1)
    df["p_bonferroni"] = np.minimum(df["p_value"] * n_test, 1.0)
    df["significant"] = df["p_bonferroni"] < alpha
    sig_rows = df[df["significant"]]
    named = (
        None
        if sig_rows.empty
        else str(sig_rows.sort_values("chi2", ascending=False)["candidate"].iloc[0])
    )
    return GlrResult(table=df, named=named, alpha=alpha)


def innovation_glr(run: InsRun, result: FilterResult, alpha: float = 0.01) -> GlrResult:
    """Generalised likelihood ratio test of the filter's innovations ``nu_k`` (covariance ``S_k`` when the
    model is right) for each candidate's signature ``g_k`` (:func:`innovation_signatures`), pooled over
    runs::

        theta_hat = sum g^T S^-1 nu / sum g^T S^-1 g,    chi2 = (sum g^T S^-1 nu)^2 / sum g^T S^-1 g

    ``chi2 ~ chi2(1)`` if the effect is absent; p-values Bonferroni-corrected over the testable candidates
    (those whose signature is not numerically zero).  The named effect is the most significant one."""
    check_param("alpha", alpha, lo=0.0, lo_open=True, hi=0.5)
    return _glr(innovation_signatures(run, result), result.kf["innov"], result.kf["S"], alpha)


def innovation_glr_per_run(
    run: InsRun, result: FilterResult, alpha: float = 0.01
) -> list[GlrResult]:
    """The test of :func:`innovation_glr` on each run alone (the sums over one run's epochs): one
    :class:`GlrResult` per run, in run order, so that how often the test names an effect is a rate over
    independent runs."""
    check_param("alpha", alpha, lo=0.0, lo_open=True, hi=0.5)
    sig = innovation_signatures(run, result)
    nu, s = result.kf["innov"], result.kf["S"]
    return [
        _glr({k: g[i : i + 1] for k, g in sig.items()}, nu[i : i + 1], s[i : i + 1], alpha)
        for i in range(nu.shape[0])
    ]


def rate_correlation(result: FilterResult, axis: int = 2) -> tuple[float, float]:
    """Pearson correlation of the normalised innovation of one channel (default Up, the yaw channel) with
    the INS angular rate about the same body axis, pooled over runs, and its two-sided p-value (the
    innovations of a right model are white, so the usual t-test applies)."""
    nu = result.kf["innov"][..., axis] / np.sqrt(result.kf["S"][..., axis, axis])
    w = result.rate_deg_s[..., axis]
    if np.std(w) < 1e-9:
        return float("nan"), float("nan")
    r, p = stats.pearsonr(nu.ravel(), w.ravel())
    return float(r), float(p)


# ------------------------------------------------------------------------------------------- generalised test
@dataclass(frozen=True)
class StructureResult:
    """The generalised innovation test on one run: chi-square statistic with ``dof`` degrees of freedom,
    its p-value, whether it flags structure at ``alpha``, and the fitted coefficients (one per regressor)."""

    chi2: float
    dof: int
    p_value: float
    flagged: bool
    coef: np.ndarray
    z: np.ndarray | None = None
    alpha: float = 0.01

    def terms(self, names=None) -> tuple[str, ...]:
        """The regressors that carry the structure: those whose coefficient differs from zero on its own
        (``|z| = |b_j| / se_j`` beyond the two-sided normal quantile at ``alpha / p``, Bonferroni over the
        ``p`` regressors; ``se_j^2`` the diagonal of ``(A^T A)^-1``).  ``names`` default to
        :data:`REGRESSOR_NAMES`; empty when nothing is flagged."""
        if not self.flagged or self.z is None:
            return ()
        names = REGRESSOR_NAMES if names is None else names
        crit = stats.norm.isf(self.alpha / (2 * len(self.z)))
        return tuple(n for n, v in zip(names, self.z) if np.isfinite(v) and abs(v) > crit)


#: The regressors of :func:`rate_regressors` (body axes), in column order.
REGRESSOR_NAMES = tuple(f"rate {a}" for a in "xyz") + tuple(f"rate derivative {a}" for a in "xyz")


def rate_regressors(cbn: np.ndarray, rate_b: np.ndarray, t_s: np.ndarray) -> np.ndarray:
    """Regressors of the generalised test per epoch, shape (..., steps, 3, 6): the columns ``C_b^n e_i w_i``
    (the body rate about axis ``i`` seen in the navigation frame) and ``C_b^n e_i dw_i/dt`` (its time
    derivative, central differences), ``i = x, y, z``; rates in rad/s, derivatives in rad/s^2."""
    cbn, rate_b = np.asarray(cbn, float), np.asarray(rate_b, float)
    dw = np.gradient(rate_b, np.asarray(t_s, float), axis=-2)
    return np.concatenate([cbn * rate_b[..., None, :], cbn * dw[..., None, :]], axis=-1)


def innovation_structure_test(nu, s, x, alpha: float = 0.01) -> StructureResult:
    """Generalised innovation test: are the innovations ``nu_k`` (covariance ``S_k`` when the model is right)
    explained by the regressors ``X_k`` (3 x p per epoch, e.g. :func:`rate_regressors`)?  With the whitened
    ``u_k = L_k^-1 nu_k`` and ``A_k = L_k^-1 X_k`` (``S_k = L_k L_k^T``), stacked over the epochs,

        b = (A^T A)^-1 A^T u,    chi2 = u^T A (A^T A)^-1 A^T u  ~  chi2(p) if nothing is missing,

    and the test flags structure when ``P(chi2(p) > chi2) < alpha``.  Unlike :func:`innovation_glr` it
    names no candidate: it says that something proportional to the rates or their derivatives is missing
    from the model.  Shapes: ``nu (steps, 3)``, ``s (steps, 3, 3)``, ``x (steps, 3, p)``."""
    check_param("alpha", alpha, lo=0.0, lo_open=True, hi=0.5)
    nu, s, x = np.asarray(nu, float), np.asarray(s, float), np.asarray(x, float)
    if nu.ndim != 2 or nu.shape[1] != 3 or s.shape != nu.shape + (3,) or x.shape[:2] != nu.shape:
        raise InputError(
            f"innovation_structure_test: shapes nu {nu.shape}, S {s.shape}, X {x.shape}; "
            "expected (steps, 3), (steps, 3, 3), (steps, 3, p)"
        )
    chol = np.linalg.cholesky(s)
    u = np.linalg.solve(chol, nu[..., None])[..., 0].reshape(-1)
    a = np.linalg.solve(chol, x).reshape(-1, x.shape[-1])
    coef, *_ = np.linalg.lstsq(a, u, rcond=None)
    fit = a @ coef
    chi2 = float(fit @ fit)
    p = int(np.linalg.matrix_rank(a))
    pv = float(stats.chi2.sf(chi2, p)) if p else 1.0
    se = np.sqrt(np.clip(np.diag(np.linalg.pinv(a.T @ a)), 0.0, None))
    z = np.divide(coef, se, out=np.full_like(coef, np.nan), where=se > 0)
    return StructureResult(chi2, p, pv, bool(pv < alpha), coef, z, alpha)


def innovation_structure_per_run(
    run: InsRun, result: FilterResult, alpha: float = 0.01
) -> list[StructureResult]:
    """:func:`innovation_structure_test` of the filter's innovations on each run alone, regressed on the
    INS's body rates and their derivatives (:func:`rate_regressors`)."""
    x = rate_regressors(run.cbn[:, 1:], result.rate_deg_s * DEG, result.t_s)
    nu, s = result.kf["innov"], result.kf["S"]
    return [innovation_structure_test(nu[i], s[i], x[i], alpha) for i in range(nu.shape[0])]


# ------------------------------------------------------------------------------------------- the loop
#: The loop's answer when neither test finds anything.
NOTHING = "nothing missing"
#: The loop's answer when structure is left that no candidate's state removes.
NOT_EXPLAINED = "not explained by the candidates"


@dataclass(frozen=True)
class LoopDecision:
    """The decision rule on one run (:func:`innovation_loop`).

    ``named_by_test``: what the candidate test names (None: nothing significant); ``flagged``: the
    generalised test on the filter as it is; ``tried``: the candidate whose state was added (the test's
    name), ``flagged_after``: the generalised test on the filter with that state (None if nothing was
    tried); ``decision``: the candidate's name, :data:`NOT_EXPLAINED` or :data:`NOTHING`; ``remains``: the
    regressors that carry the structure left (``StructureResult.terms``), ``message`` one line."""

    named_by_test: str | None
    flagged: bool
    chi2: float
    tried: str | None
    flagged_after: bool | None
    chi2_after: float | None
    decision: str
    remains: tuple
    message: str


def _take(run: InsRun, idx) -> InsRun:
    """The runs ``idx`` of ``run`` (every per-run array indexed on its first axis)."""
    return replace_spec(
        run,
        **{
            f.name: getattr(run, f.name)[idx]
            for f in fields(run)
            if isinstance(getattr(run, f.name), np.ndarray) and getattr(run, f.name).ndim >= 2
        },
    )


def innovation_loop(run: InsRun, result: FilterResult, alpha: float = 0.01) -> list[LoopDecision]:
    """The workbench's loop (:func:`navlib.workbench.diagnose.diagnose`) applied to the filter, on each run
    alone: name what is missing, add the state, check what is left, and say so when nothing in the
    catalogue fits.

    1. the candidate test (:func:`innovation_glr_per_run`, Bonferroni at ``alpha``) names the most
       significant of :data:`CANDIDATES`, or none;
    2. the generalised test (:func:`innovation_structure_per_run`, ``alpha``) looks for structure in the
       rates and their derivatives, whatever its cause;
    3. if a candidate is named, the filter is run again with that candidate's state
       (``FilterSpec.candidates``) and the generalised test repeated at the same ``alpha``.  The filter's
       innovations are one-step-ahead predictions, each made before its measurement enters the filter, so
       this is the augmented model's held-out check.  The candidate is named only if no structure is
       left (as the workbench names a candidate only when the structure the residual showed is gone);

    otherwise the answer is :data:`NOT_EXPLAINED`, with the regressors that carry the structure left (on
    the augmented filter if a candidate was tried, else on the filter as it is), or :data:`NOTHING` when
    neither test finds anything.  Returns one :class:`LoopDecision` per run, in run order."""
    check_param("alpha", alpha, lo=0.0, lo_open=True, hi=0.5)
    named = [g.named for g in innovation_glr_per_run(run, result, alpha)]
    base = innovation_structure_per_run(run, result, alpha)
    after: dict[int, StructureResult] = {}
    for cand in sorted({n for n in named if n is not None}):
        idx = np.array([i for i, n in enumerate(named) if n == cand])
        spec = replace_spec(result.spec, candidates=result.spec.candidates + (cand,))
        sub = _take(run, idx)
        for i, r in zip(idx, innovation_structure_per_run(sub, run_filter(sub, spec), alpha)):
            after[int(i)] = r
    out = []
    for i, (nm, b) in enumerate(zip(named, base)):
        a = after.get(i)
        if nm is not None and not a.flagged:
            decision, remains = nm, ()
            msg = (
                f"add '{nm}': with its state the innovations show no structure (chi2 {a.chi2:.1f}, "
                f"{a.dof} dof" + (f"; before {b.chi2:.1f})" if b.flagged else ")")
            )
        elif nm is None and not b.flagged:
            decision, remains = NOTHING, ()
            msg = (
                "the innovations are consistent with the filter's model: no candidate, no structure"
            )
        else:
            left = a if a is not None else b
            decision, remains = NOT_EXPLAINED, left.terms()
            msg = (
                f"{NOT_EXPLAINED}: structure in the {', '.join(remains) or 'rates and their derivatives'}"
                + (
                    f" remains after adding '{nm}'"
                    if nm is not None
                    else "; no candidate is significant"
                )
                + f" (chi2 {left.chi2:.1f}, {left.dof} dof)"
            )
        out.append(
            LoopDecision(
                nm,
                b.flagged,
                b.chi2,
                nm,
                None if a is None else a.flagged,
                None if a is None else a.chi2,
                decision,
                remains,
                msg,
            )
        )
    return out
