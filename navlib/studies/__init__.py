"""One module per source document; one function per table or figure, returning a tidy DataFrame.

- :mod:`navlib.studies.paper_a` -- paper A, the compass turntable comparison (LS, BP, DE-BP, ADE-BP, ELM);
- :mod:`navlib.studies.patent_b` -- document B, the ELM compass patent;
- :mod:`navlib.studies.paper_c` -- paper C, RBF identification of the axial gyro drift;
- :mod:`navlib.studies.celestial` -- the celestial chapter: paper E, BP-network-aided inertial/celestial navigation.
- :mod:`navlib.studies.paper_d` -- paper D, accelerometer temperature drift by IAFSA-SCM-ANFIS.
"""
