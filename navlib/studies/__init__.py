"""One module per source document; one function per table or figure, returning a tidy DataFrame.

- :mod:`navlib.studies.compass` -- the compass chapter: paper A's turntable comparison (LS, BP, DE-BP, ADE-BP,
  ELM), document B's ELM compass patent, and both on a real compass (a package: parameters, experiments and
  claims apart);
- :mod:`navlib.studies.paper_c` -- paper C, RBF identification of the axial gyro drift;
- :mod:`navlib.studies.paper_e` -- paper E, BP-network-aided inertial/celestial navigation.
- :mod:`navlib.studies.paper_d` -- paper D, accelerometer temperature drift by IAFSA-SCM-ANFIS.
"""
