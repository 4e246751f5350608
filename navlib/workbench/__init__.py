"""The workbench: compare a model of named physical effects with measurements, see where it fails, find
the missing effect, add it, and watch the error fall.

- :mod:`navlib.workbench.effects` -- the effect catalogues of each system;
- :mod:`navlib.workbench.fit` -- fitting a model of effects, residuals, held-out error, simulated data;
- :mod:`navlib.workbench.diagnose` -- which effect is missing, with family-wise false-alarm control;
- :mod:`navlib.workbench.trials` -- detection and false-alarm rates on data with hidden effects.
"""
