"""The accelerometer chapter (paper D, Fu Hongpo et al.): temperature-drift model of a quartz-flexure
accelerometer by IAFSA-SCM-ANFIS, replicated on simulated tumble tests (:mod:`navlib.sensors.accelerometer`;
the paper publishes no data).

The integrated model (paper eq 7) maps the sensor temperature ``T`` and its output ``N`` (mg) at that
temperature to ``Nc``, the output the same unit gives at 55 degC in the same position.  Our target ``Nc`` is,
as in the paper, the *measured* 55 degC reading of that position, so a perfect model still leaves the
noise of two readings: the noise floor of the RMSE is ``sqrt(2) noise``.

Methods (the paper's four and a physical baseline):

- ``ANN``: a 2-n-1 tansig/purelin net (:mod:`navlib.methods.mlp`) mapping (T, N) -> Nc;
- ``FIS``: ``genfis2`` with radius ``fis_radius`` (MATLAB's default 0.5), no training;
- ``ANFIS``: the same FIS trained by hybrid learning (:mod:`navlib.methods.anfis`);
- ``IAFSA-SCM-ANFIS``: the clustering radius ``ra`` and squash ``rb/ra`` chosen by the improved fish swarm
  (:mod:`navlib.methods.fish_swarm`) to minimise the checking RMSE of ``genfis2``'s FIS, then ANFIS;
- ``physical (poly K0, K1, K2)``: IEEE 1293 Fourier coefficients per training temperature, cubic polynomials
  in ``T - 55``, the quadratic model inverted (what thermal-calibration tools do);
- ``oracle`` (not a method): the simulator's own coefficients inverted, to show the noise floor.

Data split by whole temperatures: ``held_out_c`` are test temperatures (never seen), ``check_c`` are the
checking temperatures (ANFIS best epoch, swarm fitness), the rest train.  55 degC is always training.  The
other reading of the paper's "divide into a training set and a test set" is a random split of the readings
(``split_mode="random"``, :func:`~navlib.studies.accelerometer.simulation.random_split`): as many test and
checking readings, drawn from all temperatures.

Whether the swarm matters (``tuners=True``): the same ``genfis2`` fitness minimised by the plain AFSA
(``improved=False``, same school, generations and seed) and by a grid over the same box with the same number
of fitness evaluations (``genfis2`` fits), each followed by one ANFIS training, as the IAFSA's choice is.

The modules, each importing only those listed before it:

- :mod:`~navlib.studies.accelerometer.parameters` -- the methods, tuners and constants,
  :class:`~navlib.studies.accelerometer.parameters.PaperDParams` (with ``from_notebook``) and the paper's
  printed numbers;
- :mod:`~navlib.studies.accelerometer.simulation` -- both units' tumble tests per seed, the samples and the
  splits;
- :mod:`~navlib.studies.accelerometer.models` -- the physical baseline, the exact model, the swarm's fitness
  and the grid tuner;
- :mod:`~navlib.studies.accelerometer.separate` -- the separate bias and scale-factor compensator the
  integrated model is argued against (D11);
- :mod:`~navlib.studies.accelerometer.runs` -- one seed fitted by every method, the chapter's batch of runs,
  their errors;
- :mod:`~navlib.studies.accelerometer.floors` -- the noise floors of the statistics;
- :mod:`~navlib.studies.accelerometer.figures` -- Figs 2-4, 8 and 9 as tables, the drifts per seed;
- :mod:`~navlib.studies.accelerometer.batch_spread` -- unit B over the batch spreads and the spread the
  paper's 9.3 ug needs;
- :mod:`~navlib.studies.accelerometer.tables` -- Table 2 and the other tables the chapter shows;
- :mod:`~navlib.studies.accelerometer.indices` -- "every index greatly reduced": Table 2's indices paired
  over the seeds, the worst case of the conjunction;
- :mod:`~navlib.studies.accelerometer.second_order` -- "K2 and Kip negligible": the second-order terms of
  the tumbles' Fourier fits (true or false by construction of our simulator);
- :mod:`~navlib.studies.accelerometer.claims` -- the claims (integrated against separate models among
  them) and the verdict grid.

Every name the chapter and the tests use is re-exported here: ``from navlib.studies import accelerometer as
D; D.run_chapter(...)``.
"""

# re-exported: the names the chapter and the tests use (ruff: F401 would call them unused)
from .parameters import (
    BATCH_SPREADS,
    K1_MIN_INPUT_G,
    METHODS,
    MIN_SEEDS_FOR_CLAIMS,
    NEARLY_TWO_ORDERS,
    NOTEBOOK_KEYS,  # noqa: F401
    ORDER_OF_MAGNITUDE,
    PAPER_FILE,
    SIM_ENTROPY,
    SIM_PARTS,
    SEPARATE,
    SPLIT_MODES,
    TUNERS,
    PaperDParams,
    _paper_value,
    paper_numbers,
)
from .simulation import random_split, samples, sim_seed, simulate, split, unit_b_coefficients  # noqa: F401
from .models import PolyCompensator, fit_physical, grid_search, oracle, scm_objective  # noqa: F401
from .separate import SeparateCompensator, bias_points, fit_separate  # noqa: F401
from .runs import Chapter, Run, errors_long, metrics, run_chapter, run_seed, run_study  # noqa: F401
from .floors import max_error_floor_ug, rmse_floor_ug  # noqa: F401
from .figures import (
    drift_by_seed,
    drift_summary,
    fig2_output_drift,
    fig3_bias,
    fig4_scale_factor,  # noqa: F401
    fig8_residuals,
    fig9_unit_b,
)
from .batch_spread import _units_difference, spread_needed, unit_b_spread  # noqa: F401
from .tables import (
    method_summary,
    noise_floor,
    noise_permitted,
    noise_table,
    per_seed,
    spread_summary,  # noqa: F401
    swarm_choices,
    table2,
    tuner_table,
    unit_b_table,
)
from .indices import INDICES, SINGLE_MODELS, index_by_seed, index_cases, index_claims, index_table  # noqa: F401
from .second_order import second_order, second_order_by_seed, second_order_claims  # noqa: F401
from .claims import (
    claims,
    drift_claims,
    noise_claims,
    reading_claims,
    separate_claims,
    separate_noise_claims,
    tuner_claims,
    two_orders_claims,  # noqa: F401
    unit_b_spread_claims,
    verdict_grid,
)
