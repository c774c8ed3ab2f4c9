"""Solid sheave discs with scikit-fem: the axisymmetric-harmonic model and its 3D reference (issue 20).

A sheave is a body of revolution about the shaft axis ``z``; its section in the ``(r, z)`` half-plane
(:class:`SheaveSection`) is a hub at the bore, a web whose thickness falls linearly towards the rim (the
conical contact face at the flank angle) and a flat back face at ``z = 0``.

*Axisymmetric-harmonic model* (:class:`HarmonicSheave`).  For the nodal-diameter number ``n`` the
displacement is ``u_r = U_r(r, z) cos n theta``, ``u_theta = U_theta(r, z) sin n theta``,
``u_z = U_z(r, z) cos n theta`` (family ``"cos"``), or the same with sine and cosine swapped
(``"sin"``: for ``n >= 1`` the twin of each mode; for ``n = 0`` the torsional modes).  Strain energy and
kinetic energy integrated over ``theta`` in closed form leave a 2D problem on the section, solved with
quadratic triangles; the amplitudes are 3-vectors ``(U_r, U_theta, U_z)`` (m).  The integrals over
``theta`` give ``pi`` per squared cosine or sine (``2 pi`` and ``0`` at ``n = 0``), so the matrices are those
of the whole disc.

*3D model* (:class:`SolidSheave`): quadratic tetrahedra of the same body (a structured ``(r, theta, z)``
grid, each cell split into six tetrahedra), the reference the harmonic model is checked against.

Units SI: m, Pa, kg/m^3; frequencies in Hz.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.blas import arpack_start
from cvtfem.errors import InputError, NumericalError


@dataclass(frozen=True)
class SheaveSection:
    """The section of a sheave in the ``(r, z)`` half-plane, as :func:`cvtfem.elements.disk.sheave_profile`
    draws it: a disc from the back face ``z = 0`` to the contact face, and a hub sleeve behind the back face.

    Attributes
    ----------
    bore_radius, hub_radius, outer_radius : m
        Radius of the bore (the shaft seat), of the hub sleeve and of the rim (``bore = hub`` without a sleeve).
    hub_length : m
        Axial length of the hub sleeve behind the back face, ``z`` in ``[-hub_length, 0]`` (0: none).
    rim_thickness : m
        Thickness of the disc at the rim; the face rises towards the hub at the flank angle.
    flank_angle : rad
        Angle of the contact face to the radial plane between rim and hub (0: a flat annular plate).
    face : {"conical", "toroidal"}
        Straight face, or the convex arc of ``torus_radius`` (m) through the same end points.
    E, nu, rho : Pa, -, kg/m^3
        Young's modulus, Poisson's ratio and density (steel by default).
    """

    bore_radius: float
    hub_radius: float
    outer_radius: float
    hub_length: float
    rim_thickness: float
    flank_angle: float = 0.0
    face: str = "conical"
    torus_radius: float = 0.0
    E: float = 2.1e11
    nu: float = 0.3
    rho: float = 7850.0

    def __post_init__(self):
        if not 0.0 < self.bore_radius <= self.hub_radius < self.outer_radius:
            raise InputError("sheave.radii", (self.bore_radius, self.hub_radius, self.outer_radius),
                             "must satisfy 0 < bore_radius <= hub_radius < outer_radius")
        if self.hub_length < 0.0 or (self.hub_length > 0.0 and self.hub_radius == self.bore_radius):
            raise InputError("sheave.hub_length", self.hub_length, "must be >= 0, and 0 when hub_radius = bore_radius")
        if not (self.rim_thickness > 0.0 and 0.0 <= self.flank_angle < np.pi / 2):
            raise InputError("sheave.rim_thickness/flank_angle", (self.rim_thickness, self.flank_angle),
                             "must satisfy rim_thickness > 0 and 0 <= flank_angle < pi/2")
        if self.face not in ("conical", "toroidal"):
            raise InputError("sheave.face", self.face, "must be 'conical' or 'toroidal'")
        chord = np.hypot(self.outer_radius - self.hub_radius, self.hub_face - self.rim_thickness)
        if self.face == "toroidal" and not self.torus_radius > chord / 2:
            raise InputError("sheave.torus_radius", self.torus_radius,
                             f"must exceed half the face chord, {chord / 2:g} m")
        if not (0.0 < self.E and -1.0 < self.nu < 0.5 and 0.0 < self.rho):
            raise InputError("sheave.material", (self.E, self.nu, self.rho),
                             "must satisfy E > 0, -1 < nu < 0.5, rho > 0")

    @property
    def hub_face(self) -> float:
        """Height of the face at the hub radius, m."""
        return self.rim_thickness + (self.outer_radius - self.hub_radius) * np.tan(self.flank_angle)

    def face_height(self, r: np.ndarray) -> np.ndarray:
        """Axial position ``z`` (m) of the contact face at radius ``r`` (flat at ``hub_face`` inside the hub)."""
        r = np.clip(np.asarray(r, float), self.hub_radius, self.outer_radius)
        if self.face == "conical":
            return self.rim_thickness + (self.outer_radius - r) * np.tan(self.flank_angle)
        from cvtfem.elements.disk import face_arc_centre

        c = face_arc_centre(self.outer_radius, self.rim_thickness, self.hub_radius, self.hub_face, self.torus_radius)
        return c[1] + np.sqrt(np.maximum(self.torus_radius ** 2 - (r - c[0]) ** 2, 0.0))

    @property
    def lame(self) -> tuple[float, float]:
        """Lame constants ``lambda, mu``, Pa."""
        lam = self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))
        return lam, self.E / (2 * (1 + self.nu))


def section_mesh(section: SheaveSection, n_r: int = 24, n_z: int = 2):  # noqa: ANN201 - skfem mesh
    """Quadratic triangle mesh of the section (``MeshTri2``): columns at about ``n_r`` radii (nodes at the hub
    radius), ``n_z`` layers from the back face to the contact face, the hub sleeve with layers of the same
    height.  Mid-edge nodes of the disc sit at the midpoints of the map ``z = eta * face_height(r)``, so a
    toroidal face is curved, not a polygon."""
    from skfem import MeshTri2

    m = _linear_section_mesh(section, n_r, n_z)
    M = MeshTri2.from_mesh(m)
    ends = m.p[:, m.facets]                              # (2, 2 ends, n_edges)
    face = section.face_height(ends[0])
    eta = np.where(ends[1] >= 0.0, ends[1] / face, np.nan)
    r_mid = ends[0].mean(axis=0)
    z_mid = np.where(np.isnan(eta).any(axis=0), ends[1].mean(axis=0), eta.mean(axis=0) * section.face_height(r_mid))
    doflocs = M.doflocs.copy()
    doflocs[:, m.p.shape[1]:] = np.array([r_mid, z_mid])
    return replace(M, doflocs=doflocs)


def _linear_section_mesh(section: SheaveSection, n_r: int, n_z: int):  # noqa: ANN202 - skfem MeshTri1
    """The straight-edged triangles of :func:`section_mesh`."""
    from skfem import MeshTri1

    if n_r < 2 or n_z < 1:
        raise InputError("section_mesh", (n_r, n_z), "must satisfy n_r >= 2 and n_z >= 1")
    s = section
    span = s.outer_radius - s.bore_radius
    n_hub = max(1, int(round(n_r * (s.hub_radius - s.bore_radius) / span))) if s.hub_radius > s.bore_radius else 0
    r = np.concatenate([np.linspace(s.bore_radius, s.hub_radius, n_hub + 1)[:-1],
                        np.linspace(s.hub_radius, s.outer_radius, max(1, n_r - n_hub) + 1)])
    n_sleeve = max(1, int(round(n_z * s.hub_length / s.hub_face))) if s.hub_length > 0 else 0
    points, columns = [], []
    for ri in r:
        sleeve = -s.hub_length * (1 - np.arange(n_sleeve) / n_sleeve) if ri <= s.hub_radius else np.zeros(0)
        z = np.concatenate([sleeve, s.face_height(ri) * np.linspace(0.0, 1.0, n_z + 1)])
        columns.append((len(sleeve), len(points) + np.arange(len(z))))
        points += [(ri, zi) for zi in z]
    quads = []
    for (na, a), (nb, b) in zip(columns[:-1], columns[1:]):
        shared = min(na, nb)                           # sleeve layers on both columns, then the disc layers
        a, b = a[na - shared:], b[nb - shared:]
        quads += [(a[k], b[k], b[k + 1], a[k + 1]) for k in range(len(a) - 1)]
    q = np.array(quads).T
    triangles = np.hstack([q[[0, 1, 2]], q[[0, 2, 3]]])
    return MeshTri1(np.ascontiguousarray(np.array(points).T), np.ascontiguousarray(triangles))


def _theta_weights(n: int, family: str) -> tuple[float, float]:
    """``int cos^2``, ``int sin^2`` over a revolution, assigned to (r, z terms, theta terms) of ``family``."""
    c, s = (2 * np.pi, 0.0) if n == 0 else (np.pi, np.pi)
    return (c, s) if family == "cos" else (s, c)


@dataclass(frozen=True, eq=False)
class HarmonicSheave:
    """Quadratic-triangle model of a sheave section for one nodal-diameter number and family.

    Parameters
    ----------
    section : SheaveSection
    n : int
        Nodal diameters (``>= 0``).
    family : {"cos", "sin"}
        ``u_r, u_z ~ cos n theta`` (and ``u_theta ~ sin``) or the swapped family (torsion at ``n = 0``).
    n_r, n_z : int
        Mesh density (:func:`section_mesh`).
    """

    section: SheaveSection
    n: int
    family: str = "cos"
    n_r: int = 24
    n_z: int = 2

    def __post_init__(self):
        if self.family not in ("cos", "sin"):
            raise InputError("family", self.family, "must be 'cos' or 'sin'")
        if self.n < 0:
            raise InputError("n", self.n, "must be a number of nodal diameters >= 0")

    @cached_property
    def basis(self):  # noqa: ANN201 - skfem Basis
        from skfem import Basis, ElementTriP2, ElementVector

        return Basis(section_mesh(self.section, self.n_r, self.n_z), ElementVector(ElementTriP2(), 3))

    @cached_property
    def matrices(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Stiffness ``K`` (N/m) and mass ``M`` (kg) of the whole disc in this harmonic, over all section DOFs."""
        from skfem import BilinearForm, asm

        lam, mu = self.section.lame
        rho = self.section.rho
        w_a, w_t = _theta_weights(self.n, self.family)
        k = self.n if self.family == "cos" else -self.n

        def parts(u, r):  # noqa: ANN001, ANN202
            (ur, ut, uz), g = u, u.grad
            e_rr, e_zz = g[0][0], g[2][1]
            e_tt = (ur + k * ut) / r
            g_rz = g[0][1] + g[2][0]
            g_rt = g[1][0] - ut / r - k * ur / r
            g_tz = g[1][1] - k * uz / r
            return e_rr, e_tt, e_zz, g_rz, g_rt, g_tz

        @BilinearForm
        def stiffness(u, v, w):  # noqa: ANN001, ANN202
            r = w.x[0]
            a, b = parts(u, r), parts(v, r)
            normal = (lam * (a[0] + a[1] + a[2]) * (b[0] + b[1] + b[2])
                      + 2 * mu * (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]))
            return (w_a * (normal + mu * a[3] * b[3]) + w_t * mu * (a[4] * b[4] + a[5] * b[5])) * r

        @BilinearForm
        def mass(u, v, w):  # noqa: ANN001, ANN202
            (ur, ut, uz), (vr, vt, vz) = u, v
            return rho * (w_a * (ur * vr + uz * vz) + w_t * ut * vt) * w.x[0]

        return asm(stiffness, self.basis).tocsr(), asm(mass, self.basis).tocsr()

    @cached_property
    def spin_softening(self) -> sp.csr_matrix:
        """``M_c`` (kg): the centrifugal force of a displacement in the plane of the disc is ``Omega^2 M_c u``."""
        from skfem import BilinearForm, asm

        rho = self.section.rho
        w_a, w_t = _theta_weights(self.n, self.family)

        @BilinearForm
        def form(u, v, w):  # noqa: ANN001, ANN202
            return rho * (w_a * u[0] * v[0] + w_t * u[1] * v[1]) * w.x[0]

        return asm(form, self.basis).tocsr()

    def centrifugal_displacement(self, omega: float) -> np.ndarray:
        """Steady displacement (m) of the disc spinning at ``omega`` (rad/s), bore clamped: ``K u = f_c`` with
        ``f_c`` the centrifugal body force ``rho omega^2 r`` (linear prestress: the stress is proportional to
        ``omega^2``; this model must be ``n = 0``, family ``cos``)."""
        from skfem import LinearForm, asm

        if (self.n, self.family) != (0, "cos"):
            raise InputError("centrifugal_displacement", (self.n, self.family), "must be the n = 0 'cos' model")
        rho = self.section.rho

        @LinearForm
        def body(v, w):  # noqa: ANN001, ANN202
            return 2 * np.pi * rho * omega ** 2 * w.x[0] * v[0] * w.x[0]

        K, _ = self.matrices
        free = self.free_dofs()
        u = np.zeros(K.shape[0])
        u[free] = spla.spsolve(K[free][:, free].tocsc(), asm(body, self.basis)[free])
        return u

    def stress(self, u0: np.ndarray):  # noqa: ANN201 - tuple of skfem fields
        """Stresses ``(s_rr, s_tt, s_zz, s_rz)`` (Pa) at the quadrature points of an axisymmetric displacement
        ``u0`` of the ``n = 0`` 'cos' model on the same mesh."""
        lam, mu = self.section.lame
        f = self.basis.interpolate(u0)
        g, r = f.grad, self.basis.global_coordinates()[0]
        e_rr, e_tt, e_zz, g_rz = g[0][0], f[0] / r, g[2][1], g[0][1] + g[2][0]
        tr = e_rr + e_tt + e_zz
        return lam * tr + 2 * mu * e_rr, lam * tr + 2 * mu * e_tt, lam * tr + 2 * mu * e_zz, mu * g_rz

    def geometric_stiffness(self, prestress) -> sp.csr_matrix:  # noqa: ANN001 - tuple of arrays
        """``K_sigma`` (N/m) of an axisymmetric prestress ``(s_rr, s_tt, s_zz, s_rz)`` (:meth:`stress`):
        ``int sigma_ij u_k,i v_k,j dV`` with the cylindrical displacement gradient of this harmonic."""
        from skfem import BilinearForm, asm

        w_a, w_t = _theta_weights(self.n, self.family)
        k = self.n if self.family == "cos" else -self.n
        s_rr, s_tt, s_zz, s_rz = prestress

        def rows(u, r):  # noqa: ANN001, ANN202 - (d/dr, (1/r) d/dtheta, d/dz) of u_r, u_theta, u_z
            (ur, ut, uz), g = u, u.grad
            return ((g[0][0], (-k * ur - ut) / r, g[0][1]), (g[1][0], (k * ut + ur) / r, g[1][1]),
                    (g[2][0], -k * uz / r, g[2][1]))

        @BilinearForm
        def form(u, v, w):  # noqa: ANN001, ANN202
            r = w.x[0]
            total = 0.0
            for row, (a, b) in enumerate(zip(rows(u, r), rows(v, r))):
                plane, hoop = (w_t, w_a) if row == 1 else (w_a, w_t)   # the u_theta row has the other parity
                total = total + plane * (w.s_rr * a[0] * b[0] + w.s_zz * a[2] * b[2]
                                         + w.s_rz * (a[0] * b[2] + a[2] * b[0])) + hoop * w.s_tt * a[1] * b[1]
            return total * r

        return asm(form, self.basis, s_rr=s_rr, s_tt=s_tt, s_zz=s_zz, s_rz=s_rz).tocsr()

    def spinning_modes(self, omega: float, prestress, count: int = 6) -> tuple[np.ndarray, np.ndarray]:
        """Natural frequencies (Hz, in the rotating frame) and shapes of the disc spinning at ``omega`` (rad/s),
        bore clamped: ``K + K_sigma - omega^2 M_c`` with ``prestress`` the stress at ``omega`` (:meth:`stress`).
        Without the Coriolis coupling of the two families (:meth:`travelling_modes` has it)."""
        K, M = self.matrices
        Kt = K + self.geometric_stiffness(prestress) - omega ** 2 * self.spin_softening
        return _lowest_modes(Kt.tocsr(), M, self.free_dofs(), count, True)

    @cached_property
    def coriolis(self) -> sp.csr_matrix:
        """``B`` (kg): per unit spin the Coriolis force ``-2 rho Omega e_z x u'`` couples this family with its twin
        (the other family of the same ``n``, on the same mesh); over ``[cos; sin]`` amplitudes the gyroscopic
        matrix is ``G = [[0, B], [B, 0]]`` with ``B`` skew, from ``int 2 rho (u_r v_theta - u_theta v_r) dV``
        (each product integrates to ``pi`` over a revolution, ``2 pi`` at ``n = 0``)."""
        from skfem import BilinearForm, asm

        rho = self.section.rho
        weight = 2 * np.pi if self.n == 0 else np.pi

        @BilinearForm
        def form(u, v, w):  # noqa: ANN001, ANN202
            return 2 * rho * weight * (u[0] * v[1] - u[1] * v[0]) * w.x[0]

        return asm(form, self.basis).tocsr()

    def travelling_modes(self, omega: float, prestress, count: int = 6) -> tuple[np.ndarray, np.ndarray]:
        """Frequencies (Hz, rotating frame) and travelling sense of the ``2 count`` lowest waves of ``n`` diameters
        spinning at ``omega`` (rad/s), bore clamped, with Coriolis coupling of the two families:
        ``M q'' + omega G q' + (K + K_sigma - omega^2 M_c) q = 0`` over ``[cos; sin]`` amplitudes
        (``prestress`` at ``omega``, :meth:`stress`).  Sense ``+1``: the wave runs with the spin relative to the
        disc (a fixed observer sees ``f + n omega / 2 pi``), ``-1`` against it (``f - n omega / 2 pi``); ``0`` for
        ``n = 0``, whose waves do not travel."""
        if not omega > 0.0:
            raise InputError("omega", omega, "must be a spin speed > 0 rad/s (at rest the waves stand)")
        pair = (self, replace(self, family="sin" if self.family == "cos" else "cos"))
        Ks, Ms, frees = [], [], []
        for m in pair:
            K, M = m.matrices
            Ks.append(K + m.geometric_stiffness(prestress) - omega ** 2 * m.spin_softening)
            Ms.append(M)
            frees.append(m.free_dofs())
        n_a = len(frees[0])
        B = self.coriolis
        Kf = sp.block_diag([Ks[0][frees[0]][:, frees[0]], Ks[1][frees[1]][:, frees[1]]], format="csc")
        Mf = sp.block_diag([Ms[0][frees[0]][:, frees[0]], Ms[1][frees[1]][:, frees[1]]], format="csc")
        Gf = sp.bmat([[None, B[frees[0]][:, frees[1]]], [B[frees[1]][:, frees[0]], None]], format="csc")
        f, X = _gyroscopic_modes(Kf, Mf, omega * Gf, count)
        if self.n == 0:
            return f, np.zeros(len(f))
        # the r and z amplitudes of both families: a cos n theta + b sin n theta runs forward when Im(conj a b) < 0
        a_fam, b_fam = (0, 1) if self.family == "cos" else (1, 0)
        comp = np.empty(self.basis.N, int)
        for c, idx in enumerate(self.basis.split_indices()):
            comp[idx] = c
        rz = [np.isin(comp[frees[k]], (0, 2)) for k in (0, 1)]
        slot = [np.flatnonzero(rz[0]), n_a + np.flatnonzero(rz[1])]
        w = self.matrices[1].diagonal()[frees[0]][rz[0]]
        a, b = X[slot[a_fam]], X[slot[b_fam]]
        return f, -np.sign(np.sum(w[:, None] * np.imag(a.conj() * b), axis=0))

    def bore_dofs(self) -> np.ndarray:
        """All DOFs on the bore surface ``r = bore_radius`` (a sheave clamped to its shaft)."""
        b = self.section.bore_radius
        return self.basis.get_dofs(lambda x: np.isclose(x[0], b, rtol=0, atol=1e-9 * b)).flatten()

    def free_dofs(self, clamped: bool = True) -> np.ndarray:
        """DOFs left after clamping the bore (or none) and dropping those this harmonic leaves without
        stiffness and mass (``u_theta`` of family ``cos`` at ``n = 0``, ``u_r, u_z`` of ``sin``)."""
        K, M = self.matrices
        keep = M.diagonal() > 0
        if clamped:
            keep[self.bore_dofs()] = False
        return np.flatnonzero(keep)

    def rim_load(self, force: float, component: int = 2) -> np.ndarray:
        """Load vector (N) of a total ``force`` (N) spread evenly over the rim surface ``r = outer_radius``
        along ``component`` (0 radial, 1 circumferential, 2 axial), for ``n = 0`` (a ring load)."""
        from skfem import FacetBasis, LinearForm, asm

        if self.n != 0:
            raise InputError("rim_load", self.n, "must be 0: a ring load excites only the n = 0 harmonic")
        sec = self.section
        mesh = self.basis.mesh
        facets = mesh.facets_satisfying(lambda x: np.isclose(x[0], sec.outer_radius, rtol=0,
                                                             atol=1e-9 * sec.outer_radius))
        fb = FacetBasis(mesh, self.basis.elem, facets=facets)
        traction = force / (2 * np.pi * sec.outer_radius * sec.rim_thickness)
        w_a, w_t = _theta_weights(0, self.family)
        weight = w_t if component == 1 else w_a

        @LinearForm
        def load(v, w):  # noqa: ANN001, ANN202
            return traction * weight * v[component] * w.x[0]

        return asm(load, fb)

    def static(self, load: np.ndarray) -> np.ndarray:
        """Displacement amplitudes (m) under ``load`` with the bore clamped."""
        K, _ = self.matrices
        free = self.free_dofs()
        u = np.zeros(K.shape[0])
        u[free] = spla.spsolve(K[free][:, free].tocsc(), load[free])
        return u

    def modes(self, count: int = 6, clamped: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """The ``count`` lowest natural frequencies (Hz) and mode shapes (columns over all DOFs) of this
        harmonic, bore clamped or the disc free (then rigid-body modes come first, near 0 Hz)."""
        return _lowest_modes(*self.matrices, self.free_dofs(clamped), count, clamped)

    def rim_mean(self, u: np.ndarray, component: int = 2) -> float:
        """Mean of one displacement component (m) over the nodes of the rim surface ``r = outer_radius``."""
        idx = self.basis.split_indices()[component]
        r = self.basis.doflocs[0, idx]
        return float(u[idx][np.isclose(r, self.section.outer_radius, rtol=0, atol=1e-9 * r.max())].mean())


def _lowest_modes(K, M, free, count, definite):  # noqa: ANN001, ANN202
    """Lowest modes of ``K x = w^2 M x`` on ``free`` DOFs by shift-invert Lanczos (scipy ARPACK)."""
    Kf, Mf = K[free][:, free].tocsc(), M[free][:, free].tocsc()
    if count >= len(free):
        raise InputError("count", count, f"must be fewer than the {len(free)} free DOFs")
    # a clamped disc is definite: shift at 0; a free one has rigid modes: shift slightly below 0
    scale = abs(Kf.diagonal()).max() / abs(Mf.diagonal()).max()
    sigma = 0.0 if definite else -1e-6 * scale
    try:
        lam, vec = spla.eigsh(Kf, k=count, M=Mf, sigma=sigma, which="LM", v0=arpack_start(Kf.shape[0]))
    except (spla.ArpackNoConvergence, RuntimeError) as exc:
        raise NumericalError(f"sheave modes: ARPACK did not converge ({exc})") from None
    order = np.argsort(lam)
    shapes = np.zeros((K.shape[0], count))
    shapes[free] = vec[:, order]
    return np.sqrt(np.maximum(lam[order], 0.0)) / (2 * np.pi), shapes


def _gyroscopic_modes(K, M, G, count):  # noqa: ANN001, ANN202
    """The ``2 count`` lowest frequencies (Hz, ascending) and displacement shapes of ``M q'' + G q' + K q = 0``
    (K definite, G skew): ARPACK on ``A^-1 B`` of the first-order form ``A = [[0, I], [-K, -G]]``,
    ``B = diag(I, M)``, whose eigenvalues are ``1 / lambda``; applying it needs one LU of ``K``."""
    n = K.shape[0]
    k = min(4 * count, 2 * n - 2)
    lu = spla.splu(K.tocsc())

    def apply(y):  # noqa: ANN001, ANN202
        y1, y2 = y[:n], y[n:]
        return np.concatenate([-lu.solve(M @ y2 + G @ y1), y1])

    op = spla.LinearOperator((2 * n, 2 * n), matvec=apply, dtype=float)
    try:
        mu, vec = spla.eigs(op, k=k, which="LM", v0=arpack_start(2 * n))
    except (spla.ArpackNoConvergence, RuntimeError) as exc:
        raise NumericalError(f"sheave travelling waves: ARPACK did not converge ({exc})") from None
    lam = 1.0 / mu
    up = lam.imag > 0
    order = np.argsort(lam.imag[up])[:2 * count]
    return lam.imag[up][order] / (2 * np.pi), vec[:n, up][:, order]


def solid_mesh(section: SheaveSection, n_r: int = 12, n_z: int = 2, n_theta: int = 72):  # noqa: ANN201
    """The section mesh revolved in ``n_theta`` steps into linear tetrahedra (``MeshTet1``): every prism split
    into three with its triangle's vertices in global order, which makes neighbouring splits conform."""
    from skfem import MeshTet1

    if n_theta < 8:
        raise InputError("solid_mesh.n_theta", n_theta, "must be >= 8 cells around")
    m = _linear_section_mesh(section, n_r, n_z)
    n2 = m.p.shape[1]
    th = 2 * np.pi * np.arange(n_theta) / n_theta
    p = np.vstack([np.outer(np.cos(th), m.p[0]).ravel(), np.outer(np.sin(th), m.p[0]).ravel(),
                   np.tile(m.p[1], n_theta)])
    a, b, c = np.sort(m.t, axis=0)
    layer = np.arange(n_theta)[:, None] * n2
    up = ((np.arange(n_theta) + 1) % n_theta)[:, None] * n2
    lo = [(layer + v).ravel() for v in (a, b, c)]
    hi = [(up + v).ravel() for v in (a, b, c)]
    t = np.hstack([np.array([lo[0], lo[1], lo[2], hi[2]]), np.array([lo[0], lo[1], hi[1], hi[2]]),
                   np.array([lo[0], hi[0], hi[1], hi[2]])])
    d = p[:, t[1:]] - p[:, t[0]][:, None, :]
    neg = np.einsum("ij,ij->j", d[:, 0], np.cross(d[:, 1], d[:, 2], axis=0)) < 0
    t[1:3, neg] = t[2:0:-1, neg]                        # orient every tetrahedron positively
    return MeshTet1(np.ascontiguousarray(p), np.ascontiguousarray(t))


@dataclass(frozen=True, eq=False)
class SolidSheave:
    """Quadratic-tetrahedron model of the whole sheave (the reference of :class:`HarmonicSheave`)."""

    section: SheaveSection
    n_r: int = 12
    n_z: int = 2
    n_theta: int = 72

    @cached_property
    def basis(self):  # noqa: ANN201 - skfem Basis
        from skfem import Basis, ElementTetP2, ElementVector

        return Basis(solid_mesh(self.section, self.n_r, self.n_z, self.n_theta), ElementVector(ElementTetP2()))

    @cached_property
    def matrices(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Stiffness (N/m) and mass (kg) matrices."""
        from skfem import BilinearForm, asm
        from skfem.helpers import dot
        from skfem.models.elasticity import linear_elasticity

        lam, mu = self.section.lame
        rho = self.section.rho

        @BilinearForm
        def mass(u, v, w):  # noqa: ANN001, ANN202
            return rho * dot(u, v)

        return asm(linear_elasticity(lam, mu), self.basis).tocsr(), asm(mass, self.basis).tocsr()

    def _radius(self, x: np.ndarray) -> np.ndarray:
        return np.hypot(x[0], x[1])

    def bore_dofs(self) -> np.ndarray:
        """All DOFs on the (polygonal) bore surface: nothing of the body lies nearer the axis."""
        b = self.section.bore_radius
        return self.basis.get_dofs(lambda x: self._radius(x) < b * (1 + 1e-9)).flatten()

    def rim_load(self, force: float) -> np.ndarray:
        """Load vector (N): a total axial ``force`` (N) spread evenly over the rim surface."""
        from skfem import FacetBasis, LinearForm, asm

        sec = self.section
        mesh = self.basis.mesh
        # chords of the polygonal rim: select facets by their vertices' radius
        facets = mesh.facets_satisfying(lambda x: self._radius(x) > sec.outer_radius * np.cos(np.pi / self.n_theta)
                                        * (1 - 1e-9))
        fb = FacetBasis(mesh, self.basis.elem, facets=facets)
        area = asm(LinearForm(lambda v, w: v[2]), fb).sum()  # = rim area (sum of the shape functions = 1)
        traction = force / area

        @LinearForm
        def load(v, w):  # noqa: ANN001, ANN202
            return traction * v[2]

        return asm(load, fb)

    def static(self, load: np.ndarray) -> np.ndarray:
        """Displacements (m) under ``load``, bore clamped."""
        K, _ = self.matrices
        free = np.setdiff1d(np.arange(K.shape[0]), self.bore_dofs())
        u = np.zeros(K.shape[0])
        u[free] = spla.spsolve(K[free][:, free].tocsc(), load[free])
        return u

    def modes(self, count: int = 12, clamped: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """The ``count`` lowest natural frequencies (Hz) and mode shapes."""
        K, M = self.matrices
        free = np.setdiff1d(np.arange(K.shape[0]), self.bore_dofs()) if clamped else np.arange(K.shape[0])
        return _lowest_modes(K, M, free, count, clamped)

    def _free(self) -> np.ndarray:
        K, _ = self.matrices
        return np.setdiff1d(np.arange(K.shape[0]), self.bore_dofs())

    def spin_matrices(self, omega: float) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Tangent stiffness ``K + K_sigma - omega^2 M_c`` (N/m) of the sheave spinning at ``omega`` (rad/s) about
        ``z``, bore clamped (``K_sigma`` of the linear centrifugal prestress, ``M_c`` the centrifugal force of
        motion in the x-y plane), and the gyroscopic matrix per unit spin ``G`` (kg) of the Coriolis force,
        ``int 2 rho (u_x v_y - u_y v_x) dV``, all assembled by scikit-fem on the tetrahedra."""
        from skfem import BilinearForm, LinearForm, asm

        lam, mu = self.section.lame
        rho = self.section.rho
        K, _ = self.matrices
        free = self._free()

        @LinearForm
        def body(v, w):  # noqa: ANN001, ANN202
            return rho * omega ** 2 * (w.x[0] * v[0] + w.x[1] * v[1])

        u0 = np.zeros(K.shape[0])
        u0[free] = spla.spsolve(K[free][:, free].tocsc(), asm(body, self.basis)[free])

        @BilinearForm
        def geometric(u, v, w):  # noqa: ANN001, ANN202
            g = w.u0.grad
            eps = [[0.5 * (g[i][j] + g[j][i]) for j in range(3)] for i in range(3)]
            tr = eps[0][0] + eps[1][1] + eps[2][2]
            total = 0.0
            for i in range(3):
                for j in range(3):
                    sigma = 2 * mu * eps[i][j] + (lam * tr if i == j else 0.0)
                    total = total + sigma * sum(u.grad[k][i] * v.grad[k][j] for k in range(3))
            return total

        @BilinearForm
        def softening(u, v, w):  # noqa: ANN001, ANN202
            return rho * (u[0] * v[0] + u[1] * v[1])

        @BilinearForm
        def coriolis(u, v, w):  # noqa: ANN001, ANN202
            return 2 * rho * (u[0] * v[1] - u[1] * v[0])

        Kt = K + asm(geometric, self.basis, u0=self.basis.interpolate(u0)) - omega ** 2 * asm(softening, self.basis)
        return Kt.tocsr(), asm(coriolis, self.basis).tocsr()

    def travelling_modes(self, omega: float, count: int = 6) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The ``2 count`` lowest frequencies (Hz, rotating frame) of the sheave spinning at ``omega`` (rad/s) with
        prestress, spin softening and Coriolis coupling, each with its nodal-diameter number (the largest
        harmonic of ``u_z`` on the face nodes) and travelling sense (``+1`` with the spin, ``-1`` against it, ``0``
        for ``n = 0``), as :meth:`HarmonicSheave.travelling_modes` gives them."""
        Kt, G = self.spin_matrices(omega)
        _, M = self.matrices
        free = self._free()
        f, X = _gyroscopic_modes(Kt[free][:, free], M[free][:, free].tocsc(), omega * G[free][:, free], count)
        shapes = np.zeros((Kt.shape[0], X.shape[1]), complex)
        shapes[free] = X
        uz = self.basis.split_indices()[2]
        x = self.basis.doflocs[:, uz]
        theta = np.arctan2(x[1], x[0])
        orders = np.arange(9)
        a = np.cos(np.outer(orders, theta)) @ shapes[uz]          # (orders, modes) cos and sin contents
        b = np.sin(np.outer(orders, theta)) @ shapes[uz]
        n = np.argmax(np.abs(a) ** 2 + np.abs(b) ** 2, axis=0)
        cols = np.arange(X.shape[1])
        sense = np.where(n > 0, -np.sign(np.imag(a[n, cols].conj() * b[n, cols])), 0.0)
        return f, n, sense
