"""From an FE model of a free body (a link, the casing) to a :class:`~flexbodies.reduced.ReducedBody`.

Steps: tie the bores to master nodes (:mod:`~flexbodies.interfaces`),
compute the reference frequencies of the coupled FE model
(:mod:`~flexbodies.frequencies`), build the Craig-Bampton basis the mode
decision asks for (:mod:`~flexbodies.craig_bampton`), orthonormalise it
into elastic modes and compute the floating-frame invariants
(:mod:`~flexbodies.invariants`).
"""
from __future__ import annotations

import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .assembly import FEModel
from .craig_bampton import CraigBamptonBasis, elastic_coefficients, fixed_interface_set, kept_count
from .frequencies import free_free_frequencies, mounted_frequencies
from .interfaces import InterfaceCoupling, couple_interfaces, rigid_motion_rows
from .interior import InteriorSolver
from .invariants import ffrf_invariants
from .reduced import ReducedBody
from .selection import ModeDecision
from .stress import NodalStress

__all__ = ["CoupledModel", "couple", "reference_frequencies", "reduce_coupled", "reduce_for_decisions",
           "InertiaFlexibility"]


@dataclass(frozen=True)
class CoupledModel:
    """An FE model with its bores tied to master nodes.

    Attributes
    ----------
    fe_model : FEModel
    coupling : InterfaceCoupling
    stiffness, mass : scipy.sparse.csr_matrix
        ``T^T K T`` and ``T^T M T`` in coupled coordinates.
    stress : flexbodies.stress.NodalStress or None
        The mesh's nodal stress operator: when given, the reduction keeps the
        stress shapes of its modes (:mod:`flexbodies.stress`).
    """

    fe_model: FEModel
    coupling: InterfaceCoupling
    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    stress: NodalStress | None = None


def couple(fe_model, kind="RBE2") -> CoupledModel:
    """Tie the bores of ``fe_model`` to master nodes (``"RBE2"`` or ``"RBE3"``, for all or per bore)."""
    coupling = couple_interfaces(fe_model, kind)
    return CoupledModel(fe_model, coupling, coupling.reduce(fe_model.stiffness), coupling.reduce(fe_model.mass))


def reference_frequencies(coupled: CoupledModel, count: int = 6) -> dict:
    """Free-free and as-mounted frequencies of the coupled FE model, Hz."""
    return {
        "free_free_hz": free_free_frequencies(coupled.stiffness, coupled.mass, count),
        "mounted_hz": mounted_frequencies(coupled.stiffness, coupled.mass, coupled.coupling, count=3),
    }


def _padded(matrix: sp.spmatrix, extra: int) -> sp.csr_matrix:
    """A square matrix with ``extra`` zero rows and columns appended (its CSR arrays, the row pointer
    extended)."""
    matrix = sp.csr_matrix(matrix)
    n = matrix.shape[0] + extra
    indptr = np.concatenate([matrix.indptr, np.full(extra, matrix.indptr[-1])])
    return sp.csr_matrix((matrix.data, matrix.indices, indptr), shape=(n, n))


class InertiaFlexibility:
    """The held interior's flexibility seen through the inertia loads of a Craig-Bampton basis.

    A motion ``u = W x`` of the body (``x``: its frame's translation, m, and
    rotation, rad, in the body frame, then its elastic modal coordinates)
    loads the held interior with the inertia force ``w^2 f``, ``f = (M W x)_i``.
    The fixed-interface modes ``j`` the basis omits answer it and act back
    on ``x`` with the dynamic stiffness ``-w^4 sum_j f^T phi_j phi_j^T f /
    (w_j^2 - w^2)``, which is ``-w^4 R`` to leading order in ``(w / w_j)^2``,

        R = f^T (K_ii^-1 - Phi_k Omega_k^-2 Phi_k^T) f,

    the residual flexibility of the omitted modes (``K_ii^-1`` less the kept
    modes' part) seen through ``f``: no omitted mode is computed. Every
    motion of a basis made of the static modes and the lowest fixed-interface
    modes of *cb* is ``W = V C`` (``V``: *cb*'s vectors), so one block solve
    with the loads ``(M V)_i`` serves :meth:`residual_mass` of each such basis.

    Parameters
    ----------
    coupled : CoupledModel
    solver : InteriorSolver
        The factorisation *cb* was made with.
    cb : CraigBamptonBasis
        The largest basis served.
    """

    def __init__(self, coupled: CoupledModel, solver: InteriorSolver, cb: CraigBamptonBasis):
        coupling = coupled.coupling
        #: Static-mode coefficients of a rigid motion about the frame origin, shape (n_static, 6).
        self.carry = np.zeros((cb.n_static, 6))
        for interface, dofs in enumerate(coupling.master_dofs):
            self.carry[dofs[:3] - solver.masters[0]] = rigid_motion_rows(coupling.centres[interface:interface + 1])[0]
            self.carry[dofs[3:] - solver.masters[0], 3:] = np.eye(3)
        loads = (coupled.mass @ cb.vectors)[solver.interior]
        self.flexibility = loads.T @ solver.factor.solve(loads)
        self.participation = cb.vectors[solver.interior, cb.n_static:].T @ loads
        self.omega_sq = (2 * np.pi * np.asarray(cb.fixed_interface_hz)) ** 2

    def residual_mass(self, n_fixed: int, coefficients: np.ndarray) -> np.ndarray:
        """R of the basis of the static modes and the lowest ``n_fixed`` fixed-interface modes.

        Parameters
        ----------
        n_fixed : int
        coefficients : ndarray, shape (n_static + n_fixed, n_modes)
            The body's elastic modes in that basis
            (:func:`~flexbodies.craig_bampton.elastic_coefficients`).

        Returns
        -------
        ndarray, shape (6 + n_modes, 6 + n_modes)
            R, kg s^2 (per unit coordinate).
        """
        size = len(self.carry) + n_fixed
        motion = np.hstack([np.vstack([self.carry, np.zeros((n_fixed, 6))]), coefficients])
        projected = self.participation[:n_fixed, :size] @ motion
        residual = (motion.T @ self.flexibility[:size, :size] @ motion
                    - projected.T @ (projected / self.omega_sq[:n_fixed, None]))
        return 0.5 * (residual + residual.T)


def reduce_coupled(coupled: CoupledModel, cb: CraigBamptonBasis, decision: ModeDecision, frequencies: dict,
                   info: dict, flexibility: InertiaFlexibility | Future[InertiaFlexibility] | None = None) -> ReducedBody:
    """The reduced link of a Craig-Bampton basis: elastic modes, node-wise basis, floating-frame invariants.

    Parameters
    ----------
    coupled : CoupledModel
    cb : CraigBamptonBasis
        The static modes and the fixed-interface modes ``decision`` keeps.
    decision : ModeDecision
    frequencies : dict
        Reference frequencies of the coupled model (:func:`reference_frequencies`), Hz.
    info : dict
        JSON-able facts about the inputs, stored with the link; reduction
        timings and sizes are added.
    flexibility : InertiaFlexibility or Future of one, optional
        Of ``cb`` or a larger basis of the same factorisation: the link then
        keeps its residual mass (:meth:`InertiaFlexibility.residual_mass`);
        a future being made in another thread is waited for last.

    Returns
    -------
    ReducedBody
    """
    start = time.perf_counter()
    coupling = coupled.coupling
    coefficients, reduced_hz = elastic_coefficients(cb, coupled.stiffness, coupled.mass)
    modes_q = cb.vectors @ coefficients
    fe = coupled.fe_model
    n_fe = len(fe.nodes)
    n_if = len(coupling.names)
    masters_t = coupling.master_dofs[:, :3]
    mode_basis = np.vstack([coupling.transform @ modes_q, modes_q[masters_t.ravel()]])
    nodes = np.vstack([fe.nodes, coupling.centres])
    invariants = ffrf_invariants(nodes, _padded(fe.mass, 3 * n_if), _padded(fe.stiffness, 3 * n_if), mode_basis)
    stress_modes = np.zeros((0, 6, 0))
    if coupled.stress is not None:
        stress_start = time.perf_counter()
        stress_modes = coupled.stress.of(mode_basis)
        info = {**info, "stress_shape_seconds": time.perf_counter() - stress_start}
    flexible = flexibility.result() if isinstance(flexibility, Future) else flexibility
    residual = (np.zeros((0, 0)) if flexible is None
                else flexible.residual_mass(len(cb.fixed_interface_hz), coefficients))
    info = dict(info)
    info.update(
        coupling=coupling.kind,
        fe_dof=int(fe.ndof),
        coupled_dof=int(coupling.n_q),
        fe_description=fe.description,
        reduction_seconds=info.get("reduction_seconds", 0.0) + time.perf_counter() - start,
    )
    return ReducedBody(
        nodes=nodes,
        master_nodes=n_fe + np.arange(n_if),
        interface_names=coupling.names,
        interface_nodes=tuple(np.asarray(b.nodes) for b in fe.bores),
        surface_triangles=np.asarray(fe.surface_triangles, dtype=int),
        mode_basis=mode_basis,
        ffrf=invariants,
        frequencies={**frequencies, "fixed_interface_hz": cb.fixed_interface_hz, "reduced_hz": reduced_hz},
        decision=decision,
        info=info,
        stress_modes=stress_modes,
        residual_mass=residual,
    )


def reduce_for_decisions(coupled: CoupledModel, solver: InteriorSolver, decisions, frequencies: dict, infos) -> list:
    """Reduce a coupled link for several mode decisions from one factorisation.

    The fixed-interface modes are nested (the lowest ``k`` of one solve), so
    one eigen-solve up to the highest need of all decisions serves each of
    them, truncated to what it keeps; the same factorisation gives the
    static modes, and one block solve the residual mass of each
    (:class:`InertiaFlexibility`). The decisions' reductions run side by
    side in threads, beside that block solve.

    Parameters
    ----------
    coupled : CoupledModel
    solver : InteriorSolver
        The factorisation of ``coupled``'s interior stiffness.
    decisions : sequence of ModeDecision
    frequencies : dict
        Reference frequencies of the coupled model, Hz.
    infos : sequence of dict
        What :func:`reduce_coupled` stores with each link.

    Returns
    -------
    list of ReducedBody
        One per decision.
    """
    start = time.perf_counter()
    counts = [d.count for d in decisions if d.count is not None]
    cutoffs = [d.cutoff_hz for d in decisions if d.count is None]
    need_count = max(counts, default=0)
    fixed_hz, fixed = np.zeros(0), np.zeros((solver.n_q, 0))
    if cutoffs or need_count:
        fixed_hz, fixed = fixed_interface_set(
            solver.fixed_interface_modes, len(solver.interior),
            count=None if cutoffs else need_count, cutoff_hz=max(cutoffs, default=None),
        )
        if need_count > len(fixed_hz):
            fixed_hz, fixed = solver.fixed_interface_modes(need_count)
    keeps = [kept_count(fixed_hz, decision.count, decision.cutoff_hz) for decision in decisions]
    largest = CraigBamptonBasis(np.hstack([solver.static_modes(), fixed[:, :max(keeps)]]), solver.masters,
                                fixed_hz[:max(keeps)])
    shared = time.perf_counter() - start
    # the residual flexibility's block solve beside the decisions' reductions, which wait for it last
    # (SuperLU and NumPy's products release the GIL)
    with ThreadPoolExecutor(max_workers=1 + len(decisions)) as threads:
        flexibility = threads.submit(InertiaFlexibility, coupled, solver, largest)
        running = [threads.submit(reduce_coupled, coupled,
                                  CraigBamptonBasis(largest.vectors[:, :largest.n_static + keep], solver.masters,
                                                    fixed_hz[:keep]),
                                  decision, frequencies,
                                  {**info, "reduction_seconds": info.get("reduction_seconds", 0.0) + shared},
                                  flexibility)
                   for decision, keep, info in zip(decisions, keeps, infos, strict=True)]
        return [link.result() for link in running]
