"""``cvtfem spectrogram RESULTS --series NAME [--component J|norm] [--fmax HZ] [--png OUT] [--csv OUT]``:
spectrogram of a stored series (e.g. a shaft's support force) with the chain's excitation lines, and its
time-averaged intensity over f / f_chain."""
from __future__ import annotations

import argparse

#: API argument names that the command takes as options of the same name.
OPTIONS = ("series", "component", "fmax", "window", "overlap", "start")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("spectrogram", help="spectrogram of a run's series (support forces) with k f_chain and "
                                           "k/3 f_link lines; intensity over f / f_chain")
    p.add_argument("results", metavar="RESULTS", help="HDF5 results file of a run")
    p.add_argument("--series", required=True, help="stored series, e.g. driving.support_force")
    p.add_argument("--component", default="0", help="column index of the series or 'norm' (default 0)")
    p.add_argument("--fmax", type=float, default=5000.0, metavar="HZ",
                   help="highest frequency shown, Hz, at most Nyquist (default 5000)")
    p.add_argument("--window", type=float, default=None, metavar="S",
                   help="FFT window, s (default: a quarter of the analysed time, at most 0.1 s)")
    p.add_argument("--overlap", type=float, default=0.75, help="overlapping share of windows (default 0.75)")
    p.add_argument("--start", type=float, default=0.0, metavar="S", help="analyse from this time on, s (default 0)")
    p.add_argument("--chain-orders", default="1,2,3", metavar="K,...",
                   help="draw the lines k f_chain for these k (default 1,2,3; '' for none)")
    p.add_argument("--f-chain", type=float, default=None, metavar="HZ",
                   help="chain revolution frequency, Hz, instead of the one read from the run (a discrete "
                        "chain's pins' travel; band models: omega_1 r_1 / l_chain)")
    p.add_argument("--campbell", metavar="CSV", help="draw the tracked modes of a `cvtfem runcampbell --csv` file "
                                                     "of the same run over the spectrogram")
    p.add_argument("--no-lines", action="store_true", help="draw no excitation lines (a run without a chain)")
    p.add_argument("--png", metavar="OUT", help="write the spectrogram as PNG")
    p.add_argument("--intensity-png", metavar="OUT", help="write the intensity over f / f_chain as PNG")
    p.add_argument("--csv", metavar="OUT", help="write the spectrogram (dB, one row per frequency) as CSV")
    p.add_argument("--intensity-csv", metavar="OUT", help="write the intensity over f / f_chain as CSV")
    p.add_argument("--order-png", metavar="OUT", help="write the order spectrum (the signal resampled in chain "
                                                      "revolutions, one periodogram) as PNG")
    p.add_argument("--order-csv", metavar="OUT", help="write the order spectrum as CSV")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.commands.paths import check_output_file
    from cvtfem.errors import InputError

    for dest in ("intensity_png", "intensity_csv", "order_png", "order_csv"):
        value = getattr(args, dest)
        if value is not None:
            check_output_file(f"--{dest.replace('_', '-')}", value)
    for dest in ("intensity_png", "order_png"):
        value = getattr(args, dest)
        if value is not None and not value.lower().endswith(".png"):
            raise InputError(f"--{dest.replace('_', '-')}", value, "must name a .png file")
    try:
        orders = tuple(int(k) for k in args.chain_orders.split(",") if k.strip())
    except ValueError:
        raise InputError("--chain-orders", args.chain_orders, "must be comma-separated integers, e.g. 1,2,3") from None
    try:
        return _run(args, orders)
    except InputError as err:               # the API names its arguments; the command names its options
        if err.where in OPTIONS:
            raise InputError(f"--{err.where}", err.value, err.rule, err.hint) from None
        raise


def _run(args: argparse.Namespace, orders: tuple[int, ...]) -> int:
    import numpy as np

    from cvtfem.errors import InputError
    from cvtfem.io.results import read_results
    from cvtfem.post import spectrogram as sg

    results = read_results(args.results)
    t, y, label = sg.select_signal(results, args.series, args.component, args.start)
    window = args.window if args.window is not None else min(0.25 * (t[-1] - t[0]), 0.1)
    spec = sg.compute_spectrogram(t, y, window, args.overlap, args.fmax, results.units.get(args.series, ""))
    freqs = None if args.no_lines else sg.chain_frequencies(results, *chain_of(results))
    if args.f_chain is not None and freqs is not None:
        if not 0.0 < args.f_chain < spec.f[-1]:
            raise InputError("--f-chain", args.f_chain, f"must be a frequency in Hz with 0 < f_chain < {spec.f[-1]:g}")
        freqs = sg.ChainFrequencies(results.time, np.full(results.time.size, args.f_chain), freqs.n_pins)
    print(f"{label} from {t[0]:.6g} s to {t[-1]:.6g} s: {spec.t.size} windows of {1e3 * spec.window:.4g} ms, "
          f"resolution {spec.df:.4g} Hz, up to {spec.f[-1]:.6g} Hz")
    if freqs is not None:
        fc = freqs.at(spec.t)
        print(f"chain: f_chain {fc.min():.5g}..{fc.max():.5g} Hz, f_link = {freqs.n_pins} f_chain "
              f"{freqs.n_pins * fc.min():.5g}..{freqs.n_pins * fc.max():.5g} Hz")
    mean = spec.psd.mean(axis=1)
    top = np.argsort(mean[1:])[::-1][:5] + 1
    print("strongest lines of the mean spectrum: " + ", ".join(f"{spec.f[j]:.5g} Hz" for j in sorted(top)))
    if args.csv:
        sg.write_spectrogram_csv(spec, args.csv)
        print(f"wrote {args.csv}")
    if args.png:
        from cvtfem.post.spectrogram_plot import plot_spectrogram

        lines = () if freqs is None else sg.excitation_lines(freqs, spec.f[-1], orders)
        modes = None if args.campbell is None else campbell_modes(args.campbell)
        plot_spectrogram(spec, args.png, lines, None if freqs is None else freqs.t, label=label, modes=modes)
        print(f"wrote {args.png}")
    if (args.intensity_png or args.intensity_csv or args.order_png or args.order_csv) and freqs is None:
        raise InputError("--no-lines", True, "cannot be combined with --intensity-*/--order-* (the intensity and "
                         "the order spectrum over f / f_chain need the chain frequency)")
    if args.order_png or args.order_csv:
        _orders(args, t, y, freqs, label, spec.unit)
    if args.intensity_png or args.intensity_csv:
        intensity = sg.order_intensity(spec, freqs)
        if args.intensity_csv:
            sg.write_intensity_csv(intensity, args.intensity_csv)
            print(f"wrote {args.intensity_csv}")
        if args.intensity_png:
            from cvtfem.post.spectrogram_plot import plot_order_intensity

            plot_order_intensity(intensity, args.intensity_png, title=f"{label}: time-averaged intensity",
                                 unit=spec.unit)
            print(f"wrote {args.intensity_png}")
    return 0


def _orders(args: argparse.Namespace, t, y, freqs, label: str, unit: str) -> None:
    """The order spectrum of the analysed signal: written, and how far whole orders stand above half orders."""
    import numpy as np

    from cvtfem.post import spectrogram as sg

    spec = sg.order_spectrum(t, y, freqs)
    k = np.arange(1, freqs.n_pins)
    contrast = spec.band_contrast(k)
    print(f"order spectrum over {spec.revolutions:.4g} chain revolutions (resolution {1 / spec.revolutions:.3g}): "
          f"whole orders 1..{freqs.n_pins - 1} stand {contrast.mean():+.2f} dB (median {np.median(contrast):+.2f} dB) "
          f"above the half orders; peak at order {spec.order[np.argmax(spec.psd[1:]) + 1]:.4g}")
    if args.order_csv:
        np.savetxt(args.order_csv, np.column_stack([spec.order, spec.psd, spec.db()]), delimiter=",",
                   header="order,psd,dB", comments="", fmt="%.6g")
        print(f"wrote {args.order_csv}")
    if args.order_png:
        from cvtfem.post.spectrogram_plot import plot_order_spectrum

        plot_order_spectrum(spec, freqs.n_pins, args.order_png, title=f"{label}: order spectrum over "
                            f"{spec.revolutions:.3g} chain revolutions", unit=unit)
        print(f"wrote {args.order_png}")


def campbell_modes(path: str):
    """``(t (s,) s, f (s, k) Hz)``: the tracked modes of a ``cvtfem runcampbell --csv`` file."""
    import csv

    import numpy as np

    from cvtfem.errors import InputError

    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except OSError as err:
        raise InputError("--campbell", path, f"must be a readable CSV file ({err.strerror})") from None
    cols = [i for i, name in enumerate(rows[0] if rows else []) if name.startswith("mode") and name.endswith("_Hz")]
    if not cols or rows[0][0] != "t_s" or len(rows) < 3:
        raise InputError("--campbell", path, "must be a CSV of `cvtfem runcampbell --csv` with at least 2 times")
    data = np.array([[float(r[0])] + [float(r[i]) for i in cols] for r in rows[1:]])
    return data[:, 0], data[:, 1:]


def chain_of(results) -> tuple[int, float, float]:
    """``(n_pins, chain length m, centre distance m)`` of the CVT scene stored in a results file."""
    import tomllib

    from cvtfem.errors import InputError
    from cvtfem.scene.loader import scene_from_dict
    from cvtfem.scene.schema.cvt import mean_chain_length

    scene = scene_from_dict(tomllib.loads(results.scene_toml), source=str(results.path))
    if scene.kind != "cvt":
        raise InputError("RESULTS", str(results.path), f"must hold a CVT run for the chain frequencies (its scene is "
                         f"a {scene.kind} scene; use --no-lines)")
    chain = scene.cvt.chain
    return int(chain.n_pins), mean_chain_length(chain), float(scene.cvt.geometry.centre_distance)
