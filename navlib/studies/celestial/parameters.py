"""The celestial chapter's parameters: the study's settings (:class:`StudySpec`, with
:meth:`StudySpec.from_notebook` for the notebook's parameters cell), the cases, methods and phases the study
scores, paper E's BP network (:func:`bp_params`) and the seed of every draw (:func:`seed_of`)."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import InputError, check_param
from ...methods import kalman as km
from ...methods.mlp import MLPParams
from ...seeding import as_int, sequence
from ...sensors.strapdown import ImuSpec, StarSensorSpec
from ...sensors.trajectory import FlightProfile

AXES = ("pitch", "roll", "yaw")
CASES = {  # case -> (simulation kind, feature set)
    "level_raw45": ("level", "raw45"),
    "level_qr6": ("level", "qr6"),
    "sturn_qr6": ("s_turns", "qr6"),
    "sturn_qr6_rate": ("s_turns", "qr6_rate"),
    "sturn_raw45": ("s_turns", "raw45"),
    "level_resid3": ("level", "residual3"),
    "level_qr6_rate": ("level", "qr6_rate"),
}
CASE_LABEL = {
    "level_raw45": "level, 45 raw gains (Fig 3, Table 2)",
    "level_qr6": "level, 6 QR (Fig 4, Table 3)",
    "sturn_qr6": "S-turns, 6 QR (Figs 6-7, Table 4)",
    "sturn_qr6_rate": "S-turns, 6 QR + 3 rates (Figs 8-9, Table 5)",
    "sturn_raw45": "S-turns, 45 raw gains (ours)",
    "level_resid3": "level, 3 filter residuals (rejected by the paper)",
    "level_qr6_rate": "level, 6 QR + 3 rates (ours, Sec. 2.2)",
}

#: The two halves of a held-out S-turn run's scored epochs, split at the median absolute body yaw rate of the run.
PHASES = ("turning", "steady")

#: The nets timed as MATLAB trains them (paper E's three input sets).
LM_NETS = {45: "raw45", 6: "qr6", 9: "qr6_rate"}

#: The sweep's methods: label -> BPKF feature set (None: a filter without a network).
SWEEP_METHODS = {
    "KF": None,
    "BPKF 6 QR": "qr6",
    "BPKF 6 QR + 3 rates": "qr6_rate",
    "BPKF 45 raw": "raw45",
    "augmented KF": None,
}


def bp_params(
    n_in: int, n_hidden: int = 10, epochs: int = 300, learning_rate: float = 0.01
) -> MLPParams:
    """Paper E's BP network ``n_in - n_hidden - 3`` (logsig hidden, purelin output), as we train it:
    standardised inputs and targets, torch's default initialisation, full-batch Adam."""
    return MLPParams(
        n_in=n_in,
        n_hidden=n_hidden,
        n_out=3,
        hidden="logsig",
        trainer="adam",
        epochs=epochs,
        learning_rate=learning_rate,
        scaling="standardize",
        init="torch",
    )


@dataclass(frozen=True)
class StudySpec:
    """The chapter's parameters (names as in the notebook's parameters cell; units in the names)."""

    duration_s: float = 150.0
    imu_rate_hz: float = 100.0
    star_rate_hz: float = 10.0
    star_cross_arcsec: float = 3.0
    star_boresight_arcsec: float = 15.0
    gyro_drift_deg_h: float = 0.01
    gyro_arw_deg_rt_h: float = 0.001
    accel_bias_ug: float = 50.0
    accel_noise_ug_rt_hz: float = 10.0
    gyro_scale_ppm: float = 100.0
    init_level_arcsec: float = 20.0
    init_azimuth_arcsec: float = 60.0
    yaw_amplitude_deg: float = 30.0
    turn_period_s: float = 12.0
    n_hidden: int = 10
    epochs: int = 300
    n_train_runs: int = 4
    n_test_runs: int = 4
    n_repeats: int = 4
    settle_s: float = 10.0
    n_timings: int = 20
    timing_epochs: int = 50
    lm_timings: int = 6
    sweep_ppm: tuple = (0.0, 25.0, 50.0, 100.0, 200.0)
    sweep_repeats: int = 2
    star_latency_ms: float = 0.0
    latency_ms_levels: tuple = (10.0, 50.0)
    star_smear_arcsec_per_deg_s: float = 0.0
    smear_levels_arcsec_per_deg_s: tuple = (2.0, 5.0, 10.0)
    quiet_repeats: int | None = None
    seed: int = 0

    def __post_init__(self):
        check_param("duration_s", self.duration_s, lo=10.0, hi=3600.0)
        check_param("imu_rate_hz", self.imu_rate_hz, lo=10.0, hi=1000.0)
        check_param("star_rate_hz", self.star_rate_hz, lo=0.1, hi=self.imu_rate_hz)
        check_param("star_cross_arcsec", self.star_cross_arcsec, lo=0.0, lo_open=True, hi=3600.0)
        check_param(
            "star_boresight_arcsec", self.star_boresight_arcsec, lo=0.0, lo_open=True, hi=3600.0
        )
        for f in (
            "gyro_drift_deg_h",
            "gyro_arw_deg_rt_h",
            "accel_bias_ug",
            "accel_noise_ug_rt_hz",
            "init_level_arcsec",
            "init_azimuth_arcsec",
        ):
            check_param(f, getattr(self, f), lo=0.0, lo_open=f.startswith("init"), hi=1e5)
        check_param("gyro_scale_ppm", self.gyro_scale_ppm, lo=-1e5, hi=1e5)
        check_param("yaw_amplitude_deg", self.yaw_amplitude_deg, lo=0.0, hi=90.0)
        check_param("turn_period_s", self.turn_period_s, lo=2.0, hi=3600.0)
        check_param("n_hidden", self.n_hidden, lo=1, hi=1000, integer=True)
        check_param("epochs", self.epochs, lo=1, hi=100000, integer=True)
        check_param("n_train_runs", self.n_train_runs, lo=1, hi=200, integer=True)
        check_param("n_test_runs", self.n_test_runs, lo=1, hi=200, integer=True)
        check_param("n_repeats", self.n_repeats, lo=1, hi=200, integer=True)
        check_param("n_timings", self.n_timings, lo=1, hi=1000, integer=True)
        check_param("timing_epochs", self.timing_epochs, lo=1, hi=100000, integer=True)
        check_param("lm_timings", self.lm_timings, lo=1, hi=1000, integer=True)
        if not isinstance(self.sweep_ppm, tuple) or len(set(self.sweep_ppm)) != len(self.sweep_ppm):
            raise InputError(
                f"parameter sweep_ppm={self.sweep_ppm!r}: a tuple of distinct scale factors (ppm)"
            )
        for v in self.sweep_ppm:
            check_param("sweep_ppm", v, lo=-1e5, hi=1e5)
        check_param("sweep_repeats", self.sweep_repeats, lo=1, hi=self.n_repeats, integer=True)
        check_param("star_latency_ms", self.star_latency_ms, lo=0.0, hi=1000.0)
        if not isinstance(self.latency_ms_levels, tuple):
            raise InputError(
                f"parameter latency_ms_levels={self.latency_ms_levels!r}: a tuple of time offsets (ms)"
            )
        for v in self.latency_ms_levels:
            check_param("latency_ms_levels", v, lo=0.0, lo_open=True, hi=1000.0)
        check_param(
            "star_smear_arcsec_per_deg_s", self.star_smear_arcsec_per_deg_s, lo=-3600.0, hi=3600.0
        )
        if not isinstance(self.smear_levels_arcsec_per_deg_s, tuple):
            raise InputError(
                f"parameter smear_levels_arcsec_per_deg_s={self.smear_levels_arcsec_per_deg_s!r}: "
                "a tuple of rate-proportional star-sensor errors (arcsec per deg/s)"
            )
        for v in self.smear_levels_arcsec_per_deg_s:
            check_param("smear_levels_arcsec_per_deg_s", v, lo=-3600.0, hi=3600.0)
            if v == 0:
                raise InputError(
                    "parameter smear_levels_arcsec_per_deg_s: 0 is not an error (the quiet case is "
                    "the sweep's 0 ppm)"
                )
        if self.quiet_repeats is not None:
            check_param("quiet_repeats", self.quiet_repeats, lo=1, hi=1000, integer=True)
        check_param("seed", self.seed, lo=0, integer=True)
        check_param("settle_s", self.settle_s, lo=0.0, hi=self.duration_s, hi_open=True)
        ratio = self.imu_rate_hz / self.star_rate_hz
        if abs(ratio - round(ratio)) > 1e-9:
            raise InputError(
                f"parameter star_rate_hz={self.star_rate_hz!r}: must divide imu_rate_hz="
                f"{self.imu_rate_hz!r}"
            )
        for rate, name in ((self.imu_rate_hz, "imu_rate_hz"), (self.star_rate_hz, "star_rate_hz")):
            n = self.duration_s * rate
            if abs(n - round(n)) > 1e-6:
                raise InputError(
                    f"parameter duration_s={self.duration_s!r}: must be a whole number of "
                    f"samples at {name}={rate!r}"
                )
        if self.duration_s * self.star_rate_hz < 20:
            raise InputError(
                f"parameter duration_s={self.duration_s!r}: fewer than 20 star-sensor epochs "
                f"at star_rate_hz={self.star_rate_hz!r}"
            )

    @property
    def imu(self) -> ImuSpec:
        return ImuSpec(
            self.gyro_drift_deg_h,
            self.gyro_arw_deg_rt_h,
            self.accel_bias_ug,
            self.accel_noise_ug_rt_hz,
            self.gyro_scale_ppm,
        )

    @property
    def star(self) -> StarSensorSpec:
        return StarSensorSpec(
            self.star_cross_arcsec,
            self.star_boresight_arcsec,
            self.star_rate_hz,
            self.star_latency_ms,
            self.star_smear_arcsec_per_deg_s,
        )

    @property
    def filter(self) -> km.FilterSpec:
        return km.FilterSpec(
            phi_level_arcsec=self.init_level_arcsec,
            phi_azimuth_arcsec=self.init_azimuth_arcsec,
            drift_deg_h=max(2 * self.gyro_drift_deg_h, 1e-4),
            bias_ug=max(2 * self.accel_bias_ug, 1.0),
            scale_ppm=max(3 * abs(self.gyro_scale_ppm), 10.0),
        )

    def profile(self, kind: str, manoeuvre_seed: int) -> FlightProfile:
        return FlightProfile(
            kind=kind,
            duration_s=self.duration_s,
            imu_rate_hz=self.imu_rate_hz,
            yaw_amplitude_deg=self.yaw_amplitude_deg,
            turn_period_s=self.turn_period_s,
            manoeuvre_seed=manoeuvre_seed,
        )

    @classmethod
    def from_notebook(cls, **cell) -> StudySpec:
        """The spec the celestial notebook builds from its parameters cell (``notebooks/celestial.ipynb``):
        ``cell`` holds the cell's flat parameters by name (papermill's), the cell's default
        (:data:`NOTEBOOK_DEFAULTS`) for any not given; the three lists of levels become tuples, and the run
        settings (:data:`RUN_KEYS`: where the study runs, not what it computes) are accepted and left out.
        A name the cell does not have stops with an :class:`~navlib.errors.InputError` naming it."""
        for name in cell:
            if name not in NOTEBOOK_DEFAULTS:
                raise InputError(
                    f"parameter {name!r}: not a parameter of notebooks/celestial.ipynb (its parameters: "
                    f"{', '.join(NOTEBOOK_DEFAULTS)})"
                )
        given = {k: v for k, v in {**NOTEBOOK_DEFAULTS, **cell}.items() if k not in RUN_KEYS}
        return cls(**{k: tuple(v) if k in _LEVEL_TUPLES else v for k, v in given.items()})


#: The celestial notebook's parameters cell (``notebooks/celestial.ipynb``, tagged ``parameters``): name ->
#: default, in the cell's order.  Every name but :data:`RUN_KEYS` is a field of :class:`StudySpec`; the cell's
#: ``sweep_repeats`` (4) is not the spec's default (2).
NOTEBOOK_DEFAULTS = {
    "duration_s": 150.0,
    "imu_rate_hz": 100.0,
    "star_rate_hz": 10.0,
    "star_cross_arcsec": 3.0,
    "star_boresight_arcsec": 15.0,
    "gyro_drift_deg_h": 0.01,
    "gyro_arw_deg_rt_h": 0.001,
    "gyro_scale_ppm": 100.0,
    "accel_bias_ug": 50.0,
    "accel_noise_ug_rt_hz": 10.0,
    "yaw_amplitude_deg": 30.0,
    "turn_period_s": 12.0,
    "n_hidden": 10,
    "epochs": 300,
    "n_train_runs": 4,
    "n_test_runs": 4,
    "n_repeats": 4,
    "n_timings": 20,
    "timing_epochs": 50,
    "lm_timings": 6,
    "sweep_ppm": (0.0, 25.0, 50.0, 100.0, 200.0),
    "sweep_repeats": 4,
    "latency_ms_levels": (10.0, 50.0),
    "smear_levels_arcsec_per_deg_s": (2.0, 5.0, 10.0),
    "quiet_repeats": 10,
    "seed": 0,
    "n_workers": 2,
    "scheduler": None,
}
#: The notebook's parameters that say where the study runs (local worker processes, a dask scheduler), not
#: what it computes: :meth:`StudySpec.from_notebook` accepts them and leaves them out.
RUN_KEYS = ("n_workers", "scheduler")
#: The notebook's parameters that are lists of levels (the notebook passes them on as tuples).
_LEVEL_TUPLES = ("sweep_ppm", "latency_ms_levels", "smear_levels_arcsec_per_deg_s")


#: Parts of a repeat's draws (spawn-key elements after the repeat; see :func:`seed_of`).
SEED_PARTS = {"noise": 0, "manoeuvre": 1, "network": 2, "timing": 3, "trainlm": 4}
KINDS = ("level", "s_turns")


def seed_of(spec: StudySpec, rep: int, part: str, *key: int) -> int:
    """The integer seed of one draw of the study: from ``SeedSequence(spec.seed, spawn_key=(rep, part,
    *key))``, ``part`` one of :data:`SEED_PARTS` (noise of the runs of a simulation kind, the manoeuvre of a
    run, the networks' start, a timing repetition).  Spawn keys, no arithmetic: no two draws share a seed."""
    return as_int(sequence(spec.seed, rep, SEED_PARTS[part], *key))
