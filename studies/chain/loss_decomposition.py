"""Where the pin-sheave friction loss of an A-family chain run with H2 lives (session 11, issue 14's efficiency).

Run:  .venv/bin/python studies/chain/loss_decomposition.py RESULTS.h5 [--from 0.02] [--to 0.03] [--ranks 3]
      [--txt out/studies/chain/loss_variant_a.txt]

RESULTS is a ``cvtfem run`` of chain-A1 with ``cvt.effects.contact = "hertz-refined"`` on rigid (variant (a)) or
elastic shafts (variant (b)) that stores the full state (``output.state = true``; e.g.
``studies/chain/loss-variant-a.toml``).  At every stored row in the window the contacts are evaluated again from
``q`` and ``v`` in the kernel's (mirrored, sheave) frame and the relative velocity of the material points at the
contact point ``R_*`` is split exactly into three terms (their sum is the kernel's, checked per row):

- ``axis``: the pin axis end against the sheave point under it, ``(u_p', u3') - (omega k x d, z')``;
- ``spin``: the pin's spin ``omega_p`` (bisector of its link chords) against the sheave's, ``omega_p (k + gamma) x
  rho - omega k x x_*``, with ``rho = R_* - R_pin`` and ``x_*`` its in-plane part (~3.5 mm radially inwards);
- ``tilt``: the end slope's rate, ``(k x gamma') x rho``.

The friction power ``F . v_r`` (``F`` tangential, so ``F . v_r = F . (sum of the terms)``) is split by term and by
direction (circumferential ``nu``, radial ``e``, axial ``k`` of the pin end about its shaft), per shaft and per
position of the pin on its arc: the first ``--ranks`` pins from the entry, the last ones to the exit, the rest
("arc").  Mean slip speeds are plain means over the pin ends touching a shaft (as ``cvtfem history``) and
force-weighted ones.  Units in the printout: W, m/s, N.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from cvtfem.analysis.stored_state import stored_model, stored_states
from cvtfem.io.results import read_results

TERMS = ("axis", "spin", "tilt")
DIRS = ("circ", "radial", "axial")
SHAFTS = ("driving", "driven")


def kernel_contacts(model, q, v):
    """``(pins, shafts, X, d)``: the pin of each contact, its shaft, the H2 kernel's inputs (m, 21) in the kernel's
    (mirrored, sheave) frame and the kernel's details, for rigid (ChainACVT) and elastic shafts (ElasticChainACVT)."""
    if hasattr(model, "_mapped_set"):
        e, k, j, _, _, Z, (_, d) = model._mapped_set(q, v, details=True)
        n = model.refined_chain_inputs + 6
        K, dK = model._refined_frame(Z[:, :n], k, j)
        X = np.column_stack([K, np.einsum("mij,mj->mi", dK, Z[:, n:2 * n]), Z[:, -1]])
        return model.pin_of(e), k, X, d
    ends, shafts, X, (_, d) = model._contacts(q, v, details=True)
    return model.pin_of(ends), shafts, X, d


def split_slip(X, d, centres, slope_factor):
    """Per contact: the tangential slip of each term (3, m, 3), the unit vectors ``e``, ``nu`` (m, 3) and the
    kernel's slip (m, 3) for the check.  ``X`` as :func:`kernel_contacts`'s (10 positions with slopes)."""
    m = len(X)
    npos = 10
    up, u3, z = X[:, 2:4], X[:, 6], X[:, 9]
    vp, u3d, zd, w = X[:, npos + 2:npos + 4], X[:, npos + 6], X[:, npos + 9], X[:, -1]
    g = slope_factor * X[:, 7:9]
    gd = slope_factor * X[:, npos + 7:npos + 9]
    dvec = up - centres
    r = np.linalg.norm(dvec, axis=1)
    e2 = dvec / r[:, None]
    e = np.column_stack([e2, np.zeros(m)])
    nu = np.column_stack([-e2[:, 1], e2[:, 0], np.zeros(m)])
    k = np.array([0.0, 0.0, 1.0])
    x = d["offset"]
    rho = np.column_stack([x, d["point"][:, 2] - u3])
    om = d["spin_rate"]
    g3 = np.column_stack([g, np.zeros(m)])
    gd3 = np.column_stack([gd, np.zeros(m)])
    x3 = np.column_stack([x, np.zeros(m)])
    axis = np.column_stack([vp[:, 0] + w * dvec[:, 1], vp[:, 1] - w * dvec[:, 0], u3d - zd])
    spin = om[:, None] * np.cross(k + g3, rho) - w[:, None] * np.cross(k, x3)
    tilt = np.cross(np.cross(np.broadcast_to(k, (m, 3)), gd3), rho)
    n = d["normal"]
    proj = [t - np.sum(n * t, axis=1)[:, None] * n for t in (axis, spin, tilt)]
    return np.stack(proj), e, nu, d["slip"]


def arc_rank(pins, shafts, X, centres, n_pins, ranks):
    """Position class of each contact on its arc: 0..ranks-1 from the entry, -1..-ranks to the exit (negative), else
    ``ranks`` (the arc); pins on a shaft's arc are a run of consecutive indices, ordered along the travel by the
    shaft's spin."""
    cls = np.full(len(pins), ranks)
    for sh in (0, 1):
        sel = np.nonzero(shafts == sh)[0]
        if len(sel) == 0:
            continue
        p = np.unique(pins[sel])
        # the run of consecutive pins (cyclic): start after the largest gap
        gaps = np.diff(np.concatenate([p, [p[0] + n_pins]]))
        start = p[(np.argmax(gaps) + 1) % len(p)]
        order = (p - start) % n_pins                       # 0 .. run length - 1 along increasing index
        length = order.max() + 1
        i = sel[np.argmin(order[np.searchsorted(p, pins[sel])])]
        dv = X[i, 2:4] - centres[sh]
        # does the next pin index lie ahead along the spin?  tangential velocity of the pin ~ w k x d
        step = X[i, 4:6] - X[i, 2:4]
        ahead = np.sign(X[i, -1]) * np.sign(dv[0] * step[1] - dv[1] * step[0])
        pos = order[np.searchsorted(p, pins[sel])]
        if ahead < 0:
            pos = length - 1 - pos
        c = np.where(pos < ranks, pos, np.where(pos >= length - ranks, pos - length, ranks))
        cls[sel] = c
    return cls


def decompose(path, t_from, t_to, ranks):
    r = read_results(path)
    model = stored_model(r)
    t, x = stored_states(r, model)
    rows = np.nonzero((t >= t_from - 1e-12) & (t <= t_to + 1e-12))[0]
    from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR

    centres_all = np.asarray(model.contact.pair.centres, float)
    n_pins = model.family.n
    labels = list(range(ranks)) + [ranks] + list(range(-ranks, 0))
    acc = {(sh, c): dict(P=np.zeros((3, 3)), n=0, slip=np.zeros(3), speed=0.0, comp=np.zeros((3, 3)),
                         N=0.0, Nspeed=0.0) for sh in (0, 1) for c in labels}
    mean_speed = {0: [], 1: []}
    check = 0.0
    for row in rows:
        q, v, _, _ = model.split(x[row])
        pins, shafts, X, d = kernel_contacts(model, q, v)
        on = d["N"] > 0                                       # touching (the broad phase's candidates include free ends)
        pins, shafts, X, d = pins[on], shafts[on], X[on], {key: val[on] for key, val in d.items()}
        centres = centres_all[shafts]
        terms, e, nu, slip = split_slip(X, d, centres, END_SLOPE_FACTOR)
        check = max(check, float(np.abs(terms.sum(axis=0) - slip).max()))
        cls = arc_rank(pins, shafts, X, centres_all, n_pins, ranks)
        F = d["F_fr"]
        basis = np.stack([nu, e, np.broadcast_to([0.0, 0.0, 1.0], e.shape)])      # circ, radial, axial
        speed = np.linalg.norm(slip, axis=1)
        N = d["N"]
        for sh in (0, 1):
            on = shafts == sh
            if on.any():
                mean_speed[sh].append(speed[on].mean())
        for sh in (0, 1):
            for c in labels:
                s = (shafts == sh) & (cls == c)
                if not s.any():
                    continue
                a = acc[(sh, c)]
                # power by term (rows) and direction (columns): F_dir * term_dir
                Fd = np.einsum("bmi,mi->bm", basis[:, s], F[s])                  # (3 dirs, m)
                Td = np.einsum("bmi,tmi->tbm", basis[:, s], terms[:, s])         # (3 terms, 3 dirs, m)
                a["P"] += (Td * Fd[None]).sum(axis=2)
                a["comp"] += np.abs(Td).sum(axis=2)
                a["n"] += int(s.sum())
                a["speed"] += speed[s].sum()
                a["N"] += N[s].sum()
                a["Nspeed"] += (N[s] * speed[s]).sum()
    nrow = len(rows)
    return dict(acc=acc, rows=nrow, labels=labels, check=check, mean_speed=mean_speed, t=(t[rows[0]], t[rows[-1]]),
                model=model, results=r)


def report(res, ranks) -> str:
    acc, nrow = res["acc"], res["rows"]
    r = res["results"]
    t0, t1 = res["t"]
    tt = r.time
    W = np.asarray(r.series["work"])
    i0, i1 = np.argmin(abs(tt - t0)), np.argmin(abs(tt - t1))
    dW = W[i1] - W[i0]
    P_in = dW[0] / (t1 - t0)
    lines = [f"{r.path}: {nrow} rows over {t0 * 1e3:.1f}-{t1 * 1e3:.1f} ms; input power {P_in / 1e3:.2f} kW "
             f"(work integrals: in {dW[0]:.2f} J, out {dW[1]:.2f} J, dissipated {dW[2]:.3f} J); "
             f"largest |sum of terms - kernel slip| {res['check']:.1e} m/s"]
    tot = np.zeros((3, 3))
    for sh in (0, 1):
        ms = np.mean(res["mean_speed"][sh])
        lines.append(f"\n{SHAFTS[sh]}: mean slip speed over the pin ends touching {ms:.3f} m/s")
        lines.append("  class      ends/row  mean |v_r|  N-weighted |v_r|  mean N   friction power (W, <0) by term "
                     "axis/spin/tilt   by direction circ/radial/axial   mean |term| circ,radial,axial (m/s): axis | spin | tilt")
        Psh = np.zeros((3, 3))
        for c in res["labels"]:
            a = acc[(sh, c)]
            if a["n"] == 0:
                continue
            name = f"entry+{c}" if 0 <= c < ranks else ("arc" if c == ranks else f"exit{c + 1:+d}" if c < -1 else "exit")
            P = a["P"] / nrow
            Psh += P
            comp = a["comp"] / a["n"]
            lines.append(f"  {name:9s} {a['n'] / nrow:8.2f}  {a['speed'] / a['n']:9.3f}  {a['Nspeed'] / max(a['N'], 1e-30):14.3f}"
                         f"  {a['N'] / a['n']:7.0f}   {P.sum():8.1f}  = {P.sum(axis=1)[0]:8.1f} {P.sum(axis=1)[1]:8.1f} "
                         f"{P.sum(axis=1)[2]:8.1f}   {P.sum(axis=0)[0]:8.1f} {P.sum(axis=0)[1]:8.1f} {P.sum(axis=0)[2]:8.1f}"
                         "   " + " | ".join(",".join(f"{v:.3f}" for v in comp[j]) for j in range(3)))
        lines.append(f"  total friction power {Psh.sum():.1f} W ({-Psh.sum() / P_in * 100:.2f} % of the input); "
                     f"by term axis/spin/tilt {Psh.sum(axis=1).round(1)}; by direction circ/radial/axial "
                     f"{Psh.sum(axis=0).round(1)}")
        tot += Psh
    lines.append(f"\nboth shafts: {tot.sum():.1f} W ({-tot.sum() / P_in * 100:.2f} % of the input); by term "
                 f"axis/spin/tilt {tot.sum(axis=1).round(1)}; by direction {tot.sum(axis=0).round(1)}")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("--from", dest="t_from", type=float, default=0.02)
    ap.add_argument("--to", dest="t_to", type=float, default=np.inf)
    ap.add_argument("--ranks", type=int, default=3)
    ap.add_argument("--txt")
    a = ap.parse_args(argv)
    res = decompose(a.results, a.t_from, a.t_to, a.ranks)
    text = report(res, a.ranks)
    print(text)
    if a.txt:
        Path(a.txt).parent.mkdir(parents=True, exist_ok=True)
        Path(a.txt).write_text(text + "\n")


if __name__ == "__main__":
    main()
