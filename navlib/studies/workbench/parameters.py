"""The workbench chapter's parameters: where the real recordings are, the sample files of "Bring your own
data", the row steps, the book's targets for the loop, and the notebook's parameters as one dataclass
(:class:`WorkbenchParams`, built from the papermill cell by :meth:`WorkbenchParams.from_notebook`).

Real data: the BROAD benchmark (D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD - A Benchmark for
Robust Inertial Orientation Estimation", Data 6(7):72, 2021, CC BY 4.0), derived files in
``../shared/realdata/broad`` (never copied into this repository; where the folder is absent the functions
return None and the chapter says so).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

from ...errors import InputError, check_param
from ...paths import ROOT, data_path
from ...workbench.effects import check_effects

#: Where the third-party measurements live (beside the repository, never inside it).
REALDATA = ROOT.parent / "shared" / "realdata"
LEVEL_DIR = REALDATA / "broad" / "level"
MAG_DIR = REALDATA / "broad" / "3d"
CALIBRATION_TRIAL = "broad_05_undisturbed_slow_rotation_with_breaks_B.csv"
#: Attached-magnet trials (file -> nominal distance of the magnet from the IMU in cm, from BROAD's trial list).
ATTACHED = {
    "broad_32_attached_magnet_1cm.csv": 1.0,
    "broad_33_attached_magnet_2cm.csv": 2.0,
    "broad_34_attached_magnet_3cm.csv": 3.0,
    "broad_35_attached_magnet_4cm.csv": 4.0,
    "broad_36_attached_magnet_5cm.csv": 5.0,
}
STATIONARY = (
    "broad_28_stationary_magnet_A.csv",
    "broad_29_stationary_magnet_B.csv",
    "broad_30_stationary_magnet_C.csv",
    "broad_31_stationary_magnet_D.csv",
)
MAX_ATT_BLUR = 0.01  # README: keep the block attitude blur below 0.01 for precise fits


def realdata_available() -> bool:
    """True when ``../shared/realdata/broad`` holds both the level and the 3-D files."""
    return LEVEL_DIR.is_dir() and MAG_DIR.is_dir()


# ------------------------------------------------------------------------------------ bring your own data
# The file each system's section of "Bring your own data" samples: shipped in ``data/`` or BROAD trial 05
# in ``../shared/realdata`` (read there, never copied; no doc comment: the API page would print this
# machine's folders).
OWN_DATA_FILES = {
    "compass": data_path("compass_sweeps.csv"),
    "drift": data_path("gyro_drift_measurements.csv"),
    "magnetometer": MAG_DIR / CALIBRATION_TRIAL,
    "magnetometer_free": MAG_DIR / CALIBRATION_TRIAL,
    "accelerometer": data_path("accel_tumble.csv"),
}
#: Options a system's command needs on its sample file: the workbench fits one accelerometer, and
#: ``data/accel_tumble.csv`` holds two (units A and B), so the command picks one.
OWN_DATA_COMMAND_OPTIONS = {"accelerometer": ["--unit", "A"]}
#: How many rows of each sample file are shown.
SAMPLE_ROWS = 5


# ------------------------------------------------------------------------------------ 3-D magnetometer
#: The loops of :func:`~navlib.studies.workbench.magnets.magnet_study` drawn as staircases: the calibration,
#: the nearest and the farthest attached magnet, and the first stationary magnet.
MAGNET_STAIRCASES = (
    "broad_32_attached_magnet_1cm.csv",
    "broad_36_attached_magnet_5cm.csv",
    "broad_28_stationary_magnet_A.csv",
)
#: Share of each recording (its first rows, in time) the calibrations are fitted on; the rest judges them.
PEER_TRAIN_SHARE = 0.7
#: Where BROAD was recorded, as its README states it: it gives no site or date, so the reference-free
#: loop's local field is not compared with IGRF on BROAD (the CLI does it wherever a site is known).
BROAD_SITE = None
#: Every this-many 0.1 s blocks of a BROAD trial in the reference-free loops (about 1 Hz: the chapter's time
#: is bounded).
FREE_ROW_STEP = 9


# ------------------------------------------------------------------------------------ the book's targets
#: Our users' targets for the loop (the book's own; no paper states them), as shares of trials.
TARGET_NAMED = 0.95  # a hidden catalogued effect is named in at least 95 % of trials
TARGET_FALSE_ALARMS = 0.05  # data with nothing missing raise at most 5 % false alarms
TARGET_QUIET = 0.90  # an error outside the catalogue names no catalogued effect in at least 90 %
#: Our bound on a real sweep: the unexplained structure left at the end, as a multiple of the residual rms.
STRUCTURE_BOUND = 3.0


# ------------------------------------------------------------------------------------ the notebook
@dataclass(frozen=True)
class WorkbenchParams:
    """The parameters of ``notebooks/workbench.ipynb`` (its papermill cell, defaults as there), checked as
    the notebook checks them, and ``start``: the start model ``start_model`` (comma-separated effect names)
    as the compass system's effects in catalogue order.

    ``hidden_effect``: the compass effect hidden in the simulated data and missing from the start model;
    ``hidden_ratio``: its RMS as a multiple of the heading noise ``noise_deg`` (deg, 1 sigma); ``sim_seed``:
    seed of the simulated compass; ``alpha``: family-wise false-alarm level of diagnose;
    ``three_cycle_deg``: amplitude of the three-cycle error in the user-effect section (deg);
    ``study_seeds``: trials per (hidden effect, size, noise) in the detection study;
    ``study_null_trials`` and ``drift_null_trials``: trials with nothing hidden per noise level (compass,
    drift tables); ``ooc_seeds``: trials per (out-of-catalogue error, size, noise); ``mag_row_step``: every
    n-th 0.1 s block of the BROAD 3-D trials; ``corr_seeds``: trials per case in the correlated-noise
    section; ``n_workers``, ``scheduler``: where the trials run (:mod:`navlib.engine`)."""

    hidden_effect: str = "temperature"
    hidden_ratio: float = 10.0
    noise_deg: float = 0.1
    start_model: str = "misalignment,hard_iron"
    sim_seed: int = 7
    alpha: float = 0.025
    three_cycle_deg: float = 0.5
    study_seeds: int = 20
    study_null_trials: int = 150
    drift_null_trials: int = 300
    ooc_seeds: int = 9
    mag_row_step: int = 3
    corr_seeds: int = 10
    n_workers: int = 2
    scheduler: str | None = None
    start: tuple[str, ...] = field(init=False)

    def __post_init__(self):
        check_param("hidden_ratio", self.hidden_ratio, lo=0)
        check_param("noise_deg", self.noise_deg, lo=0, lo_open=True)
        check_param("alpha", self.alpha, lo=0, lo_open=True, hi=1, hi_open=True)
        check_param("three_cycle_deg", self.three_cycle_deg, lo=0)
        for name in (
            "study_seeds",
            "study_null_trials",
            "drift_null_trials",
            "ooc_seeds",
            "mag_row_step",
            "corr_seeds",
            "n_workers",
        ):
            check_param(name, getattr(self, name), lo=1, integer=True)
        start = check_effects("compass", self.start_model.split(","))
        check_effects("compass", [self.hidden_effect])
        if self.hidden_effect in start:
            raise InputError(
                f"parameter hidden_effect={self.hidden_effect!r} is already in start_model;"
                " hide another effect"
            )
        object.__setattr__(self, "start", start)

    @classmethod
    def from_notebook(cls, **cell) -> WorkbenchParams:
        """The parameters from the notebook's papermill cell (``cell``: name -> value, flat; a name left
        out keeps the notebook's default), checked; an unknown name raises :class:`navlib.errors.InputError`
        naming it."""
        known = [f.name for f in fields(cls) if f.init]
        for key in cell:
            if key not in known:
                raise InputError(
                    f"parameter {key!r}: not a parameter of the workbench notebook "
                    f"(one of {', '.join(known)})"
                )
        return cls(**cell)
