"""The model the discrepancy workflow ends with: a base model plus fitted effects.

:class:`ExtendedModel` is an ordinary model object: ``simulate`` it on a new excitation,
``fit`` it to another recording (same effects, parameters refitted), print its ``report``,
or hand ``base`` (a :class:`contactlab.Masing` or normal-contact model) to other tools.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._arrays import as_1d
from ..errors import InputError
from ._family import Family, Prepared
from ._inputs import arrays as _arrays
from .select import fit


class ExtendedModel:
    """Base model with effects, as found by :func:`contactlab.diagnose`.

    Parameters
    ----------
    family : Family
        Tangential or normal family (defines the base model and candidate physics).
    effects : tuple of str
        Effect names in the order added.
    params, stderr : dict
        All parameter values (base and effects) and their standard errors.
    """

    def __init__(
        self,
        family: Family,
        effects: tuple[str, ...],
        params: dict[str, float],
        stderr: dict[str, float] | None = None,
        context: dict[str, float] | None = None,
    ) -> None:
        self.family = family
        self.context = dict(context or {})
        self.effects = tuple(effects)
        self.params = dict(params)
        self.stderr = dict(stderr or {})

    @property
    def kind(self) -> str:
        return self.family.kind

    @property
    def base(self) -> Any:
        """The base model with the fitted base parameters (effects not included)."""
        return self.family.base_model(self.params, self.context)

    def __repr__(self) -> str:
        eff = " + ".join(self.effects) if self.effects else "no effects"
        ps = ", ".join(f"{k}={v:.4g}" for k, v in self.params.items())
        return f"ExtendedModel({self.kind}: {eff}; {ps})"

    def simulate(self, t: Any, u: Any) -> np.ndarray:
        """Measured output for the input ``u`` sampled at ``t`` (tangential: ``F`` for
        displacement ``x``; normal: ``delta`` for pressure ``p``), SI units."""
        ta = as_1d(t, "t")
        ua = as_1d(u, self.family.input_name)
        if ta.size != ua.size:
            raise InputError(f"t has {ta.size} samples but {self.family.input_name} has {ua.size}")
        d = Prepared.build(ta, ua)
        d.extra.update(self.context)
        self.family.prepare(d)
        return self.family.predict(self.params, self.effects, d)

    def fit(self, recording: Any) -> ExtendedModel:
        """Refit all parameters (same effects) to ``recording``; returns a new model."""
        t, u, y = _arrays(recording, self.family)
        d = Prepared.build(t, u, y)
        d.extra.update(self.context)
        self.family.prepare(d)
        res = fit(
            self.family, self.effects, d, np.ones(y.size, bool), self.params, self.family.scales(d)
        )
        out = ExtendedModel(self.family, self.effects, res.params, res.stderr, self.context)
        out.fit_result_ = res  # type: ignore[attr-defined]
        return out

    def coefficients(self) -> dict[str, float] | None:
        """Normal contact: the stiffness law's coefficients of the paper's eq. 6 (``a1`` Pa/m,
        ``a2`` Pa/m², ``a3`` Pa/m³), independent of the record's displacement scale ``δ_r``
        that ``kappa1`` and ``kappa`` are relative to; None for the tangential model."""
        f = getattr(self.family, "coefficients", None)
        return None if f is None else f(self.params, self.effects, self.context)

    def to_dict(self) -> dict[str, Any]:
        out = {
            "model": self.kind,
            "effects": list(self.effects),
            "parameters": dict(self.params),
            "context": dict(self.context),
            "stderr": {k: (v if np.isfinite(v) else None) for k, v in self.stderr.items()},
        }
        coeffs = self.coefficients()
        if coeffs is not None:
            out["coefficients"] = coeffs
            out["coefficient_units"] = {"a1": "Pa/m", "a2": "Pa/m^2", "a3": "Pa/m^3"}
        return out

    def report(self) -> str:
        """Parameters with standard errors, one per line."""
        lines = [repr(self)]
        for k, v in self.params.items():
            s = self.stderr.get(k, np.nan)
            lines.append(f"  {k:>8} = {v:.6g} ± {s:.2g}")
        return "\n".join(lines)
