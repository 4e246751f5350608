"""The workbench chapter's study (``notebooks/workbench.ipynb``): the loop on simulated data, on the shipped
measurements and on the real BROAD recordings (level compass sweeps and 3-D magnetometer trials), the
magnet-distance law, the calibrations compared, and the claims of the chapter's Results at a glance.

The notebook imports ``from navlib.studies import workbench as wb``; every name it uses is here.  Which
module holds what (each imports only the ones above it):

- :mod:`navlib.studies.workbench.parameters` -- where the BROAD recordings are, the sample files of "Bring
  your own data", row steps, the book's targets, and the notebook's parameters
  (:class:`~navlib.studies.workbench.parameters.WorkbenchParams` with ``from_notebook``);
- :mod:`navlib.studies.workbench.tables` -- results shaped for display (the effects a loop added, its
  steps) and the library's conventions on one worked example;
- :mod:`navlib.studies.workbench.own_data` -- "Bring your own data": columns, sample rows, the command and
  its report;
- :mod:`navlib.studies.workbench.simulated` -- the loop on a simulated compass, an error outside the
  catalogue, paper A's networks beside the physical model;
- :mod:`navlib.studies.workbench.shipped` -- the loop on paper C's drift tables and the accelerometer
  tumble test;
- :mod:`navlib.studies.workbench.broad_loops` -- the loop on BROAD: level sweeps, undisturbed 3-D trials
  with and without the reference;
- :mod:`navlib.studies.workbench.magnets` -- the attached and stationary magnets, the ellipsoid fit beside
  the loop, the distance law;
- :mod:`navlib.studies.workbench.calibrations` -- ``navlib calibrate`` beside a dedicated calibrator, the
  reference-free calibration beside the reference-based one;
- :mod:`navlib.studies.workbench.claims` -- the chapter's claims and how rates are judged.
"""

from .parameters import (
    ATTACHED,
    BROAD_SITE,
    CALIBRATION_TRIAL,
    FREE_ROW_STEP,
    LEVEL_DIR,  # noqa: F401
    MAG_DIR,
    MAGNET_STAIRCASES,
    MAX_ATT_BLUR,
    OWN_DATA_COMMAND_OPTIONS,
    OWN_DATA_FILES,
    PEER_TRAIN_SHARE,
    REALDATA,
    SAMPLE_ROWS,
    STATIONARY,
    STRUCTURE_BOUND,
    TARGET_FALSE_ALARMS,
    TARGET_NAMED,
    TARGET_QUIET,
    WorkbenchParams,
    realdata_available,
)
from .tables import added, conventions_example, steps_frame  # noqa: F401
from .own_data import OwnData, own_data, own_data_report, shell_command, wrap_report  # noqa: F401
from .simulated import network_vs_physics, simulated_compass, with_three_cycle  # noqa: F401
from .shipped import DriftStudy, accelerometer_loop, drift_study  # noqa: F401
from .broad_loops import (
    LevelLoops,
    free_undisturbed_loop,
    free_undisturbed_loops,
    level_loops,  # noqa: F401
    load_trial,
    undisturbed_loop,
    undisturbed_loops,
    undisturbed_trials,
)
from .magnets import DistanceLaw, MagnetStudy, distance_law, magnet_staircases, magnet_study  # noqa: F401
from .calibrations import (
    PeerComparison,
    calibration_beside_peer,
    held_out_field_errors,  # noqa: F401
    reference_free_headings,
)
from .claims import (
    LEVEL_CLAIMS,
    NOT_IN_PAPER,
    REALDATA_KEYS,
    Case,
    free_vs_reference_claim,  # noqa: F401
    glance_claims,
    rate_cases,
    trials_needed,
    worst_case,
)
