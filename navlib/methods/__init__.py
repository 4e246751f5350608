"""Estimators, networks, optimisers and filters: the compensation methods the papers compare.

- :mod:`navlib.methods.smith` -- Archibald Smith's deviation series and the 8-position least squares (A);
- :mod:`navlib.methods.de` -- differential evolution DE/rand/1/bin and paper A's adaptive variant;
- :mod:`navlib.methods.compensator` -- the protocol every compensation method follows (fit, predict, correct);
- :mod:`navlib.methods.bpnet` -- the 1-M-1 BP network, MATLAB's default BP and their trainers (A);
- :mod:`navlib.methods.lm` -- MATLAB's ``trainlm`` (batched) and ``dividerand`` with its validation stop;
- :mod:`navlib.methods.elm` -- extreme learning machine and the patent's incremental back-tuned ELM (B);
- :mod:`navlib.methods.ielm` -- Huang's point-incremental ELM (I-ELM), the baseline of the patent's iterations claim (B);
- :mod:`navlib.methods.preprocess` -- the patent's median filter and field-gravity screen (B);
- :mod:`navlib.methods.rbf` -- MATLAB-compatible ``newrb``/``newrbe`` RBF networks (C);
- :mod:`navlib.methods.scaling` -- explicit min-max scaling (also MATLAB's ``mapminmax``);
- :mod:`navlib.methods.seeding` -- the one seeding convention (``SeedSequence(base).spawn``; :mod:`navlib.seeding`);
- :mod:`navlib.methods.arrays` -- shared input checks;
- :mod:`navlib.methods.kalman` -- the INS/star-sensor Kalman filter, QR gain features, innovation GLR test (E);
- :mod:`navlib.methods.subclust` -- MATLAB ``subclust``/``genfis2`` and first-order Sugeno inference (D);
- :mod:`navlib.methods.anfis` -- ANFIS with Jang's hybrid learning as MATLAB ``anfis`` (D);
- :mod:`navlib.methods.fish_swarm` -- artificial fish swarm and its improved variant, batched (D);
- :mod:`navlib.methods.mlp` -- a generic n_in-n_hidden-n_out tansig/logsig-purelin network in torch, trained
  full-batch, with its time per pass (D, E).
"""
