"""The names the command line offers, kept apart so that parsing a command line (and ``--help``) loads
nothing but the standard library: the workbench's systems, ``rates``' and ``calibrate``'s defaults and the
example files shipped with navlib.  Each list equals the library's own registry (``tests/cli/test_cli_surface.py``
keeps them equal)."""

from __future__ import annotations

#: The systems of the workbench (``navlib.workbench.SYSTEMS``; a test keeps the two equal).
SYSTEM_NAMES = ("accelerometer", "compass", "drift", "magnetometer", "magnetometer_free")
#: The systems ``rates`` simulates (:data:`navlib.workbench.rates.RATE_SYSTEMS`).
RATE_SYSTEM_NAMES = ("accelerometer", "compass", "drift", "magnetometer", "magnetometer_free")
#: ``calibrate``'s default model (``navlib.workbench.calibration.DEFAULT_MODEL``).
CALIBRATION_MODEL = ("hard_iron", "scale", "soft_iron")
#: ``rates``' default effect sizes (:data:`navlib.workbench.rates.DEFAULT_RATIOS`).
RATE_RATIOS = (3.0, 10.0)
#: ``rates``' default noise per system, in the system's unit (:data:`navlib.workbench.rates.DEFAULT_NOISE`).
RATE_NOISE = {
    "compass": 0.1,
    "drift": 1e-4,
    "magnetometer": 0.3,
    "accelerometer": 0.003,
    "magnetometer_free": 0.3,
}
#: The unit of each system's noise in ``rates`` (``navlib.workbench.System.unit``).
RATE_UNITS = {
    "compass": "deg",
    "drift": "deg/h",
    "magnetometer": "uT",
    "accelerometer": "mg",
    "magnetometer_free": "uT",
}
#: The date of the field when none is given (``navlib.sensors.earth_field.Site.date``).
FIELD_DATE = "2025-01-01"
#: The example files shipped with navlib (``navlib examples``; ``--example NAME`` instead of FILE): name ->
#: (system, file among navlib's data files, one command that runs on it).
EXAMPLES = {
    "compass_sweeps": (
        "compass",
        "compass_sweeps.csv",
        "navlib loop compass --example compass_sweeps --model misalignment",
    ),
    "gyro_drift_measurements": (
        "drift",
        "gyro_drift_measurements.csv",
        "navlib diagnose drift --example gyro_drift_measurements --model earth_rate",
    ),
    "accel_tumble": (
        "accelerometer",
        "accel_tumble.csv",
        "navlib loop accelerometer --example accel_tumble --unit A",
    ),
}
#: The systems ``compare`` knows (:data:`navlib.workbench.compare.COMPARISONS`), its split rules and, per
#: system, the default methods (``navlib.workbench.compare.COMPASS_DEFAULT``) and settings.
COMPARE_SYSTEM_NAMES = ("compass",)
COMPARE_SPLITS = ("sweep", "heading", "random")
COMPARE_DEFAULT_METHODS = {
    "compass": (
        "uncompensated",
        "ls8",
        "ls8_planar",
        "ls8_h3",
        "physical",
        "bp_matlab",
        "de_bp_full_trainlm",
        "ade_bp_full_trainlm",
        "elm",
        "elm_backtuned",
    )
}
COMPARE_SEEDS = 10
COMPARE_BIN_DEG = 15.0
COMPARE_LS_TOLERANCE_DEG = 5.0
#: What ``--workers`` does when not given.
WORKERS_HELP = (
    "local worker processes (default: the cores this process may use, or 1 when dask.distributed "
    "is not installed; 1 = in this process)"
)
