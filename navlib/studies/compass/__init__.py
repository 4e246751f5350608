"""The compass chapter (``notebooks/compass.ipynb``): paper A's turntable comparison of LS, BP, DE-BP, ADE-BP
and ELM under every reading of its training, document B's ELM patent, and both documents' methods on a
real compass.

Paper A's study and the pieces both studies share are read here as one namespace (``compass.seed_study``,
``compass.claims``, ``compass.Sweeps``, ...); document B, the real compass and the hidden-node count are sub-namespaces
(``compass.elm_patent.claims``, ``compass.elm_iterations.iteration_study``,
``compass.real.real_claims``).  Which module holds what:

- :mod:`navlib.studies.compass.parameters` -- the methods' settings (``StudyParams``), the method lists and
  constants of the studies, the robustness study's draw rule, and ``params_from_notebook`` (the notebook's
  flat parameters to these objects);
- :mod:`navlib.studies.compass.sweeps` -- shared by both studies: the sweeps (``Sweeps``), a compensation's
  test-sweep error, and the per-seed and paired statistics the claims rest on;
- :mod:`navlib.studies.compass.turntable` -- paper A's runs: the seed study, the noise floor and noise study,
  the LS against its positions, the DE stage's convergence, our choices;
- :mod:`navlib.studies.compass.tables` -- the runs shaped for display and for the results file;
- :mod:`navlib.studies.compass.turntable_claims` -- paper A's claims and the verdict tables;
- :mod:`navlib.studies.compass.robustness` -- paper A's claims on drawn compasses;
- :mod:`navlib.studies.compass.hidden_nodes` -- paper A's hidden-node count (MATLAB's BP against M) and its
  claims;
- :mod:`navlib.studies.compass.initial_weights` -- paper A's "ADE overcomes the difficulty of choosing BP's
  initial weights" on the seed study's runs: runs far from the floor and the spread over seeds;
- :mod:`navlib.studies.compass.ellipse` -- paper A's "the ellipse-hypothesis model's accuracy is limited"
  against ADE-BP (by construction on our simulator; real sweeps decide);
- :mod:`navlib.studies.compass.elm_patent` -- document B: node count, data preparation and glitches, small
  samples, and its claims;
- :mod:`navlib.studies.compass.elm_iterations` -- document B's iterations: the back-tuned ELM against
  Huang's point-incremental ELM, and with its pruning off;
- :mod:`navlib.studies.compass.elm_nodes` -- document B's node-count claims (each added node lowers the
  training error; the node count's influence) on the chapter's node-count runs;
- :mod:`navlib.studies.compass.elm_data` -- document B's claims about its data: zero error on N samples,
  min-max normalisation, the sample size deep learning needs;
- :mod:`navlib.studies.compass.explicit_model` -- document B's "any explicit error model can hardly include
  all error factors": the ellipse model against the back-tuned ELM on the same training readings, on a
  simulated compass with the AMR cross-axis effect (real sweeps decide, in ``real``);
- :mod:`navlib.studies.compass.real` -- both documents' methods and claims on BROAD's real level sweeps.

The methods themselves (ids, labels, readings, settings) are registered in
:mod:`navlib.methods.compass_methods`; their public names are re-exported here.
"""

from ...methods.compass_methods import (
    ADE_DEFAULT_RULES,
    ADE_RULE_READINGS,
    ELM_METHODS,
    LEGACY_NAMES,  # noqa: F401
    LS_MODELS,
    METHODS,
    R1,
    R2,
    R2V,
    R3,
    R3V,
    R4,
    R4V,
    RA,
    READINGS,
    RULE_READINGS,
    RUN_COST_S,
    EightPosition,
    MethodParams,
    MethodSpec,
    NetworkMethod,
    PlanarFit,
    Uncompensated,
    elm_trainer,
    fit_family,
    fit_method,
    fitting_units,
    label,
    method_id,
    unit_cost,
)

# document B, the real compass and the hidden-node count: sub-namespaces
from . import (  # noqa: F401
    ellipse,
    elm_data,
    elm_iterations,
    elm_nodes,
    elm_patent,
    explicit_model,
    hidden_nodes,
    initial_weights,
    real,
)
from .parameters import (
    BASE_READINGS,
    BOX_BOUNDS,
    BP_VARIANTS,
    CONVERGENCE_AT_FRACTIONS,  # noqa: F401
    CONVERGENCE_RMS_DEG,
    FLOOR_GRID_UT,
    LS_POSITIONS,
    LS_REF_POSITIONS,
    LS_TOLERANCE_MAX_DEG,
    MAIN_METHODS,
    NOISE_METHODS,
    NOTEBOOK_DEFAULTS,
    R_ANY,
    ROBUST_METHODS,
    ChapterParams,
    CompassDrawRule,
    StudyParams,
    params_from_notebook,
)
from .robustness import (
    draw_compass,
    draw_compasses,
    robustness_flips,
    robustness_study,  # noqa: F401
    robustness_table,
)
from .sweeps import (
    TRAINING_ONLY,
    Sweeps,
    error_stats,
    ls_assumption,
    ordering_probability,  # noqa: F401
    ordering_rate,
    paired_by_seed,
    paired_rms_difference,
    paired_seed_difference,
    per_seed,
    rms_deg,
    test_errors,
    width_estimate,
)
from .tables import (
    fig4_panels,
    noise_summary,
    ordering_table,
    reach_summary,
    results_methods,  # noqa: F401
    side_by_side,
    summarize,
)
from .turntable import (
    MAX_TASK_S,
    SEED_BATCH,
    choices_study,
    compensate,
    convergence_curves,  # noqa: F401
    convergence_generations,
    floor_curve,
    generations_to_reach,
    implied_noise_ut,
    largest_noise,
    ls_positions_rms,
    noise_study,
    seed_studies,
    seed_study,
)
from .turntable_claims import (
    READING_KEYS,
    claims,
    convergence_claims,
    headline_claims,  # noqa: F401
    rule_reading_table,
    sweep_claims,
    verdict_table,
)
