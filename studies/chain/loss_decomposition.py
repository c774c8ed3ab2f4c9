"""Where the pin-sheave friction loss of a chain run lives (session 11, issue 14's efficiency).

Run:  .venv/bin/python studies/chain/loss_decomposition.py RESULTS.h5 [RESULTS.h5 ...] [--from 0.02] [--to 0.03]
      [--ranks 3] [--txt out/studies/chain/loss_variant_a.txt]

RESULTS is a ``cvtfem run`` of chain-A1 or chain-S2 with H1 or H2 (``cvt.effects.contact``), A1 with H2 also on
elastic shafts (variant (b)), that stores the full state (``output.state = true``; ``studies/chain/loss-*.toml``).  At every stored row in the window the contacts are evaluated again from
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
force-weighted ones; the slip and friction power against the pin's angle about its shaft; the share of ends
sliding faster than ``v0``, the friction used ``sum |F_fr| / (f0 sum N)``, the mean contact offset ``|x_*|`` and, as
a check that the rebuilt model is the run's, the stored ``contact.friction_power``.  H1 contacts (on the pin axis)
have the ``axis`` term only.  Several files end with a one-line-per-file summary.  Units in the printout: W, m/s, N.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from cvtfem.analysis.stored_state import stored_model, stored_states
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.io.results import read_results

SHAFTS = ("driving", "driven")


def contact_kernel(model):
    """``(kernel, mirror)``: the pair kernel of the model's contact and the number of pin ends one contact stands
    for (2 for the mirrored pair of the symmetric chains, 1 for single ends)."""
    con = model.contact
    return (con.pair, 1) if hasattr(con, "pair") else (con, 2)


def kernel_contacts(model, q, v):
    """``(pins, shafts, X, d)``: the pin of each contact, its shaft, the kernel's inputs in the kernel's (mirrored,
    sheave) frame and the kernel's details, for rigid (ChainCVT, ChainACVT) and elastic shafts (ElasticChainACVT)."""
    if hasattr(model, "_mapped_set") and contact_kernel(model)[0].__class__ is RefinedSheaveContact:
        e, k, j, _, _, Z, (_, d) = model._mapped_set(q, v, details=True)
        n = model.refined_chain_inputs + 6
        K, dK = model._refined_frame(Z[:, :n], k, j)
        X = np.column_stack([K, np.einsum("mij,mj->mi", dK, Z[:, n:2 * n]), Z[:, -1]])
        return model.pin_of(e), k, X, d
    ends, shafts, X, (_, d) = model._contacts(q, v, details=True)
    return model.pin_of(ends), shafts, X, d


def split_slip(con, X, d, centres):
    """Per contact: the tangential slip of each term (3, m, 3) and the unit vectors ``e``, ``nu`` (m, 3) of the pin
    end about its shaft.  H2 (:class:`RefinedSheaveContact`, inputs as its ``local``): the three terms; H1
    (:class:`SheaveContact`): the pin-axis end is the contact point, all of the slip is ``axis``."""
    m = len(X)
    if not isinstance(con, RefinedSheaveContact):
        dvec = X[:, :2] - centres
        e2 = dvec / np.linalg.norm(dvec, axis=1)[:, None]
        zero = np.zeros((m, 3))
        return (np.stack([d["slip"], zero, zero]), np.column_stack([e2, np.zeros(m)]),
                np.column_stack([-e2[:, 1], e2[:, 0], np.zeros(m)]))
    npos = con.n_pos
    up, u3 = X[:, 2:4], X[:, 6]
    vp, u3d, zd, w = X[:, npos + 2:npos + 4], X[:, npos + 6], X[:, 2 * npos - 1], X[:, -1]
    if con.slopes:
        g, gd = END_SLOPE_FACTOR * X[:, 7:9], END_SLOPE_FACTOR * X[:, npos + 7:npos + 9]
    else:
        g = gd = np.zeros((m, 2))
    dvec = up - centres
    e2 = dvec / np.linalg.norm(dvec, axis=1)[:, None]
    e = np.column_stack([e2, np.zeros(m)])
    nu = np.column_stack([-e2[:, 1], e2[:, 0], np.zeros(m)])
    k = np.array([0.0, 0.0, 1.0])
    x = d["offset"]
    rho = np.column_stack([x, d["point"][:, 2] - u3])
    g3, gd3, x3 = (np.column_stack([a, np.zeros(m)]) for a in (g, gd, x))
    axis = np.column_stack([vp[:, 0] + w * dvec[:, 1], vp[:, 1] - w * dvec[:, 0], u3d - zd])
    spin = d["spin_rate"][:, None] * np.cross(k + g3, rho) - w[:, None] * np.cross(k, x3)
    tilt = np.cross(np.cross(np.broadcast_to(k, (m, 3)), gd3), rho)
    n = d["normal"]
    return np.stack([t - np.sum(n * t, axis=1)[:, None] * n for t in (axis, spin, tilt)]), e, nu


#: Bins of the pin angle about its shaft (world frame, from -180 deg) for the slip against the angle.
ANGLE_BINS = 24


def X_inplane(con, X):
    """In-plane position (m, 2) of the pin end in the kernel's inputs (H2: pin ``p``; H1: the end)."""
    return X[:, 2:4] if isinstance(con, RefinedSheaveContact) else X[:, :2]


def arc_rank(pins, shafts, u, w, centres, ranks):
    """Position class of each contact on its arc: 0..ranks-1 from the entry, -1..-ranks to the exit, else ``ranks``
    (the arc).  The pins touching a shaft are a run of consecutive indices (cyclic), ordered along the travel by
    the shaft's spin ``w`` (2,) rad/s; ``u`` (n, 2) the pin positions."""
    n_pins = len(u)
    cls = np.full(len(pins), ranks)
    for sh in (0, 1):
        sel = np.nonzero(shafts == sh)[0]
        if len(sel) == 0:
            continue
        p = np.unique(pins[sel])
        gaps = np.diff(np.concatenate([p, [p[0] + n_pins]]))
        start = p[(np.argmax(gaps) + 1) % len(p)]
        order = (p - start) % n_pins
        length = order.max() + 1
        dv, step = u[start] - centres[sh], u[(start + 1) % n_pins] - u[start]
        ahead = np.sign(w[sh]) * np.sign(dv[0] * step[1] - dv[1] * step[0])   # higher index further on
        pos = order[np.searchsorted(p, pins[sel])]
        if ahead < 0:
            pos = length - 1 - pos
        cls[sel] = np.where(pos < ranks, pos, np.where(pos >= length - ranks, pos - length, ranks))
    return cls


def decompose(path, t_from, t_to, ranks):
    """Sums over the stored rows in ``[t_from, t_to]`` per (shaft, arc class): friction power by term and
    direction (3, 3) W, contact count, slip speed, normal force, force-weighted slip; the largest mismatch of the
    terms' sum against the kernel's slip (m/s)."""
    r = read_results(path)
    model = stored_model(r)
    t, x = stored_states(r, model)
    rows = np.nonzero((t >= t_from - 1e-12) & (t <= t_to + 1e-12))[0]
    con, mirror = contact_kernel(model)
    centres_all = np.asarray(con.centres, float)
    nc, iphi = model._idx[0], model._idx[1]
    labels = list(range(ranks)) + [ranks] + list(range(-ranks, 0))
    acc = {(sh, c): dict(P=np.zeros((3, 3)), n=0, speed=0.0, comp=np.zeros((3, 3)), N=0.0, Nspeed=0.0, sat=0,
                         Ffr=0.0, torque=0.0, offset=0.0)
           for sh in (0, 1) for c in labels}
    mean_speed = {0: [], 1: []}
    bins = np.zeros((2, ANGLE_BINS, 4))          # per shaft and pin angle: count, radial slip, circ slip, power
    check = 0.0
    for row in rows:
        q, v, _, _ = model.split(x[row])
        pins, shafts, X, d = kernel_contacts(model, q, v)
        on = d["N"] > 0                                   # touching (the broad phase's candidates include free ends)
        pins, shafts, X = pins[on], shafts[on], X[on]
        d = {key: val[on] for key, val in d.items() if np.ndim(val) and len(val) == len(on)}
        terms, e, nu = split_slip(con, X, d, centres_all[shafts])
        check = max(check, float(np.abs(terms.sum(axis=0) - d["slip"]).max()))
        cls = arc_rank(pins, shafts, model.pin_positions(q[:nc]), v[iphi], centres_all, ranks)
        F, N = mirror * d["F_fr"], d["N"]
        basis = np.stack([nu, e, np.broadcast_to([0.0, 0.0, 1.0], e.shape)])      # circ, radial, axial
        speed = np.linalg.norm(d["slip"], axis=1)
        slip = d["slip"]
        ang = np.arctan2(X_inplane(con, X)[:, 1] - centres_all[shafts, 1], X_inplane(con, X)[:, 0] - centres_all[shafts, 0])
        b = ((ang + np.pi) / (2 * np.pi) * ANGLE_BINS).astype(int) % ANGLE_BINS
        for col, val in enumerate((np.ones(len(b)), np.sum(slip * e, axis=1), np.sum(slip * nu, axis=1),
                                   mirror * np.sum(d["F_fr"] * slip, axis=1))):
            np.add.at(bins[:, :, col], (shafts, b), val)
        for sh in (0, 1):
            if (shafts == sh).any():
                mean_speed[sh].append(speed[shafts == sh].mean())
            for c in labels:
                s = (shafts == sh) & (cls == c)
                if not s.any():
                    continue
                a = acc[(sh, c)]
                Fd = np.einsum("bmi,mi->bm", basis[:, s], F[s])                  # (3 directions, m)
                Td = np.einsum("bmi,tmi->tbm", basis[:, s], terms[:, s])         # (3 terms, 3 directions, m)
                a["P"] += (Td * Fd[None]).sum(axis=2)
                a["comp"] += mirror * np.abs(Td).sum(axis=2)
                a["n"] += mirror * int(s.sum())
                a["speed"] += mirror * speed[s].sum()
                a["N"] += mirror * N[s].sum()
                a["Nspeed"] += mirror * (N[s] * speed[s]).sum()
                a["sat"] += mirror * int((speed[s] > con.v0).sum())
                a["Ffr"] += np.linalg.norm(F[s], axis=1).sum()
                a["torque"] += (Fd[0] * d["radius"][s]).sum()
                if "offset" in d:
                    a["offset"] += mirror * np.linalg.norm(d["offset"][s], axis=1).sum()
    return dict(acc=acc, rows=len(rows), labels=labels, check=check, mean_speed=mean_speed,
                t=(t[rows[0]], t[rows[-1]]), results=r, f0=con.f0, v0=con.v0, bins=bins,
                row_index=rows)


def report(res, ranks) -> str:
    acc, nrow = res["acc"], res["rows"]
    r = res["results"]
    t0, t1 = res["t"]
    tt = r.time
    W = np.asarray(r.series["work"])
    i0, i1 = np.argmin(abs(tt - t0)), np.argmin(abs(tt - t1))
    dW = W[i1] - W[i0]
    P_in = dW[0] / (t1 - t0)
    E = np.asarray(r.series["energy"]).reshape(-1)
    sel = slice(i0, i1 + 1)
    ratio = np.asarray(r.series["ratio"]).reshape(-1)[sel].mean()
    F12 = (np.asarray(r.series["driving.clamping_force"]).reshape(-1)[sel]
           / np.asarray(r.series["driven.clamping_force"]).reshape(-1)[sel]).mean()
    res["summary"] = dict(eff=dW[1] / dW[0], eff_c=(dW[1] + E[i1] - E[i0]) / dW[0], ratio=ratio, F12=F12)
    lines = [f"{r.path}: {nrow} rows over {t0 * 1e3:.1f}-{t1 * 1e3:.1f} ms; input power {P_in / 1e3:.2f} kW "
             f"(work integrals: in {dW[0]:.2f} J, out {dW[1]:.2f} J, dissipated {dW[2]:.3f} J); efficiency "
             f"{dW[1] / dW[0]:.4f}, kinetic-energy corrected {(dW[1] + E[i1] - E[i0]) / dW[0]:.4f}; mean ratio "
             f"{ratio:.4f}, F1/F2 {F12:.3f}; largest |sum of terms - kernel slip| {res['check']:.1e} m/s"]
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
        n = sum(acc[(sh, c)]["n"] for c in res["labels"])
        sat = sum(acc[(sh, c)]["sat"] for c in res["labels"])
        Ffr = sum(acc[(sh, c)]["Ffr"] for c in res["labels"])
        Nsum = sum(acc[(sh, c)]["N"] for c in res["labels"])
        torque = sum(acc[(sh, c)]["torque"] for c in res["labels"])
        off = sum(acc[(sh, c)]["offset"] for c in res["labels"])
        lines.append(f"  mean contact offset |x_*| {off / n * 1e3:.2f} mm (H1: 0)")
        lines.append(f"  pin ends sliding faster than v0 = {res['v0']:g} m/s: {sat / n * 100:.1f} %; friction used "
                     f"sum|F_fr| / (f0 sum N) = {Ffr / (res['f0'] * Nsum):.3f}; circumferential friction torque "
                     f"{abs(torque) / nrow:.1f} N m; sum N {Nsum / nrow / 1e3:.2f} kN")
        edge = sum(acc[(sh, c)]["P"].sum() for c in res["labels"] if c != ranks) / nrow
        res["summary"][sh] = dict(loss=-Psh.sum() / P_in, slip=ms, sat=sat / n, used=Ffr / (res["f0"] * Nsum),
                                  edge=edge / Psh.sum(), spin=Psh.sum(axis=1)[1] / Psh.sum(),
                                  radial=Psh.sum(axis=0)[1] / Psh.sum())
        B = res["bins"][sh]
        keep = B[:, 0] > 0
        lines.append("  by pin angle (deg): " + "  ".join(
            f"{-180 + 360 * (i + 0.5) / ANGLE_BINS:.0f}: radial {B[i, 1] / B[i, 0]:+.3f} circ {B[i, 2] / B[i, 0]:+.3f} "
            f"P {B[i, 3] / nrow:.0f} W" for i in np.nonzero(keep)[0]))
        stored = float(np.mean(np.asarray(r.series["contact.friction_power"])[res["row_index"], sh]))
        lines.append(f"  stored contact.friction_power over the same rows {stored:.1f} W (the run's own model)")
        lines.append(f"  total friction power {Psh.sum():.1f} W ({-Psh.sum() / P_in * 100:.2f} % of the input); "
                     f"by term axis/spin/tilt {Psh.sum(axis=1).round(1)}; by direction circ/radial/axial "
                     f"{Psh.sum(axis=0).round(1)}")
        tot += Psh
    lines.append(f"\nboth shafts: {tot.sum():.1f} W ({-tot.sum() / P_in * 100:.2f} % of the input); by term "
                 f"axis/spin/tilt {tot.sum(axis=1).round(1)}; by direction {tot.sum(axis=0).round(1)}")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="+")
    ap.add_argument("--from", dest="t_from", type=float, default=0.02)
    ap.add_argument("--to", dest="t_to", type=float, default=np.inf)
    ap.add_argument("--ranks", type=int, default=3)
    ap.add_argument("--txt")
    a = ap.parse_args(argv)
    texts, rows = [], []
    for path in a.results:
        res = decompose(path, a.t_from, a.t_to, a.ranks)
        texts.append(report(res, a.ranks))
        print(texts[-1] + "\n")
        s = res["summary"]
        rows.append(f"{Path(path).stem:28s} {s['eff']:.4f} {s['eff_c']:.4f} {s['ratio']:.4f} {s['F12']:.3f}  " + "  ".join(
            f"{100 * s[k]['loss']:5.2f} {s[k]['slip']:6.3f} {100 * s[k]['sat']:5.1f} {s[k]['used']:5.3f} "
            f"{100 * s[k]['edge']:5.1f} {100 * s[k]['spin']:5.1f} {100 * s[k]['radial']:5.1f}" for k in (0, 1)))
    head = ("run                          eff    eff_c  ratio  F1/F2   per shaft (driving, driven): loss %, mean slip "
            "m/s, sliding > v0 %, friction used, edge share %, spin share %, radial share %")
    texts.append("\n".join([head] + rows))
    print(texts[-1])
    text = "\n\n".join(texts)
    if a.txt:
        Path(a.txt).parent.mkdir(parents=True, exist_ok=True)
        Path(a.txt).write_text(text + "\n")


if __name__ == "__main__":
    main()
