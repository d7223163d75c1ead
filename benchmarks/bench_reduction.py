"""Link reduction cost against mesh size: a table of medians.

Each mesh size runs in a fresh process (so peak memory is that of the size
alone) and repeats every stage; the table shows the median wall time of the
repeats, in s, and the process's peak resident memory, in MB.

Stages: mesh (gmsh), assembly (K and M), coupling (RBE2 transformation),
factorisation of the interior stiffness (fill-reducing ordering, and
scipy's default ordering for comparison), the fixed-interface eigen-solve
(12 modes, reusing that factorisation) and the whole Craig-Bampton
reduction with 12 modes (static modes, eigen-solve, orthonormalisation,
the floating-frame invariants). ``--exudyn`` adds Exudyn's own
``ComputeHurtyCraigBamptonModes`` (RBE2, 12 modes) on the same matrices.

``--reference`` instead reduces the links of the reference mount cold (no
cache), for every excitation of the case, in two ways side by side: as
before (per excitation, each link's reference frequencies and its
Craig-Bampton basis each with a factorisation of their own) and as now
(:func:`flexbodies.link.reduce_link_set`: one factorisation per unique link
serving the reference frequencies, the static modes and one fixed-interface
eigen-solve for all excitations; the unique links side by side in worker
processes, and again all in one process). It prints the median times of the
repeats and the largest relative difference of every frequency.

``--warm`` times what a warm run pays per reference link: loading and
verifying its file (uncompressed, as stored, and the same arrays
compressed, as before) and a reload from the process's memory.

``--cold`` times the whole cold ``mountwb run`` of the reference mount
(both rotors, an empty cache each time, a fresh process each time) of this
tree, and with ``--before REV`` of the package as it was at git revision
REV too, the two alternating, and checks that both print the same
isolation table. It prints the median wall and CPU times (the run's
processes' user and system time, which another load on the machine
disturbs less) side by side and the load average before and after.

Run::

    python benchmarks/bench_reduction.py                 # 14, 10 and 7 mm
    python benchmarks/bench_reduction.py --sizes 10 5 --repeats 3 --exudyn
    python benchmarks/bench_reduction.py --reference --repeats 3
    python benchmarks/bench_reduction.py --warm --repeats 5
    python benchmarks/bench_reduction.py --cold --before HEAD~3 --repeats 3
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

#: The test link of the measured-facts sheet: steel, eyes 0.30 m apart, 40x25 mm shank.
TEST_LINK = dict(length=0.30, eye_outer_radius=0.030, bore_radius=0.015, thickness=0.025,
                 shank_width=0.040, shank_thickness=0.025)


def _timed(function, repeats):
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def measure(size_mm: float, repeats: int, with_exudyn: bool) -> dict:
    """All stages for one mesh size, in this process."""
    import numpy as np
    import scipy.sparse.linalg as spla

    from flexbodies import STEEL, LinkGeometry, assemble, mesh_link
    from flexbodies.craig_bampton import craig_bampton, elastic_modes
    from flexbodies.eigen import factorize, lowest_modes
    from flexbodies.invariants import ffrf_invariants
    from flexbodies.reduction import couple

    geometry = LinkGeometry(**TEST_LINK)
    row = {"size [mm]": size_mm}
    row["mesh [s]"], link_mesh = _timed(lambda: mesh_link(geometry, size_mm * 1e-3), repeats)
    row["assembly [s]"], fe = _timed(lambda: assemble(link_mesh, STEEL), repeats)
    row["DOF"] = fe.ndof
    row["coupling [s]"], coupled = _timed(lambda: couple(fe, "RBE2"), repeats)
    K, M = coupled.stiffness, coupled.mass
    interior = np.setdiff1d(np.arange(K.shape[0]), coupled.coupling.boundary)
    K_ii = K[interior][:, interior].tocsc()
    M_ii = M[interior][:, interior].tocsc()
    row["factorise [s]"], factor = _timed(lambda: factorize(K_ii), repeats)
    row["factorise, scipy default [s]"], _ = _timed(lambda: spla.splu(K_ii), repeats)
    row["12 modes [s]"], _ = _timed(lambda: lowest_modes(K_ii, M_ii, 12, 0.0, factor), repeats)

    def reduce_12():
        cb = craig_bampton(K, M, coupled.coupling.boundary, count=12)
        modes_q, _ = elastic_modes(cb, K, M)
        return modes_q

    row["CB, 12 modes [s]"], _ = _timed(reduce_12, repeats)
    if with_exudyn:
        from exudyn.FEM import FEMinterface, HCBstaticModeSelection

        fem = FEMinterface()
        fem.nodes = {"Position": fe.nodes}
        fem.massMatrix, fem.stiffnessMatrix = fe.mass, fe.stiffness
        bores = [list(map(int, b.nodes)) for b in fe.bores]
        row["Exudyn CB, 12 modes [s]"], _ = _timed(
            lambda: fem.ComputeHurtyCraigBamptonModes(bores, 12, computationMode=HCBstaticModeSelection.RBE2),
            repeats,
        )
    modes = reduce_12()
    row["invariants [s]"], _ = _timed(
        lambda: ffrf_invariants(fe.nodes, fe.mass, fe.stiffness, coupled.coupling.transform @ modes),
        repeats,
    )
    row["peak memory [MB]"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return row


def _before(case, frequencies_hz):
    """The reduction chain as it was: per excitation, per link not yet reduced for that decision.

    As it was also means: a link keyed by its exact length (0.26 and 0.25999999999999995 m were two
    links), K and M by scikit-fem's assembly of the weak forms and the floating-frame invariants
    computed by Exudyn.
    """
    from flexbodies.assembly import FEModel
    from flexbodies.craig_bampton import craig_bampton
    from flexbodies.meshing import mesh_link
    from flexbodies.reduction import couple, reduce_coupled, reference_frequencies
    from flexbodies.selection import decide_modes
    from flexbodies.validation import exudyn_invariants, scikit_fem_matrices

    def build_fe_model(model):
        # a parametric link is meshed in its link frame already
        link_mesh = mesh_link(model.geometry, model.element_size)
        stiffness, mass = scikit_fem_matrices(link_mesh.mesh, model.material)
        fe = FEModel(nodes=link_mesh.nodes, stiffness=stiffness, mass=mass, bores=tuple(link_mesh.bores),
                     surface_triangles=link_mesh.surface_triangles(), material=model.material, description="")
        return fe, {}

    summaries, done, links = {}, set(), {}
    for f in frequencies_hz:
        for link in case.links:
            key = (link.model.key(), link.length)
            decision = decide_modes(link.modes, summaries[key]["mounted_hz"][0], f) if key in summaries else None
            if decision is not None and (key, decision.key) in done:
                continue  # a cache hit
            fe, _ = build_fe_model(link.model)
            coupled = couple(fe, link.model.interface)
            if key not in summaries:
                summaries[key] = reference_frequencies(coupled)
                decision = decide_modes(link.modes, summaries[key]["mounted_hz"][0], f)
                if (key, decision.key) in done:
                    continue
            cb = craig_bampton(coupled.stiffness, coupled.mass, coupled.coupling.boundary,
                               count=decision.count, cutoff_hz=decision.cutoff_hz)
            reduced = reduce_coupled(coupled, cb, decision, summaries[key], {})
            exudyn_invariants(reduced.nodes[:len(fe.nodes)], fe.mass, fe.stiffness,
                              reduced.mode_basis[:fe.ndof], fe.surface_triangles)
            links[(link.name, f)] = reduced
            done.add((key, decision.key))
    return links


def _now(case, frequencies_hz, workers=None):
    """The reduction chain as it is: one job per unique link for every excitation, as a run does it:
    into an empty cache, the jobs side by side in worker processes (``workers`` of them, default one per
    core; 1: all in this process)."""
    import shutil
    import tempfile

    from workbook.scene.link_workers import LinkJob, reduce_in_workers

    jobs = {}
    for link in case.links:
        jobs.setdefault(LinkJob(link.model, link.modes, tuple(frequencies_hz), False), link.name)
    folder, previous = tempfile.mkdtemp(prefix="bench-now-"), os.environ.get("MOUNTWB_CACHE")
    os.environ["MOUNTWB_CACHE"] = folder
    try:
        reduce_in_workers(list(jobs), workers=workers)
        return {(name, f): reduced for job, name in jobs.items() for f, reduced in zip(frequencies_hz, job.reduce(), strict=True)}
    finally:
        if previous is None:
            os.environ.pop("MOUNTWB_CACHE")
        else:
            os.environ["MOUNTWB_CACHE"] = previous
        shutil.rmtree(folder, ignore_errors=True)


def largest_difference(case, before: dict, now: dict) -> float:
    """Largest relative difference of any frequency between the links reduced before and now.

    Both map (link name, excitation Hz) to a reduced link; ``now`` holds the
    first link of each unique model, which serves every equal one.
    """
    import numpy as np

    keys = {link.name: link.model.key() for link in case.links}
    now_by_key = {(keys[name], f): link for (name, f), link in now.items()}
    worst = 0.0
    for (name, f), old in before.items():
        new = now_by_key[(keys[name], f)]
        assert old.decision.key == new.decision.key, (name, f)
        for key in ("free_free_hz", "mounted_hz", "fixed_interface_hz", "reduced_hz"):
            a, b = np.asarray(old.frequencies[key]), np.asarray(new.frequencies[key])
            assert a.shape == b.shape, (name, f, key)
            if a.size:
                worst = max(worst, float(np.max(np.abs(b / a - 1))))
    return worst


def reference_links(repeats: int) -> None:
    """Cold reduction of the reference mount's links, before and now, with the largest frequency difference."""

    from workbook.model.reference import reference_case

    case = reference_case()
    frequencies_hz = sorted({e.frequency for e in case.excitations})
    before_s, before = _timed(lambda: _before(case, frequencies_hz), repeats)
    now_s, now = _timed(lambda: _now(case, frequencies_hz), repeats)
    alone_s, _ = _timed(lambda: _now(case, frequencies_hz, workers=1), repeats)
    worst = largest_difference(case, before, now)
    unique = len({link.model.key() for link in case.links})
    print(f"Cold reduction of the {len(case.links)} reference links ({unique} unique) for "
          f"{', '.join(f'{f:g}' for f in frequencies_hz)} Hz, median of {repeats}, 1 BLAS thread")
    print(f"  before: {before_s:7.2f} s   ({len(before)} reductions)")
    print(f"  now:    {now_s:7.2f} s   (one per unique link, side by side in worker processes)")
    print(f"  now, in one process: {alone_s:7.2f} s")
    print(f"  speed-up {before_s / now_s:.2f}x ({before_s / alone_s:.2f}x in one process); "
          f"largest relative frequency difference {worst:.1e}")


def warm_links(repeats: int) -> None:
    """Loading the reference mount's reduced links: file as stored, the same compressed, from memory."""
    import shutil
    import tempfile
    from pathlib import Path

    import numpy as np

    from flexbodies.cache import BodyCache
    from flexbodies.link import reduce_link_set
    from flexbodies.reduced import load_reduced_body
    from workbook.model.reference import reference_case

    case = reference_case()
    frequencies_hz = sorted({e.frequency for e in case.excitations})
    folder = Path(tempfile.mkdtemp(prefix="bench-warm-"))
    for link in {link.model.key(): link for link in case.links}.values():
        reduce_link_set(link.model, link.modes, frequencies_hz, cache_dir=folder)
    files = sorted(folder.glob("link-*.npz"))
    compressed = []
    for path in files:
        with np.load(path) as data:
            arrays = {key: data[key] for key in data.files}
        target = folder / f"z{path.name}"
        np.savez_compressed(target, **arrays)
        compressed.append(target)
    store = BodyCache(folder)
    keys = [path.stem.split("-", 1)[1] for path in files]
    stored_s, _ = _timed(lambda: [load_reduced_body(path) for path in files], repeats)
    zipped_s, _ = _timed(lambda: [load_reduced_body(path) for path in compressed], repeats)
    for key in keys:
        store.load_body(key)
    memory_s, _ = _timed(lambda: [store.load_body(key) for key in keys], repeats)
    size = sum(p.stat().st_size for p in files) / 1e6
    size_z = sum(p.stat().st_size for p in compressed) / 1e6
    shutil.rmtree(folder)
    print(f"Loading the {len(files)} reduced links of the reference mount (both rotors), median of {repeats}")
    print(f"  uncompressed file (as stored): {stored_s:.3f} s, {size:.1f} MB")
    print(f"  compressed file (as before):   {zipped_s:.3f} s, {size_z:.1f} MB")
    print(f"  from the process's memory:     {memory_s:.4f} s")


def _cold_run(tree: str) -> tuple[float, float, str]:
    """Wall and CPU time (its processes' user and system time) of one cold ``mountwb run`` of the package
    in *tree*, s, and its isolation table."""
    import shutil
    import tempfile

    cache = tempfile.mkdtemp(prefix="bench-cold-")
    env = dict(os.environ, MOUNTWB_CACHE=cache, PYTHONPATH=tree)
    try:
        used, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
        output = subprocess.run([sys.executable, "-m", "workbook.cli.main", "run", "--no-progress"], check=True,
                                capture_output=True, text=True, env=env, cwd=tree).stdout
        wall, now = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = now.ru_utime + now.ru_stime - used.ru_utime - used.ru_stime
        return wall, cpu, output.split("Model card")[0]
    finally:
        shutil.rmtree(cache, ignore_errors=True)


def cold_runs(repeats: int, before: str | None) -> None:
    """The cold run of the reference mount, this tree and (``before``) a git revision, alternating."""
    import shutil
    import tempfile
    from pathlib import Path

    root = str(Path(__file__).resolve().parents[1])
    trees = {"now": root}
    if before is not None:
        folder = tempfile.mkdtemp(prefix="bench-before-")
        archive = subprocess.run(["git", "-C", root, "archive", before, "flexbodies", "workbook"], check=True,
                                 capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", folder], input=archive, check=True)
        trees = {f"before ({before})": folder, **trees}
    load = os.getloadavg()
    times: dict = {name: [] for name in trees}
    cpu: dict = {name: [] for name in trees}
    tables = {}
    try:
        for _ in range(repeats):
            for name, tree in trees.items():
                seconds, used, tables[name] = _cold_run(tree)
                times[name].append(seconds)
                cpu[name].append(used)
    finally:
        if before is not None:
            shutil.rmtree(trees[f"before ({before})"], ignore_errors=True)
    print(f"Cold `mountwb run` of the reference mount (empty cache, both rotors), median of {repeats}, "
          f"1 BLAS thread, {os.cpu_count()} cores; load average {load[0]:.2f} before, {os.getloadavg()[0]:.2f} after")
    print(f"  {'':24s} {'wall':>8s} {'CPU':>8s}   (wall of each run)")
    for name, values in times.items():
        print(f"  {name:24s} {statistics.median(values):6.2f} s {statistics.median(cpu[name]):6.2f} s   "
              f"({', '.join(f'{v:.2f}' for v in values)})")
    if before is not None:
        old, new = (statistics.median(values) for values in times.values())
        old_cpu, new_cpu = (statistics.median(values) for values in cpu.values())
        same = len(set(tables.values())) == 1
        print(f"  speed-up {old / new:.2f}x wall, {old_cpu / new_cpu:.2f}x CPU; isolation tables "
              f"{'identical' if same else 'DIFFER'}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=float, nargs="+", default=[14.0, 10.0, 7.0], help="element sizes, mm")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--exudyn", action="store_true", help="also time Exudyn's ComputeHurtyCraigBamptonModes")
    parser.add_argument("--reference", action="store_true",
                        help="cold reduction of the reference mount's links, before and now")
    parser.add_argument("--warm", action="store_true", help="loading the reference mount's reduced links")
    parser.add_argument("--cold", action="store_true", help="the whole cold `mountwb run` of the reference mount")
    parser.add_argument("--before", metavar="REV", help="with --cold: also time the package at git revision REV")
    parser.add_argument("--one", type=float, help=argparse.SUPPRESS)  # a single size, in this process
    args = parser.parse_args(argv)
    if args.warm:
        warm_links(args.repeats)
        return
    if args.cold:
        cold_runs(args.repeats, args.before)
        return
    if args.reference:
        reference_links(args.repeats)
        return
    if args.one is not None:
        print(json.dumps(measure(args.one, args.repeats, args.exudyn)))
        return
    import pandas as pd

    rows = []
    for size in args.sizes:
        command = [sys.executable, __file__, "--one", str(size), "--repeats", str(args.repeats)]
        if args.exudyn:
            command.append("--exudyn")
        output = subprocess.run(command, check=True, capture_output=True, text=True).stdout
        rows.append(json.loads(output.strip().splitlines()[-1]))
        print(f"  {size:g} mm done", file=sys.stderr)
    table = pd.DataFrame(rows).set_index("size [mm]")
    print(f"Reduction of the 0.30 m steel test link, median of {args.repeats} repeats, 1 BLAS thread")
    print(table.T.to_string(float_format=lambda v: f"{v:.3g}"))


if __name__ == "__main__":
    main()
