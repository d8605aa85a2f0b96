"""What :func:`contactlab.diagnose` returns: the report of a diagnosis (:class:`DiagnosisReport`)
with its steps (:class:`Step`) and the effects named (:class:`Effect`), their text and JSON
forms. Split from :mod:`contactlab.diagnose.workflow`, which names them as before."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._moved import moved
from ._family import Prepared
from .model import ExtendedModel
from .select import Trial, Verdict

__all__ = ["DiagnosisReport", "Effect", "Step"]


@dataclass(frozen=True)
class Effect:
    """An effect added to the model, with fitted parameters and standard errors.

    A standard error of ``inf`` means the parameter is not identifiable from this record.
    """

    name: str
    parameters: dict[str, float]
    stderr: dict[str, float]
    #: why the fitted effect is physically plausible on this record, in numbers
    plausibility: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "parameters": dict(self.parameters),
            "stderr": {k: _finite_or_none(v) for k, v in self.stderr.items()},
            "plausibility": self.plausibility,
        }


@dataclass(frozen=True)
class Step:
    """Held-out errors of the model after one step (``added`` is None for the base fit).

    ``heldout_rms`` and ``heldout_peak``: RMS and largest absolute error of the output over
    the held-out cycles (each cycle predicted by the fit that did not see it);
    ``energy_error``: ``Σ |E_model - E_measured| / Σ |E_measured|`` over the held-out cycles,
    ``E`` the loop area of one cycle; ``candidates``: the verdict on each candidate tried
    after this step. A step of the backward elimination has ``removed`` set (and ``added``
    None): the effect dropped because, refitted without it, the model no longer needs it
    (``removal`` is the verdict on adding it back). A swap has both: ``removed`` replaced by
    ``added``, which predicts the held-out cycles better (``removal`` is the verdict on it).
    A pair move (:func:`_pair_search`) has ``added`` ``"a + b"``: both added at once.
    """

    added: str | None
    heldout_rms: float
    heldout_peak: float
    energy_error: float
    candidates: tuple[Verdict, ...] = ()
    #: the effect the backward step dropped (``added`` is None then), with the verdict on it
    removed: str | None = None
    removal: Verdict | None = None

    @property
    def label(self) -> str:
        """``base model``, ``+ name`` (added), ``- name`` (dropped by the backward step) or
        ``out ⇄ in`` (a swap)."""
        if self.removed is not None and self.added is not None:
            return f"{self.removed} ⇄ {self.added}"
        if self.removed is not None:
            return f"- {self.removed}"
        return "base model" if self.added is None else f"+ {self.added}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "added": self.added,
            "removed": self.removed,
            "heldout_rms": self.heldout_rms,
            "heldout_peak": self.heldout_peak,
            "energy_error": _finite_or_none(self.energy_error),
        }


def _finite_or_none(v: float) -> float | None:
    return float(v) if np.isfinite(v) else None


@dataclass
class DiagnosisReport:
    """What :func:`diagnose` found. ``to_dict()`` gives the JSON layout of issue 5.

    Attributes
    ----------
    model : str
        ``"tangential"`` or ``"normal"``.
    effects : list of Effect
        Effects added, in the order added (empty when the base model suffices).
    steps : list of Step
        Held-out RMS / peak / loop-energy error of the base model and after each addition,
        with the verdict on every candidate tried at that step.
    where : list of str
        Where the base model's residual lives, as statements with numbers.
    noise_rms : float
        Output noise RMS estimated from the data (units of the output).
    final_model : ExtendedModel
        The base model plus the effects, ready to simulate or refit.
    """

    model: str
    effects: list[Effect]
    steps: list[Step]
    where: list[str]
    noise_rms: float
    final_model: ExtendedModel
    location: dict[str, Any] = field(repr=False, default_factory=dict)
    _data: Prepared | None = field(repr=False, default=None)
    _trials: list[Trial] = field(repr=False, default_factory=list)
    #: whether ``model`` was inferred from the recording's channels (``diagnose(model=None)``)
    model_inferred: bool = False
    # -- issue 29 items 1-3 (detection.py, power.py, misfit.py) -----------------------------
    #: noise of both channels, estimated separately (:class:`.detection.ChannelNoise`)
    channel_noise: Any = field(repr=False, default=None)
    #: per candidate not named: the smallest magnitude this record would have revealed
    #: (:class:`.power.Detectable`)
    not_detected: list[Any] = field(repr=False, default_factory=list)
    #: structure the final model leaves over phase and branch (:class:`.misfit.Unexplained`)
    unexplained: Any = field(repr=False, default=None)

    @property
    def effect_names(self) -> list[str]:
        return [e.name for e in self.effects]

    @property
    def prepared(self) -> Prepared | None:
        """The data as the diagnosis saw it (filtered, weighted, cycles found), for plots."""
        return self._data

    @property
    def trials(self) -> list[Trial]:
        """Every model fitted along the way, base first (for plots and inspection)."""
        return list(self._trials)

    def to_dict(self) -> dict[str, Any]:
        return {
            "model": self.model,
            "effects": [e.to_dict() for e in self.effects],
            "steps": [s.to_dict() for s in self.steps],
            "where": list(self.where),
            "noise_rms": self.noise_rms,
            "final_model": self.final_model.to_dict(),
            # issue 29 item 5: the regime analyze decides, the final h0 against its plateau
            **({"regime": self.location["regime"]} if "regime" in self.location else {}),
            **({"h0_check": self.location["h0_check"]} if "h0_check" in self.location else {}),
            # issue 29: both channels' noise, stated power, unexplained structure
            **({"channel_noise": self.channel_noise.to_dict()} if self.channel_noise else {}),
            **(
                {"not_detected": [b.to_dict() for b in self.not_detected]}
                if self.channel_noise
                else {}
            ),
            **({"unexplained": self.unexplained.to_dict()} if self.unexplained else {}),
            # issue 29 item 5: effects the final model was refitted without, and candidates
            # that passed the held-out rules but are physically implausible on the record,
            # each with its reason
            **(
                {"withdrawn": dict(self.location["withdrawn_why"])}
                if "withdrawn_why" in self.location
                else {}
            ),
            **({"refused": dict(self.location["refused"])} if "refused" in self.location else {}),
            # issue 29: a flagged final model, and the candidate the flag route named to
            # explain it (or why none): :mod:`contactlab.diagnose.flag_route`
            **(
                {"flag_route": dict(self.location["flag_route"])}
                if "flag_route" in self.location
                else {}
            ),
            # a frame's reconstructed force: its mass read from an inertia term
            **(
                {"frame_constants": dict(self.location["frame_constants"])}
                if "frame_constants" in self.location
                else {}
            ),
        }

    def to_json(self, indent: int = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def table(self, unit: str = "") -> str:
        """The gap-shrink table as text (``unit``: the output's, named in the header)."""
        u = f" [{unit}]" if unit else ""
        lines = [
            f"{'step':<24}{'held-out RMS' + u:>18}{'/ noise':>9}{'peak' + u:>12}{'energy err':>12}",
        ]
        for s in self.steps:
            name = s.label
            lines.append(
                f"{name:<24}{s.heldout_rms:>18.4g}{s.heldout_rms / self.noise_rms:>9.2f}"
                f"{s.heldout_peak:>12.4g}{100 * s.energy_error:>11.2f}%"
            )
        return "\n".join(lines)

    def param_units(self) -> dict[str, str]:
        """SI unit of every parameter name of the family (base and candidates)."""
        fam = self.final_model.family
        specs = list(getattr(fam, "base_params", ()))
        for cand in getattr(fam, "candidates", {}).values():
            specs.extend(getattr(cand, "params", ()))
        return {s.name: s.unit for s in specs}

    def noise_text(self) -> str:
        """``noise RMS (declared|estimated from the data): 0.0123 N``, as the console and the
        HTML report both say it."""
        how = "declared" if self.location.get("noise_declared") else "estimated from the data"
        unit = getattr(self.final_model.family, "output_unit", "")
        return f"noise RMS ({how}): {self.noise_rms:.4g} {unit}".rstrip()

    def summary(self) -> str:
        """Findings, effects with parameters (with their units) and the argument that makes
        each physically plausible, and the gap-shrink table."""
        how = " (inferred from the channels; model= sets it)" if self.model_inferred else ""
        out = [f"contactlab diagnose — {self.model} model{how}", ""]
        import textwrap

        def wrap(text: str, first: str, rest: str) -> str:
            return textwrap.fill(text, width=100, initial_indent=first, subsequent_indent=rest,
                                 break_long_words=False, break_on_hyphens=False)  # fmt: skip

        out += ["Where the base model disagrees:"] + [wrap(w, "  - ", "    ") for w in self.where]
        out.append("")
        if not self.effects:
            out.append("No candidate improves the held-out error significantly.")
        units = self.param_units()
        for e in self.effects:
            parts = []
            for k, v in e.parameters.items():
                u = f" {units[k]}" if units.get(k) else ""
                se = e.stderr.get(k, np.nan)
                pm = f" ± {se:.2g}" if np.isfinite(se) else " (error not identifiable)"
                parts.append(f"{k} = {v:.4g}{pm}{u}")
            out.append(wrap(f"Added {e.name}: {', '.join(parts)}", "", "    "))
            if e.plausibility:
                out.append(wrap(f"why plausible: {e.plausibility}", "  ", "    "))
        coeffs = self.final_model.coefficients()
        if coeffs is not None and ({"kappa1", "kappa"} & set(self.final_model.params)):
            law = (
                "Stiffness law (eq. 6): "
                + ", ".join(
                    f"{k} = {v:.4g} {u}"
                    for (k, v), u in zip(coeffs.items(), ("Pa/m", "Pa/m²", "Pa/m³"), strict=True)
                )
                + f" (κ1 and κ are relative to δ_r = {self.final_model.context['delta_r']:.4g} m)"
            )
            out.append(wrap(law, "", "    "))
        unit = getattr(self.final_model.family, "output_unit", "")
        out += ["", self.table(unit), self.noise_text()]
        if self.channel_noise is not None:  # issue 29: stated power, unexplained structure
            cn = self.channel_noise
            out.append(
                f"channel noise: input {cn.input:.3g} {cn.input_unit}, output "
                f"{cn.output:.3g} {cn.output_unit}"
            )
            out += [wrap(b.sentence(), "  - ", "    ") for b in self.not_detected]
        if self.unexplained is not None:
            out.append(wrap(self.unexplained.sentence(), "", "    "))
        return "\n".join(out)

    # -- figures ------------------------------------------------------------------------------
    def plot_overlay(self, step: int | None = None, ax: Any = None) -> Any:
        """Measured and modelled loops (output against input), base model and final model.
        Deprecated: use :func:`contactlab.report.diagnosis_plots.plot_overlay`."""
        fn = moved(
            "contactlab.diagnose.DiagnosisReport",
            "plot_overlay",
            "contactlab.report.diagnosis_plots",
        )
        return fn(self, step=step, ax=ax)

    def plot_residual(self, ax: Any = None) -> Any:
        """Held-out residual over time, before (base) and after (final model).
        Deprecated: use :func:`contactlab.report.diagnosis_plots.plot_residual`."""
        return moved(
            "contactlab.diagnose.DiagnosisReport",
            "plot_residual",
            "contactlab.report.diagnosis_plots",
        )(self, ax=ax)

    def plot_location(self, ax: Any = None) -> Any:
        """Where the base residual lives: residual power by position in the branch.
        Deprecated: use :func:`contactlab.report.diagnosis_plots.plot_location`."""
        return moved(
            "contactlab.diagnose.DiagnosisReport",
            "plot_location",
            "contactlab.report.diagnosis_plots",
        )(self, ax=ax)

    def write_html(self, directory: Any) -> Any:
        """Write a self-contained ``diagnose.html`` (figures embedded, also as PNGs under
        ``figures/``) and ``diagnose.json`` into ``directory``; returns the HTML's path.
        Deprecated: use :func:`contactlab.report.diagnosis.write_html`."""
        return moved(
            "contactlab.diagnose.DiagnosisReport", "write_html", "contactlab.report.diagnosis"
        )(self, directory)

    def plot_gap(self, ax: Any = None) -> Any:
        """Held-out RMS (in units of the noise level) after each step.
        Deprecated: use :func:`contactlab.report.diagnosis_plots.plot_gap`."""
        return moved(
            "contactlab.diagnose.DiagnosisReport", "plot_gap", "contactlab.report.diagnosis_plots"
        )(self, ax=ax)
