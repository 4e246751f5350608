"""One protocol for heading-compensation methods.

A *method* is fitted on a training sweep and returns a *fitted compensator*::

    fitted = method.fit(measured_deg, reference_deg, rng)      # or method.fit_many(..., rngs)
    fitted.correct(measured_deg)  -> compensated heading, deg in [0, 360)
    fitted.predict(measured_deg)  -> the fitted model's raw output (network output, deviation, ...)

Everything a method needs to map a measured heading to a compensated one lives inside the fitted object:
the min-max scalers of a network (:class:`ScaledRegressor`, :class:`navlib.methods.bpnet.BPNet`) and the
choice of network target, the true heading or the heading error (:class:`HeadingTarget`).  The measured
heading handed to ``fit`` and ``correct`` may be unwrapped along the sweep (networks need a continuous
input); models of periodic form (Smith, the planar model) do not mind.

The registry of the compass's concrete methods, keyed by stable ids with display labels, is
:mod:`navlib.methods.compass_methods` (``METHODS``); the compass chapter's studies and the workbench's
``navlib compare`` both fit them from there.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Literal, Protocol, Sequence

import numpy as np

from ..errors import check_choice
from .scaling import MinMax

TargetKind = Literal["heading", "error"]


class Fitted(Protocol):
    """A fitted compensator."""

    def predict(self, measured_deg) -> np.ndarray: ...

    def correct(self, measured_deg) -> np.ndarray: ...


class Method(Protocol):
    """A compensation method: ``fit`` one run, ``fit_many`` several independent runs (one generator
    each; deterministic methods ignore the generators)."""

    def fit(self, measured_deg, reference_deg, rng=None) -> Fitted: ...

    def fit_many(self, measured_deg, reference_deg, rngs: Sequence) -> list[Fitted]: ...


@dataclass(frozen=True)
class HeadingTarget:
    """What a network learns: ``'heading'`` (output = true heading, paper A's Sec. 1.1) or ``'error'``
    (output = true - measured, the abstract's wording; compensated = measured + output)."""

    kind: TargetKind = "heading"

    def __post_init__(self):
        check_choice("network_target", self.kind, ("heading", "error"))

    def target(self, measured_deg, reference_deg) -> np.ndarray:
        m, r = np.asarray(measured_deg, dtype=float), np.asarray(reference_deg, dtype=float)
        return r - m if self.kind == "error" else r

    def heading(self, measured_deg, output) -> np.ndarray:
        """Compensated heading in [0, 360) from the network output."""
        out = np.asarray(output, dtype=float)
        return np.mod(
            np.asarray(measured_deg, dtype=float) + out if self.kind == "error" else out, 360.0
        )


@dataclass
class ScaledRegressor:
    """A model trained on min-max normalised data, with its scalers: ``predict`` maps raw inputs to raw
    outputs, ``t_scale.inverse(model.predict(x_scale.transform(x)))``."""

    model: Any
    x_scale: MinMax
    t_scale: MinMax

    @classmethod
    def fit(
        cls, x, t, fit_normalised: Callable[[np.ndarray, np.ndarray], Any]
    ) -> "ScaledRegressor":
        """Fit the scalers on ``x`` and ``t``, then ``fit_normalised(x', t')`` (returns the model)."""
        xs, ts = MinMax.fit(x, name="network input"), MinMax.fit(t, name="network target")
        return cls(fit_normalised(xs.transform(x), ts.transform(t)), xs, ts)

    @property
    def n_hidden(self) -> int:
        return self.model.n_hidden

    def predict(self, x) -> np.ndarray:
        return self.t_scale.inverse(
            self.model.predict(self.x_scale.transform(np.asarray(x, dtype=float)))
        )


@dataclass
class NetworkCompensator:
    """A trained regressor (scalers inside) and the target it learnt."""

    net: Any
    target: HeadingTarget = HeadingTarget()
    info: dict = field(default_factory=dict)

    def predict(self, measured_deg) -> np.ndarray:
        return self.net.predict(np.asarray(measured_deg, dtype=float))

    def correct(self, measured_deg) -> np.ndarray:
        return self.target.heading(measured_deg, self.predict(measured_deg))


@dataclass
class ModelCompensator:
    """A fitted explicit model exposing ``correct`` (Smith's series, the planar model, or none)."""

    model: Any = None
    info: dict = field(default_factory=dict)

    def predict(self, measured_deg) -> np.ndarray:
        return self.correct(measured_deg)

    def correct(self, measured_deg) -> np.ndarray:
        m = np.asarray(measured_deg, dtype=float)
        return np.mod(m, 360.0) if self.model is None else np.mod(self.model.correct(m), 360.0)


class MethodBase:
    """``fit`` from ``fit_many`` (or the reverse); subclasses implement one of them."""

    def fit(self, measured_deg, reference_deg, rng=None) -> Fitted:
        return self.fit_many(measured_deg, reference_deg, [rng])[0]

    def fit_many(self, measured_deg, reference_deg, rngs: Sequence) -> list[Fitted]:
        return [self.fit(measured_deg, reference_deg, g) for g in rngs]
