"""Are the standard errors of ``contactlab.structure.identify`` honest? Coverage on fresh
seeds (issue 10).

For each case (1 and 2 DOFs, force and base excitation, Jenkins and Bouc-Wen joints) and
noise level (1 % and 0.2 % of each channel's RMS, white, on the input AND on every response
channel), records from rest are simulated, identified, and every fitted structure and joint
parameter (not the initial state) is checked: is ``|fitted − truth| ≤ 2·stderr``? Printed:
the share of such parameters for the standard errors ``identify`` reports (``reported``: input
and output noise, :func:`contactlab.structure._fitkit.noise_model_covariance`) and for the
white-noise ones ``(JᵀJ)⁻¹ χ²/ν`` computed from the same fit (``white``: what ``identify``
reported before), and the median ratio reported/white. Near 95 % is honest. The records are
integrated with 16 steps per sample (``--truth-substeps``), the fits with 4: the
discretisation error of the fitted model is part of the test (``--truth-substeps 4`` leaves
it out).

    python benches/eval_structure_stderr.py [--seeds 6] [--first 71000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from contactlab.structure import Structure, identify

FS = 500.0
M2 = np.diag([1.0, 0.5])
K2 = np.array([[6e3, -2e3], [-2e3, 2e3]])
C2 = np.array([[3.0, -1.0], [-1.0, 1.0]])
CHAIN = {"m0": 1.0, "m1": 0.5, "k0": 4e3, "k1": 2e3, "c0": 2.0, "c1": 1.0}
BW = {"alpha": 2e3, "beta": 1.0, "gamma": 300.0, "delta": -100.0, "nu": 1.0}
BW_FIT = {"alpha": 2e3, "gamma": 300.0, "delta": -100.0, "nu": 1.0}
# name: (n_dofs, joint, joint_dofs, excitation, joint kwargs, fitted joint truth)
CASES = {
    "1 dof jenkins force": (1, "jenkins", (0, None), "force", {"k": 1.5e3, "fs": 1.5},
                            {"kj": 1.5e3, "fs": 1.5}),
    "1 dof bouc_wen force": (1, "bouc_wen", (0, None), "force", BW, BW_FIT),
    "1 dof jenkins base": (1, "jenkins", (0, None), "base", {"k": 1.5e3, "fs": 1.5},
                           {"kj": 1.5e3, "fs": 1.5}),
    "2 dof jenkins 0-1 force": (2, "jenkins", (0, 1), "force", {"k": 1.5e3, "fs": 1.5},
                                {"kj": 1.5e3, "fs": 1.5}),
    "2 dof bouc_wen 0-g force": (2, "bouc_wen", (0, None), "force", BW, BW_FIT),
    "2 dof jenkins 1-g base": (2, "jenkins", (1, None), "base", {"k": 1.5e3, "fs": 1.5},
                               {"kj": 1.5e3, "fs": 1.5}),
}  # fmt: skip


def record(case: str, seed: int, noise: float, sub: int):
    nd, joint, jd, exc, jp, _ = CASES[case]
    rng = np.random.default_rng(seed)
    n = int(3.0 * FS)
    t = np.arange(n) / FS
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, 40, 0.5))
    u = u / np.std(u) * (6.0 if exc == "force" else 2e-3)
    if nd == 1:
        s = Structure(1.0, 2.0, 4e3)
        f = u
    else:
        s = Structure(M2, C2, K2)
        f = np.zeros((n, 2))
        f[:, 1] = u
    s.add_joint(joint, jd[0], jd[1], **jp)
    y = (s.simulate(t, force=f, substeps=sub) if exc == "force" else
         s.simulate(t, base=u, substeps=sub)).x  # fmt: skip
    um = u + noise * np.std(u) * rng.standard_normal(n)
    ym = y + noise * np.std(y, axis=0) * rng.standard_normal(y.shape)
    return t, um, ym


def truth(case: str) -> dict[str, float]:
    nd, *_, jtruth = CASES[case]
    lin = {"m": 1.0, "c": 2.0, "k": 4e3} if nd == 1 else CHAIN
    return {**lin, **jtruth}


def white_stderr(fit) -> np.ndarray:
    J, r = fit.jac, fit.residual
    nrm = np.linalg.norm(J, axis=0)
    A = np.linalg.pinv((J / nrm).T @ (J / nrm), rcond=1e-16)
    return np.sqrt(np.diag(A) * (r @ r) / (r.size - J.shape[1])) / nrm


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--first", type=int, default=71000)
    ap.add_argument("--substeps", type=int, default=4, help="identify's steps per sample")
    ap.add_argument("--truth-substeps", type=int, default=16, help="the records' steps")
    ap.add_argument("--cases", default="", help="only cases containing this text")
    args = ap.parse_args()
    print(f"{'case':<26}{'noise':>6}{'params':>7}{'white cover':>12}{'reported':>10}"
          f"{'rep/white':>10}{'time s':>8}")  # fmt: skip
    tot = {"n": 0, "w": 0, "h": 0}
    for noise in (0.01, 0.002):
        for case, (nd, joint, jd, exc, _, _) in CASES.items():
            if args.cases not in case:
                continue
            cnt = {"n": 0, "w": 0, "h": 0}
            ratios = []
            t0 = time.perf_counter()
            for seed in range(args.first, args.first + args.seeds):
                t, u, y = record(case, seed, noise, args.truth_substeps)
                kw = {}
                if nd == 2:
                    kw = {"joint_dofs": jd, "input_dof": 1 if exc == "force" else None,
                          "mass": [1.0, 0.5] if exc == "base" else None}  # fmt: skip
                elif exc == "base":
                    kw = {"mass": 1.0}
                m = identify(t, u, y, joint=joint, excitation=exc, substeps=args.substeps,
                             start_samples=1500, **kw)  # fmt: skip
                fit = m.fit
                sw = dict(zip(fit.var_names, white_stderr(fit), strict=True))
                for name, val in truth(case).items():
                    p = fit.params.get(name)
                    if p is None or not p.vary or p.stderr is None:
                        continue
                    err = abs(p.value - val)
                    cnt["n"] += 1
                    cnt["w"] += err <= 2 * sw[name]
                    cnt["h"] += err <= 2 * p.stderr
                    ratios.append(p.stderr / sw[name])
            for key in tot:
                tot[key] += cnt[key]
            el = time.perf_counter() - t0
            print(f"{case:<26}{100 * noise:>5.1f}%{cnt['n']:>7}{100 * cnt['w'] / cnt['n']:>11.0f}%"
                  f"{100 * cnt['h'] / cnt['n']:>9.0f}%{np.median(ratios):>10.2f}{el:>8.1f}",
                  flush=True)  # fmt: skip
    print(f"{'all':<32}{tot['n']:>7}{100 * tot['w'] / tot['n']:>11.1f}%"
          f"{100 * tot['h'] / tot['n']:>9.1f}%")  # fmt: skip


if __name__ == "__main__":
    main()
