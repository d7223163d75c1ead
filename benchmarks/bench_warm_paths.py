"""Warm paths: the wall time of the commands a user runs most, now and (optionally) before, side by side.

Measured, each the median of its repeats, every repeat a new process of
this source tree (``python -m workbook.cli.main``): the wall time, and the
CPU time (user and system) of that process with the processes it waited
for (a report's picture process), which the load of other work changes far
less than the wall time:

- ``mountwb run`` with the reduction cache filled (both rotors of the
  reference mount);
- ``mountwb run cases/reference.xlsx --report r.xlsx`` with the cache filled
  (both rotors and the 25-point sweep, written back into a fresh copy of the
  workbook, plus the report), the second run of the workbook;
- the same command again on that copy, which then holds the results of the
  first run (the rows of the earlier run read, its result sheets replaced);
- ``mountwb run`` with an empty cache (a new, empty cache folder each time:
  the three distinct links reduced side by side, one worker process per
  core; ``--cold-repeats 0``: not measured);
- which of pandas, pint, matplotlib, openpyxl, scikit-fem, meshio, gmsh and
  SciPy's ``linalg`` and ``sparse`` the warm ``mountwb run`` imports (none
  is needed).

The commands run with the BLAS thread counts of the environment the
benchmark is started in, as a user's ``mountwb`` would (the header says
``OPENBLAS_NUM_THREADS``); ``mountwb`` itself runs the BLAS on one thread.

``--before REV`` measures the source tree of the git revision REV the same
way, interleaved with this one (``git archive`` into a temporary folder), so
that a change of the machine's load hits both alike. Python caches the
compiled modules of both trees in a temporary folder (``PYTHONPYCACHEPREFIX``),
as an installed package has them, and a first run of each command fills it.

Measured on the shared 2-core machine of the project, ``OPENBLAS_NUM_THREADS=1``.
With ``python benchmarks/bench_warm_paths.py --before 6ec551f`` (6ec551f:
the code before the warm-path changes; load average 0.3 to 1.7 from other
work), medians of 5 (cold: 3)::

    | what                                                    | before  | now    | target |
    | warm `mountwb run`                                      | 1.45 s  | 1.00 s | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx` | 4.69 s  | 2.60 s | 2 s    |
    | cold `mountwb run` (empty cache)                        | 10.62 s | 9.85 s | 6 s    |
    | unneeded packages the warm run imports                  | meshio, pandas, skfem | none | none |

The cold path since (the reductions' changes), with ``--before 95f7844 --repeats 3
--cold-repeats 5`` (95f7844: before the residual mass shared by a link's
decisions and the nested-dissection ordering; load average 3.3 to 4 from
other work, so every time is longer than on the quieter machine above)::

    | what                                                    | before  | now     | target |
    | warm `mountwb run`                                      | 1.11 s  | 1.23 s  | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx` | 3.37 s  | 3.62 s  | 2 s    |
    | cold `mountwb run` (empty cache)                        | 18.90 s | 16.63 s | 6 s    |

The warm paths do not run the changed code (their difference is the load's).
The cold run stays above 6 s: it waits for the thrust rod (47k DOF), reduced
alone in one worker while the other reduces the front and rear links. Of the
thrust rod's 10.9 s (load about 3): 1.7 s factorisation, 2.7 s in the 64
single solves of three Lanczos runs (fixed-interface modes, 30 solves, the
fewest of the ``ncv`` tried; free-free, 21; mounted, 13), 1.7 s assembly,
1.2 s meshing, 1.5 s geometric stiffness, 0.55 s stress operator and shapes.

The warm paths since (only the
command's own module imported, the geometric stiffness projected once per
reduction, a workbook's result tables made once, a table's number cells
sharing their column's style, the checksum without copies; for the cold
run also the bores' meshes sharing their connectivity), with
``--before ca25197 --repeats 7 --cold-repeats 3`` (ca25197: before these
changes; load average 1.3 to 1.4, the machine otherwise quiet), wall time
and in brackets CPU time (all the run's processes)::

    | what                                                    | before                | now                   | target |
    | warm `mountwb run`                                      | 1.44 s (CPU 1.43 s)   | 1.33 s (CPU 1.32 s)   | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx` | 3.46 s (CPU 4.53 s)   | 3.59 s (CPU 4.58 s)   | 2 s    |
    | cold `mountwb run` (empty cache)                        | 12.20 s (CPU 18.02 s) | 10.89 s (CPU 16.61 s) | 6 s    |

The warm run takes 0.1 s less (the other commands' modules it no longer
imports), the workbook with its report the same within the noise; neither
meets its target. The cold run's CPU time, 16.6 s on two cores, bounds it
above 8 s whatever the layout of its processes. Where the warm run's time goes
(``python -X importtime`` and cProfile of one run, load about 2): imports
about 0.5 s, of which ``scipy.linalg`` 0.23 to 0.30 s (SciPy's array-API
layer copies NumPy's namespace, which imports ``numpy.f2py``, 0.09 to
0.12 s, and ``numpy.testing``, 0.03 s; every SciPy module the run needs
brings it) and Exudyn 0.05 s; under cProfile, for the two rotors, the four
cached reductions read and verified (36 MB) 0.14 s, the scene built four
times (before and after the stress stiffening) 0.17 s, the preload solved
and checked four times 0.24 s, the harmonic models' central differences
0.13 s (22,000 Exudyn output reads). The workbook
adds pandas and openpyxl (0.55 s of imports) and the hinge-force sheet
(13,000 cells, built and saved by openpyxl: most of the 1.4 s the results'
write takes under cProfile). Answering the two rotors in two processes (a
fork after the links are loaded) was tried and dropped: at a load average
of 4 it was slower (0.90 s against 0.84 s for the two rotors' run, medians
of 10 processes each).

The warm run without SciPy's linear algebra (the modes, the harmonic solve and
the pinned-pinned frequencies in NumPy, the links' projected geometric
stiffness read from the cache, SciPy imported only where a link is reduced),
with ``--before 5455b52 --repeats 7 --cold-repeats 1`` (load average 2.2 at
the start, 3.7 at the end)::

    | what                                                    | before                | now                   | target |
    | warm `mountwb run`                                      | 1.74 s (CPU 1.51 s)   | 1.44 s (CPU 1.07 s)   | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx` | 7.77 s (CPU 5.17 s)   | 4.92 s (CPU 4.67 s)   | 2 s    |
    | cold `mountwb run` (empty cache)                        | 32.65 s (CPU 20.53 s) | 31.57 s (CPU 20.93 s) | 6 s    |
    | SciPy subpackages the warm run imports                  | linalg, sparse        | none                  | none   |

The warm run's CPU time falls by 0.44 s (29 %); its wall time, at that load,
stays above the target. It still imports SciPy's top package (15 ms): Exudyn's
FEM module, which adds the flexible links, imports it to check that SciPy is
installed.

All of this release's warm-path changes together (the above; the cached
values read from a read-only workbook, only for the sheets read; an
earlier write's rows read from the stored cells), with ``--before 25730bd
--repeats 7 --cold-repeats 3`` (load average 1.0 at the start, 1.5 at the
end), including the run again on the workbook holding the first run's
results::

    | what                                                      | before                | now                   | target |
    | warm `mountwb run`                                        | 1.57 s (CPU 1.51 s)   | 1.14 s (CPU 1.10 s)   | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx`   | 3.72 s (CPU 4.79 s)   | 3.60 s (CPU 4.65 s)   | 2 s    |
    | the same again, on the workbook holding the first results | 4.69 s (CPU 5.77 s)   | 3.75 s (CPU 4.73 s)   | 2 s    |
    | cold `mountwb run` (empty cache)                          | 12.00 s (CPU 18.47 s) | 12.65 s (CPU 19.66 s) | 6 s    |

None of the four targets is met. The warm run's CPU time falls by 0.41 s
(27 %); the workbook run again by 1.04 s. The cold run's three repeats scatter
by seconds; its CPU time bounds it above 9 s on two cores. (These commands
ran with one BLAS thread, as this benchmark then set it.)

As a user runs them, without a thread count in the environment (``env -u
OPENBLAS_NUM_THREADS python benchmarks/bench_warm_paths.py --before 25730bd
--repeats 7 --cold-repeats 0``): ``mountwb`` before had set its one BLAS
thread after the command had loaded NumPy, too late, so OpenBLAS ran a thread
per core::

    | what                                                      | before                | now                  | target |
    | warm `mountwb run`                                        | 1.86 s (CPU 3.15 s)   | 0.99 s (CPU 0.99 s)  | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx`   | 5.84 s (CPU 9.86 s)   | 3.15 s (CPU 4.12 s)  | 2 s    |
    | the same again, on the workbook holding the first results | 6.40 s (CPU 10.43 s)  | 3.15 s (CPU 4.18 s)  | 2 s    |

(load average 1.0 at the start, 2.0 at the end). The warm run meets its
1 s target; the workbook with its report does not.

The cold run's reductions made cheaper (a link's three Lanczos runs side by
side in threads, their single solves made together as one block solve per
round; the stress operator beside the factorisation; the element stiffness
formed and summed in batches that stay in the processor's cache; the
reduction's modules imported once, before the workers' fork: measured so,
and taken back since, as the parent of a rigid run should not load them;
it saved 0.5 s of CPU time a worker and no wall time), with
``--before 1471351 --repeats 1 --cold-repeats 3`` (load average 3.6 to 4.5
from other work)::

    | what                             | before                | now                  | target |
    | cold `mountwb run` (empty cache) | 16.38 s (CPU 16.12 s) | 9.62 s (CPU 14.17 s) | 6 s    |

The CPU time falls by 12 % (per link, user and system time, least of 3 in
one process: thrust rod 8.50 to 7.78 s, front and rear links 2.43 and 2.24
to 2.19 and 2.06 s); at this load the wall time scatters by seconds. The
target stays out of reach: the thrust rod alone needs about 7 s of CPU
time one step after the other (meshing 0.6 s, assembly 0.55 s,
factorisation and static modes 2.4 s, the three Lanczos runs 2.1 s, the
reductions 0.9 s).

The case workbook without pandas (its result tables plain rows, the printed
summary laid out as pandas lays it out), each report picture drawn as soon as
its run is done, the garbage collector run seldom while the workbook is read,
run and written, with ``env -u OPENBLAS_NUM_THREADS python
benchmarks/bench_warm_paths.py --before 1471351 --repeats 5 --cold-repeats 0``
(load average 2.5 at the start, 2.0 at the end)::

    | what                                                      | before              | now                 | target |
    | warm `mountwb run`                                        | 0.87 s (CPU 0.87 s) | 0.94 s (CPU 0.93 s) | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx`   | 2.98 s (CPU 3.99 s) | 2.45 s (CPU 3.42 s) | 2 s    |
    | the same again, on the workbook holding the first results | 3.27 s (CPU 4.23 s) | 2.65 s (CPU 3.26 s) | 2 s    |

The workbook's runs take 0.5 to 0.6 s less; at this load they stay above
2 s. Of the command's own CPU time (about 2 s): imports 0.45 s, the three
runs 0.8 s (their three scenes prepared, 0.63 s), the results written 0.34 s
(openpyxl's save of the hinge sheet most of it), the report 0.07 s; the
interpreter's exit adds 0.2 s of wall time.

The two together, as a user runs them, with ``env -u OPENBLAS_NUM_THREADS
python benchmarks/bench_warm_paths.py --before 1471351 --repeats 5
--cold-repeats 3`` on a quieter machine (load average 1.1 at the start, 1.6
at the end)::

    | what                                                      | before                | now                   | target |
    | warm `mountwb run`                                        | 0.73 s (CPU 0.73 s)   | 0.72 s (CPU 0.72 s)   | 1 s    |
    | warm `mountwb run cases/reference.xlsx --report r.xlsx`   | 2.21 s (CPU 2.98 s)   | 1.63 s (CPU 2.28 s)   | 2 s    |
    | the same again, on the workbook holding the first results | 2.46 s (CPU 3.20 s)   | 1.91 s (CPU 2.64 s)   | 2 s    |
    | cold `mountwb run` (empty cache)                          | 8.95 s (CPU 13.86 s)  | 8.55 s (CPU 12.97 s)  | 6 s    |

The workbook with its report meets its target, also run again on its
results; the cold run does not (measured with the reduction's modules
imported before the fork, taken back since: about 1 s more CPU time for
the two workers).

The thrust rod's critical path shortened (the nested-dissection graph made
from the matrix's own arrays, 0.70 to 0.30 s; the mounted eigenproblem
without the bordered stiffness Lanczos never reads; the unit tension's
geometric stiffness beside the eigen-solves; the decisions' reductions and
the residual flexibility's block solve side by side in threads; Exudyn
imported by the parent on the core the first idle worker leaves), the
reductions' results equal bit for bit, with ``env -u OPENBLAS_NUM_THREADS
python benchmarks/bench_warm_paths.py --before 25ca568 --repeats 1
--cold-repeats 5`` (load average 0.0 at the start, 2.1 at the end, the
benchmark's own)::

    | what                             | before                | now                  | target |
    | cold `mountwb run` (empty cache) | 10.57 s (CPU 16.54 s) | 9.81 s (CPU 16.18 s) | 6 s    |

The target stays out of reach: the thrust rod alone, one step after the
other, needs about 7.5 s (meshing 0.75 s, assembly 0.6 to 1.1 s,
factorisation and static modes 2.2 s, of which SuperLU's 1.6 s, the three
Lanczos runs 2.3 s in 30 block-solve rounds), while the other worker is
done with the front and rear links after about 5 s. A Cholesky
factorisation would halve it (CHOLMOD: 0.49 s against 2.15 s for the
ordering and SuperLU's LU), but no permissively licensed wheel of one
beats SuperLU here.

Run from the repository's root::

    python benchmarks/bench_warm_paths.py [--repeats 5] [--cold-repeats 3] [--before REV]
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Packages the warm ``mountwb run`` of the reference mount has no use for.
NOT_NEEDED = ("pandas", "pint", "matplotlib", "openpyxl", "skfem", "meshio", "gmsh", "scipy.linalg", "scipy.sparse")

_PROBE = """
import sys
from workbook.cli.main import main
code = main(sys.argv[1:])
print("MODULES " + " ".join(sorted(m for m in {not_needed!r} if m in sys.modules)))
sys.exit(code)
"""


def _environment(tree: Path, cache: Path, pycache: Path) -> dict:
    # the BLAS threads as the user's environment sets them (mountwb sets them itself)
    env = dict(os.environ, MOUNTWB_CACHE=str(cache), PYTHONPATH=str(tree), PYTHONPYCACHEPREFIX=str(pycache))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _cpu_of_children() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _command(tree: Path, args: list[str], cache: Path, pycache: Path, cwd: Path) -> tuple[float, float]:
    """Wall time and CPU time (user and system, with the processes it waited for) of one ``mountwb ARGS``
    process of the source tree *tree*, s."""
    start, cpu = time.perf_counter(), _cpu_of_children()
    subprocess.run([sys.executable, "-m", "workbook.cli.main", *args, "--no-progress"], check=True, cwd=cwd,
                   env=_environment(tree, cache, pycache), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start, _cpu_of_children() - cpu


def _imported(tree: Path, cache: Path, pycache: Path, cwd: Path) -> list[str]:
    """The packages of :data:`NOT_NEEDED` a warm ``mountwb run`` of *tree* imports."""
    done = subprocess.run([sys.executable, "-c", _PROBE.format(not_needed=NOT_NEEDED), "run", "--no-progress"],
                          check=True, cwd=cwd, env=_environment(tree, cache, pycache), capture_output=True, text=True)
    return done.stdout.rpartition("MODULES")[2].split()


def _workbook_run(tree: Path, cache: Path, pycache: Path, folder: Path, label: str) -> list[tuple[float, float]]:
    """The workbook with its report run on a fresh copy of the reference workbook, then again on that copy (which
    then holds the results of the first run): the times of both."""
    copy = folder / f"reference-{label}.xlsx"
    shutil.copy(ROOT / "cases" / "reference.xlsx", copy)
    report = folder / f"report-{label}.xlsx"
    report.unlink(missing_ok=True)
    return [_command(tree, ["run", str(copy), "--report", str(report)], cache, pycache, folder) for _ in range(2)]


def measure(trees: dict[str, Path], repeats: int, cold_repeats: int, folder: Path) -> dict:
    """Median wall and CPU times per tree: warm run, warm workbook with report, cold run; and the warm run's imports."""
    pycache = folder / "pycache"
    caches = {name: folder / f"cache-{name}" for name in trees}
    times: dict[str, dict[str, list[tuple[float, float]]]] = {
        name: {"warm": [], "report": [], "again": [], "cold": []} for name in trees}
    for name, tree in trees.items():   # fill the caches and the compiled modules; the first workbook run
        _command(tree, ["run"], caches[name], pycache, folder)
        _workbook_run(tree, caches[name], pycache, folder, f"{name}-first")
    for i in range(repeats):           # interleaved: a change of the machine's load hits every tree alike
        for name, tree in trees.items():
            times[name]["warm"].append(_command(tree, ["run"], caches[name], pycache, folder))
            first, again = _workbook_run(tree, caches[name], pycache, folder, f"{name}-{i}")
            times[name]["report"].append(first)
            times[name]["again"].append(again)
    for i in range(cold_repeats):
        for name, tree in trees.items():
            empty = folder / f"cold-{name}-{i}"
            times[name]["cold"].append(_command(tree, ["run"], empty, pycache, folder))
            shutil.rmtree(empty, ignore_errors=True)
    return {name: {**{what: (statistics.median(wall for wall, _ in values), statistics.median(cpu for _, cpu in values))
                      for what, values in times[name].items() if values},
                   "imports": _imported(trees[name], caches[name], pycache, folder)} for name in trees}


def source_tree(revision: str, folder: Path) -> Path:
    """The files of git revision *revision* of this repository, unpacked into *folder*."""
    folder.mkdir()
    archive = subprocess.run(["git", "archive", revision], cwd=ROOT, check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="repeats of the warm commands")
    parser.add_argument("--cold-repeats", type=int, default=3, help="repeats of the cold run (0: not measured)")
    parser.add_argument("--before", metavar="REV", help="also measure the source tree of this git revision")
    args = parser.parse_args(argv)
    folder = Path(tempfile.mkdtemp(prefix="bench-warm-"))
    try:
        trees = {"now": ROOT}
        if args.before:
            trees = {"before": source_tree(args.before, folder / "before"), **trees}
        results = measure(trees, args.repeats, args.cold_repeats, folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    load = os.getloadavg()[0]
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "unset")
    print(f"Reference mount, medians of new processes (wall, CPU), OPENBLAS_NUM_THREADS {threads}, "
          f"{os.cpu_count()} cores, load average {load:.1f} at the end (targets: an idle machine)")
    names = list(results)
    print("| what | " + " | ".join(names) + " | target | met (now) |")
    print("|---|" + "---|" * len(names) + "---|---|")
    rows = [("warm `mountwb run`", "warm", args.repeats, 1.0),
            ("warm `mountwb run cases/reference.xlsx --report r.xlsx` (second run)", "report", args.repeats, 2.0),
            ("the same again, on the workbook holding the results of the first", "again", args.repeats, 2.0),
            ("cold `mountwb run` (empty cache)", "cold", args.cold_repeats, 6.0)]
    for what, key, repeats, target in rows:
        if not repeats:
            continue
        values = " | ".join(f"{results[name][key][0]:.2f} s (CPU {results[name][key][1]:.2f} s)" for name in names)
        met = "yes" if results["now"][key][0] <= target else "no"
        print(f"| {what}, {repeats} repeats | {values} | <= {target:g} s | {met} |")
    imports = " | ".join(", ".join(results[name]["imports"]) or "none" for name in names)
    print(f"| packages of {', '.join(NOT_NEEDED)} the warm run imports | {imports} | none | "
          f"{'yes' if not results['now']['imports'] else 'no'} |")


if __name__ == "__main__":
    main()
