"""The chain CVT: geometry, chain, shafts and supports, friction, control, regime.

Spec: ``shared/spec/low-order-models-control-regimes.md`` (section 9 is the
reference parameter table), ``chain-models-*.md``, ``shafts-sheaves-supports.md``.
Machine keys have no defaults on purpose: the ``reference_cvt`` preset gives
every value with its provenance.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from cvtfem.errors import InputError
from cvtfem.scene.schema.base import Key, Table

#: Model variants: low-order band models (issue 5) and discrete chains
#: (Table 1.1 of the source; internal names of chain-models-2.md section 0).
MODELS = (
    "band-1dof", "band-4dof", "band-6+2n", "band-6+2n+8",
    "chain-S1", "chain-S2", "chain-S3", "chain-A1", "chain-A2", "chain-A3", "chain-A4",
    "chain-A5", "chain-A5-point",
)

GEOMETRY = Table("geometry", "Shaft centre distance and sheave faces.", (
    Key("centre_distance", "float", "Distance L between the shaft axes.", "m", gt=0.0),
    Key("sheave_profile", "str", "Shape of the sheave face in an axial section.", "", choices=("conical", "toroidal")),
    Key("flank_angle", "float",
        "Angle gamma between face normal and shaft axis (conical: exact; toroidal: nominal, for estimates).",
        "rad", gt=0.0, lt=math.pi / 4),
    Key("torus_radius", "float", "Radius R of the toroidal face's generating arc (toroidal sheaves).", "m", 0.0, ge=0.0),
    Key("torus_offset", "float", "Radial offset y of the torus centre from the shaft axis (toroidal sheaves).",
        "m", 0.0, ge=0.0),
    Key("r_min", "float", "Smallest contact radius the sheaves allow.", "m", gt=0.0),
    Key("r_max", "float", "Largest contact radius the sheaves allow.", "m", gt=0.0),
    Key("sheave_outer_radius", "float", "Outer radius of the sheaves.", "m", gt=0.0),
), checks=(lambda t, p: _check_geometry(t, p),))

CHAIN = Table("chain", "The chain (pins, plates, links) and its band abstraction.", (
    Key("n_pins", "int", "Number of pins (= links); a multiple of the lacing period (at most 1000: CVT chains "
        "have 60-130).", "-", ge=6, le=1000),
    Key("pitch_short", "float", "Length of a short link.", "m", gt=0.0),
    Key("pitch_long", "float", "Length of a long link.", "m", gt=0.0),
    Key("long_fraction", "float", "Fraction of long links in the randomised pattern (seeded by `seed`).",
        "-", ge=0.0, le=1.0),
    Key("plates_per_link", "int", "Plates in one link (at most 64: CVT chains have 10-20).", "-", ge=1, le=64),
    Key("lacing_period", "int", "Number of links after which the plate lacing repeats.", "-", ge=1),
    Key("mass", "float", "Total chain mass.", "kg", gt=0.0),
    Key("pin_length", "float", "Pin length (across the chain).", "m", gt=0.0),
    Key("pin_I_min", "float", "Smallest principal second moment of area of a whole pin.", "m^4", gt=0.0),
    Key("pin_area", "float", "Cross-section area of a whole pin (two halves).", "m^2", gt=0.0),
    Key("pin_axial_stiffness", "float", "Axial stiffness c_p of a pin between its sheave contacts.", "N/m", gt=0.0),
    Key("link_stiffness", "float", "Tensile stiffness of one link (all its plates).", "N/m", gt=0.0),
    Key("band_transverse_stiffness", "float",
        "Transverse (axial) stiffness c of the band per unit length, both sheaves (6+2n models).", "N/m^2", gt=0.0),
    Key("half_width", "float", "Half-width w of the band (pin end to chain mid-plane).", "m", gt=0.0),
    Key("damping_ratio", "float", "Modal damping ratio nu of the chain's elastic elements (beta = 2 nu / k).",
        "-", ge=0.0, lt=1.0),
    Key("face_radius", "float", "Crown radius R_f of the pin end faces, both directions (the face z = tan(theta) "
        "xi_out + |xi|^2 / (2 R_f) over the pin section): sets the Hertz constant and, with the refined contact, "
        "the contact point.", "m", 0.02, gt=0.0, le=1.0),
    Key("face_inclination", "float", "Angle theta of the pin end face's normal (at the pin axis) from the pin axis, "
        "tilted outward towards the sheave flank; refined contact only. 0: crowned symmetrically about the axis; "
        "`geometry.flank_angle`: parallel to a conical flank (the contact point on the pin axis).", "rad", 0.0,
        ge=0.0, lt=math.pi / 4),
), checks=(lambda t, p: _check_chain(t, p),))


def _shaft(name: str, doc: str) -> Table:
    return Table(name, doc, (
        Key("inertia", "float", "Axial moment of inertia J of shaft plus sheaves.", "kg m^2", gt=0.0),
        Key("sheave_mass", "float", "Mass of the sheave pair.", "kg", gt=0.0),
        Key("sheave_transverse_inertia", "float", "Transverse moment of inertia Theta of the sheave pair.",
            "kg m^2", gt=0.0),
        Key("radial_stiffness", "float", "Radial stiffness c_U of the shaft at the sheaves (6+2n+8).", "N/m", gt=0.0),
        Key("tilt_stiffness", "float", "Tilt stiffness c_psi of the shaft at the sheaves (6+2n+8).",
            "N m/rad", gt=0.0),
        Key("shaft_length", "float", "Length between the bearings (elastic shaft models).", "m", gt=0.0),
        Key("shaft_diameter", "float", "Shaft diameter (elastic shaft models).", "m", gt=0.0),
        Key("shaft_elements", "int", "Beam elements of the elastic shaft model (at most 500: 8 resolve the first "
            "three bending modes).", "-", ge=1, le=500),
        Key("bearing_stiffness", "float", "Radial stiffness of each of the two bearings.", "N/m", gt=0.0),
        Key("bearing_damping", "float", "Radial damping of each bearing.", "N s/m", ge=0.0),
        Key("sheave_offset", "float", "Axial distance of each sheave's centre of mass from the chain mid-plane "
            "(elastic shaft models).", "m", 0.025, gt=0.0),
    ))


FRICTION = Table("friction", "Pin-sheave friction: regularised Coulomb law.", (
    Key("f0", "float", "Friction coefficient of the saturated branch.", "-", gt=0.0, lt=1.0),
    Key("v0", "float", "Slip speed at which friction saturates (regularisation).", "m/s", gt=0.0),
    Key("law", "str", "Regularisation of the kink at v0.", "", "linear-saturated",
        choices=("linear-saturated", "smoothed", "tanh")),
))

CONTROL = Table("control", "Speed and ratio stabilisation systems (spec section 5).", (
    Key("tau_omega", "float", "Time constant of the speed smoothing filter.", "s", gt=0.0),
    Key("eps", "float", "Speed guard in the ratio measurement.", "rad/s", gt=0.0),
    Key("i_min", "float", "Lower clamp of the measured ratio.", "-", gt=0.0),
    Key("i_max", "float", "Upper clamp of the measured ratio.", "-", gt=0.0),
    Key("k_sat", "float", "Saturation of the driving clamping force, in units of its static part.", "-", gt=1.0),
    Key("c_f0", "float", "Proportional gain of the ratio loop.", "N", gt=0.0),
    Key("c_f1", "float", "Integral gain of the ratio loop.", "N/s", ge=0.0),
    Key("c_sat", "float", "Saturation of the resistance coefficient, in units of its static part.", "-", gt=1.0),
    Key("tau", "float", "Time constant of the driven-speed loop.", "s", gt=0.0),
    Key("nu", "float", "Damping ratio of the driven-speed loop.", "-", gt=0.0),
    Key("ratio_loop_start", "str", "Start of the ratio loop's integral: zero (the source; F1 starts at its "
        "estimate) or at the driving clamping force `start_force_ratio` x F2.", "", "zero",
        choices=("zero", "force-ratio")),
    Key("start_force_ratio", "float", "Clamping-force ratio F1/F2 at which the chain runs at the target ratio (open "
        "loop, studies/chain/clamping_ratio_variant.py); used by ratio_loop_start = 'force-ratio' (0: unset).", "-",
        0.0, ge=0.0, le=10.0),
), checks=(lambda t, p: _check_ordered(t, p, "i_min", "i_max"), lambda t, p: _check_loop_start(t, p),
            lambda t, p: _check_speed_loop_time(t, p)))

REGIME = Table("regime", "Operating regime of a run.", (
    Key("kind", "str", "Regime type.", "", "stationary",
        choices=("stationary", "torque-ramp", "speed-ramp", "ratio-change")),
    Key("input_speed", "float", "Target driving-shaft speed.", "rad/s", gt=0.0),
    Key("torque", "float", "Driving torque M1 (start value of a torque ramp).", "N m", ge=0.0),
    Key("ratio", "float", "Target ratio i = omega1/omega2 (start value of a ratio change).", "-", gt=0.0),
    Key("clamping_safety", "float", "Clamping forces as a multiple of the estimate (1.13) for the torque.",
        "-", gt=0.0),
    Key("clamping_split", "str",
        "How F1, F2 share the safety: at the equilibrium force ratio of the target ratio, or (1.13) per shaft.",
        "", "equilibrium", choices=("equilibrium", "per-shaft")),
    Key("min_clamping_force", "float",
        "Floor of each prescribed clamping force (a preload; the equilibrium split scales the pair to keep its ratio).",
        "N", 1000.0, gt=0.0),
    Key("end_value", "float", "End value of a ramp or ratio change (unit of the ramped quantity; 0: none).",
        "-", 0.0, ge=0.0),
    Key("ramp_time", "float", "Duration of a ramp or ratio change.", "s", 0.0, ge=0.0),
    Key("misalignment", "float", "Imposed axial misalignment d0 of the pulleys.", "m", 0.0, ge=0.0),
))

EFFECTS = Table("effects", "Physical effects switched on; what is off is not computed at all.", (
    Key("friction", "bool", "Pin-sheave friction.", "", True),
    Key("damping", "bool", "Structural damping of chain, shafts and supports.", "", True),
    Key("stabilisation", "bool", "Speed and ratio stabilisation systems.", "", True),
    Key("pin_bending", "bool", "Pin bending (chain models S3 and above).", "", False),
    Key("shaft_elasticity", "bool", "Elastic shafts on elastic supports (band-6+2n+8, chain models (b)..(zh)).",
        "", False),
    Key("gyroscopic", "bool", "Gyroscopic moments of sheaves and shafts.", "", True),
    Key("contact", "str", "Pin-sheave contact model (discrete chains).", "", "hertz-refined",
        choices=("rigid", "impact", "hertz", "hertz-refined")),
))

CVT = Table("cvt", "A chain CVT: two shafts with sheave pairs and a chain.", (
    Key("model", "str", "Model variant: band model (issue 5) or discrete chain (Table 1.1).", "", "band-4dof",
        choices=MODELS),
    Key("ritz_order", "int", "Number n of Ritz functions per arc (band-6+2n models).", "-", 5, ge=1, le=9),
    Key("quadrature_nodes", "int", "Gauss-Legendre nodes per contact arc (band models: friction, normal force).",
        "-", 32, ge=4, le=128),
    Key("source_literal", "bool",
        "Band models: use the printed factors of the source (kappa = 1) instead of the consistent ones (spec 4.6).",
        "", False),
    Key("young_modulus", "float", "Young's modulus of pins and plates.", "Pa", gt=0.0),
    GEOMETRY, CHAIN,
    _shaft("driving", "Driving shaft (k = 1) with its sheave pair."),
    _shaft("driven", "Driven shaft (k = 2) with its sheave pair."),
    FRICTION, CONTROL, REGIME, EFFECTS,
), optional=True, checks=(lambda t, p: _check_cvt(t, p),))


#: Keys of a CVT scene the discrete chain models do not read, with what they describe: a scene that changes one for a
#: chain model is refused (:func:`cvtfem.scene.loader.scene_from_dict`) rather than run with the value ignored.
CHAIN_UNREAD = {
    **{f"cvt.{shaft}.{key}": f"the shaft compliance of band-6+2n+8 ({what}); a chain on elastic shafts takes it "
       "from `shaft_diameter`, `shaft_length` and `bearing_stiffness`, on rigid shafts there is none"
       for shaft in ("driving", "driven") for key, what in (("radial_stiffness", "c_U"), ("tilt_stiffness", "c_psi"))},
    "cvt.chain.band_transverse_stiffness": "the band's transverse compliance c of the 6+2n band models; a discrete "
                                           "chain's comes from its pins and the Hertz contact",
}


#: The pin end face: read by the discrete chains' Hertz contacts (``face_radius``: the Hertz constant of H1 and H2;
#: ``face_inclination``: H2's contact point and Hertz constant), by no band model.
FACE_KEYS = {
    "cvt.chain.face_radius": "the crown radius of the pin end faces of a discrete chain's Hertz contact (a band "
                             "model has no pins; the rigid contact of chain-S1 no Hertz constant)",
    "cvt.chain.face_inclination": "the inclination of the pin end faces, read by the refined contact "
                                  "(`effects.contact = 'hertz-refined'`) only: the other contacts act at the pin-axis "
                                  "end",
}


#: The elastic shafts' beam and bearing model (``machines/shaft_structure.py``): read only by a discrete chain with
#: ``effects.shaft_elasticity`` (the band models' compliant shaft is ``radial_stiffness`` and ``tilt_stiffness``).
ELASTIC_SHAFT_KEYS = {
    f"cvt.{shaft}.{key}": f"the elastic shaft's {what}, read only by a discrete chain with "
                          "`cvt.effects.shaft_elasticity = true` (rigid shafts and band models have no beam model)"
    for shaft in ("driving", "driven")
    for key, what in (("shaft_length", "length between the bearings"), ("shaft_diameter", "diameter"),
                      ("shaft_elements", "beam element count"), ("bearing_stiffness", "bearing stiffness"),
                      ("bearing_damping", "bearing damping"), ("sheave_offset", "sheave position on the beam"))
}


#: The discrete chain's own description, read by no band model (the band has a length from ``n_pins`` and the pitch
#: pattern, a mass, a half-width, a transverse stiffness and a damping ratio; no pins, plates or links).
BAND_UNREAD = {
    **{f"cvt.chain.{key}": f"the discrete chain's {what} (a band model's band has no pins, plates or links)"
       for key, what in (("plates_per_link", "plates per link"), ("lacing_period", "plate lacing period"),
                         ("pin_length", "pin length"), ("pin_I_min", "pin section's second moment of area"),
                         ("pin_area", "pin section area"), ("pin_axial_stiffness", "pin axial stiffness"),
                         ("link_stiffness", "link tensile stiffness"))},
    "cvt.effects.contact": "the pin-sheave contact model of a discrete chain (a band model's band meets the sheaves "
                           "along its arcs through the friction law)",
}


def unread_keys(cvt: Mapping[str, Any]) -> dict[str, str]:
    """Dotted keys the validated CVT table ``cvt`` (its model, contact and shafts) does not read, each with what it
    describes (see :data:`CHAIN_UNREAD`, :data:`FACE_KEYS`, :data:`ELASTIC_SHAFT_KEYS`, :data:`BAND_UNREAD`)."""
    model = cvt["model"]
    if not model.startswith("chain"):
        return {**FACE_KEYS, **ELASTIC_SHAFT_KEYS, **BAND_UNREAD}
    unread = dict(CHAIN_UNREAD)
    if not cvt["effects"]["shaft_elasticity"]:
        unread.update(ELASTIC_SHAFT_KEYS)
    if cvt["effects"]["contact"] != "hertz-refined":
        unread["cvt.chain.face_inclination"] = FACE_KEYS["cvt.chain.face_inclination"]
    if model == "chain-S1":
        unread["cvt.chain.face_radius"] = FACE_KEYS["cvt.chain.face_radius"]
    return unread


def _check_ordered(table: Mapping[str, Any], path: str, low: str, high: str) -> None:
    if table[low] >= table[high]:
        raise InputError(f"{path}.{high}", table[high], f"must be greater than `{low}` = {table[low]:g}")


def _check_loop_start(t: Mapping[str, Any], path: str) -> None:
    seeded, rho = t["ratio_loop_start"] == "force-ratio", t["start_force_ratio"]
    if seeded and rho == 0.0:
        raise InputError(f"{path}.start_force_ratio", rho, "must be set (> 0: the F1/F2 the chain holds its ratio "
                         "at) when `ratio_loop_start` = 'force-ratio'")
    if not seeded and rho != 0.0:
        raise InputError(f"{path}.start_force_ratio", rho, "must stay unset (0) unless `ratio_loop_start` = "
                         f"'force-ratio' (it is '{t['ratio_loop_start']}'): the value would be ignored")


def _check_geometry(t: Mapping[str, Any], path: str) -> None:
    _check_ordered(t, path, "r_min", "r_max")
    if t["r_max"] > t["sheave_outer_radius"]:
        raise InputError(f"{path}.r_max", t["r_max"],
                         f"must not exceed `sheave_outer_radius` = {t['sheave_outer_radius']:g} m")
    if 2 * t["r_max"] >= 2 * t["centre_distance"]:
        raise InputError(f"{path}.centre_distance", t["centre_distance"],
                         f"must exceed 2 `r_max` / 2 = {t['r_max']:g} m so the pulleys do not overlap")
    if t["sheave_profile"] == "toroidal":
        reach = max(abs(t["r_min"] + t["torus_offset"]), abs(t["r_max"] + t["torus_offset"]))
        if t["torus_radius"] <= reach:
            raise InputError(f"{path}.torus_radius", t["torus_radius"],
                             f"must exceed |r + torus_offset| over r_min..r_max = {reach:g} m for toroidal sheaves "
                             "(the generating arc must reach every contact radius)")


def _check_speed_loop_time(t: Mapping[str, Any], path: str) -> None:
    """The driven-speed loop's transient time is at least 2-3 filter constants (spec 1.6.4): a loop faster than
    its own speed measurement has gains ``~ 1/tau^2`` that no run resolves (a fuzzed 4.5e-30 s made BDF crawl)."""
    if t["tau"] < 2 * t["tau_omega"]:
        raise InputError(f"{path}.tau", t["tau"], f"must be at least 2 `tau_omega` = {2 * t['tau_omega']:g} s (spec "
                         "1.6.4: the loop's transient time is 2-3 filter constants or more)")


def _check_chain(t: Mapping[str, Any], path: str) -> None:
    _check_ordered(t, path, "pitch_short", "pitch_long")
    if t["n_pins"] % t["lacing_period"]:
        raise InputError(f"{path}.n_pins", t["n_pins"],
                         f"must be a multiple of `lacing_period` = {t['lacing_period']}")


def chain_length_bounds(cvt: Mapping[str, Any]) -> tuple[float, float]:
    """Shortest and longest chain length that still closes on the pulleys, m.

    At span angle 0 both radii are equal: l = 2 L + 2 pi r (spec eq. (1.36)).
    """
    g = cvt["geometry"]
    length = 2 * g["centre_distance"]
    return length + 2 * math.pi * g["r_min"], length + 2 * math.pi * g["r_max"]


def mean_chain_length(chain: Mapping[str, Any]) -> float:
    """Expected chain length of the long/short pattern, m."""
    pitch = chain["long_fraction"] * chain["pitch_long"] + (1 - chain["long_fraction"]) * chain["pitch_short"]
    return chain["n_pins"] * pitch


def _check_cvt(t: Mapping[str, Any], path: str) -> None:
    low, high = chain_length_bounds(t)
    length = mean_chain_length(t["chain"])
    if not low < length < high:
        raise InputError(f"{path}.chain.n_pins", t["chain"]["n_pins"],
                         f"must give a chain that closes on the pulleys: n_pins x mean pitch = {length:.4f} m, "
                         f"allowed {low:.4f}..{high:.4f} m for this centre distance and radius range")
    model = t["model"]
    effects = t["effects"]
    if effects["pin_bending"] and model.startswith("band") | (model in ("chain-S1", "chain-S2")):
        raise InputError(f"{path}.effects.pin_bending", True,
                         f"needs a chain model with pin bending (chain-S3 or above), not `{model}`")
    if effects["shaft_elasticity"] and model in ("band-1dof", "band-4dof", "band-6+2n"):
        raise InputError(f"{path}.effects.shaft_elasticity", True,
                         f"needs `band-6+2n+8` or a discrete chain model, not `{model}`")
