"""Link stresses from the reduced coordinates: stress shapes and what they tell.

At reduction time the stress field of every elastic mode of a link (its
*stress shape*) is computed once on the link's own mesh and kept with the
reduced link (:attr:`~flexbodies.reduced.ReducedBody.stress_modes`), so the
stress of any state of the modal coordinates ``q`` is one matrix product,
``sigma = S q``, with no FE solve. The rigid-body motion of the floating
frame carries no stress.

The stress is kept at the FE **nodes**, averaged: each element's stress is
evaluated at its own nodes (for quadratic tetrahedra the element's linear
stress field at its corners and mid-edge nodes, no extrapolation from
integration points needed) and averaged over the elements that share a
node, weighted by their volume. Nodes, not integration points, because the
peaks sit on the surface (at the bores and the shank's edges), where no
integration point lies, because a node has coordinates a report can name,
and because the node set is that of the mode basis (fewer values than the
integration points of a quadratic mesh).

Components are in the link frame (x from eye A to eye B, z along the bores),
in Voigt order :data:`VOIGT`, Pa.
"""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from .materials import Material

if TYPE_CHECKING:  # meshing loads scikit-fem and gmsh: imported where a link is meshed
    from .meshing import BodyMesh
    from .reduced import ReducedBody

__all__ = ["VOIGT", "REGIONS", "NodalStress", "nodal_stress_operator", "von_mises", "max_principal",
           "link_regions", "state_stress", "alternating_von_mises", "signed_von_mises", "goodman_factor",
           "gerber_factor", "haigh_factor", "write_vtu"]

#: Stress components, in the order of the stress shapes.
VOIGT = ("xx", "yy", "zz", "yz", "xz", "xy")
#: The regions of a link a peak stress is reported in.
REGIONS = ("eye A", "shank", "eye B")


@dataclass(frozen=True)
class NodalStress:
    """Nodal-averaged stress of a mesh as a linear map of its nodal displacements.

    Attributes
    ----------
    gradients : tuple of 3 scipy.sparse.csr_matrix, shape (n, n)
        ``gradients[i] @ f`` is the nodal-averaged ``d f / d x_i`` of a
        nodal scalar field ``f`` (mesh coordinates), 1/m.
    material : Material
    rotation : ndarray, shape (3, 3)
        The link frame against the mesh's: a mesh vector ``v`` is ``rotation @ v``
        in the link frame.
    """

    gradients: tuple
    material: Material
    rotation: np.ndarray

    def of(self, displacements: np.ndarray) -> np.ndarray:
        """The stress of node-major displacement fields in the link frame.

        Parameters
        ----------
        displacements : ndarray, shape (>= 3 n, k)
            Node-major displacements in the link frame, m (rows beyond the
            FE nodes, e.g. master nodes, ignored).

        Returns
        -------
        ndarray, shape (n, 6, k)
            Stress, Voigt order :data:`VOIGT`, Pa.
        """
        n = self.gradients[0].shape[0]
        u = np.asarray(displacements, dtype=float)
        if u.ndim == 1:
            u = u[:, None]
        u = u[: 3 * n].reshape(n, 3, -1)
        R = np.asarray(self.rotation, dtype=float)
        u_mesh = np.einsum("ji,njk->nik", R, u)                      # components in the mesh frame
        flat = u_mesh.reshape(n, -1)
        grad = np.stack([(g @ flat).reshape(n, 3, -1) for g in self.gradients], axis=2)   # (n, c, i, k)
        grad = np.einsum("ac,ncik,bi->nabk", R, grad, R)              # du_a/dx_b in the link frame
        strain = 0.5 * (grad + grad.transpose(0, 2, 1, 3))
        trace = strain[:, 0, 0] + strain[:, 1, 1] + strain[:, 2, 2]
        mu, lam = self.material.shear_modulus, self.material.lame_lambda
        out = np.empty((n, 6, strain.shape[-1]))
        for row, (a, b) in enumerate(((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))):
            out[:, row] = 2 * mu * strain[:, a, b] + (lam * trace if a == b else 0.0)
        return out


def nodal_stress_operator(link_mesh: BodyMesh, material: Material, rotation=None) -> NodalStress:
    """The nodal-averaged stress operator of a meshed link.

    Parameters
    ----------
    link_mesh : BodyMesh
    material : Material
    rotation : ndarray, shape (3, 3), optional
        The link frame against the mesh's (default: the same frame), as
        returned with the FE model of :func:`flexbodies.link.build_fe_model`.

    Returns
    -------
    NodalStress
    """
    import skfem
    from skfem.quadrature import get_quadrature

    mesh = link_mesh.mesh
    element = mesh.elem()
    local = element.doflocs                                  # the element's nodes, reference coordinates
    at_nodes = skfem.Basis(mesh, element, quadrature=(local.T, np.ones(len(local))))
    # the element volumes at a basis's default integration order, without its shape functions (0.14 s on
    # the thrust rod); the mesh's mapping keeps the Jacobians the mass matrix's assembly computed there
    points, weights = get_quadrature(element.refdom, 2 * element.maxdeg)
    volume = (np.abs(mesh.mapping().detDF(points)) * weights).sum(axis=1)   # (elements,)
    dofs = at_nodes.element_dofs                             # (functions, elements): DOF i is node i
    n_f, n_e = dofs.shape
    n = at_nodes.N
    weight_sum = np.bincount(dofs.ravel(), weights=np.repeat(volume[None, :], n_f, axis=0).ravel(), minlength=n)
    rows = np.broadcast_to(dofs[:, None, :], (n_f, n_f, n_e))         # (point k, function j, e): node of point k
    cols = np.broadcast_to(dofs[None, :, :], (n_f, n_f, n_e))         # node of function j
    weight = volume[None, None, :] / weight_sum[rows]
    gradients = []
    for i in range(3):
        # d phi_j / d x_i at the element's node k: basis.basis[j][0].grad[i] has shape (elements, points)
        values = np.stack([at_nodes.basis[j][0].grad[i].T for j in range(n_f)], axis=1)   # (k, j, e)
        matrix = sp.csr_matrix(((values * weight).ravel(), (rows.ravel(), cols.ravel())), shape=(n, n))
        gradients.append(matrix)
    return NodalStress(tuple(gradients), material, np.eye(3) if rotation is None else np.asarray(rotation, float))


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress of Voigt stress (components on axis 1), Pa.

    Parameters
    ----------
    stress : ndarray, shape (n, 6, ...)
        Pa.

    Returns
    -------
    ndarray, shape (n, ...)
    """
    s = np.asarray(stress)
    xx, yy, zz, yz, xz, xy = (s[:, i] for i in range(6))
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2) + 3 * (yz**2 + xz**2 + xy**2))


def _von_mises_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The bilinear form of the von Mises stress, ``von_mises(s)**2 == _von_mises_product(s, s)``, Pa^2."""
    normal = 0.5 * sum((a[:, i] - a[:, j]) * (b[:, i] - b[:, j]) for i, j in ((0, 1), (1, 2), (2, 0)))
    return normal + 3 * (a[:, 3] * b[:, 3] + a[:, 4] * b[:, 4] + a[:, 5] * b[:, 5])


def alternating_von_mises(amplitude: np.ndarray) -> np.ndarray:
    """Alternating equivalent stress of a harmonic stress ``Re(S exp(i w t))``, Pa.

    The largest von Mises stress over the cycle,
    ``max_phi von_mises(Re(S exp(i phi)))``: the stress path is an ellipse,
    and this is half its major axis in the von Mises norm (its longest chord
    over two). With ``A = Re S``, ``B = Im S`` and ``<.,.>`` the von Mises
    bilinear form it is ``sqrt((a + b)/2 + sqrt(((a - b)/2)^2 + c^2))``,
    ``a = <A, A>``, ``b = <B, B>``, ``c = <A, B>``. For proportional stress
    (all components in phase) it is the von Mises stress of ``|S|``.

    Parameters
    ----------
    amplitude : ndarray, complex, shape (n, 6)
        Complex amplitude, Voigt order :data:`VOIGT`, Pa.

    Returns
    -------
    ndarray, shape (n,)
    """
    s = np.asarray(amplitude, dtype=complex)
    real, imag = s.real, s.imag
    a, b, c = _von_mises_product(real, real), _von_mises_product(imag, imag), _von_mises_product(real, imag)
    return np.sqrt(np.maximum(0.5 * (a + b) + np.sqrt(0.25 * (a - b) ** 2 + c**2), 0.0))


def signed_von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises stress signed as the hydrostatic stress (negative when the trace is), shape (n, 6) -> (n,), Pa.

    The equivalent mean stress of the fatigue factors: a compressive mean
    (negative trace) counts as negative and earns no credit.
    """
    s = np.asarray(stress)
    return np.where(s[:, 0] + s[:, 1] + s[:, 2] < 0, -1.0, 1.0) * von_mises(s)


def goodman_factor(alternating, mean, endurance: float, ultimate: float) -> np.ndarray:
    """Fatigue safety factor by the modified Goodman line.

    ``1 / n = sigma_a / S_e + sigma_m / S_u`` for a tensile mean; a
    compressive mean is taken as zero (``n = S_e / sigma_a``).

    Parameters
    ----------
    alternating, mean : array_like
        Equivalent alternating and (signed) mean stress, Pa.
    endurance, ultimate : float
        Endurance strength S_e and ultimate strength S_u, Pa.

    Returns
    -------
    ndarray
        The factor n (inf where nothing alternates and the mean is not tensile).
    """
    load = np.asarray(alternating, float) / endurance + np.maximum(np.asarray(mean, float), 0.0) / ultimate
    with np.errstate(divide="ignore"):
        return 1.0 / load


def gerber_factor(alternating, mean, endurance: float, ultimate: float) -> np.ndarray:
    """Fatigue safety factor by the Gerber parabola ``n sigma_a / S_e + (n sigma_m / S_u)^2 = 1``.

    ``n = 2 S_e / (sigma_a + sqrt(sigma_a^2 + (2 sigma_m S_e / S_u)^2))``,
    the root of Shigley's eq. 6-47 written without cancellation; a
    compressive mean is taken as zero (``n = S_e / sigma_a``). Parameters
    and return as :func:`goodman_factor`.
    """
    sa = np.asarray(alternating, float)
    sm = np.maximum(np.asarray(mean, float), 0.0)
    with np.errstate(divide="ignore"):
        return 2 * endurance / (sa + np.sqrt(sa**2 + (2 * sm * endurance / ultimate) ** 2))


def haigh_factor(alternating, mean, curve) -> np.ndarray:
    """Fatigue safety factor on a Haigh diagram: the factor n with ``(n sigma_m, n sigma_a)`` on the curve.

    The proportional load line (the ray from the origin through the
    stress point) meets the polyline once, the curve falling from the
    alternating to the mean axis (:attr:`flexbodies.materials.Material.haigh_curve`):
    on the segment ``P_k P_k+1`` whose polar angles bracket the ray's,
    ``n = (P_k x d) / (r x d)`` with ``d = P_k+1 - P_k`` and ``r`` the stress
    point (``x`` the 2D cross product). A compressive mean is taken as zero
    (``n = S_a0 / sigma_a``, no credit). The curve ``((0, S_e), (S_u, 0))``
    gives :func:`goodman_factor`.

    Parameters
    ----------
    alternating, mean : array_like
        Equivalent alternating and (signed) mean stress, Pa.
    curve : sequence of (float, float)
        ``(mean, alternating)`` points, Pa, as a :class:`~flexbodies.materials.Material`
        holds them (checked there).

    Returns
    -------
    ndarray
        The factor n (inf where nothing alternates and the mean is not tensile).
    """
    points = np.asarray(curve, dtype=float)
    sa = np.asarray(alternating, float)
    sm = np.maximum(np.asarray(mean, float), 0.0)
    angles = np.arctan2(points[::-1, 1], points[::-1, 0])           # increasing, 0 to pi/2
    k = len(points) - 2 - np.clip(np.searchsorted(angles, np.arctan2(sa, sm), side="right") - 1, 0, len(points) - 2)
    start, step = points[k], points[k + 1] - points[k]
    with np.errstate(divide="ignore"):
        return (start[..., 0] * step[..., 1] - start[..., 1] * step[..., 0]) / (sm * step[..., 1] - sa * step[..., 0])


def max_principal(stress: np.ndarray) -> np.ndarray:
    """Largest principal stress of Voigt stress, shape (n, 6) -> (n,), Pa.

    In closed form (the trigonometric solution of the characteristic cubic
    of the deviator): the largest eigenvalue is ``p + 2 q cos(phi)`` with
    ``p`` the mean normal stress, ``q = sqrt(J2 / 3)`` and
    ``cos(3 phi) = J3 / (2 q^3)``, in a few array operations over all nodes
    rather than an eigen-solve per node.
    """
    s = np.asarray(stress, dtype=float)
    xx, yy, zz, yz, xz, xy = (s[:, i] for i in range(6))
    mean = (xx + yy + zz) / 3
    a, b, c = xx - mean, yy - mean, zz - mean
    j2 = 0.5 * (a * a + b * b + c * c) + yz * yz + xz * xz + xy * xy
    j3 = a * b * c + 2 * yz * xz * xy - a * yz * yz - b * xz * xz - c * xy * xy
    q = np.sqrt(j2 / 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        cosine = np.where(q > 0, j3 / (2 * q**3), 0.0)
    phi = np.arccos(np.clip(cosine, -1.0, 1.0)) / 3
    return mean + 2 * q * np.cos(phi)


#: Regions of the links seen in this process, by the key of their inputs (their mesh), most recent last.
_regions: OrderedDict = OrderedDict()
_REGIONS_KEPT = 32


def link_regions(link: ReducedBody) -> np.ndarray:
    """Which region of the link each FE node lies in: 0 eye A, 1 shank, 2 eye B (:data:`REGIONS`).

    A node within the eye's outer radius of an eye centre (the bore radius
    times two for a link read from a mesh file) is in that eye, every other
    node in the shank. Kept per link mesh (the key of the link's inputs), so
    each stress recovery after the first finds it made; read-only.

    Returns
    -------
    ndarray of int, shape (n,)
    """
    key = link.info.get("input_hash")
    if key is not None and key in _regions:
        _regions.move_to_end(key)
        return _regions[key]
    regions = _regions_of(link)
    regions.flags.writeable = False
    if key is not None:
        _regions[key] = regions
        while len(_regions) > _REGIONS_KEPT:
            _regions.popitem(last=False)
    return regions


def _regions_of(link: ReducedBody) -> np.ndarray:
    n = int(link.master_nodes[0])
    nodes = link.nodes[:n]
    geometry = (link.info.get("inputs") or {}).get("geometry")
    regions = np.ones(n, dtype=int)
    for region, (interface, bore_nodes) in ((0, (0, link.interface_nodes[0])), (2, (1, link.interface_nodes[1]))):
        centre = link.master_position(interface)
        if geometry is not None:
            radius = float(geometry["eye_outer_radius"])
        else:
            radial = nodes[bore_nodes] - centre
            radius = 2.0 * float(np.median(np.linalg.norm(radial[:, :2], axis=1)))
        inside = np.linalg.norm((nodes - centre)[:, :2], axis=1) <= radius * (1 + 1e-9)
        regions[inside] = region
    return regions


def state_stress(link: ReducedBody, modal_coordinates) -> np.ndarray:
    """The stress field of a state of a link's modal coordinates, ``S q``.

    Parameters
    ----------
    link : ReducedBody
        Reduced with its stress shapes.
    modal_coordinates : array_like, shape (n_modes,)
        Real, or complex for the amplitude of a harmonic state.

    Returns
    -------
    ndarray, shape (n, 6)
        Stress at the FE nodes (complex for complex coordinates), link
        frame, Voigt order :data:`VOIGT`, Pa.
    """
    from .errors import LinkModelError

    shapes = link.stress_modes
    if shapes.size == 0:
        raise LinkModelError("this reduced body was reduced without its stress shapes")
    q = np.asarray(modal_coordinates)
    n = shapes.shape[0]
    matrix = shapes.reshape(6 * n, -1)
    if np.iscomplexobj(q):  # one real product of two columns: no complex copy of the shapes, read once
        parts = matrix @ np.stack([q.real, q.imag], axis=1)
        return (parts[:, 0] + 1j * parts[:, 1]).reshape(n, 6)
    return (matrix @ q).reshape(n, 6)


def write_vtu(path, link: ReducedBody, fields: dict, modes: int = 0):
    """Write a link's surface with nodal fields as a VTU file (meshio) that ParaView opens.

    Parameters
    ----------
    path : str or Path
        The ``.vtu`` file.
    link : ReducedBody
        Its surface triangles and FE nodes (link frame, m).
    fields : dict of str to ndarray, shape (n,) or (n, k)
        Point data at the FE nodes (e.g. a stress field, shape (n, 6), Pa).
    modes : int
        Also write the displacement of this many of the link's elastic modes
        (``mode 1``, ..., m per modal unit).
    """
    import meshio

    n = int(link.master_nodes[0])
    data = {name: np.asarray(value, dtype=float) for name, value in fields.items()}
    for k in range(min(modes, link.n_modes)):
        data[f"mode {k + 1}"] = link.mode_basis[: 3 * n, k].reshape(n, 3)
    meshio.write(str(path), meshio.Mesh(link.nodes[:n], [("triangle", np.asarray(link.surface_triangles))],
                                        point_data=data))
