"""``cvtfem jacobian RESULTS --at T[,T...] [--png OUT] [--csv OUT]``: eigenvalues of the full Jacobian of a run's
model at stored states, on the signed-log complex plane (spec integrators §2.3), with the figures an integrator
choice rests on (stiffness: the most negative real part; oscillation: the largest imaginary part)."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("jacobian", help="spectrum of the full Jacobian at stored states of a run (signed-log plane)")
    p.add_argument("results", metavar="RESULTS", help="HDF5 results file of a run with `output.state = true`")
    p.add_argument("--at", required=True, metavar="T[,T...]",
                   help="stored times, s (the nearest stored row each; at most 4)")
    p.add_argument("--png", metavar="OUT", help="write the eigenvalues on the signed-log plane as PNG")
    p.add_argument("--csv", metavar="OUT", help="write the eigenvalues as CSV (t_s, re, im)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from cvtfem.analysis.accuracy_cost import jacobian_spectrum
    from cvtfem.analysis.stored_state import rows_at, stored_model, stored_states
    from cvtfem.blas import single_thread_blas
    from cvtfem.errors import InputError
    from cvtfem.io.results import read_results

    try:
        times = [float(v) for v in args.at.split(",") if v.strip()]
    except ValueError:
        raise InputError("--at", args.at, "must be comma-separated times in s, e.g. 0.001,0.002") from None
    if not 1 <= len(times) <= 4:
        raise InputError("--at", args.at, "must name 1 to 4 times")
    results = read_results(args.results)
    t = results.time
    rows = rows_at(t, times)
    model = stored_model(results)
    _, x = stored_states(results, model)
    spectra = {}
    with single_thread_blas():
        for i in rows:
            lam = jacobian_spectrum(model, x[i], float(t[i]))
            if not np.all(np.isfinite(lam)):
                raise InputError("--at", float(t[i]), "must name a state whose Jacobian is finite")
            spectra[float(t[i])] = lam
            osc = lam[np.abs(lam.imag) > 0]
            print(f"t = {t[i]:.6g} s: {lam.size} eigenvalues, min Re {lam.real.min():.4g} 1/s, max Re "
                  f"{lam.real.max():.4g} 1/s, max |Im| {np.abs(lam.imag).max():.4g} 1/s "
                  f"({np.abs(lam.imag).max() / (2 * np.pi):.4g} Hz), {osc.size // 2} oscillatory pairs, "
                  f"{int(np.count_nonzero(lam.real > 1e-6 * np.abs(lam).max()))} with Re > 0")
    if args.csv:
        rows = [(ti, v.real, v.imag) for ti, lam in spectra.items() for v in lam]
        np.savetxt(args.csv, np.array(rows), delimiter=",", header="t_s,re_1_s,im_1_s", comments="", fmt="%.9g")
        print(f"wrote {args.csv}")
    if args.png:
        from cvtfem.post.accuracy_cost import plot_spectra

        labelled = {f"t = {ti:.6g} s": lam for ti, lam in spectra.items()}
        plot_spectra(labelled, args.png, title=f"{results.path.name}: eigenvalues of the full Jacobian "
                                               f"({model.size} states)")
        print(f"wrote {args.png}")
    return 0
