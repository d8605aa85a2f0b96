"""HTML report of an identified structure: measured vs simulated response, the joint's loop
(with the force reconstructed from the equation of motion), the residual, the fit report and
the amplitude-dependent frequency and damping."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..report.html import Column, Report
from .amplitude import amplitude_dependence, plot_amplitude_dependence
from .identify import IdentifiedModel, equation_error


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
    rows += [{"quantity": "joint", "value": model.joint},
             {"quantity": "excitation", "value": model.excitation},
             {"quantity": "identification time [s]", "value": model.elapsed}]  # fmt: skip
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
    rep.figure(fig, "response", "Measured and simulated displacement; residual (dashed: end "
               "of the training part).")  # fmt: skip
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
            fig, ax2 = plt.subplots(1, 2, figsize=(9, 3.5))
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
    from .amplitude_mdof import modal_amplitude_dependence, plot_modal_amplitude_dependence

    amp = float(np.nanmax(np.abs(y)))
    amps = np.geomspace(amp / 100, amp, 12)
    try:
        ads = [modal_amplitude_dependence(model.structure, amps, mode=i)
               for i in range(model.structure.n)]  # fmt: skip
    except ContactLabError as exc:
        summary["amplitude_dependence"] = {"error": str(exc)}
        return
    summary["amplitude_dependence"] = [ad.to_dict() for ad in ads]
    rep.section("Amplitude-dependent frequency and damping of each mode")
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
    plot_modal_amplitude_dependence(ads, ax)
    rep.figure(fig, "amplitude", "Equivalent-linear natural frequency and damping ratio of "
               "each mode against the amplitude of its reference DOF (mode shape and joint "
               "stiffness iterated together).")  # fmt: skip


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
        m_, c_, k_ = (float(model.structure.M[0, 0]), float(model.structure.C[0, 0]),
                      float(model.structure.K[0, 0]))  # fmt: skip
        xd = np.gradient(y, t, edge_order=2)
        xdd = np.gradient(xd, t, edge_order=2)
        if model.excitation == "force":
            recon = u - m_ * xdd - c_ * xd - k_ * y
            d_meas = y
        else:
            ud = np.gradient(u, t, edge_order=2)
            recon = -m_ * xdd - c_ * (xd - ud) - k_ * (y - u)
            d_meas = y
        ax.plot(d_meas, recon, ".", ms=1.5, alpha=0.4, color="0.5",
                label="reconstructed from the equation of motion")  # fmt: skip
        summary["equation_error_linear"] = {k: ee[k] for k in ("m", "c", "k")}
    except Exception:
        pass


def _mdof_loop(ax: Any, model: IdentifiedModel, sim: Any, t: np.ndarray, u: np.ndarray,
               y: np.ndarray, summary: dict[str, Any]) -> None:  # fmt: skip
    """Several DOFs: the joint force against the joint's relative displacement, identified
    and reconstructed from the equations of motion with the identified ``M``, ``C``, ``K``
    (the force ``b F`` left over, projected on the joint's direction ``b``)."""
    from .identify_mdof import _derivs

    s = model.structure
    i, j = model.joint_dofs or (0, None)
    b = np.zeros(s.n)
    b[i] = 1.0
    if j is not None:
        b[j] = -1.0
    xd, xdd = _derivs(t, y, False)
    if model.excitation == "force":
        f = np.zeros_like(y)
        f[:, model.input_dof if model.input_dof is not None else s.n - 1] = u
        left = f - xdd @ s.M.T - xd @ s.C.T - y @ s.K.T
    else:
        ud = _derivs(t, u[:, None], False)[0]
        left = -(xdd @ s.M.T) - (xd - ud) @ s.C.T - (y - u[:, None]) @ s.K.T
    ax.plot(y @ b, left @ b / float(b @ b), ".", ms=1.5, alpha=0.4, color="0.5",
            label="reconstructed from the equations of motion")  # fmt: skip
    if sim.joint_force.shape[1]:
        xs = np.asarray(sim.x).reshape(-1, s.n)
        ax.plot(xs @ b, sim.joint_force.sum(axis=1)[: xs.shape[0]], lw=0.6,
                label="identified joint")  # fmt: skip
    summary["joint_dofs"] = [i, j]
