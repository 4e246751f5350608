"""Data preparation of patent B (ELM compass compensation), "second" to "fifth step".

Patent text (our translation):

- second step: "using the invariance of the geomagnetic and gravity vectors at one site, design a sliding
  median filter to pre-process the measured data; discard data whose geomagnetic-vector / gravity-vector
  inner product is abnormal, reducing magnetometer and accelerometer noise and random-error
  interference" -> :func:`median_filter`, :func:`dot_product_screen` / :func:`reject_dot_product_outliers`;
- third step: "normalise the raw data by the max-min method" -> :class:`navlib.methods.scaling.MinMax`;
- fourth/fifth step: "randomly draw 90 % of the training set ... the remaining 10 % are the test set"
  -> :func:`train_test_split`.

The patent gives no window length, no rule for "abnormal" and no split seed: those are parameters here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..errors import InputError, check_param

__all__ = [
    "MEDIAN_MODES",
    "median_filter",
    "field_gravity_dot",
    "DotScreen",
    "dot_product_screen",
    "reject_dot_product_outliers",
    "train_test_split",
    "MAD_TO_SIGMA",
]

MEDIAN_MODES = ("nearest", "reflect", "mirror", "wrap", "closed")
MAD_TO_SIGMA = 1.482602218505602  # 1 / Phi^-1(3/4): MAD of a normal sample * this = sigma


def median_filter(values, window: int, *, mode: str = "nearest") -> np.ndarray:
    """Sliding median over ``window`` consecutive samples (patent, second step), each column of a 2-D
    array filtered separately along axis 0 (samples).  ``scipy.ndimage.median_filter`` does the work.

    ``window`` must be odd (a centred window); 1 returns a copy.  ``mode`` sets how the ends are padded:

    - ``'nearest'`` (default): repeat the end samples (a straight line sweep, e.g. unwrapped heading);
    - ``'reflect'``, ``'mirror'``: scipy's reflections;
    - ``'wrap'``: periodic with period n (the sweep's last sample is followed by its first);
    - ``'closed'``: a full revolution sampled *including both ends*, as in the 0..360 deg, 121-point
      turntable sweeps: the last sample is the first orientation again, so the ring has period n - 1;
      the window of sample 0 reaches back to samples n-2, n-3, ... and that of sample n-1 forward to
      1, 2, ...  (the two readings at 0 and 360 deg are filtered separately).

    Use the periodic modes only for quantities that are periodic over the sweep (field components,
    gravity components, heading error), never for the unwrapped heading itself, which jumps by 360 deg.
    """
    check_param("window", window, lo=1, integer=True)
    window = int(window)
    if window % 2 == 0:
        raise InputError(f"parameter window={window}: must be odd (a centred window)")
    if mode not in MEDIAN_MODES:
        raise InputError(f"parameter mode={mode!r}: must be one of {', '.join(MEDIAN_MODES)}")
    v = np.asarray(values, dtype=float)
    if v.ndim not in (1, 2) or v.shape[0] == 0:
        raise InputError(f"values: need a non-empty 1-D or 2-D array, got shape {v.shape}")
    n, half = v.shape[0], window // 2
    size = (window,) + (1,) * (v.ndim - 1)
    if mode == "closed":
        if n - 1 < window:
            raise InputError(
                f"parameter window={window}: a closed sweep of {n} samples needs window <= {n - 1}"
            )
        padded = np.concatenate([v[n - 1 - half : n - 1], v, v[1 : half + 1]], axis=0)
        return ndimage.median_filter(padded, size=size, mode="nearest")[half : half + n]
    if mode == "wrap" and n < window:
        raise InputError(
            f"parameter window={window}: a periodic sweep of {n} samples needs window <= {n}"
        )
    return ndimage.median_filter(v, size=size, mode=mode)


def field_gravity_dot(mag_xyz, grav_xyz, *, normalize: bool = False) -> np.ndarray:
    """Per-sample inner product m . g of the measured field (N x 3) and gravity (N x 3), both in the
    sensor frame.  At one site the angle between the geomagnetic and gravity vectors (90 deg + magnetic
    dip) is fixed, so ``m . g = |m| |g| sin(dip)`` is invariant under any rotation of the sensor (patent,
    second step; the "dot-product invariance" constraint).  ``normalize=True`` returns the cosine of
    the angle between them instead (insensitive to magnitude errors of either sensor)."""
    m = np.asarray(mag_xyz, dtype=float)
    g = np.asarray(grav_xyz, dtype=float)
    if m.ndim != 2 or m.shape[1] != 3 or m.shape[0] == 0:
        raise InputError(f"mag_xyz: need an N x 3 array, got shape {m.shape}")
    if g.shape != m.shape:
        raise InputError(f"grav_xyz: shape {g.shape} differs from mag_xyz {m.shape}")
    dot = np.einsum("ij,ij->i", m, g)
    if normalize:
        with np.errstate(invalid="ignore", divide="ignore"):
            dot = dot / (np.linalg.norm(m, axis=1) * np.linalg.norm(g, axis=1))
    return dot


@dataclass(frozen=True)
class DotScreen:
    """Result of :func:`dot_product_screen`: the statistic per sample, its robust centre and scale, the
    acceptance band ``center +- threshold * scale`` and the keep mask (True = clean reading)."""

    dot: np.ndarray
    center: float
    scale: float
    threshold: float
    keep: np.ndarray

    @property
    def band(self) -> tuple[float, float]:
        return self.center - self.threshold * self.scale, self.center + self.threshold * self.scale

    @property
    def n_rejected(self) -> int:
        return int(np.size(self.keep) - np.count_nonzero(self.keep))


def dot_product_screen(
    mag_xyz, grav_xyz, *, threshold: float = 4.0, normalize: bool = False, min_scale: float = 0.0
) -> DotScreen:
    """Flag readings whose field-gravity inner product is abnormal (patent, second step: "discard data
    whose geomagnetic/gravity inner product is abnormal").

    "Abnormal" is our rule (the patent gives none): robust z-score with the median and the median
    absolute deviation, which a few glitches cannot drag::

        s_n = m_n . g_n,   c = median(s),   scale = max(1.4826 median|s - c|, min_scale),
        keep_n  <=>  |s_n - c| <= threshold * scale   (and s_n finite).

    The default ``threshold`` 4 keeps every reading of a normal sample with probability 1 - 6e-5 and
    every reading of a bounded (e.g. sinusoidal, amplitude A) variation, whose 1.4826 MAD is about A.
    ``min_scale`` (units of s) guards against a zero MAD when the clean readings are identical.
    """
    check_param("threshold", threshold, lo=0, lo_open=True)
    check_param("min_scale", min_scale, lo=0)
    s = field_gravity_dot(mag_xyz, grav_xyz, normalize=normalize)
    finite = np.isfinite(s)
    if not finite.any():
        raise InputError("mag_xyz/grav_xyz: no finite field-gravity inner product")
    c = float(np.median(s[finite]))
    scale = max(MAD_TO_SIGMA * float(np.median(np.abs(s[finite] - c))), float(min_scale))
    with np.errstate(invalid="ignore"):
        keep = finite & (np.abs(s - c) <= threshold * scale)
    return DotScreen(dot=s, center=c, scale=scale, threshold=float(threshold), keep=keep)


def reject_dot_product_outliers(
    mag_xyz, grav_xyz, *, threshold: float = 4.0, normalize: bool = False, min_scale: float = 0.0
) -> np.ndarray:
    """Boolean keep-mask (True = clean) of :func:`dot_product_screen`."""
    return dot_product_screen(
        mag_xyz, grav_xyz, threshold=threshold, normalize=normalize, min_scale=min_scale
    ).keep


def train_test_split(n: int, frac: float = 0.9, rng=None) -> tuple[np.ndarray, np.ndarray]:
    """Random split of sample indices 0..n-1 into a training set with round(frac n) samples and a test
    set with the rest (patent, fourth and fifth steps: random 90 % / 10 %).  Both sets keep at least one
    sample.  Returns ``(train_idx, test_idx)``, each sorted ascending (so a sweep keeps its order).

    ``rng``: a ``numpy.random.Generator`` or an int seed (``None``: unseeded)."""
    check_param("n", n, lo=2, integer=True)
    check_param("frac", frac, lo=0, hi=1, lo_open=True, hi_open=True)
    if not isinstance(rng, np.random.Generator):
        if rng is not None:
            check_param("seed", rng, lo=0, integer=True)
            rng = int(rng)
        rng = np.random.default_rng(rng)
    n = int(n)
    n_train = min(max(int(round(frac * n)), 1), n - 1)
    perm = rng.permutation(n)
    return np.sort(perm[:n_train]), np.sort(perm[n_train:])
