"""Issue 18: significance on serially correlated samples, over at least 100 trials per case.

Hand-turned 10 Hz magnetometer recordings (navlib.workbench.magnetometer.simulate_hand_turned) and compass
sweeps read every 5 s (navlib.workbench.fit.simulate), with AR(1) noise of lag-1 correlation 0.9: with
nothing hidden the diagnosis must end "consistent with noise" in at least 95 % of trials, and each
catalogued effect hidden at 3 times the noise must still be named in at least 95 %.  The trials run in two
processes (the rates do not depend on it: every trial has its own seed)."""

import numpy as np
import pytest

from navlib import verdicts
from navlib.workbench.trials import correlated_noise_rates, correlated_noise_study

pytestmark = pytest.mark.slow  # Monte Carlo rates over 100 trials per case: not in make check

TARGET = 0.95
TRIALS = 100


@pytest.fixture(scope="module", params=["magnetometer", "compass"])
def rates_of(request):
    study = correlated_noise_study(
        request.param, correlations=(0.9,), ratio=3.0, seeds=range(TRIALS), workers=2
    )
    return study, correlated_noise_rates(study)


def test_correlated_noise_with_nothing_hidden_is_called_noise(rates_of):
    study, rates = rates_of
    none = rates.xs("(none)", level="hidden effect")
    assert int(none["trials"].iloc[0]) >= TRIALS
    assert none["value"].iloc[0] >= TARGET, none
    # the rate is a Wilson interval over independent trials (navlib.verdicts.wilson)
    k = int(study[study.hidden == "(none)"].consistent_with_noise.sum())
    assert verdicts.wilson(k, TRIALS).lo == pytest.approx(none["95% low"].iloc[0])
    # the noise model found the correlation the data were made with
    assert np.median(study.lag1) == pytest.approx(0.9, abs=0.03)


def test_an_effect_three_times_the_noise_is_still_named(rates_of):
    study, rates = rates_of
    hidden = [h for h in study.hidden.unique() if h != "(none)"]
    assert len(hidden) >= 4  # every catalogued effect of the system
    for h in hidden:
        row = rates.xs(h, level="hidden effect")
        assert int(row["trials"].iloc[0]) >= TRIALS and row["value"].iloc[0] >= TARGET, (h, row)
