"""The gyro chapter's study: paper C (Yu et al. 2012), RBF identification of a rotating INS's axial gyro drift.

Every table and figure of the gyro chapter (``notebooks/gyro.ipynb``) is computed in this package, one function per
table or figure, from the paper's real Tables 2-5 (``data/gyro_table*.csv``), its printed settings and claims
(``data/paper_c_facts.csv``), the MATLAB-compatible ``newrb`` (:mod:`navlib.methods.rbf`) and the static-base
rotating-INS error simulator (:mod:`navlib.sensors.ins`).  Every public name of the modules below is re-exported
here, so ``from navlib.studies import gyro`` and ``gyro.hot_network(params)`` reach them all.  (The function
``gyro.claims`` shadows the module of the same name: import that one as ``navlib.studies.gyro.claims``.)

Which module holds what, in the order they import each other (each imports only those above it):

- :mod:`~navlib.studies.gyro.parameters` -- paper C's printed facts (``paper_facts``, ``fact``), the settings
  dataclasses with the top one, ``StudyParams`` (and ``StudyParams.from_notebook``: the notebook's
  ``parameters`` cell in one call), the thermal worlds, the seeds (``experiment_seeds``, ``bootstrap_seed``);
- :mod:`~navlib.studies.gyro.measured` -- the measured Tables 2-5 (``measured_tables``), their printed
  precision (``printed_decimals``, ``temperature_spans``) and the error summaries;
- :mod:`~navlib.studies.gyro.networks` -- the hot and cold networks' inputs and designs (``latitude_scaler``,
  ``cold_inputs``, ``design_hot_net``, ``rate_coefficient``, ``design_cold_net``) and other bases
  (``swap_basis``);
- :mod:`~navlib.studies.gyro.simulation` -- the experiments in the error simulator: Table 1, Fig 1, the
  simulated hot tests (``reference_gap``, ``position_requirement``), the printed position errors read through
  the simulator's gain;
- :mod:`~navlib.studies.gyro.hot_state` -- the hot net on Tables 2 and 3, Figs 2 and 3, Table 1 against the
  data, leave-one-out over Table 2;
- :mod:`~navlib.studies.gyro.readings` -- the readings of the ambiguous settings (input unit, goal, width,
  basis) and the resolution the latitudes' rounding leaves;
- :mod:`~navlib.studies.gyro.cold_state` -- the cold start: Table 4 by leave-one-out, Table 5 and Fig 4 in
  simulation;
- :mod:`~navlib.studies.gyro.thermal_worlds` -- the cold-state protocol in simulated thermal worlds;
- :mod:`~navlib.studies.gyro.bp_compare` -- the hot net against MATLAB's BP network by leave-one-out over
  Table 2 (``bp_leave_one_out``) and its claims (``bp_claims``, register entry C12);
- :mod:`~navlib.studies.gyro.diagnosis` -- the paper's own reasoning: Table 1 against the error model per
  source (``table1_gaps``, ``table1_claims``, C17) and the cold-start diagnosis on the printed Tables 3-5
  (``cold_diagnosis_claims``, C19-C21);
- :mod:`~navlib.studies.gyro.mechanisms` -- why the method should work: centres against basis functions on
  Table 2 (``centre_claims``, C14), the axial drift's share of the measured 12 h latitude error
  (``latitude_share_claims``, C16) and of the 72 h position error with rotation on (``rotation_claims``, C18);
- :mod:`~navlib.studies.gyro.claims` -- the claims and their verdicts, the verdict table, the methods' headline
  statistics.

Where each figure and table of the paper is reproduced (notebook section -> function, module):

==================  ===============================================  ==================================
paper C             gyro chapter section                             function (module)
==================  ===============================================  ==================================
Tables 2-5          "The measured tables"                            ``measured_tables`` (measured)
Table 1             "Physics: Table 1 against the error simulator"   ``table1_vs_simulator``
                                                                     (simulation)
Fig 1               "Fig 1 analogue"                                 ``fig1_simulated_tests``
                                                                     (simulation)
Table 3             "The hot-state network"                          ``hot_network``,
                                                                     ``table3_identification``
                                                                     (hot_state)
SPREAD/goal/unit    "The hot-state network" (variants)               ``hot_net_variants`` (readings)
Fig 2               "The hot-state network" (training path)          ``fig2_training_path`` (hot_state)
Fig 3, Table 3      "Fig 3 analogue"                                 ``fig3_position_errors``
                                                                     (hot_state)
Table 1 vs data     "Table 1 against the measured tables"            ``slopes_table``,
                                                                     ``drift_against_latitude``
                                                                     (hot_state)
claim 0.0003 deg/h  "Generalisation on the hot data"                 ``hot_leave_one_out`` (hot_state)
Table 4             "Cold start"                                     ``table4_hot_net``,
                                                                     ``cold_leave_one_out``
                                                                     (cold_state)
Table 5, Fig 4      "Cold start" (simulation)                        ``table5_simulation`` (cold_state)
Sec. 2.3, cold      "Cold start in thermal worlds"                   ``cold_thermal_study``
                                                                     (thermal_worlds)
claims              "Verdict", "Results at a glance"                 ``reference_gap`` (simulation),
                                                                     ``verdict``, ``claims``,
                                                                     ``methods_summary`` (claims),
                                                                     ``printed_decimals`` (measured),
                                                                     ``latitude_rounding_effect``
                                                                     (readings), ``bootstrap_seed``
                                                                     (parameters)
==================  ===============================================  ==================================

Conventions: errors are *indicated minus true*, a drift is *gyro output minus true rate*, an identification
error is **true minus identified** (as the paper's Table 3 "error" column).  Drifts in deg/h, latitude errors
in deg (arcmin = nautical miles of latitude where a column says so), position errors in nmi (worst over the
72 h).  Simulated experiments draw their seeds from ``numpy.random.SeedSequence(seed).spawn`` (one child per
experiment, see :func:`~navlib.studies.gyro.parameters.experiment_seeds`), so no two experiments share
residual-error draws; so do the bootstrap intervals over the rows of the real tables
(:func:`~navlib.studies.gyro.parameters.bootstrap_seed`).  Every claim's verdict follows from its 95 % interval
by the book's one rule (:mod:`navlib.verdicts`).

The simulation-heavy functions (``fig3_position_errors``, ``table5_simulation``, ``reference_gap``,
``latitude_rounding_effect``, ``cold_thermal_study``) cache their result per parameter set; treat returned
frames as read-only.
"""

from .parameters import (
    BOOTSTRAPS,
    FACT_KEYS,
    FACTS_FILE,
    NOTEBOOK_PARAMETERS,
    THERMAL_WORLDS,
    ColdDtColumn,
    ColdNetSettings,
    ColdStudySettings,
    BpSettings,
    GoalKind,
    HotNetSettings,
    InputUnit,
    SimulationSettings,
    StudyParams,
    ThermalWorld,
    WidthReading,
    bootstrap_seed,
    experiment_seeds,
    fact,
    paper_facts,
)
from .measured import (
    SHORT_HEADERS,
    MeasuredTables,
    measured_tables,
    printed_decimals,
    temperature_spans,
)
from .networks import (
    BASIS_FUNCTIONS,
    GOAL_READINGS,
    LATITUDE_UNITS,
    cold_inputs,
    design_cold_net,
    design_hot_net,
    latitude_scaler,
    rate_coefficient,
    swap_basis,
)
from .simulation import (
    Fig1,
    Table1Comparison,
    before_identification,
    fig1_simulated_tests,
    implied_drift_error,
    position_requirement,
    reference_gap,
    table1_vs_simulator,
    table3_other_error,
)
from .hot_state import (
    HOT_LOO_METHODS,
    TABLE3_METHODS,
    DriftLatitude,
    Fig2,
    Fig3,
    HotLoo,
    HotNet,
    Slopes,
    Table3,
    drift_against_latitude,
    fig2_training_path,
    fig3_position_errors,
    hot_leave_one_out,
    hot_network,
    slopes_table,
    table3_identification,
)
from .readings import (
    basis_readings,
    fig2_goal_readings,
    hot_net_variants,
    input_scale_scan,
    latitude_rounding_effect,
    scale_band,
    target_spread,
    width_readings,
)
from .cold_state import (
    COLD_METHODS,
    TABLE5_METHODS,
    ColdLoo,
    Table5,
    cold_leave_one_out,
    table4_hot_net,
    table5_simulation,
)
from .thermal_worlds import (
    COLD_STUDY_METHODS,
    cold_thermal_study,
    cold_thermal_summary,
    thermal_worlds_table,
)
from .bp_compare import BP_READINGS, BpLoo, bp_claims, bp_leave_one_out
from .diagnosis import (
    TABLE1_SOURCES,
    cold_diagnosis_claims,
    rate_corrected_loo,
    table1_claims,
    table1_gaps,
)
from .mechanisms import (
    centre_claims,
    latitude_share_claims,
    mechanism_claims,
    rotation_claims,
)
from .claims import (
    claims,
    cold_world_claims,
    methods_summary,
    reading_claims,
    register_claims,
    verdict,
)
