"""Rotor-scene sheaves -> solid sheave sections (issue 20): the ``[[disk]]`` tables with ``geometry = "sheave"``.

The section is the one :func:`cvtfem.elements.disk.sheave_profile` draws for the rigid disk's mass
properties (bore, hub sleeve, conical or toroidal face), with the disk's material; Poisson's ratio
follows from the material's ``E`` and ``G``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from cvtfem.elements.sheave_reduction import ReducedSheave, craig_bampton, spin_reduction
from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection
from cvtfem.errors import InputError
from cvtfem.scene.loader import Scene


def sheave_indices(scene: Scene) -> list[int]:
    """Positions of the scene's ``[[disk]]`` tables that describe a sheave by its section."""
    return [i for i, d in enumerate(scene.disk) if d.geometry == "sheave"]


def sheave_section(scene: Scene, index: int | None = None) -> SheaveSection:
    """The section of ``[[disk]]`` number ``index`` (default: the first sheave) of a rotor scene."""
    found = sheave_indices(scene)
    if not found:
        raise InputError("disk", None, "needs a [[disk]] with geometry = \"sheave\" in the scene")
    index = found[0] if index is None else index
    if index not in found:
        raise InputError("--disk", index, f"must be the index of a sheave disk: {found}")
    d = scene.disk[index]
    mat = {m.name: m for m in scene.material}[d.material]
    return SheaveSection(bore_radius=d.inner_diameter / 2, hub_radius=d.hub_diameter / 2,
                         outer_radius=d.outer_diameter / 2, hub_length=d.hub_length, rim_thickness=d.rim_thickness,
                         flank_angle=d.cone_angle, face=d.face, torus_radius=d.torus_radius, E=mat.E,
                         nu=mat.E / (2 * mat.G) - 1.0, rho=mat.rho)


#: Per harmonic of a flexible sheave: ``(n, family, node DOFs of the rigid interface, their signs for a sheave
#: facing +z)``.  The second ``n = 1`` entry is the ``sin`` twin of
#: the first, the ``cos`` model turned by 90 degrees about the axis (x -> y, a tilt about y -> one about -x):
#: the same matrices, so it is not built again.  Node DOF kinds as in the rotor: u1 u2 u3 theta1 theta2 phi.
HARMONICS = ((0, "cos", (2,), (1.0,)), (0, "sin", (5,), (1.0,)), (1, "cos", (0, 4), (1.0, 1.0)),
             (1, "twin", (1, 3), (1.0, -1.0)))


@dataclass(frozen=True)
class FlexibleSheaves:
    """Craig–Bampton sheaves for a rotor model: blocks to add to its M and K, over its node DOFs and the modal
    coordinates appended after them.

    Attributes
    ----------
    mass, stiffness, gyroscopic, damping, spin_stiffness : list of (blocks (1, m, m), dofs (1, m))
        Families for :func:`cvtfem.assembly.assemble` (kg, kg m, kg m^2; N/m, N m/rad; per unit spin speed;
        modal coordinates of unit modal mass); ``damping`` is ``2 zeta omega_k`` (1/s) on each fixed-interface
        mode, ``zeta`` the scene's ``sheave.damping_ratio``; ``spin_stiffness`` the fixed-frame stiffness per
        ``Omega^2`` (kg: prestress less spin softening, and the turning of the waves' amplitudes).
    kinds : int array (n_extra,)
        Node DOF kind (0..5) given to each modal coordinate: ``n >= 1`` modes as u1 (``cos``) and u2 (the twin,
        interleaved so that each pair is one orbit: a forward orbit is a wave running with the spin), ``n = 0``
        modes as u3 (umbrella/axial) and phi (torsion).
    diameters : int array (n_extra,)
        Nodal-diameter number of each modal coordinate.
    disks : tuple of int
        The ``[[disk]]`` indices made flexible.
    faces : tuple of FaceModes
        Per sheave its contact face's axial displacement per modal coordinate
        (:class:`~cvtfem.machines.sheave_face_modes.FaceModes`).
    """

    mass: list
    stiffness: list
    gyroscopic: list
    damping: list
    spin_stiffness: list
    kinds: np.ndarray
    diameters: np.ndarray
    disks: tuple[int, ...]
    faces: tuple = ()


def reduced_harmonics(section: SheaveSection, n_modes: int | None, cells: tuple[int, int],
                      tilt_centre: float) -> tuple[dict[tuple[int, str], ReducedSheave], dict[int, np.ndarray],
                                                   dict[int, np.ndarray]]:
    """Craig–Bampton models of the harmonics ``n = 0`` (both families) and ``n = 1`` (``cos``) of ``section``,
    bore rigid on the shaft node at ``z = tilt_centre`` (m, section coordinates); ``n_modes`` fixed-interface
    modes each (``None``: all, the unreduced model); and per ``n`` the reduced fixed-frame gyroscopic matrix per
    unit spin (kg, kg m, kg m^2) and stiffness per unit ``Omega^2`` (:func:`spin_reduction`'s ``K2_fixed``; at
    ``n = 0`` the prestress less the spin softening of each family) over ``[cos coordinates, sin (n = 0) or twin
    (n = 1) coordinates]``.  Both vanish on rigid motions but for the spin's own gyroscopic term.

    In the frame turning with the sheave, Coriolis forces couple the two families of ``n``
    (:attr:`HarmonicSheave.coriolis`, ``G_c = [[0, B], [B, 0]]``).  A fixed observer's amplitudes are those
    turned by ``n Omega t`` between the families, ``y = exp(n Omega t J) x`` with ``J = [[0, -P], [P, 0]]``
    (``P`` flips ``U_theta``); the matrices of an axisymmetric body commute with ``J``, so the fixed-frame
    equation is ``M y'' + Omega (G_c - 2 n M J) y' + (K_t - n Omega^2 (n M + G_c J)) y = 0``.  The gyroscopic
    matrix ``G_c - 2 n M J`` is what this returns, with the ``Omega^2`` stiffness (zero for rigid motions, the
    spin stiffening of a few per mille for the sheave's own).  With the twin ``P Phi`` of the ``cos``
    basis ``Phi`` and ``M_r = Phi^T M Phi`` the ``n = 1`` block is ``[[0, C], [-C^T, 0]]``,
    ``C = Phi^T B P Phi + 2 M_r``; at ``n = 0`` it is the Coriolis coupling of axial/radial and torsional
    motion."""
    models = {key: HarmonicSheave(section, key[0], key[1], *cells) for key in ((0, "cos"), (0, "sin"), (1, "cos"))}
    reduced = {key: craig_bampton(m, n_modes, tilt_centre=tilt_centre) for key, m in models.items()}
    prestress = unit_prestress(models[(0, "cos")])
    blocks = [red.basis.T @ ((models[key].geometric_stiffness(prestress) - models[key].spin_softening) @ red.basis)
              for key, red in reduced.items() if key[0] == 0]
    spin = {0: sla.block_diag(*(0.5 * (X + X.T) for X in blocks))}
    spin[1] = spin_reduction(models[(1, "cos")], reduced[(1, "cos")], prestress).K2_fixed
    gyro = {}
    for n, other in ((0, (0, "sin")), (1, (1, "cos"))):
        model, Phi = models[(n, "cos")], reduced[(n, "cos")].basis
        B = model.coriolis
        if n == 0:
            C = Phi.T @ (B @ reduced[other].basis)
        else:
            flip = np.ones(model.basis.N)
            flip[model.basis.split_indices()[1]] = -1.0                 # P: the twin has U_theta turned over
            C = Phi.T @ (B @ (flip[:, None] * Phi)) + 2 * n * reduced[(n, "cos")].M
        a, b = C.shape
        gyro[n] = np.block([[np.zeros((a, a)), C], [-C.T, np.zeros((b, b))]])
    return reduced, gyro, spin


def unit_prestress(axisymmetric: HarmonicSheave):  # noqa: ANN201 - tuple of skfem fields
    """The sheave's axisymmetric stress spinning at 1 rad/s (it scales with ``Omega^2``), from its ``n = 0``
    ``cos`` model."""
    return axisymmetric.stress(axisymmetric.centrifugal_displacement(1.0))


def own_waves_model(section: SheaveSection, n: int, n_modes: int | None, cells: tuple[int, int],
                    prestress) -> tuple[np.ndarray, ...]:  # noqa: ANN001 - tuple of skfem fields
    """The bore-clamped waves of ``n >= 2`` nodal diameters reduced to ``n_modes`` fixed-interface modes and their
    twins (:func:`spin_reduction`, fixed frame), coordinates interleaved ``[cos_0, twin_0, cos_1, ...]`` so that
    each pair is one orbit: ``(M, K, G, K2, Phi)`` (kg; N/m; per unit spin, kg; per ``Omega^2``, kg; the ``cos``
    coordinates' section basis, the twins' being ``P Phi``)."""
    model = HarmonicSheave(section, n, "cos", *cells)
    reduced = craig_bampton(model, n_modes)
    spin = spin_reduction(model, reduced, prestress)
    m = spin.M.shape[0] // 2
    order = np.ravel(np.column_stack([np.arange(m), m + np.arange(m)]))
    return tuple(X[np.ix_(order, order)] for X in (spin.M, spin.K, spin.G_fixed, spin.K2_fixed)) + (reduced.basis,)


def flexible_sheaves(scene: Scene, nodes: np.ndarray, first_extra: int) -> FlexibleSheaves:
    """The scene's sheave disks as Craig–Bampton bodies (``[sheave] flexibility = "reduced"``, or ``"full"``:
    all fixed-interface modes), each attached to the node it sits on (``nodes[i]`` for disk ``i``: its shaft
    node, or its own node when elastically connected) at its centre of mass, the modal coordinates numbered
    from ``first_extra``.  The interface block is the sheave's rigid inertia, so the rotor drops the rigid
    disk's mass and gyroscopic matrix for these disks: the fixed-frame gyroscopic matrix of the harmonics
    (:func:`reduced_harmonics`) holds the rigid sheave's ``Ip`` and the spin of its own modes."""
    from cvtfem.elements.disk import axisymmetric_properties, sheave_profile
    from cvtfem.machines.sheave_face_modes import face_modes, face_nodes

    opts = scene.sheave
    n_modes = None if opts.flexibility == "full" else opts.modes
    cells = (opts.cells_radial, opts.cells_axial)
    mass, stiffness, gyroscopic, damping, spin_stiffness, kinds, diameters, faces = [], [], [], [], [], [], [], []
    nxt = first_extra
    for i in sheave_indices(scene):
        d = scene.disk[i]
        section = sheave_section(scene, i)
        zc = axisymmetric_properties(*sheave_profile(d.inner_diameter, d.outer_diameter, d.hub_diameter,
                                                     d.hub_length, d.rim_thickness, d.cone_angle, d.face,
                                                     d.torus_radius, n_arc=256), section.rho).zc
        models, gyro, spin = reduced_harmonics(section, n_modes, cells, zc)
        facing = -1.0 if d.facing == "-z" else 1.0
        n_axial, n_torsion, n_lateral = (models[key].M.shape[0] - r for key, r in
                                         (((0, "cos"), 1), ((0, "sin"), 1), ((1, "cos"), 2)))
        own_dofs = {"cos0": nxt + np.arange(n_axial), "sin0": nxt + n_axial + np.arange(n_torsion),
                    # cos and twin coordinates interleaved: each pair is one orbit for the whirl sense
                    "cos1": nxt + n_axial + n_torsion + 2 * np.arange(n_lateral)}
        own_dofs["twin1"] = own_dofs["cos1"] + 1
        pair_dofs, pair_signs = {0: [], 1: []}, {0: [], 1: []}
        face_blocks = []                           # (own DOFs, their section basis, n, sin n a): the face's motion
        for n, family, node_dofs, signs in HARMONICS:
            red = models[(n, "cos" if family == "twin" else family)]
            own = own_dofs[f"{family}{n}"]
            n_own = len(own)
            # the z mirror of a -z-facing sheave turns its axial motion and its tilts (not x, y or the spin)
            flip = np.array([facing if dof in (2, 3, 4) else 1.0 for dof in node_dofs]) * np.array(signs)
            S = np.concatenate([flip, np.ones(n_own)])
            dofs = np.concatenate([6 * nodes[i] + np.array(node_dofs), own])
            mass.append(((S[:, None] * red.M * S)[None], dofs[None]))
            stiffness.append(((S[:, None] * red.K * S)[None], dofs[None]))
            if opts.damping_ratio > 0.0 and n_own:  # modal damping of the fixed-interface modes (unit modal mass)
                omega = np.sqrt(np.maximum(np.diag(red.K)[-n_own:], 0.0))
                damping.append((np.diag(2 * opts.damping_ratio * omega)[None], own[None]))
            pair_dofs[n].append(dofs)
            pair_signs[n].append(S)
            if (n, family) != (0, "sin"):           # torsion moves no face axially
                face_blocks.append((own, red.basis[:, -n_own:] if n_own else red.basis[:, :0], n, family == "twin"))
        for n in (0, 1):
            # the mirror keeps x, y and the spin's sense from x to y: only the signs S of the coordinates change
            S = np.concatenate(pair_signs[n])
            gyroscopic.append(((S[:, None] * gyro[n] * S)[None], np.concatenate(pair_dofs[n])[None]))
            spin_stiffness.append(((S[:, None] * spin[n] * S)[None], np.concatenate(pair_dofs[n])[None]))
        nxt += n_axial + n_torsion + 2 * n_lateral
        kinds += [2] * n_axial + [5] * n_torsion + [0, 1] * n_lateral
        diameters += [0] * (n_axial + n_torsion) + [1] * (2 * n_lateral)
        prestress = unit_prestress(HarmonicSheave(section, 0, "cos", *cells)) if opts.model_diameters > 1 else None
        for n in range(2, opts.model_diameters + 1):  # own waves: modal coordinates only (the z mirror keeps them)
            M, K, G, K2, Phi = own_waves_model(section, n, n_modes, cells, prestress)
            own = nxt + np.arange(M.shape[0])[None]
            face_blocks += [(own[0, 0::2], Phi, n, False), (own[0, 1::2], Phi, n, True)]
            for family, X in ((mass, M), (stiffness, K), (gyroscopic, G), (spin_stiffness, K2)):
                family.append((X[None], own))
            if opts.damping_ratio > 0.0:
                omega = np.sqrt(np.maximum(np.diag(K) / np.diag(M), 0.0))
                damping.append((np.diag(2 * opts.damping_ratio * omega)[None], own))
            nxt += M.shape[0]
            kinds += [0, 1] * (M.shape[0] // 2)
            diameters += [n] * M.shape[0]
        faces.append(face_modes(i, face_nodes(HarmonicSheave(section, 0, "cos", *cells)), face_blocks, facing))
    return FlexibleSheaves(mass, stiffness, gyroscopic, damping, spin_stiffness, np.array(kinds, dtype=np.int64),
                           np.array(diameters, dtype=np.int64), tuple(sheave_indices(scene)), tuple(faces))


def cvt_sheave_section(scene: Scene) -> SheaveSection:
    """The section of a CVT scene's sheaves: bore, hub and rim from ``[sheave]``, the outer radius, face and flank
    angle from ``cvt.geometry`` (a toroidal face as the arc of ``torus_radius`` through the face's end points)."""
    opts, g = scene.sheave, scene.cvt.geometry
    for name in ("bore_diameter", "hub_diameter", "rim_thickness"):
        if not opts[name] > 0.0:
            raise InputError(f"sheave.{name}", opts[name], "must be given (> 0) for flexible sheaves in a CVT scene")
    return SheaveSection(bore_radius=opts.bore_diameter / 2, hub_radius=opts.hub_diameter / 2,
                         outer_radius=g.sheave_outer_radius, hub_length=opts.hub_length,
                         rim_thickness=opts.rim_thickness, flank_angle=g.flank_angle, face=g.sheave_profile,
                         torus_radius=g.torus_radius, E=opts.young_modulus or scene.cvt.young_modulus,
                         nu=opts.poisson_ratio, rho=opts.density)


def band_faces(scene: Scene):  # noqa: ANN201 - tuple of FaceCompliance or None
    """The face compliance of a band-model CVT scene's sheaves (``[sheave] flexibility = "reduced"``), one per
    pulley, over the contact radii ``cvt.geometry.r_min..r_max``; None for rigid sheaves (no sheave code runs)."""
    opts = scene.sheave
    if opts is None or opts.flexibility == "rigid":
        return None
    model = scene.cvt.model
    if opts.flexibility != "reduced" or model not in ("band-6+2n", "band-6+2n+8"):
        raise InputError("sheave.flexibility", opts.flexibility,
                         f"must be 'rigid' for `{model}`: the band-6+2n models run on 'reduced' sheaves "
                         "(the faces' static compliance under the contact arcs); chain models and 'full' not yet")
    from cvtfem.elements.sheave_face import face_compliance

    g = scene.cvt.geometry
    faces = face_compliance(cvt_sheave_section(scene), g.r_min, g.r_max, opts.harmonics,
                            (opts.cells_radial, opts.cells_axial))
    return faces, faces
