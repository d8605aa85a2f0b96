"""HTML report of an identified structure: measured vs simulated response, the joint's loop
(with the force reconstructed from the equation of motion), the residual, the fit report and
the amplitude-dependent frequency and damping."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .._html import Column, Report
from ..structure.amplitude import amplitude_dependence
from ..structure.identify import IdentifiedModel, equation_error
from .structure_plots import plot_amplitude_dependence


def build_structure_report(
    model: IdentifiedModel,
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    *,
    title: str = "Structure identification",
    n_train: int | None = None,
    mass: float | None = None,
    intro: str | None = None,
) -> tuple[Report, dict[str, Any]]:
    """The report and a summary dict (``rms_train``, ``rms_holdout`` when held out)."""
    import matplotlib.pyplot as plt

    kw = {"force": u} if model.excitation == "force" else {"base": u}
    sim = model.simulate(t, x0=np.atleast_1d(model.x0), v0=np.atleast_1d(model.v0), **kw)
    x = np.full(y.shape, np.nan)
    x[: sim.x.shape[0]] = sim.x
    res = x - y
    n_train = t.size if n_train is None else n_train

    def rms(r: np.ndarray) -> float | None:
        # over the samples the simulation reached: one that stopped early leaves NaN after
        # (None when it reached none of them: numpy warned "mean of empty slice", fuzz/identify)
        r = r[np.isfinite(r)]
        return float(np.sqrt(np.mean(r * r))) if r.size else None

    summary: dict[str, Any] = {
        "rms_train": rms(res[:n_train]),
        "simulation_success": bool(sim.success),
    }
    if n_train < t.size:
        summary["rms_holdout"] = rms(res[n_train:])
    rep = Report(title, intro=intro)
    rep.section("Summary")
    rows = [{"quantity": k, "value": v} for k, v in summary.items()]
    rows += [
        {"quantity": "joint", "value": model.joint},
        {"quantity": "excitation", "value": model.excitation},
        {"quantity": "identification time [s]", "value": model.elapsed},
    ]
    rep.table(rows, [Column("quantity"), Column("value")])
    rep.table(
        [
            {
                "parameter": n,
                "value": p.value,
                "stderr": p.stderr,
                "unit": p.unit,
                "identifiable": p.identifiable,
                "vary": p.vary,
            }
            for n, p in model.fit.params.items()
        ],
        ["parameter", "value", "stderr", "unit", "identifiable", "vary"],
        caption="Fitted parameters (standard errors from the fit's covariance).",
    )
    rep.section("Response")
    fig, ax = plt.subplots(2, 1, figsize=(10, 5.5), sharex=True)
    multi = y.ndim == 2
    names = [f" x{i}" for i in range(y.shape[1])] if multi else [""]
    ax[0].plot(t, y, lw=0.7, label=[f"measured{s}" for s in names])
    ax[0].plot(t, x, lw=0.7, ls="--" if multi else "-", label=[f"simulated{s}" for s in names])
    if n_train < t.size:
        for a in ax:
            a.axvline(t[n_train], color="k", ls="--", lw=0.8)
    ax[0].set_ylabel("displacement [m]")
    ax[0].legend(loc="upper right")
    ax[1].plot(t, res, lw=0.6, color="C3")
    ax[1].set_ylabel("residual [m]")
    ax[1].set_xlabel("t [s]")
    rep.figure(
        fig,
        "response",
        "Measured and simulated displacement; residual (dashed: end of the training part).",
    )
    rep.section("Joint loop")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    if multi:
        _mdof_loop(ax, model, sim, t, u, y, summary)
    else:
        _sdof_reconstructed(ax, model, t, u, y, mass, summary)
    if sim.joint_force.shape[1] and not multi:
        ax.plot(x[: sim.x.size], sim.joint_force.sum(axis=1), lw=0.6, label="identified joint")
    ax.set_xlabel("joint displacement [m]")
    ax.set_ylabel("joint force [N]")
    ax.legend(loc="upper left", fontsize=8)
    rep.figure(fig, "joint-loop", "The joint's force against its displacement.")
    if model.joint not in ("linear", "kelvin_voigt") and model.structure.joints and not multi:
        amp = float(np.nanmax(np.abs(y)))
        amps = np.geomspace(amp / 100, amp, 12)
        try:
            ad = amplitude_dependence(model.structure, amps)
            summary["amplitude_dependence"] = ad.to_dict()
            rep.section("Amplitude-dependent frequency and damping")
            fig, ax2 = plt.subplots(1, 2, figsize=(9, 3.5), layout="constrained")
            plot_amplitude_dependence(ad, ax2)
            rep.figure(fig, "amplitude", "Equivalent-linear natural frequency and damping.")
        except Exception:
            pass
    if multi and model.structure.joints:
        _mdof_amplitude(rep, model, y, summary)
    rep.section("Fit report")
    rep.preformatted(model.report())
    return rep, summary


def _mdof_amplitude(rep: Any, model: IdentifiedModel, y: np.ndarray, summary: dict) -> None:
    """Each mode's frequency and damping ratio against amplitude (equivalent linearisation),
    up to the record's largest displacement."""
    import matplotlib.pyplot as plt

    from ..errors import ContactLabError
    from ..structure.amplitude_mdof import modal_amplitude_dependence
    from .structure_plots import plot_modal_amplitude_dependence

    amp = float(np.nanmax(np.abs(y)))
    amps = np.geomspace(amp / 100, amp, 12)
    try:
        ads = [
            modal_amplitude_dependence(model.structure, amps, mode=i)
            for i in range(model.structure.n)
        ]
    except ContactLabError as exc:
        summary["amplitude_dependence"] = {"error": str(exc)}
        return
    summary["amplitude_dependence"] = [ad.to_dict() for ad in ads]
    rep.section("Amplitude-dependent frequency and damping of each mode")
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.5), layout="constrained")
    plot_modal_amplitude_dependence(ads, ax)
    rep.figure(
        fig,
        "amplitude",
        "Equivalent-linear natural frequency and damping ratio of "
        "each mode against the amplitude of its reference DOF (mode shape and joint "
        "stiffness iterated together).",
    )


def _sdof_reconstructed(
    ax: Any,
    model: IdentifiedModel,
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    mass: float | None,
    summary: dict[str, Any],
) -> None:
    try:
        ee = equation_error(t, u, y, model.excitation, mass if mass is not None else None)
        m_, c_, k_ = (
            float(model.structure.M[0, 0]),
            float(model.structure.C[0, 0]),
            float(model.structure.K[0, 0]),
        )
        xd = np.gradient(y, t, edge_order=2)
        xdd = np.gradient(xd, t, edge_order=2)
        if model.excitation == "force":
            recon = u - m_ * xdd - c_ * xd - k_ * y
            d_meas = y
        else:
            ud = np.gradient(u, t, edge_order=2)
            recon = -m_ * xdd - c_ * (xd - ud) - k_ * (y - u)
            d_meas = y
        ax.plot(
            d_meas,
            recon,
            ".",
            ms=1.5,
            alpha=0.4,
            color="0.5",
            label="reconstructed from the equation of motion",
        )
        summary["equation_error_linear"] = {k: ee[k] for k in ("m", "c", "k")}
    except Exception:
        pass


def _mdof_loop(
    ax: Any,
    model: IdentifiedModel,
    sim: Any,
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    summary: dict[str, Any],
) -> None:
    """Several DOFs: the joint force against the joint's relative displacement, identified
    and reconstructed from the equations of motion with the identified ``M``, ``C``, ``K``
    (the force ``b F`` left over, projected on the joint's direction ``b``)."""
    from ..structure.fitkit import column_derivatives

    s = model.structure
    i, j = model.joint_dofs or (0, None)
    b = np.zeros(s.n)
    b[i] = 1.0
    if j is not None:
        b[j] = -1.0
    xd, xdd = column_derivatives(t, y, False)
    if model.excitation == "force":
        f = np.zeros_like(y)
        f[:, model.input_dof if model.input_dof is not None else s.n - 1] = u
        left = f - xdd @ s.M.T - xd @ s.C.T - y @ s.K.T
    else:
        ud = column_derivatives(t, u[:, None], False)[0]
        left = -(xdd @ s.M.T) - (xd - ud) @ s.C.T - (y - u[:, None]) @ s.K.T
    ax.plot(
        y @ b,
        left @ b / float(b @ b),
        ".",
        ms=1.5,
        alpha=0.4,
        color="0.5",
        label="reconstructed from the equations of motion",
    )
    if sim.joint_force.shape[1]:
        xs = np.asarray(sim.x).reshape(-1, s.n)
        ax.plot(
            xs @ b, sim.joint_force.sum(axis=1)[: xs.shape[0]], lw=0.6, label="identified joint"
        )
    summary["joint_dofs"] = [i, j]


# ------------------------------------------------------------------ structure diagnosis
def build_diagnosis_report(diag: Any, intro: str | None = None) -> Report:
    """The HTML report of a :class:`~contactlab.diagnose.structure.StructureDiagnosis`:
    findings, the named effects with their parameters ± standard errors, the held-out error
    after each step, measured against simulated response (base and final model), the joint's
    loop, the residual before and after (time and spectrum), the unexplained part with where
    it lives, and every candidate's verdict. ``intro`` (the "Made by" line of a command-line
    run) heads it."""

    from .._html import format_measurement

    rec = diag.record
    if not rec or diag.base_prediction is None or diag.residual is None:
        from ..errors import InputError

        raise InputError(
            "this diagnosis carries no record (loaded from JSON?): re-run "
            "diagnose_structure to write its report"
        )
    y = rec["y"]
    base, final = diag.base_prediction, y + diag.residual
    sigma = diag.noise_rms
    r = Report(
        f"Structure diagnosis: {diag.joint} joint, {diag.excitation} excitation",
        "Which effect the identified structure misses: the base model and each candidate are "
        "refitted on the first part of the record and judged on the held-out end, which no fit "
        "saw (dashed line in the figures).",
    )
    if intro:
        r.text(intro)
    _diag_findings(r, diag, format_measurement)
    _diag_tables(r, diag, sigma)
    _diag_response(r, diag, base, final, sigma)
    _diag_joint_loop(r, diag, base, final)
    _diag_residual(r, diag, base, final, sigma)
    _diag_candidates(r, diag, format_measurement)
    r.section("Result (JSON)")
    r.preformatted(diag.to_json())
    return r


def _diag_findings(r: Report, diag: Any, fmt: Any) -> None:
    """Findings: the named effects, where the model disagrees, explained or not."""
    r.section("Findings")
    if diag.effects:
        for name in diag.effects:
            keys = [k for k in diag.parameters if k in _EXTRA_KEYS.get(name, ())]
            r.text(
                f"Named: {name} — "
                + ", ".join(
                    f"{k} = {_pm(diag.parameters[k], diag.stderr.get(k), fmt)}" for k in keys
                )
            )
    else:
        r.text("No candidate improves the held-out error significantly.")
    r.subheading("Where the model disagrees")
    for w in diag.where:
        r.text(w, note=w.startswith("after "))
    r.text(
        (
            "Unexplained: the final model's held-out error is above 1.5 × the noise level."
            if diag.unexplained
            else "Explained: the final model's held-out error is within 1.5 × the noise level."
        ),
        note=diag.unexplained,
    )


def _diag_tables(r: Report, diag: Any, sigma: float) -> None:
    """The final model's parameters and the held-out error after each step."""
    r.section("Parameters of the final model")
    r.table(
        [
            {
                "parameter": k,
                "value": v,
                "stderr": diag.stderr.get(k),
                "added": any(k in _EXTRA_KEYS.get(e, ()) for e in diag.effects),
            }
            for k, v in diag.parameters.items()
        ],
        ["parameter", Column("value", stderr="stderr"), "added"],
        caption="Fitted on the training part; standard errors from the fit's covariance.",
    )
    r.section("Held-out error after each step")
    r.table(
        [
            {
                "step": "base model" if s["added"] is None else f"+ {s['added']}",
                "heldout_rms": s["heldout_rms"],
                "over_noise": s["heldout_rms"] / sigma,
                "train_rms": s["train_rms"],
            }
            for s in diag.steps
        ],
        [
            "step",
            Column("heldout_rms", "held-out RMS", unit="m"),
            Column("over_noise", "/ noise RMS"),
            Column("train_rms", "training RMS", unit="m"),
        ],
    )
    r.text(f"Noise RMS estimated from the data: {sigma:.4g} m")


def _diag_response(r: Report, diag: Any, base: np.ndarray, final: np.ndarray, sigma: float) -> None:
    """Input, measured and simulated displacement, residual before and after."""
    from matplotlib.figure import Figure

    t, y, ntr = diag.record["t"], diag.record["y"], diag.n_train
    u = diag.record["u"]
    r.section("Response")
    fig = Figure(figsize=(10, 6.5), layout="constrained")
    ax = fig.subplots(3, 1, sharex=True)
    ax[0].plot(t, u, lw=0.6, color="0.3")
    ax[0].set_ylabel("force [N]" if diag.excitation == "force" else "base [m]")
    ax[1].plot(t, y, lw=0.7, color="k", label="measured")
    ax[1].plot(t, base, lw=0.7, label="base model")
    if diag.effects:
        ax[1].plot(
            t, final, lw=0.7, ls="--", label="final model (+ " + ", ".join(diag.effects) + ")"
        )
    ax[1].set_ylabel("displacement [m]")
    ax[1].legend(loc="upper right", fontsize=8)
    ax[2].plot(t, base - y, lw=0.6, label="base model")
    if diag.effects:
        ax[2].plot(t, diag.residual, lw=0.6, label="final model")
    for a in (2 * sigma, -2 * sigma):
        ax[2].axhline(a, color="0.5", ls=":", lw=0.8)
    ax[2].set_ylabel("residual [m]")
    ax[2].set_xlabel("t [s]")
    ax[2].legend(loc="upper right", fontsize=8)
    for a in ax:
        a.axvline(t[ntr], color="k", ls="--", lw=0.8)
    r.figure(
        fig,
        "response",
        "Input; measured and simulated displacement (base and final "
        "model); residual before and after (dotted: ± 2 × noise RMS).",
        dpi=110,
    )


def _diag_joint_loop(r: Report, diag: Any, base: np.ndarray, final: np.ndarray) -> None:
    """The joint's simulated force against the displacement on the held-out part."""
    from matplotlib.figure import Figure

    ntr = diag.n_train
    r.section("Joint loop")
    fig = Figure(figsize=(6.5, 4.6), layout="constrained")
    ax1 = fig.add_subplot()
    for lab, x, jf in (
        ("base model", base, diag.base_joint_force),
        ("final model", final, diag.joint_force),
    ):
        if jf is not None and jf.ndim == 2 and jf.shape[1] and jf.shape[0] == x.size:
            ax1.plot(x[ntr:], jf[ntr:, 0], lw=0.7, label=f"{lab}: {diag.joint} joint")
            if jf.shape[1] > 1 and lab == "final model":
                ax1.plot(
                    x[ntr:],
                    jf[ntr:].sum(axis=1),
                    lw=0.7,
                    ls="--",
                    label="final model: all joint elements",
                )
    ax1.set_xlabel("displacement of the mass [m]")
    ax1.set_ylabel("joint force [N]")
    if ax1.get_lines():
        ax1.legend(loc="upper left", fontsize=8)
    else:  # a linear model has no joint (matplotlib warned of a legend with no entries)
        ax1.text(
            0.5,
            0.5,
            f"no joint force: the {diag.joint} model has no joint",
            ha="center",
            va="center",
            transform=ax1.transAxes,
        )
    r.figure(
        fig,
        "joint-loop",
        "The joint's force against the displacement on the held-out part (simulated).",
        dpi=110,
    )


def _diag_residual(r: Report, diag: Any, base: np.ndarray, final: np.ndarray, sigma: float) -> None:
    """The held-out residual's spectrum and its size against the speed of the mass."""
    from matplotlib.figure import Figure

    t, y, ntr = diag.record["t"], diag.record["y"], diag.n_train
    r.section("Residual: where the unexplained part lives")
    fig = Figure(figsize=(10, 3.8), layout="constrained")
    axs = fig.subplots(1, 2)
    dt = float(np.median(np.diff(t)))
    v = np.gradient(final, dt)
    for lab, e in (("base model", (base - y)[ntr:]), ("final model", diag.residual[ntr:])):
        if lab == "final model" and not diag.effects:
            continue
        spec = np.abs(np.fft.rfft((e - e.mean()) * np.hanning(e.size))) ** 2
        f = np.fft.rfftfreq(e.size, dt)
        axs[0].semilogy(f[1:], spec[1:] + 1e-300, lw=0.6, label=lab)
        axs[1].plot(np.abs(v[ntr:]), np.abs(e), ".", ms=1.5, alpha=0.5, label=lab)
    axs[0].set_xlabel("frequency [Hz]")
    axs[0].set_ylabel("held-out residual power")
    axs[1].set_xlabel("|velocity| [m/s] (reversals at the left)")
    axs[1].set_ylabel("|held-out residual| [m]")
    axs[1].axhline(2 * sigma, color="0.5", ls=":", lw=0.8)
    for a in axs:
        a.legend(fontsize=8)
    r.figure(
        fig,
        "residual-where",
        "Held-out residual: its spectrum, and its size against the "
        "speed of the mass (near reversals on the left).",
        dpi=110,
    )


def _diag_candidates(r: Report, diag: Any, fmt: Any) -> None:
    """Every candidate's verdict after each step."""
    r.section("Candidates tried")
    for i, s in enumerate(diag.steps):
        if s["candidates"]:
            r.subheading(f"after step {i} ({s['added'] or 'base model'})")
            rows = []
            for c in s["candidates"]:
                d = c.to_dict()
                d["parameters"] = ", ".join(
                    f"{k} = {_pm(val, c.stderr.get(k), fmt)}" for k, val in c.parameters.items()
                )
                rows.append(d)
            r.table(
                rows,
                [
                    "name",
                    "accepted",
                    Column("heldout_rms", "held-out RMS", unit="m"),
                    Column("gain", "gain / σ²"),
                    "t",
                    "parameters",
                    "reason",
                ],
            )


#: the parameters each structure candidate adds (as diagnose.structure names them)
_EXTRA_KEYS = {"joint_damping": ("cj",), "second_joint": ("k2", "fs2"), "base_coupling": ("e",)}


def _pm(value: float, stderr: float | None, fmt: Any) -> str:
    if stderr is None or not np.isfinite(stderr):
        return f"{value:.4g} (stderr unknown)"
    return str(fmt(value, stderr))


def write_diagnosis_html(diag: Any, directory: Any, intro: str | None = None) -> Path:
    """Write a structure diagnosis as ``diagnose.html`` (see :func:`build_diagnosis_report`),
    its figures under ``figures/`` and ``diagnose.json`` into ``directory``, all or nothing.

    Parameters
    ----------
    diag : contactlab.diagnose.StructureDiagnosis
        The result of :func:`contactlab.diagnose.diagnose_structure`.
    directory : path
        Output folder (created if missing).
    intro : str, optional
        A line heading the report (the command line that made it).

    Returns
    -------
    Path
        The HTML file written.
    """
    rep = build_diagnosis_report(diag, intro)
    extra = {"diagnose.json": (diag.to_json() + "\n").encode("utf-8")}
    return rep.write(directory, extra=extra, html_name="diagnose.html")[0]
