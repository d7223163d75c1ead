"""Every solve a link's reduction needs, from one factorisation of its interior stiffness.

In coupled coordinates ``q = [interior, masters]`` the interior stiffness
``K_ii`` (every master DOF held) is regular. Its one factorisation serves:

- the static (constraint) modes ``psi = -K_ii^-1 K_ib``;
- the fixed-interface eigenproblem (``K_ii``, ``M_ii``, shift 0);
- the mounted eigenproblem (masters pinned, spin held) and the free-free one,
  whose stiffness borders ``K_ii`` with a few master coordinates ``r``
  (master motion ``N r``). A solve with the bordered matrix is one ``K_ii``
  solve plus a small dense one with the condensed boundary stiffness
  ``S = N^T (K_bb + K_bi psi) N``. The free body is held statically
  determinate at the first master, and its rigid-body motion is projected
  out (inertia relief), so the operator's eigenvalues are those of the
  elastic modes.

Each eigenproblem then runs shift-invert Lanczos on the full coupled model:
the frequencies are those of the FE model, not of a reduced one. The
reference frequencies' two eigenproblems, and the fixed-interface one when
asked for, run side by side, their solves made together
(:func:`~flexbodies.eigen.solved_together`).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .eigen import PlainSolver, factorize, lowest_modes, solved_together, start_vector
from .frequencies import mounted_constraint_basis
from .interfaces import rigid_motion_rows

__all__ = ["InteriorSolver"]

#: Lanczos tolerance (a symmetric problem's eigenvalue errors go with the square of the residual: the
#: frequencies of the reference links agree with those at machine precision to 1e-15). Against 1e-10 it
#: saved 9 of 30 solves on a short link's free body and 7 of 29 on the thrust rod's fixed-interface modes.
_TOLERANCE = 1e-8

#: Lanczos vectors between restarts for the 3 mounted modes. With the shift at 0 they converge in one
#: short cycle; ARPACK's default of 20 vectors took 21 solves on every reference link, 12 vectors 13.
_VECTORS_MOUNTED = 12


class InteriorSolver:
    """One factorisation of a coupled link's interior stiffness, and what it solves.

    Parameters
    ----------
    stiffness, mass : scipy.sparse matrix, shape (n_q, n_q)
        Coupled stiffness (N/m) and mass (kg).
    coupling : InterfaceCoupling
        Gives the master DOF (the last coordinates of ``q``) and the bore centres.
    """

    def __init__(self, stiffness, mass, coupling):
        K = sp.csr_matrix(stiffness)
        self.mass = sp.csr_matrix(mass)
        self.stiffness = K
        self.coupling = coupling
        self.masters = np.asarray(coupling.boundary, dtype=int)
        self.interior = np.setdiff1d(np.arange(K.shape[0]), self.masters)
        if not np.array_equal(self.masters, np.arange(len(self.interior), K.shape[0])):
            raise ValueError("the master DOF must be the last coordinates of the coupled model")
        n_i = len(self.interior)  # the interior coordinates come first: slices, not index arrays
        # CSR, as the solves and the Lanczos runs take it (a conversion to CSC cost 0.1 to 0.2 s on the thrust rod)
        self.K_ii = K[:n_i, :n_i]
        self.K_ib = K[:n_i, n_i:].toarray()
        self.M_ii = self.mass[:n_i, :n_i]
        self.factor = factorize(self.K_ii)
        #: Interior part of the static modes, one column per master DOF.
        self.psi = -self.factor.solve(self.K_ib)
        K_bb = K[n_i:, n_i:].toarray()
        condensed = K_bb + self.K_ib.T @ self.psi
        #: Condensed (Guyan) boundary stiffness, symmetrised.
        self.condensed = 0.5 * (condensed + condensed.T)
        self._fixed = None  # the largest set of fixed-interface modes computed so far

    @property
    def n_q(self) -> int:
        return self.stiffness.shape[0]

    def reference_frequencies(self, fixed_modes: int = 0) -> dict:
        """``free_free_hz`` (6 elastic) and ``mounted_hz`` (3) of the coupled FE model, Hz.

        Parameters
        ----------
        fixed_modes : int
            Also compute the lowest so many fixed-interface modes (kept for
            :meth:`fixed_interface_modes`), side by side with the frequencies.
        """
        problems = [lambda factor: self.free_free_frequencies(6, factor),
                    lambda factor: self.mounted_frequencies(3, factor)]
        if fixed_modes:
            problems.append(lambda factor: self.fixed_interface_modes(fixed_modes, factor))
        free_free, mounted = solved_together(self.factor, problems)[:2]
        return {"free_free_hz": free_free, "mounted_hz": mounted}

    def static_modes(self) -> np.ndarray:
        """Static modes in coupled coordinates, shape (n_q, n_masters): unit value at one master DOF."""
        vectors = np.zeros((self.n_q, len(self.masters)))
        vectors[self.interior] = self.psi
        vectors[self.masters, np.arange(len(self.masters))] = 1.0
        return vectors

    def fixed_interface_modes(self, count: int, factor: PlainSolver | None = None):
        """The lowest ``count`` fixed-interface modes: frequencies (Hz) and mass-normalised shapes in ``q``.

        The modes are nested, so the largest set computed so far serves every
        smaller request (the stress stiffening's pinned model and the
        reduction ask for them in turn). ``factor`` solves with ``K_ii``
        (default: this solver's factorisation; see :meth:`reference_frequencies`).
        """
        if self._fixed is None or len(self._fixed[0]) < count:
            freqs, phi = lowest_modes(self.K_ii, self.M_ii, count, 0.0, factor or self.factor, tol=_TOLERANCE,
                                      ncv=2 * count + 5)
            vectors = np.zeros((self.n_q, phi.shape[1]))
            vectors[self.interior] = phi
            self._fixed = (freqs, vectors)
        freqs, vectors = self._fixed
        return freqs[:count], vectors[:, :count]

    def _bordered(self, basis: np.ndarray, factor: PlainSolver):
        """Solver of the stiffness with master motion ``basis @ r``, in ``[interior, r]`` coordinates
        (``factor`` solves with ``K_ii``)."""
        n_i = len(self.interior)
        coupling = self.K_ib @ basis            # K_ib N
        psi_n = self.psi @ basis                # -K_ii^-1 K_ib N
        schur = sla.cho_factor(basis.T @ self.condensed @ basis)

        def solve(f):
            f = np.asarray(f, dtype=float)
            y = factor.solve_plain(f[:n_i])
            r = sla.cho_solve(schur, f[n_i:] - coupling.T @ y)
            return np.concatenate([y + psi_n @ r, r])

        return solve

    def _bordered_mass(self, basis: np.ndarray) -> sp.csr_matrix:
        """Mass in ``[interior, r]`` coordinates with master motion ``basis @ r``."""
        n_i = len(self.interior)
        lift = sp.bmat([[sp.identity(n_i, format="csr"), None], [None, sp.csr_matrix(basis)]], format="csr")
        return (lift.T @ self.mass @ lift).tocsr()

    def mounted_frequencies(self, count: int = 3, factor: PlainSolver | None = None) -> np.ndarray:
        """Frequencies with both bore centres pinned and the spin about the link axis held, Hz
        (``factor`` as for :meth:`fixed_interface_modes`)."""
        basis = mounted_constraint_basis(self.coupling)
        M = self._bordered_mass(basis)
        solve = self._bordered(basis, factor or self.factor)
        operator = spla.LinearOperator(M.shape, matvec=solve, dtype=float)
        # shift-invert Lanczos asks only for the solves (OPinv) and the mass: of the stiffness (the first
        # argument), eigsh reads only the shape, so the bordered stiffness is not formed
        lam, _ = spla.eigsh(M, k=count, M=M, sigma=0.0, which="LM", OPinv=operator, v0=start_vector(M.shape[0]),
                            tol=_TOLERANCE, ncv=min(max(_VECTORS_MOUNTED, 2 * count + 1), M.shape[0] - 1))
        return np.sort(np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi))

    def _rigid_masters(self) -> np.ndarray:
        """Master DOF of the six rigid-body motions about the first master, shape (n_masters, 6)."""
        centres = self.coupling.centres
        blocks = []
        for rows in rigid_motion_rows(centres - centres[0]):
            blocks.append(rows)
            blocks.append(np.hstack([np.zeros((3, 3)), np.eye(3)]))
        return np.vstack(blocks)

    def free_free_frequencies(self, count: int = 6, factor: PlainSolver | None = None) -> np.ndarray:
        """First elastic frequencies of the free link, Hz (its six rigid-body modes skipped; ``factor``
        as for :meth:`fixed_interface_modes`)."""
        n_i, n_q = len(self.interior), self.n_q
        held, others = self.masters[:6], self.masters[6:]
        solve = self._bordered(np.eye(len(self.masters))[:, 6:], factor or self.factor)  # held at the first master
        rigid = self.static_modes() @ self._rigid_masters()
        rigid = rigid @ np.linalg.inv(np.linalg.cholesky(rigid.T @ (self.mass @ rigid))).T
        mass_rigid = self.mass @ rigid

        def relieved(f):
            # P^T F P f with P = I - M R R^T: loads balanced by inertia, flexibility with the first master
            # held, rigid motion removed; the rigid-body modes map to 0 and the elastic ones to 1/lambda
            f = f - mass_rigid @ (rigid.T @ f)
            z = solve(np.concatenate([f[self.interior], f[others]]))
            x = np.zeros(n_q)
            x[self.interior], x[others] = z[:n_i], z[n_i:]
            assert not x[held].any()
            return x - rigid @ (mass_rigid.T @ x)

        operator = spla.LinearOperator((n_q, n_q), matvec=relieved, dtype=float)
        lam, _ = spla.eigsh(self.stiffness, k=count, M=self.mass, sigma=0.0, which="LM", OPinv=operator,
                            v0=start_vector(n_q), tol=_TOLERANCE)
        return np.sort(np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi))
