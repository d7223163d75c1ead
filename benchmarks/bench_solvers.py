"""Sparse direct solvers on the link matrices of the reference mount: a table of medians.

For each unique link of the reference case, the matrix every reduction
factorises (the interior stiffness, both master nodes held) is factorised
and solved by each solver that imports here: scipy's SuperLU (in the
package's order, METIS's nested dissection of the node graph, with SuperLU's
minimum-degree ordering, and with scipy's default), CHOLMOD
through ``cholespy``, MKL Pardiso through ``pypardiso`` and MUMPS through
``python-mumps``. The table gives the median wall time of the factorisation,
of one solve and of a solve with 12 right-hand sides (the static modes), in
s, and the largest relative residual. A solver that does not import is
listed with the reason.

Run::

    python benchmarks/bench_solvers.py --repeats 3
"""
from __future__ import annotations

import argparse
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402
from bench_reduction import _timed  # noqa: E402  (this folder is on the path of a script run from it)


def _superlu(ordering):
    def factor(A):
        options = {"SymmetricMode": True} if ordering == "MMD_AT_PLUS_A" else {}
        lu = spla.splu(A.tocsc(), permc_spec=ordering, options=options)
        return lambda B: np.column_stack([lu.solve(np.ascontiguousarray(c)) for c in B.T]) if B.ndim == 2 else lu.solve(B)
    return factor


def _nested_dissection(A):
    from flexbodies.eigen import factorize

    factor = factorize(A)
    return lambda B: np.column_stack([factor.solve_plain(c) for c in B.T]) if B.ndim == 2 else factor.solve_plain(B)


def _cholespy(A):
    from cholespy import CholeskySolverD, MatrixType

    A = A.tocsr()
    solver = CholeskySolverD(A.shape[0], A.indptr.astype(np.int32), A.indices.astype(np.int32), A.data, MatrixType.CSR)

    def solve(B):
        B = np.ascontiguousarray(B)
        X = np.empty_like(B)
        solver.solve(B, X)
        return X
    return solve


def _pypardiso(A):
    import pypardiso

    solver = pypardiso.PyPardisoSolver(mtype=2)  # real symmetric positive definite
    upper = sp.triu(A, format="csr")
    solver.factorize(upper)
    return lambda B: solver.solve(upper, np.ascontiguousarray(B))


def _mumps(A):
    import mumps

    context = mumps.Context()
    context.set_matrix(A, symmetric=True)
    context.analyze()
    context.factor()
    return context.solve


SOLVERS = {
    "SuperLU, METIS ND (the package's)": _nested_dissection,
    "SuperLU, MMD(A^T+A)": _superlu("MMD_AT_PLUS_A"),
    "SuperLU, scipy default": _superlu("COLAMD"),
    "CHOLMOD (cholespy)": _cholespy,
    "Pardiso (pypardiso)": _pypardiso,
    "MUMPS (python-mumps)": _mumps,
}


def link_matrices():
    """(name, interior stiffness) of each unique link of the reference case."""
    from flexbodies.link import build_fe_model
    from flexbodies.reduction import couple
    from workbook.model.reference import reference_case

    seen = {}
    for link in reference_case().links:
        seen.setdefault(link.model.key(), link)
    for link in seen.values():
        fe, _ = build_fe_model(link.model)
        coupled = couple(fe, link.model.interface)
        K = coupled.stiffness
        interior = np.setdiff1d(np.arange(K.shape[0]), coupled.coupling.boundary)
        yield link.name, K[interior][:, interior].tocsr()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    import pandas as pd

    rows = []
    for name, A in link_matrices():
        rhs = np.random.default_rng(0).standard_normal((A.shape[0], 12))
        for solver, make in SOLVERS.items():
            row = {"link": f"{name} ({A.shape[0]} DOF)", "solver": solver}
            try:
                row["factorise [s]"], solve = _timed(lambda make=make, A=A: make(A), args.repeats)
            except Exception as error:  # an optional solver that is missing or broken here
                row["note"] = f"{type(error).__name__}: {str(error).splitlines()[0][:60]}"
                rows.append(row)
                continue
            row["1 solve [s]"], _ = _timed(lambda solve=solve, rhs=rhs: solve(rhs[:, 0].copy()), args.repeats)
            row["12 solves [s]"], X = _timed(lambda solve=solve, rhs=rhs: solve(rhs), args.repeats)
            row["residual"] = float(np.abs(A @ X - rhs).max() / np.abs(rhs).max())
            rows.append(row)
    table = pd.DataFrame(rows).set_index(["link", "solver"])
    print(f"Interior stiffness of the reference links, median of {args.repeats} repeats, 1 thread")
    print(table.to_string(float_format=lambda v: f"{v:.3g}", na_rep=""))


if __name__ == "__main__":
    main()
