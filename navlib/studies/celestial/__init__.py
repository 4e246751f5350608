"""The celestial chapter's study: paper E (Sun et al. 2019), BP-network-aided inertial/celestial integrated
navigation, with its tables, figures and claims (notebook ``notebooks/celestial.ipynb``).

- :mod:`navlib.studies.celestial.parameters` -- the study's settings ``StudySpec`` (with
  ``StudySpec.from_notebook`` for the notebook's parameters cell, ``NOTEBOOK_DEFAULTS``), the cases, methods
  and phases it scores, paper E's BP network ``bp_params`` and the seed of every draw ``seed_of``;
- :mod:`navlib.studies.celestial.step` -- the running BPKF's network step at one filter epoch (45 raw gains
  or 6 QR features and one forward pass), its paired timings ``step_timings`` and operation count
  ``step_flops``;
- :mod:`navlib.studies.celestial.simulation` -- the experiment: ``simulate`` flies the runs, filters them
  and trains the networks (every repeat, the scale-factor sweep, the blind effects, the ``trainlm``
  timings) and returns a ``StudyData``;
- :mod:`navlib.studies.celestial.scores` -- one method's error per run, paired run by run (``per_run``,
  ``sweep_per_run``, ``phase_per_run``), and the rows of the innovation diagnosis by case;
- :mod:`navlib.studies.celestial.tables` -- the chapter's tables and figures as tidy DataFrames (Tables 2-5,
  training times, error traces, the sweep, the blind-effect diagnosis and the decision rule, the devices);
- :mod:`navlib.studies.celestial.claims` -- the claims under the one verdict rule (``claims``), the sweep's
  verdicts per level and the results file's extra numbers.

The modules import one way: parameters, step <- simulation <- scores <- tables <- claims.  Every public name is
also here: ``from navlib.studies import celestial``, then ``celestial.simulate(spec)``.
"""

from .parameters import (
    AXES,
    CASE_LABEL,
    CASES,
    KINDS,
    LM_NETS,
    NOTEBOOK_DEFAULTS,
    PHASES,  # noqa: F401
    RUN_KEYS,
    SEED_PARTS,
    SWEEP_METHODS,
    StudySpec,
    bp_params,
    seed_of,
)
from .step import STEP_READINGS, StepNet, step, step_flops, step_timings  # noqa: F401
from .simulation import StudyData, quiet_repeats_flown, simulate  # noqa: F401
from .scores import per_run, phase_per_run, sweep_per_run  # noqa: F401
from .tables import (
    accuracy_table,
    blind_effect_table,
    case_label,
    device_table,
    error_traces,  # noqa: F401
    innovation_test,
    lm_timing_pairs,
    loop_runs,
    loop_table,
    method_summary,
    named_effect,
    overall,
    paper_numbers,
    step_time,
    step_timing_pairs,
    sweep_table,
    time_ratio,
    timing_pairs,
    trainlm_time,
    training_time,
    yaw_manoeuvre,
)
from .claims import (
    FALSE_NAMING_BOUNDARY,
    MISSING_EFFECT,
    NAMED_RATE_BOUNDARY,
    TURN_CLAIM,  # noqa: F401
    claims,
    improvement_pct,
    results_extra,
    sweep_verdicts,
)
