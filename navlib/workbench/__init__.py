"""The workbench: compare a model of named physical effects with measurements, see where it fails, find
the missing effect, add it, and watch the error fall.

- :mod:`navlib.workbench.effects` -- the two types everything is built from: :class:`.Effect` (name,
  parameters with units, needed columns, meaning, and for a user effect its contribution to the model) and
  :class:`.System` (unit, catalogue, ``load``, ``fit``, ``structure``); the registry :data:`.SYSTEMS`;
  user effects from a file (:func:`.load_effects`);
- :mod:`navlib.workbench.fit` -- :class:`.Fit` (residuals, held-out error, ``add``), the compass and drift
  systems, simulated data;
- :mod:`navlib.workbench.magnetometer` -- the 3-D magnetometer system (hard and soft iron, misalignment,
  time lag; the local field estimated);
- :mod:`navlib.workbench.screen` -- before any test: outlying rows set aside (robust, MAD-studentised
  residuals), the numerical floor, the noise's serial correlation;
- :mod:`navlib.workbench.serial` -- the AR(p) noise model of a time series (restricted maximum likelihood)
  and its whitening, so that the F tests hold on correlated samples;
- :mod:`navlib.workbench.diagnose` -- which effect is missing, with family-wise false-alarm control;
- :mod:`navlib.workbench.loop` -- the whole loop (diagnose, add, repeat) as one function, its JSON and report;
- :mod:`navlib.workbench.trials` -- detection and false-alarm rates on data with hidden effects, in and
  outside the catalogue, with independent and with serially correlated noise.

Adding a system (e.g. an accelerometer): write ``navlib/workbench/accelerometer.py`` that defines its
catalogue (a dict of :class:`.Effect`), a loader ``load(path) -> DataFrame`` (one-line InputError naming file,
column, row; :func:`navlib.data.tables.read_table` with a finite range for every column the model uses, and
plausibility checks of units and stuck sensors stated in its docstring), ``fit(data, effects, start) -> Fit`` (use :func:`navlib.workbench.fit.best_least_squares`
from the previous parameters and a linearised start; add user effects with
:func:`navlib.workbench.fit.user_columns`), and ``structure(fit) -> [(what, X, scale)]``; then call
``register_system(System(name, unit, catalogue, load, fit, structure, meaning))`` at the end of the module
and import the module below (and name its measured columns in :data:`navlib.workbench.fit.MEASURED`, which
the outlier screen needs).  ``fit_model``, ``Fit.add``, ``diagnose``, ``loop`` and the CLI
(``python -m navlib loop accelerometer FILE``) then work unchanged.
"""

from . import accelerometer, fit, magnetometer, magnetometer_free  # noqa: F401  (importing registers the compass, drift, magnetometer

#                                                and accelerometer systems)
from .effects import SYSTEMS, Effect, System, get_system, load_effects, register_system  # noqa: F401
