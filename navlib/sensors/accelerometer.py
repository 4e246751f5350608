"""Quartz-flexure (pendulous) accelerometer on a dividing head in a temperature chamber: the IEEE Std 1293
tumble test of paper D (Fu Hongpo et al., Beijing Institute of Aerospace Control Devices).

Model (IEEE Std 1293-1998 static model, pendulous accelerometer; ``a_i`` along the input axis, ``a_p``
along the pendulum axis, both in g)::

    U / K1_nom = K0(T) + (1 + kappa(T)) (1000 a_i + K2(T) a_i^2 + Kip a_i a_p + delta_o a_p) + noise   [mg]

with the dividing head at angle ``q``: ``a_i = cos q``, ``a_p = sin q`` (1 g, input axis in the plane of
rotation).  The output is expressed in mg (output divided by the nominal scale factor), so a perfect sensor
reads ``1000 cos q`` mg.  Temperature dependence (``dT = T - T_ref``, ``T_ref`` = 55 degC, paper D 2.1):

- bias ``K0(T) = K0c + b1 dT + b2 dT^2 + b3 dT^3 + s (tanh((T - T_s)/w) - tanh((T_ref - T_s)/w))`` mg;
  the tanh step is a stand-in for non-polynomial behaviour (e.g. stress relief in the bonding adhesive) so
  that a cubic does not describe the sensor exactly; set its height to 0 for a purely polynomial sensor;
- relative scale-factor deviation ``kappa(T) = k1 dT + k2 dT^2`` (magnet and coil temperature
  coefficients; the quartz expansion, < 1e-6 /degC, is neglected as in the paper);
- second-order coefficient ``K2(T) = K2c + k2t dT`` mg/g^2: this makes the apparent scale factor
  ``(U(a) - K0)/a`` depend on the input as the paper observes (its Fig 4: K1 = g(T, a)).

Thermal lag: the sensor temperature follows the chamber set point with a first-order lag (time constant
``lag_tau_min``); readings start after a soak of ``soak_min`` and one position takes ``dwell_min``, so the
recorded temperature of each reading differs from the set point by the residual lag (a few tenths of a
degree with the defaults, the paper's "0.1..0.5 degC").  The internal temperature sensor that the model uses
is this lagged temperature.  White noise ``noise_ug`` (1 sigma per averaged reading) is added.

Defaults and their story: against 55 degC over -40..70 degC the 0/180 deg bias test drifts 1.68 mg, the
scale factor up to 5.6 mg/g (input-dependent), the output up to 5.8 mg (paper D: 1.7 mg, 6 mV/g, 5 mV; the
three cannot all hold at once under this model, because at +-1 g the bias and scale-factor drifts add in one
direction); noise 3 ug per reading (a 10 s average of a 10 ug/sqrt(Hz) sensor); second unit of the same
batch: every coefficient scaled by ``1 + spread N(0, 1)`` with ``batch_spread_rel`` = 0.25.  The stored data
set (:func:`paper_units`, ``data/accel_tumble.csv``) uses batch seed 2, picked because its maximum output drift,
6.75 mg, is the nearest to the paper's 7.21 mg among seeds 1-11; the chapter's study does not pick: it draws
unit B afresh for every seed (:func:`navlib.studies.accelerometer.simulation.simulate`) and reports the spread
of the drifts.

The Fourier coefficients of one tumble (``q`` over 24 equally spaced positions) give, with ``K1 = 1 + kappa``
(see :func:`tumble_fourier` and :func:`coefficients_from_fourier`)::

    A0 = K0 + K1 K2/2,  A1 = 1000 K1,  B1 = K1 delta_o,  A2 = K1 K2/2,  B2 = K1 Kip/2.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ..data.tables import write_new_csv
from ..errors import InputError, check_param
from ..seeding import child

#: The paper's reference (normal operating) temperature, degC.
T_REF_C = 55.0


@dataclass(frozen=True)
class AccelCoefficients:
    """Temperature model of one accelerometer (see the module docstring for the equation).

    Units are in the names: ``mg``, ``per_c`` (relative per degC), ``mg_g2`` (mg per g^2)."""

    k0c_mg: float = 0.8  # bias at 55 degC
    bias_lin_mg_c: float = 0.0175  # b1
    bias_quad_mg_c2: float = 2.0e-5  # b2
    bias_cub_mg_c3: float = 2.0e-7  # b3
    bias_step_mg: float = 0.12  # height s of the tanh step
    bias_step_c: float = 10.0  # its centre T_s
    bias_step_width_c: float = 8.0  # its width w
    sf_lin_per_c: float = -4.2e-5  # k1 (relative scale-factor change per degC)
    sf_quad_per_c2: float = 1.5e-8  # k2
    k2c_mg_g2: float = 0.02  # K2 at 55 degC (20 ug/g^2)
    k2_temp_mg_g2_c: float = -0.002  # k2t (K2 change per degC)
    kip_mg_g2: float = 0.03  # cross-coupling Kip (30 ug/g^2)
    delta_o_mg: float = 0.2  # misalignment delta_o (0.2 mrad = 0.2 mg per g of a_p)

    def __post_init__(self):
        for name in self.__dataclass_fields__:
            check_param(name, getattr(self, name))
        check_param("bias_step_width_c", self.bias_step_width_c, lo=0, lo_open=True)
        check_param("k0c_mg", self.k0c_mg, lo=-50, hi=50)

    def bias_mg(self, temperature_c) -> np.ndarray:
        """``K0(T)`` in mg."""
        t = np.asarray(temperature_c, float)
        d = t - T_REF_C
        w = self.bias_step_width_c
        step = np.tanh((t - self.bias_step_c) / w) - np.tanh((T_REF_C - self.bias_step_c) / w)
        return (
            self.k0c_mg
            + self.bias_lin_mg_c * d
            + self.bias_quad_mg_c2 * d**2
            + self.bias_cub_mg_c3 * d**3
            + self.bias_step_mg * step
        )

    def scale_factor(self, temperature_c) -> np.ndarray:
        """``K1(T) = 1 + kappa(T)`` relative to the nominal scale factor."""
        d = np.asarray(temperature_c, float) - T_REF_C
        return 1.0 + self.sf_lin_per_c * d + self.sf_quad_per_c2 * d**2

    def second_order_mg_g2(self, temperature_c) -> np.ndarray:
        """``K2(T)`` in mg/g^2."""
        d = np.asarray(temperature_c, float) - T_REF_C
        return self.k2c_mg_g2 + self.k2_temp_mg_g2_c * d

    def output_mg(self, temperature_c, position_deg) -> np.ndarray:
        """Noise-free output (mg) at sensor temperature ``T`` and dividing-head angle ``q`` (deg)."""
        q = np.deg2rad(np.asarray(position_deg, float))
        ai, ap = np.cos(q), np.sin(q)
        k1 = self.scale_factor(temperature_c)
        return self.bias_mg(temperature_c) + k1 * (
            1000.0 * ai
            + self.second_order_mg_g2(temperature_c) * ai**2
            + self.kip_mg_g2 * ai * ap
            + self.delta_o_mg * ap
        )

    def batch_member(
        self, spread_rel: float, seed: int | np.random.SeedSequence
    ) -> "AccelCoefficients":
        """Another unit of the same batch: every temperature coefficient (and the bias, K2, Kip, delta_o at
        55 degC) multiplied by ``1 + spread_rel z`` with ``z ~ N(0, 1)`` drawn from ``seed`` (an integer
        entropy or a ``SeedSequence``); the step position and width stay (same construction).  The same
        ``seed`` gives the same ``z`` at every spread, so a sweep of ``spread_rel`` scales one unit's
        deviation from this one."""
        check_param("batch_spread_rel", spread_rel, lo=0, hi=1)
        rng = np.random.default_rng(child(seed))
        names = [
            n for n in self.__dataclass_fields__ if n not in ("bias_step_c", "bias_step_width_c")
        ]
        f = 1.0 + spread_rel * rng.standard_normal(len(names))
        return replace(self, **{n: getattr(self, n) * fi for n, fi in zip(names, f)})


@dataclass(frozen=True)
class TumbleExperiment:
    """The paper's experiment: chamber set points ``t_start_c..t_stop_c`` every ``t_step_c`` (23 points for
    -40..70 by 5), an ``n_positions``-position tumble at each (24), white noise ``noise_ug`` per reading,
    first-order thermal lag (``lag_tau_min``) after a ``soak_min`` soak, ``dwell_min`` per position.  The
    chamber starts at ``start_chamber_c`` before the first set point.  ``lag_tau_min = 0`` means the sensor
    is exactly at the set point."""

    t_start_c: float = -40.0
    t_stop_c: float = 70.0
    t_step_c: float = 5.0
    n_positions: int = 24
    noise_ug: float = 3.0
    lag_tau_min: float = 8.0
    soak_min: float = 30.0
    dwell_min: float = 1.0
    start_chamber_c: float = 25.0
    reference_c: float = T_REF_C

    def __post_init__(self):
        check_param("t_start_c", self.t_start_c, lo=-60, hi=130)
        check_param("t_stop_c", self.t_stop_c, lo=-60, hi=130)
        check_param("t_step_c", self.t_step_c, lo=0.5, hi=100)
        if self.t_stop_c <= self.t_start_c:
            raise InputError(
                f"parameter t_stop_c={self.t_stop_c!r}: must be above t_start_c={self.t_start_c!r}"
            )
        check_param("n_positions", self.n_positions, lo=4, hi=360, integer=True)
        if 360 % int(self.n_positions):
            raise InputError(
                f"parameter n_positions={self.n_positions!r}: must divide 360 (whole-degree grid)"
            )
        check_param("noise_ug", self.noise_ug, lo=0, hi=10000)
        check_param("lag_tau_min", self.lag_tau_min, lo=0, hi=600)
        check_param("soak_min", self.soak_min, lo=0, hi=1440)
        check_param("dwell_min", self.dwell_min, lo=0, hi=60)
        check_param("start_chamber_c", self.start_chamber_c, lo=-60, hi=130)
        if not np.any(np.isclose(self.set_points_c, self.reference_c)):
            raise InputError(
                f"parameter reference_c={self.reference_c!r}: must be one of the set points "
                f"{self.t_start_c:g}..{self.t_stop_c:g} step {self.t_step_c:g}"
            )
        if self.set_points_c.size < 3:
            raise InputError(
                "parameters t_start_c..t_stop_c step t_step_c: fewer than 3 temperatures"
            )

    @property
    def set_points_c(self) -> np.ndarray:
        n = int(np.floor((self.t_stop_c - self.t_start_c) / self.t_step_c + 1e-9)) + 1
        return self.t_start_c + self.t_step_c * np.arange(n)

    @property
    def positions_deg(self) -> np.ndarray:
        return np.arange(self.n_positions) * (360.0 / self.n_positions)


def sensor_temperatures_c(exp: TumbleExperiment) -> np.ndarray:
    """Sensor temperature of every reading, ``(n_set_points, n_positions)``: first-order lag toward each set
    point, starting from the previous point's final temperature (the chamber's start temperature first)."""
    sp = exp.set_points_c
    t_read = exp.soak_min + exp.dwell_min * np.arange(exp.n_positions)  # minutes after the step
    out = np.empty((sp.size, exp.n_positions))
    prev = exp.start_chamber_c
    for k, s in enumerate(sp):
        decay = np.exp(-t_read / exp.lag_tau_min) if exp.lag_tau_min > 0 else np.zeros_like(t_read)
        out[k] = s + (prev - s) * decay
        last = exp.soak_min + exp.dwell_min * exp.n_positions
        prev = s + (prev - s) * (np.exp(-last / exp.lag_tau_min) if exp.lag_tau_min > 0 else 0.0)
    return out


def simulate_tumble(
    coef: AccelCoefficients,
    exp: TumbleExperiment,
    seed: int | np.random.SeedSequence,
    unit: str = "A",
) -> pd.DataFrame:
    """One unit's multi-position full-temperature test: a tidy frame with ``set_point_c``, ``temperature_c``
    (the sensor's, lagged), ``position_deg``, ``output_mg`` (noisy), ``true_output_mg`` (noise-free) and
    ``unit``; 552 rows for the paper's experiment.  Noise from ``np.random.SeedSequence(seed)`` (or from
    ``seed`` itself when it is a ``SeedSequence``)."""
    if not str(unit).strip():
        raise InputError("parameter unit='': give the unit a name")
    rng = np.random.default_rng(child(seed))
    temps = sensor_temperatures_c(exp)
    pos = np.broadcast_to(exp.positions_deg, temps.shape)
    sp = np.broadcast_to(exp.set_points_c[:, None], temps.shape)
    true = coef.output_mg(temps, pos)
    noisy = true + 1e-3 * exp.noise_ug * rng.standard_normal(true.shape)
    return pd.DataFrame(
        {
            "set_point_c": sp.ravel(),
            "temperature_c": temps.ravel(),
            "position_deg": pos.ravel(),
            "output_mg": noisy.ravel(),
            "true_output_mg": true.ravel(),
            "unit": str(unit),
        }
    )


def bias_test(
    coef: AccelCoefficients, exp: TumbleExperiment, seed: int | np.random.SeedSequence
) -> pd.DataFrame:
    """The 0/180 deg bias test at each set point: ``(U(0) + U(180))/2 = K0 + K1 K2`` (the second-order term
    stays in: this is what the paper's bias test measures).  Columns ``set_point_c``, ``temperature_c``,
    ``bias_mg`` (measured), ``true_bias_mg`` (the same test without noise).  ``seed``: an integer entropy
    or a ``SeedSequence``."""
    rng = np.random.default_rng(child(seed))
    temps = sensor_temperatures_c(exp)[:, 0]
    u = coef.output_mg(temps[:, None], np.array([0.0, 180.0])[None, :])
    noisy = u + 1e-3 * exp.noise_ug * rng.standard_normal(u.shape)
    return pd.DataFrame(
        {
            "set_point_c": exp.set_points_c,
            "temperature_c": temps,
            "bias_mg": noisy.mean(axis=1),
            "true_bias_mg": u.mean(axis=1),
        }
    )


# ------------------------------------------------------------------------------------- Fourier analysis
FOURIER_TERMS = ("A0", "A1", "B1", "A2", "B2", "A3", "B3")


def tumble_fourier(position_deg, output_mg) -> dict:
    """Least-squares Fourier coefficients of one tumble, ``U(q) = A0 + sum_k (Ak cos kq + Bk sin kq)``,
    k = 1..3 (IEEE Std 1293 Annex on multi-position tests); needs at least 7 distinct positions."""
    q = np.deg2rad(np.asarray(position_deg, float))
    u = np.asarray(output_mg, float)
    if np.unique(np.round(q, 9)).size < 7:
        raise InputError(
            f"tumble Fourier fit: {np.unique(np.round(q, 9)).size} distinct positions, needs >= 7"
        )
    X = np.column_stack([np.ones_like(q)] + [f(k * q) for k in (1, 2, 3) for f in (np.cos, np.sin)])
    c, *_ = np.linalg.lstsq(X, u, rcond=None)
    return dict(zip(FOURIER_TERMS, c))


def coefficients_from_fourier(f: dict) -> dict:
    """IEEE 1293 coefficients from the Fourier terms: ``K1 = A1/1000``, ``K2 = 2 A2/K1`` (mg/g^2),
    ``K0 = A0 - A2`` (mg), ``Kip = 2 B2/K1`` (mg/g^2), ``delta_o = B1/K1`` (mg/g)."""
    k1 = f["A1"] / 1000.0
    return {
        "k0_mg": f["A0"] - f["A2"],
        "k1": k1,
        "k2_mg_g2": 2 * f["A2"] / k1,
        "kip_mg_g2": 2 * f["B2"] / k1,
        "delta_o_mg": f["B1"] / k1,
    }


def tumble_coefficients(df: pd.DataFrame, by: str = "set_point_c") -> pd.DataFrame:
    """Per temperature group of a tumble frame: mean sensor temperature and the IEEE coefficients."""
    rows = []
    for key, g in df.groupby(by, sort=True):
        c = coefficients_from_fourier(tumble_fourier(g["position_deg"], g["output_mg"]))
        rows.append({by: key, "temperature_c": float(g["temperature_c"].mean()), **c})
    return pd.DataFrame(rows)


DEFAULT_COEFFICIENTS = AccelCoefficients()
DEFAULT_EXPERIMENT = TumbleExperiment()
#: Seeds of the stored data set: unit A's noise, unit B's coefficients and noise.
DATA_SEEDS = {"noise_a": 12, "batch_b": 2, "noise_b": 13}
BATCH_SPREAD_REL = 0.25


def paper_units(
    exp: TumbleExperiment = DEFAULT_EXPERIMENT,
    coef: AccelCoefficients = DEFAULT_COEFFICIENTS,
    batch_spread_rel: float = BATCH_SPREAD_REL,
    seeds: dict | None = None,
) -> pd.DataFrame:
    """Both units of the chapter: unit ``A`` (the modelled one) and unit ``B`` (same batch, coefficients
    within ``batch_spread_rel``), stacked."""
    s = {**DATA_SEEDS, **(seeds or {})}
    b = coef.batch_member(batch_spread_rel, s["batch_b"])
    return pd.concat(
        [simulate_tumble(coef, exp, s["noise_a"], "A"), simulate_tumble(b, exp, s["noise_b"], "B")],
        ignore_index=True,
    )


def write_paper_data(path, overwrite: bool = False):
    """Write the chapter's stored data set (:func:`paper_units` with the defaults) to ``path`` (CSV)."""
    df = paper_units()
    return write_new_csv(df, path, overwrite=overwrite, float_format="%.9f")


if __name__ == "__main__":  # pragma: no cover - data regeneration entry point
    import sys

    print(write_paper_data(sys.argv[1], overwrite="--overwrite" in sys.argv))
