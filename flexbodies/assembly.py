"""Stiffness and consistent mass matrices of a meshed link (scikit-fem).

The matrices are ordered node-major: DOF ``3*i + c`` is displacement
component ``c`` (x, y, z) of finite element node ``i``, where the nodes are
``LinkMesh.nodes`` (vertices and, for quadratic elements, the edge/face/cell
nodes).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import skfem

from .materials import Material
from .meshing import Bore, LinkMesh

__all__ = ["FEModel", "Bore", "assemble"]

logger = logging.getLogger(__name__)

#: Default integration orders (stiffness, mass) per mesh type: exact for
#: straight-sided elements, and few points for hexahedra (scikit-fem's
#: default of twice the element degree means 64 points for a quadratic hex).
_DEFAULT_INTORDER = {
    skfem.MeshTet2: (2, 4),
    skfem.MeshTet1: (1, 2),
    skfem.MeshHex2: (4, 4),
    skfem.MeshHex1: (2, 2),
}


@dataclass(frozen=True)
class FEModel:
    """Finite element model of one link: nodes, K, M and bores.

    Parameters
    ----------
    nodes : ndarray, shape (n, 3)
        Finite element node coordinates, m.
    stiffness : scipy.sparse.csr_matrix, shape (3n, 3n)
        Stiffness matrix, N/m, symmetric, node-major DOF order.
    mass : scipy.sparse.csr_matrix, shape (3n, 3n)
        Consistent mass matrix, kg, symmetric, node-major DOF order.
    bores : tuple of Bore
        Bore surfaces in the order given (A first, B second for
        :func:`~flexbodies.meshing.mesh_link`).
    surface_triangles : ndarray of int, shape (k, 3)
        Node indices of triangles covering the outer surface (for drawing).
    material : Material
        The material of the link.
    description : str
        One-line summary, e.g. "quadratic tetrahedra, 6810 nodes, 20430 DOF".
    """

    nodes: np.ndarray
    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    bores: tuple
    surface_triangles: np.ndarray
    material: Material
    description: str

    @property
    def ndof(self) -> int:
        """Number of degrees of freedom, 3 per node."""
        return 3 * self.nodes.shape[0]

    @property
    def total_mass(self) -> float:
        """Total mass in kg, from the mass matrix (rigid translation along x)."""
        ex = np.zeros(self.ndof)
        ex[0::3] = 1.0
        return float(ex @ (self.mass @ ex))


def assemble(link_mesh: LinkMesh, material: Material, intorder: int | None = None) -> FEModel:
    """Assemble linear elastic stiffness and consistent mass of a link.

    Parameters
    ----------
    link_mesh : LinkMesh
        The meshed link (m) with its bores.
    material : Material
        Isotropic linear elastic material (Pa, kg/m^3).
    intorder : int, optional
        Polynomial degree integrated exactly on the reference element, for
        both matrices. Default: per element type, exact for straight-sided
        elements (quadratic tetrahedra: 2 for K, 4 for M; quadratic
        hexahedra: 4, i.e. 3x3x3 points).

    Returns
    -------
    FEModel
        Matrices in node-major DOF order.

    Raises
    ------
    ValueError
        If an element is tangled or degenerate (Jacobian determinant zero or
        changing sign inside it), e.g. a hexahedron whose node order is not
        meshio's. Mirrored elements (negative determinant throughout) are
        valid and accepted.
    """
    mesh = link_mesh.mesh
    k_order, m_order = _DEFAULT_INTORDER[type(mesh)] if intorder is None else (intorder, intorder)
    k_basis = skfem.Basis(mesh, skfem.ElementVector(mesh.elem()), intorder=k_order)
    _check_orientation(k_basis, link_mesh.source)
    stiffness = _symmetric(skfem.asm(_stiffness_form(material), k_basis))
    perm = _node_major_permutation(k_basis, mesh)
    if perm is not None:
        stiffness = stiffness[perm][:, perm]
    # The mass couples equal components only: M = M_scalar (x) I3, node-major,
    # nine times fewer form evaluations than with the vector element.
    scalar_mass = skfem.asm(_mass_form(material.density), skfem.Basis(mesh, mesh.elem(), intorder=m_order))
    mass = sp.kron(_symmetric(scalar_mass), sp.identity(3), format="csr")
    nodes = np.ascontiguousarray(link_mesh.nodes)
    description = f"{link_mesh.element_name}, {nodes.shape[0]} nodes, {3 * nodes.shape[0]} DOF"
    logger.info("assembled %s, material %s", description, material.name)
    return FEModel(
        nodes=nodes,
        stiffness=sp.csr_matrix(stiffness),
        mass=sp.csr_matrix(mass),
        bores=tuple(link_mesh.bores),
        surface_triangles=link_mesh.surface_triangles(),
        material=material,
        description=description,
    )


def _stiffness_form(material: Material) -> skfem.BilinearForm:
    """Isotropic elasticity: 2 mu eps(u):eps(v) + lambda div(u) div(v)."""
    lam, mu = material.lame_lambda, material.shear_modulus

    @skfem.BilinearForm
    def stiffness(u, v, _):
        gu, gv = u.grad, v.grad
        shear = np.einsum("ij...,ij...->...", gu, gv) + np.einsum("ij...,ji...->...", gu, gv)
        trace_u = gu[0, 0] + gu[1, 1] + gu[2, 2]
        trace_v = gv[0, 0] + gv[1, 1] + gv[2, 2]
        return mu * shear + lam * trace_u * trace_v

    return stiffness


def _mass_form(density: float) -> skfem.BilinearForm:
    """Consistent mass of one displacement component: rho u v (scalar element)."""

    @skfem.BilinearForm
    def mass(u, v, _):
        return density * u * v

    return mass


def _symmetric(matrix) -> sp.csr_matrix:
    """Remove round-off asymmetry of an assembled symmetric form."""
    matrix = sp.csr_matrix(matrix)
    return sp.csr_matrix((matrix + matrix.T) * 0.5)


def _check_orientation(basis: skfem.CellBasis, source: str) -> None:
    """Raise if an element's Jacobian determinant vanishes or changes sign.

    scikit-fem integrates with |det J|. That is harmless for a mirrored
    element (det J < 0 everywhere: the map is still one-to-one), but a
    tangled element, e.g. a hexahedron whose nodes are not in meshio's
    order, would assemble silently into a wrong matrix. The determinant is
    checked at the integration points and at the element's nodes.
    """
    points = np.hstack([basis.X, basis.mesh.elem().doflocs.T])
    det = basis.mapping.detDF(points)
    positive, negative = (det > 0).all(axis=1), (det < 0).all(axis=1)
    bad = np.flatnonzero(~(positive | negative))
    if bad.size:
        raise ValueError(
            f"{source}: {bad.size} of {det.shape[0]} elements are tangled or degenerate (the Jacobian "
            f"determinant vanishes or changes sign inside; first: element {bad[0]}); check the element "
            "node order (meshio's order is expected) and the mesh quality"
        )
    if negative.any():
        logger.debug("%s: %d mirrored (negatively oriented) elements; valid", source, negative.sum())


def _node_major_permutation(vector_basis: skfem.CellBasis, mesh) -> np.ndarray | None:
    """Permutation ``p`` with ``p[3*i + c]`` = scikit-fem DOF of component c at node i.

    Every supported element has at most one scalar DOF per vertex, edge, face
    or cell, so each of those entities carries one node. Returns None when
    scikit-fem's numbering is node-major already (it is, in scikit-fem 12).
    """
    perm = np.empty(vector_basis.N, dtype=np.int64)
    for kind in ("nodal_dofs", "edge_dofs", "facet_dofs", "interior_dofs"):
        nodes = getattr(mesh.dofs, kind)
        if nodes.shape[0]:
            components = getattr(vector_basis.dofs, kind)
            for c in range(3):
                perm[3 * nodes[0] + c] = components[c]
    return None if np.array_equal(perm, np.arange(perm.size)) else perm
