"""The book's chapters as studies: one package per chapter, parameters, experiments and claims apart; one
function per table or figure, returning a tidy DataFrame.

- :mod:`navlib.studies.compass` -- the compass chapter: paper A's turntable comparison (LS, BP, DE-BP, ADE-BP,
  ELM), document B's ELM compass patent (:mod:`navlib.studies.compass.elm_patent`), and both on a real
  compass (:mod:`navlib.studies.compass.real`);
- :mod:`navlib.studies.gyro` -- the gyro chapter: paper C, RBF identification of the axial gyro drift;
- :mod:`navlib.studies.accelerometer` -- the accelerometer chapter: paper D, temperature drift by
  IAFSA-SCM-ANFIS;
- :mod:`navlib.studies.celestial` -- the celestial chapter: paper E, BP-network-aided inertial/celestial
  navigation;
- :mod:`navlib.studies.workbench` -- the workbench chapter: the compare/diagnose/add loop on simulated data
  with hidden effects and on real recordings.
"""
