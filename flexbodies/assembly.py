"""Stiffness and consistent mass matrices of a meshed link (scikit-fem).

The matrices are ordered node-major: DOF ``3*i + c`` is displacement
component ``c`` (x, y, z) of finite element node ``i``, where the nodes are
``BodyMesh.nodes`` (vertices and, for quadratic elements, the edge/face/cell
nodes).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import skfem
from skfem.quadrature import get_quadrature

from .errors import TangledElements
from .materials import Material
from .meshing import BodyMesh, Bore

__all__ = ["FEModel", "Bore", "assemble", "INTEGRATION_ORDERS", "tangled_elements"]

logger = logging.getLogger(__name__)

#: Default integration orders (stiffness, mass) per mesh type: exact for
#: straight-sided elements, and few points for hexahedra (scikit-fem's
#: default of twice the element degree means 64 points for a quadratic hex).
INTEGRATION_ORDERS = {
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


def assemble(link_mesh: BodyMesh, material: Material, intorder: int | None = None) -> FEModel:
    """Assemble linear elastic stiffness and consistent mass of a link.

    scikit-fem gives the shape functions, their gradients and the
    integration weights of every element; the element matrices of all
    elements are then formed at once (batched products) and summed into
    node blocks over one sorted pattern, which the stiffness (3x3 blocks)
    and the mass (one scalar per block, ``M = M_scalar (x) I3``) share.

    Parameters
    ----------
    link_mesh : BodyMesh
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
    TangledElements
        A ValueError, if an element is tangled or degenerate (Jacobian determinant zero or
        changing sign inside it), e.g. a hexahedron whose node order is not
        meshio's. Mirrored elements (negative determinant throughout) are
        valid and accepted.
    """
    mesh = link_mesh.mesh
    k_order, m_order = INTEGRATION_ORDERS[type(mesh)] if intorder is None else (intorder, intorder)
    k_basis = skfem.Basis(mesh, mesh.elem(), intorder=k_order)
    _check_orientation(k_basis, link_mesh.source)
    pattern = _BlockPattern(k_basis.element_dofs, k_basis.N)
    stiffness = pattern.blocks(_element_stiffness(k_basis, material))
    mass = sp.kron(pattern.scalars(_element_mass(mesh, m_order, material.density)), sp.identity(3), format="csr")
    nodes = np.ascontiguousarray(link_mesh.nodes)
    description = f"{link_mesh.element_name}, {nodes.shape[0]} nodes, {3 * nodes.shape[0]} DOF"
    logger.info("assembled %s, material %s", description, material.name)
    return FEModel(
        nodes=nodes,
        stiffness=stiffness,
        mass=mass,
        bores=tuple(link_mesh.bores),
        surface_triangles=link_mesh.surface_triangles(),
        material=material,
        description=description,
    )


def _gradients(basis: skfem.CellBasis) -> np.ndarray:
    """Shape-function gradients at the integration points, shape (elements, points, functions, 3), 1/m."""
    return np.stack([np.moveaxis(field[0].grad, 0, -1) for field in basis.basis], axis=2)


#: Pattern entries summed at once (:class:`_BlockPattern`): their element values, gathered, stay in the
#: processor's cache.
_ENTRY_BATCH = 4096
#: Elements whose stiffness is formed at once: the temporaries of a batch stay in the processor's cache (the
#: 47,000-DOF thrust rod's 9,300 elements at once took 8 times as long, in fresh pages of memory).
_ELEMENT_BATCH = 256


def _element_stiffness(basis: skfem.CellBasis, material: Material) -> np.ndarray:
    """Element stiffness of isotropic elasticity, node-pair blocks: shape (elements, functions, functions, 3, 3), N/m.

    For shape functions a, b and components i, j:
    ``K[a,i,b,j] = int mu (delta_ij grad a . grad b + d_j a d_i b) + lambda d_i a d_j b``,
    the form ``2 mu eps(u):eps(v) + lambda div u div v``, formed :data:`_ELEMENT_BATCH` elements at a time.
    """
    grad = _gradients(basis)
    n_e, n_p, n_f, _ = grad.shape
    lam, mu = material.lame_lambda, material.shear_modulus
    identity = np.eye(3)[None, None, :, None, :]
    stiffness = np.empty((n_e, n_f, n_f, 3, 3))
    for start in range(0, n_e, _ELEMENT_BATCH):
        batch = slice(start, start + _ELEMENT_BATCH)
        flat = grad[batch].reshape(-1, n_p, 3 * n_f)
        # T[e, (a,i), (b,j)] = int d_i a d_j b
        products = np.matmul(np.swapaxes(flat * basis.dx[batch, :, None], 1, 2), flat).reshape(-1, n_f, 3, n_f, 3)
        laplace = np.einsum("eaibi->eab", products)
        element = lam * products + mu * np.swapaxes(products, 2, 4)
        element += mu * laplace[:, :, None, :, None] * identity
        stiffness[batch] = 0.5 * (element + element.transpose(0, 3, 4, 1, 2)).transpose(0, 1, 3, 2, 4)
    return stiffness


def _element_mass(mesh: skfem.Mesh, intorder: int, density: float) -> np.ndarray:
    """Element mass of one displacement component, ``int rho a b``, shape (elements, functions, functions), kg.

    The shape functions' values at the integration points are the reference element's (the map moves
    the points, not the values), so no basis is made: only the Jacobian determinants are the elements'
    (a basis's shape-function gradients took 0.14 s on the 9,300 elements of the reference thrust rod).
    """
    points, weights = get_quadrature(mesh.elem().refdom, intorder)
    dx = np.abs(mesh.mapping().detDF(points)) * weights                        # (elements, points)
    values = np.stack([np.broadcast_to(mesh.elem().lbasis(points, j)[0], dx.shape)
                       for j in range(mesh.elem().doflocs.shape[0])], axis=2)  # (elements, points, functions)
    element = density * np.matmul(np.swapaxes(values * dx[:, :, None], 1, 2), values)
    return 0.5 * (element + np.swapaxes(element, 1, 2))


class _BlockPattern:
    """Node-pair pattern of a mesh: where each element's (a, b) pair sums into the global matrix.

    Parameters
    ----------
    element_nodes : ndarray of int, shape (functions, elements)
        Global node of each element's shape function (scikit-fem's ``element_dofs``).
    n_nodes : int
    """

    def __init__(self, element_nodes: np.ndarray, n_nodes: int):
        rows = np.broadcast_to(element_nodes[:, None, :], (element_nodes.shape[0],) * 2 + element_nodes.shape[1:])
        cols = np.swapaxes(rows, 0, 1)
        # entry order of the element arrays: (element, a, b)
        keys = (rows.astype(np.int64) * n_nodes + cols).transpose(2, 0, 1).ravel()
        self._order = np.argsort(keys, kind="stable")
        sorted_keys = keys[self._order]
        self._starts = np.flatnonzero(np.r_[True, sorted_keys[1:] != sorted_keys[:-1]])
        unique = sorted_keys[self._starts]
        self.n_nodes = n_nodes
        self.indices = (unique % n_nodes).astype(np.int32)
        self.indptr = np.searchsorted(unique // n_nodes, np.arange(n_nodes + 1)).astype(np.int32)

    def _summed(self, values: np.ndarray) -> np.ndarray:
        """The sum of each pattern entry's element values, :data:`_ENTRY_BATCH` entries at a time."""
        summed = np.empty((len(self._starts),) + values.shape[1:])
        ends = np.append(self._starts[1:], len(self._order))
        for first in range(0, len(self._starts), _ENTRY_BATCH):
            starts = self._starts[first:first + _ENTRY_BATCH]
            taken = values[self._order[starts[0]:ends[first + len(starts) - 1]]]
            summed[first:first + len(starts)] = np.add.reduceat(taken, starts - starts[0], axis=0)
        return summed

    def scalars(self, element: np.ndarray) -> sp.csr_matrix:
        """Sum element matrices (elements, a, b) into a node-by-node matrix."""
        data = self._summed(element.reshape(-1))
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n_nodes, self.n_nodes))

    def blocks(self, element: np.ndarray) -> sp.csr_matrix:
        """Sum element matrices of node-pair blocks (elements, a, b, 3, 3) into a node-major matrix of 3x3
        node blocks."""
        data = self._summed(element.reshape(-1, 3, 3))
        n = 3 * self.n_nodes
        matrix = sp.bsr_matrix((data, self.indices, self.indptr), shape=(n, n)).tocsr()
        matrix.eliminate_zeros()  # entries of a block that cancel exactly
        return matrix


def _orientation(basis: skfem.CellBasis) -> tuple[np.ndarray, np.ndarray]:
    """The tangled elements' indices, and which elements are mirrored (det J < 0 throughout)."""
    points = np.hstack([basis.X, basis.mesh.elem().doflocs.T])
    det = basis.mapping.detDF(points)
    positive, negative = (det > 0).all(axis=1), (det < 0).all(axis=1)
    return np.flatnonzero(~(positive | negative)), negative


def tangled_elements(mesh: skfem.Mesh) -> np.ndarray:
    """Indices of the elements of *mesh* that :func:`assemble` refuses as tangled or degenerate."""
    return _orientation(skfem.Basis(mesh, mesh.elem(), intorder=INTEGRATION_ORDERS[type(mesh)][0]))[0]


def _check_orientation(basis: skfem.CellBasis, source: str) -> None:
    """Raise :class:`TangledElements` if an element's Jacobian determinant vanishes or changes sign.

    scikit-fem integrates with |det J|. That is harmless for a mirrored
    element (det J < 0 everywhere: the map is still one-to-one), but a
    tangled element, e.g. a hexahedron whose nodes are not in meshio's
    order, would assemble silently into a wrong matrix. The determinant is
    checked at the integration points and at the element's nodes.
    """
    bad, negative = _orientation(basis)
    if bad.size:
        raise TangledElements(
            f"{source}: {bad.size} of {negative.size} elements are tangled or degenerate (the Jacobian "
            f"determinant vanishes or changes sign inside; first: element {bad[0]}); check the element "
            "node order (meshio's order is expected) and the mesh quality", bad.size, negative.size)
    if negative.any():
        logger.debug("%s: %d mirrored (negatively oriented) elements; valid", source, negative.sum())
