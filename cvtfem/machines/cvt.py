"""CVT scenes -> the band CVT model (:func:`closed_loop`) and the layout of any CVT model.

Coordinate counts follow the spec: band models (low-order digest section 4),
chain models (chain-models-2.md section 0: 2/3/5/10/21 per pin), shafts
(shafts-sheaves-supports.md: rigid 2 per shaft, elastic 6 per node plus the
movable sheave's axial coordinate), controller states (low-order digest section 5.5).
"""
from __future__ import annotations

import importlib.util
import math
from typing import Any

from cvtfem.control.stabilisation import LOOP_OUTPUTS, Stabilisation
from cvtfem.elements.base import Layout
from cvtfem.errors import InputError, NumericalError
from cvtfem.outputs import OutputSpec
from cvtfem.scene.loader import Scene

#: Generalized coordinates per pin of each discrete chain model.
CHAIN_COORDS_PER_PIN = {"chain-S1": 2, "chain-S2": 3, "chain-S3": 5, "chain-A1": 10, "chain-A2": 10,
                        "chain-A3": 10, "chain-A4": 10, "chain-A5": 21, "chain-A5-point": 21}


def _band(model: str, ritz_order: int, nodes: int) -> Layout:
    outputs = [OutputSpec("band.span_angle", "rad", "Span angle phi of the band.")]
    if model == "band-1dof":
        return Layout("band", model, 1, outputs=tuple(outputs), note="equilibrium angle phi only (static)")
    outputs += [OutputSpec("band.slip_speed", "m/s", "Circumferential slip speed at the middle of each arc.", 2),
                OutputSpec("band.slip_max", "m/s", "Largest slip speed along each arc.", 2),
                OutputSpec("band.mean_normal_force", "N/m", "Mean normal force per sheave on each arc.", 2)]
    kernel = "numba" if importlib.util.find_spec("numba") else "numpy (numba not installed)"
    if model == "band-4dof":
        return Layout("band", model, 2, outputs=tuple(outputs), note=f"phi, sigma; right-hand side: {kernel}")
    outputs += [OutputSpec("band.normal_force", "N/m",
                           f"Normal force per sheave at the {nodes} Gauss nodes of each arc (arc 1, then arc 2).",
                           2 * nodes)]
    return Layout("band", model, 2 + 2 * ritz_order, outputs=tuple(outputs),
                  note=f"phi, sigma and {ritz_order} Ritz coefficients per arc; right-hand side: {kernel}")


def _shaft(name: str, scene: Scene, model: str) -> Layout:
    cvt = scene.cvt
    shaft = cvt[name]
    outputs = [OutputSpec(f"{name}.speed", "rad/s", f"Angular speed of the {name} shaft."),
               OutputSpec(f"{name}.torque", "N m", f"External torque on the {name} shaft."),
               OutputSpec(f"{name}.clamping_force", "N", f"Clamping force of the {name} pulley.")]
    if model == "band-1dof":
        return Layout(f"{name} pulley", "rigid-static", 0, outputs=tuple(outputs[2:]), note="prescribed")
    if model == "band-4dof":
        return Layout(f"{name} pulley", "rigid-shaft", 1, outputs=tuple(outputs), note="spin angle")
    if model == "band-6+2n":
        return Layout(f"{name} pulley", "rigid-shaft", 2, outputs=tuple(outputs), note="spin angle, sheave axial")
    if model == "band-6+2n+8":
        return Layout(f"{name} pulley", "compliant-shaft", 6, outputs=tuple(outputs),
                      note="spin, sheave axial, 2 shifts, 2 tilts")
    if not cvt.effects.shaft_elasticity:
        return Layout(f"{name} pulley", "rigid-shaft", 2, outputs=tuple(outputs), note="spin angle, sheave axial")
    nodes = shaft.shaft_elements + 1
    outputs.append(OutputSpec(f"{name}.support_force", "N", "Radial force in each of the two bearings.", 4))
    return Layout(f"{name} pulley", "beam-shaft+rigid-sheaves", 6 * nodes + 1, outputs=tuple(outputs),
                  note=f"{nodes} beam nodes x 6 + movable sheave axial (machines/shaft_structure.py)")


def _chain(scene: Scene) -> Layout:
    cvt = scene.cvt
    chain = cvt.chain
    n = chain.n_pins
    model = cvt.model
    per_pin = CHAIN_COORDS_PER_PIN[model]
    outputs = [OutputSpec("chain.link_tension", "N", "Tension of each link.", n),
               OutputSpec("chain.pin_axial_force", "N", "Axial force of each pin.", n),
               OutputSpec("chain.contact_pressure", "Pa", "Peak pin-sheave contact pressure per pin end.", 2 * n)]
    if cvt.effects.pin_bending:
        outputs.append(OutputSpec("chain.pin_bending_moment", "N m", "Bending moment at pin mid-length.", n))
    halves = 2 if model.startswith("chain-A5") else 1
    discrete = 2 * halves * n  # contact on/off at each pin(-half) end
    note = f"{n} pins x {per_pin}"
    if model in ("chain-A4", "chain-A5", "chain-A5-point"):
        discrete += n * chain.plates_per_link  # plate contact states (10 values each)
        note += f"; plate states {n} x {chain.plates_per_link}"
    return Layout("chain", model, n * per_pin, discrete=discrete, outputs=tuple(outputs), note=note)


def _components(scene: Scene, body: Layout) -> tuple[Layout, ...]:
    """``body`` (band or chain), both pulleys, the loops when switched on, and the derived outputs, in DOF order."""
    cvt = scene.cvt
    model = cvt.model
    parts = [body, _shaft("driving", scene, model), _shaft("driven", scene, model)]
    if cvt.effects.stabilisation and model != "band-1dof":
        parts.append(Layout("stabilisation", "speed-ratio-control", 0, n1=Stabilisation.size, outputs=LOOP_OUTPUTS,
                            note="smoothed speeds, F1 integral, b2 integral"))
    parts.append(Layout("transmission", "derived", 0,
                        outputs=(OutputSpec("efficiency", "-", "Output over input power (instantaneous; 0 while no power is put in)."),
                                 OutputSpec("ratio", "-", "Speed ratio omega1 / omega2."),
                                 OutputSpec("power", "W", "Input, output, dissipated and clamping power.", 4),
                                 OutputSpec("work", "J", "Input, output, dissipated and clamping work since t = 0.", 4),
                                 OutputSpec("energy", "J", "Kinetic plus elastic energy of the model.")),
                        note="derived outputs"))
    return tuple(parts)


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of the CVT model the scene calls for, in DOF order (a running chain: from its model)."""
    cvt = scene.cvt
    if cvt.model in RUNNING_CHAINS and chain_refusal(scene) is None:
        return _running_chain_layout(scene)
    body = _band(cvt.model, cvt.ritz_order, cvt.quadrature_nodes) if cvt.model.startswith("band") else _chain(scene)
    return _components(scene, body)


def band_params(scene: Scene, **overrides: Any):
    """:class:`~cvtfem.elements.band.params.BandParams` of a band-model CVT scene (``overrides`` replace fields)."""
    from cvtfem.elements.band.geometry import Sheave
    from cvtfem.elements.band.params import BandParams
    from cvtfem.scene.schema.cvt import mean_chain_length

    cvt = scene.cvt
    g, ch, eff = cvt.geometry, cvt.chain, cvt.effects
    sheave = Sheave(g.sheave_profile, g.flank_angle, g.torus_radius, g.torus_offset, ch.half_width)
    shafts = (cvt.driving, cvt.driven)
    values = dict(
        length=mean_chain_length(ch), L=g.centre_distance, w=ch.half_width, mass=ch.mass, sheaves=(sheave, sheave),
        J=tuple(s.inertia for s in shafts), m_sheave=tuple(s.sheave_mass for s in shafts),
        Theta=tuple(s.sheave_transverse_inertia for s in shafts), c_U=tuple(s.radial_stiffness for s in shafts),
        c_psi=tuple(s.tilt_stiffness for s in shafts), f0=cvt.friction.f0, v0=cvt.friction.v0, law=cvt.friction.law,
        c=ch.band_transverse_stiffness, damping_ratio=ch.damping_ratio, n_ritz=cvt.ritz_order,
        n_gauss=cvt.quadrature_nodes, friction=eff.friction, damping=eff.damping, gyroscopic=eff.gyroscopic,
        source_literal=cvt.source_literal)
    values.update(overrides)
    return BandParams(**values)


def pin_section(scene):
    """The pins' :class:`~cvtfem.elements.chain.geometry.PinSection`: the rectangle with the scene's ``pin_area`` and
    smallest second moment ``pin_I_min`` (side along the chain ``sqrt(12 I / F)``, ``width_n`` across it)."""
    import numpy as np

    from cvtfem.elements.chain.geometry import PinSection

    ch = scene.cvt.chain
    width_tau = float(np.sqrt(12.0 * ch.pin_I_min / ch.pin_area))
    section = PinSection(width_tau, ch.pin_area / width_tau, scene.cvt.young_modulus)
    if section.width_n < width_tau:
        raise InputError("cvt.chain.pin_I_min", ch.pin_I_min,
                         f"must be at most pin_area^2 / 12 = {ch.pin_area ** 2 / 12:.4g} m^4 (the square section) "
                         "for a rectangular pin of that area")
    return section


def chain_geometry(scene: Scene):
    """:class:`~cvtfem.elements.chain.geometry.ChainGeometry` of a CVT scene's ``[cvt.chain]``.

    Links: the long/short pattern of :func:`~cvtfem.elements.link_pattern.link_lengths` seeded by ``seed``
    (a uniform chain when ``long_fraction`` is 0 or 1).  Pins: the rectangle with the scene's ``pin_area`` and
    smallest second moment ``pin_I_min`` (side along the chain ``sqrt(12 I / F)``), steel, ``pin_length`` long;
    the rest of ``mass`` in equal plates sharing ``link_stiffness``, laced with ``lacing_period``.
    """
    import numpy as np

    from cvtfem.elements.chain.geometry import chain_geometry as build
    from cvtfem.elements.link_pattern import link_lengths

    ch = scene.cvt.chain
    pitch = link_lengths(ch.n_pins, ch.pitch_short, ch.pitch_long, ch.long_fraction, np.random.default_rng(scene.seed))
    section = pin_section(scene)
    return build(ch.n_pins, ch.pin_length, pitch, ch.plates_per_link, ch.link_stiffness, ch.mass, section,
                 period=ch.lacing_period, c_pin=ch.pin_axial_stiffness)


#: The per-plate whole-pin chains (A3: plates clamped to the pins, A4: the ten plate states); they run with H1 or H2 on
#: rigid or elastic shafts (variants (g), (d)), :func:`_per_plate_refusal`.
PER_PLATE_CHAINS = ("chain-A3", "chain-A4")
#: Discrete-chain models that run as a transmission (the others exist as element families only).
RUNNING_CHAINS = ("chain-S1", "chain-S2", "chain-S3", "chain-A1", "chain-A2", "chain-A5", "chain-A5-point",
                  *PER_PLATE_CHAINS)
#: The chains that take the impact at contact onset (``effects.contact = "impact"``, rigid shafts).
IMPACT_CHAINS = ("chain-S2", "chain-S3", "chain-A1")


def band_model(scene: Scene, **overrides: Any):
    """The dynamic band model a scene calls for (``band-4dof``, ``band-6+2n``, ``band-6+2n+8``).

    Raises InputError for the static ``band-1dof`` and for discrete-chain models (:func:`chain_loop`).
    """
    from cvtfem.elements.band import model_for

    model = scene.cvt.model
    if model.startswith("chain"):
        raise InputError("cvt.model", model, "is a discrete-chain model, not a band model")
    if model == "band-1dof":
        raise InputError("cvt.model", model, "is the static equilibrium model and has no time run",
                         "use a dynamic band model (band-4dof, band-6+2n, band-6+2n+8)")
    band = model_for(model, band_params(scene, **overrides))
    if scene.sheave is not None and scene.sheave.flexibility != "rigid":  # issue 20: sheave faces give way
        import dataclasses

        from cvtfem.machines.sheave import band_faces

        band = dataclasses.replace(band, faces=band_faces(scene))
    return band


def check_ratio_range(scene: Scene, p=None) -> tuple[float, float]:
    """Admissible ratio range of the scene's sheaves; InputError for a regime ratio outside it.

    Both contact radii must stay within ``cvt.geometry.r_min .. r_max`` at the target ratio (and at
    the end value of a ratio change), otherwise the band would run below the hub or beyond the rim.
    """
    from cvtfem.elements.band.geometry import admissible_ratio_range

    p = p or band_params(scene)
    g, rg = scene.cvt.geometry, scene.cvt.regime
    lo, hi = admissible_ratio_range(p.length, p.L, g.r_min, g.r_max)
    values = [("cvt.regime.ratio", rg.ratio)]
    if rg.kind == "ratio-change":
        values.append(("cvt.regime.end_value", rg.end_value))
    for where, value in values:
        if not lo <= value <= hi:
            what = "" if where == "cvt.regime.ratio" else "(the end ratio of the change of `cvt.regime.ratio`) "
            raise InputError(where, value, f"{what}must lie in {lo:.4f}..{hi:.4f}: the ratios whose contact radii "
                             f"stay within r_min = {g.r_min:g} m .. r_max = {g.r_max:g} m of the sheaves")
    return lo, hi


def closed_loop(scene: Scene, **overrides: Any):
    """Scene -> :class:`~cvtfem.machines.band_cvt.BandCVT` (band family, clamping schedule, regime, control
    family and the components with their outputs), in one pass; ``overrides`` replace band parameters."""
    from cvtfem.control.clamping import Clamping
    from cvtfem.control.loop_start import integral_start
    from cvtfem.control.regimes import Regime
    from cvtfem.control.stabilisation import OpenLoop, StabilisationParams
    from cvtfem.elements.band.geometry import phi_for_ratio, radii
    from cvtfem.machines.band_cvt import BandCVT

    cvt = scene.cvt
    if cvt.model.startswith("chain"):
        return chain_loop(scene)
    model = band_model(scene, **overrides)
    p = model.p
    rg = cvt.regime
    check_ratio_range(scene, p)
    regime = Regime(rg.kind, rg.input_speed, rg.torque, rg.ratio, rg.end_value, rg.ramp_time)
    clamping = Clamping(p, rg.clamping_safety, rg.clamping_split, rg.min_clamping_force)
    control = OpenLoop()
    if cvt.effects.stabilisation:
        c = cvt.control
        r2 = radii(phi_for_ratio(rg.ratio, p.length, p.L), p.length, p.L)[0][1]
        J_sigma = p.J[0] * rg.ratio ** 2 + p.J[1] + p.mass * r2 ** 2
        control = Stabilisation(StabilisationParams(c.tau_omega, c.eps, c.i_min, c.i_max, c.k_sat, c.c_f0, c.c_f1,
                                                    c.c_sat, c.tau, c.nu, J_sigma,
                                                    integral_start(c.ratio_loop_start, c.start_force_ratio,
                                                                   clamping.forces(rg.torque, rg.ratio), c.k_sat)))
    parts = _components(scene, _band(cvt.model, p.n_ritz, p.n_gauss))
    return BandCVT(model, clamping, regime, control, parts)


def chain_refusal(scene: Scene) -> InputError | None:
    """Why :func:`chain_loop` cannot build the scene's chain as a running transmission yet (the error naming the
    key), or None when it can."""
    cvt = scene.cvt
    model, eff = cvt.model, cvt.effects
    if model in PER_PLATE_CHAINS:
        return _per_plate_refusal(model, eff)
    if model not in RUNNING_CHAINS:
        return InputError("cvt.model", model, "must be a discrete chain that runs in time: " + ", ".join(RUNNING_CHAINS)
                          + " (the other chain models exist as element families only so far, docs/chain.md)")
    if model not in ("chain-S1", "chain-S2") and not eff.pin_bending:
        return InputError("cvt.effects.pin_bending", False, f"must be true for `{model}` (its pins bend); "
                          "without pin bending use `chain-S2`")
    if model == "chain-S1" and eff.contact == "impact":
        return InputError("cvt.effects.contact", eff.contact, "must be 'rigid' for `chain-S1`: its pins carry no axial "
                          "inertia, so a pin end entering a sheave takes no impulse (chain-models-1 2.1); the impact "
                          "at contact onset runs with " + ", ".join(IMPACT_CHAINS))
    if eff.contact == "impact" and model not in IMPACT_CHAINS:
        return InputError("cvt.effects.contact", eff.contact, f"must be 'hertz' or 'hertz-refined' for `{model}`: the "
                          "impact at contact onset runs with " + ", ".join(IMPACT_CHAINS) + " only so far (rigid "
                          "shafts)")
    if model == "chain-S1" and eff.contact != "rigid":
        return InputError("cvt.effects.contact", eff.contact, "must be 'rigid' for `chain-S1`: its pins have no axial "
                          "coordinate, their ends follow the sheave faces (chain-models-1 2.2)")
    if eff.shaft_elasticity and model not in ("chain-S2", "chain-S3", "chain-A1", "chain-A2", "chain-A5",
                                              "chain-A5-point"):
        return InputError("cvt.effects.shaft_elasticity", True, f"is not available for `{model}` yet: elastic shafts "
                          "run under chain-S2, chain-S3, chain-A1, chain-A2 and chain-A5 (set it false to run on rigid "
                          "shafts)")
    if eff.shaft_elasticity and eff.contact != "hertz" and not (eff.contact == "hertz-refined"
                                                                and model in ("chain-A1", "chain-A2", "chain-A5")):
        return InputError("cvt.effects.shaft_elasticity", True, f"is not available with contact '{eff.contact}' for "
                          f"`{model}` yet: elastic shafts run with H1 contact ('hertz'), or the refined one under "
                          "chain-A1, chain-A2 and chain-A5 (variants (b), (v), (e)); set it false for the refined or "
                          "rigid contact")
    if model != "chain-S1" and eff.contact not in ("hertz", "hertz-refined", "impact"):
        return InputError("cvt.effects.contact", eff.contact, f"must be 'hertz' or 'hertz-refined' for `{model}`: "
                          "Hertz contact at the pin-axis end or refined (the rigid contact runs with `chain-S1` only, "
                          "the impact at contact onset with " + ", ".join(IMPACT_CHAINS) + ")")
    if eff.contact == "hertz-refined" and model not in ("chain-S2", "chain-S3", "chain-A1", "chain-A2", "chain-A5"):
        return InputError("cvt.effects.contact", eff.contact, f"must be 'hertz' for `{model}`: the refined contact "
                          "runs with chain-S2, chain-S3, chain-A1, chain-A2 and chain-A5 only so far")
    if model == "chain-A2" and eff.contact != "hertz-refined":
        return InputError("cvt.effects.contact", eff.contact, "must be 'hertz-refined' for `chain-A2`: its coupled "
                          "pin halves touch the sheaves with their biconvex end faces (Table 1.1 (v))")
    if not eff.friction:
        return InputError("cvt.effects.friction", False, "must be true for a chain transmission: the chain "
                          "transmits torque only by pin-sheave friction")
    return None


def _per_plate_refusal(model: str, eff) -> InputError | None:
    """:func:`chain_refusal` for ``chain-A3``/``chain-A4``: pins that bend, Hertz contact (H1 or H2) and friction; rigid or
    elastic shafts."""
    if not eff.pin_bending:
        return InputError("cvt.effects.pin_bending", False, f"must be true for `{model}` (its pins bend); "
                          "without pin bending use `chain-S2`")
    if eff.contact not in ("hertz", "hertz-refined"):
        return InputError("cvt.effects.contact", eff.contact, f"must be 'hertz' or 'hertz-refined' for `{model}`: Hertz "
                          "contact at the pin-axis end or refined (the rigid contact runs with `chain-S1` only, the "
                          "impact at contact onset with " + ", ".join(IMPACT_CHAINS) + ")")
    if not eff.friction:
        return InputError("cvt.effects.friction", False, "must be true for a chain transmission: the chain "
                          "transmits torque only by pin-sheave friction")
    return None


def chain_loop(scene: Scene):
    """Scene -> :class:`~cvtfem.machines.chain_cvt.ChainCVT`: the chain of :func:`chain_geometry` on two rigid
    shafts with Hertz contact at the pin-axis ends (H1) or refined (H2, ``effects.contact = "hertz-refined"``),
    the scene's friction, shafts, loops and regime.

    The prescribed clamping forces are those the band models get (:class:`~cvtfem.control.clamping.Clamping`
    at the regime's start: torque, ratio, safety factor, split); the ratio loop corrects ``F1`` from there.
    Only what runs is accepted: ``chain-S1`` (rigid contact: the pin ends follow the faces), ``chain-S2`` (no pin
    bending), ``chain-S3`` and the whole-pin chains ``chain-A1`` and ``chain-A2`` (pin bending;
    :mod:`~cvtfem.machines.chain_a_cvt`, a fixed and a movable sheave per shaft; A2's coupled halves
    :mod:`~cvtfem.machines.chain_a2_cvt`), rigid shafts, ``effects.contact = "hertz"`` (S2, S3, A1) or
    ``"hertz-refined"`` (all four; variant (a) is A1 with it), friction on; with ``effects.shaft_elasticity`` S2, S3
    and A1 with H1 on elastic shafts (:mod:`~cvtfem.machines.chain_cvt_elastic`).  The per-plate chains ``chain-A3`` and
    ``chain-A4`` run as A1 does (H1 or H2, rigid or elastic shafts: variants (g), (d)), starting from A1's balance.
    """
    from cvtfem.control.clamping import Clamping
    from cvtfem.machines.chain_cvt import from_scene

    refusal = chain_refusal(scene)
    if refusal is not None:
        raise refusal
    cvt = scene.cvt
    model, eff, rg = cvt.model, cvt.effects, cvt.regime
    check_ratio_range(scene)
    clamping = Clamping(band_params(scene), rg.clamping_safety, rg.clamping_split, rg.min_clamping_force)
    F_appl = clamping.forces(rg.torque, rg.ratio)
    overrides = {} if eff.damping else {"damping_ratio": 0.0}
    geom = chain_geometry(scene)
    try:    # building places the chain on the sheaves at the start ratio (the fixed sheaves' wedge estimate)
        if eff.shaft_elasticity:
            from cvtfem.machines.chain_cvt_elastic import from_scene as elastic_from_scene
            built = elastic_from_scene(scene, geom, F_appl, model=model, contact=eff.contact, **overrides)
        elif eff.contact == "impact":
            from cvtfem.machines.chain_impact_cvt import from_scene as impact_from_scene
            built = impact_from_scene(scene, geom, F_appl, model=model, **overrides)
        else:
            built = from_scene(scene, geom, F_appl, model=model, contact=eff.contact, **overrides)
    except NumericalError as err:   # no placement exists: the scene's geometry and stiffnesses disagree
        raise InputError("cvt.chain", f"{cvt.chain.n_pins} pins", f"must be placeable on the sheaves at the start "
                         f"ratio {rg.ratio} with the clamping forces {F_appl[0]:.4g} / {F_appl[1]:.4g} N: {err}",
                         "check the chain's lengths and stiffnesses against cvt.geometry") from None
    if scene.sheave is not None and scene.sheave.flexibility != "rigid":  # issue 20: faces that open under the pins
        from cvtfem.machines.chain_cvt_flexible import flexible_faces_model
        built = flexible_faces_model(scene, built)
    return built


def _pulley_layouts(model, outputs, sheave: str) -> list[Layout]:
    """The two pulleys of a running chain: rigid shafts (2 coordinates) or the elastic structure block."""
    structure = getattr(model, "structure", None)
    if structure is None:
        return [Layout(f"{name} pulley", "rigid-shaft", 2, outputs=outputs(f"{name}."),
                       note=f"spin angle, {sheave} axial") for name in ("driving", "driven")]
    return [Layout(f"{name} pulley", "beam-shaft+rigid-sheaves", 6 * len(x) + 1, outputs=outputs(f"{name}."),
                   note=f"{len(x)} beam nodes x 6 + movable sheave axial") for name, x in zip(("driving", "driven"),
                                                                                             structure.x)]


def _contact_note(scene: Scene) -> str:
    """Which contact the running chain's pin ends have, for `describe`."""
    if scene.cvt.model == "chain-S1":
        return "rigid contact: the pin ends follow the faces of"
    if scene.cvt.effects.contact == "impact":
        return "impact at contact onset (C2), then Hertz (H1) contact at both pin ends with"
    refined = scene.cvt.effects.contact == "hertz-refined"
    where = "both ends of both pin halves" if scene.cvt.model in ("chain-A2", "chain-A5", "chain-A5-point") else \
        "both pin ends"
    faces = ", the faces opening under the pin forces," if scene.sheave is not None and \
        scene.sheave.flexibility != "rigid" else ""
    ch = scene.cvt.chain
    pin_face = f" (pin end faces crowned {ch.face_radius * 1e3:g} mm" + (
        f", inclined {math.degrees(ch.face_inclination):.3g} deg)" if refined else ")")
    return f"{'refined (H2)' if refined else 'Hertz (H1)'} contact{pin_face}{faces} at {where} with"


def _plate_state_note(scene: Scene, model) -> str:
    """``chain-A4``: where its plates' contact states live, for `describe`."""
    if scene.cvt.model != "chain-A4":
        return ""
    return (f"; each of its {model.family.chain.n_plates} plates in one of 10 contact states, classified from its "
            "strains inside the right-hand side (no events: the forces are continuous across the state boundaries)")


def _running_chain_layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of :func:`chain_loop`'s model with the outputs it writes, grouped by name prefix."""
    model = chain_loop(scene)
    n, per_pin = model.family.n, CHAIN_COORDS_PER_PIN[scene.cvt.model]
    sheave = "sheave pair" if model.sheaves_per_z == 2 else "movable sheave"

    def outputs(*prefixes: str) -> tuple[OutputSpec, ...]:
        return tuple(o for o in model.output_specs if o.name.startswith(prefixes))

    parts = [Layout("chain", scene.cvt.model, n * per_pin, outputs=outputs("chain.", "contact."),
                    n1=getattr(model, "n_discrete", -1) + 1, discrete=getattr(model, "n_discrete", 0),
                    note=f"{n} pins x {per_pin}; {_contact_note(scene)} each shaft's sheaves "
                         + ("(discrete state per pin end and shaft, impact loss)" if hasattr(model, "n_discrete")
                            else "(continuous: no discrete state)") + _plate_state_note(scene, model)),
             *_pulley_layouts(model, outputs, sheave)]
    if scene.cvt.effects.stabilisation:
        parts.append(Layout("stabilisation", "speed-ratio-control", 0, n1=Stabilisation.size,
                            outputs=outputs("control."), note="smoothed speeds, F1 integral, b2 integral"))
    parts.append(Layout("transmission", "derived", 0, n1=4, outputs=outputs("ratio", "efficiency", "power", "work",
                                                                            "energy"),
                        note="work integrals and derived outputs"))
    return tuple(parts)
