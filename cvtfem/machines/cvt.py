"""Layout of a chain-CVT model: which element families a CVT scene calls for.

Coordinate counts follow the spec: band models (low-order digest section 4),
chain models (chain-models-2.md section 0: 2/3/5/10/21 per pin), shafts
(shafts-sheaves-supports.md: rigid 2 per shaft, elastic 6 per node plus a
6-DOF movable sheave), controller states (low-order digest section 5.5).
"""
from __future__ import annotations

from cvtfem.elements.base import Layout, OutputSpec
from cvtfem.scene.loader import Scene

#: Generalized coordinates per pin of each discrete chain model.
CHAIN_COORDS_PER_PIN = {"chain-S1": 2, "chain-S2": 3, "chain-S3": 5, "chain-A1": 10, "chain-A2": 10,
                        "chain-A3": 10, "chain-A4": 10, "chain-A5": 21, "chain-A5-point": 21}

#: Controller states z = [smoothed omega1, smoothed omega2, F1 integral, b2 integral] (spec 5.5).
CONTROLLER_STATES = 4


def _band(model: str, ritz_order: int) -> Layout:
    outputs = [OutputSpec("band.span_angle", "rad", "Span angle phi of the band."),
               OutputSpec("band.tension", "N", "Band tension in the two spans.", 2)]
    if model == "band-1dof":
        return Layout("band", model, 1, outputs=tuple(outputs), note="equilibrium angle phi only (static)")
    outputs += [OutputSpec("band.slip_speed", "m/s", "Mean slip speed on each pulley.", 2)]
    if model == "band-4dof":
        return Layout("band", model, 2, outputs=tuple(outputs), note="phi, sigma")
    outputs += [OutputSpec("band.normal_force", "N/m", "Normal force along each contact arc.", 2 * 32)]
    return Layout("band", model, 2 + 2 * ritz_order, outputs=tuple(outputs),
                  note=f"phi, sigma and {ritz_order} Ritz coefficients per arc")


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
    return Layout(f"{name} pulley", "beam-shaft+rigid-sheave", 6 * nodes + 6, outputs=tuple(outputs),
                  note=f"{nodes} beam nodes x 6 + movable sheave 6")


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


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of the CVT model the scene calls for, in DOF order."""
    cvt = scene.cvt
    model = cvt.model
    band = model.startswith("band")
    parts = [_band(model, cvt.ritz_order) if band else _chain(scene),
             _shaft("driving", scene, model), _shaft("driven", scene, model)]
    if cvt.effects.stabilisation and model != "band-1dof":
        parts.append(Layout("stabilisation", "speed-ratio-control", 0, n1=CONTROLLER_STATES,
                            outputs=(OutputSpec("control.ratio_estimate", "-", "Smoothed ratio estimate."),
                                     OutputSpec("control.resistance", "N m s", "Driven-shaft resistance b2.")),
                            note="smoothed speeds, F1 integral, b2 integral"))
    parts.append(Layout("transmission", "derived", 0,
                        outputs=(OutputSpec("efficiency", "-", "Output over input power."),
                                 OutputSpec("ratio", "-", "Speed ratio omega1 / omega2.")),
                        note="derived outputs"))
    return tuple(parts)
