"""Stress recovery after the reduction: the wall time of turning modal coordinates into link stresses.

The reference mount's eight links, reduced (from the cache), each given
modal coordinates (the values do not change the work). Measured, each the
median of its repeats:

- the recovery itself: each link's preload stress field and its von Mises
  stress, and the complex stress amplitude of each of the two rotors;
- one load case: :func:`workbook.solve.load_cases.link_stress` of all eight
  links (stress field, regions, von Mises and largest principal stress at
  every node, the peaks and the margins);
- both rotors' fatigue: for each of the two excitations and each link, the
  complex stress amplitude (:func:`flexbodies.stress.state_stress`) and
  :func:`workbook.solve.fatigue.link_fatigue` (alternating and mean
  equivalent stress at every node, Goodman and Gerber factors);
- the parts of one load case over all links: the stress fields alone, the
  regions, the von Mises and the largest principal stresses.

Target: all links and both rotors after the reduction in 0.1 s
or less. Before (the closed-form principal stress, the regions made once
per mesh and the complex state in one real product) and after, one run of
each source tree back to back on the shared 2-core machine, load average
7.5 from other work, ``OPENBLAS_NUM_THREADS=1``, medians of 21 (8 links,
70930 FE nodes, 6 to 11 modes)::

    | what                                                              | before   | after    |
    | recovery: the preload's and both rotors' stress fields, all links | 121.9 ms | 62.0 ms  |
    | one load case, all links                                          | 394.1 ms | 48.0 ms  |
    | both rotors' fatigue, all links                                   | 248.9 ms | 162.2 ms |
    |   regions, all links                                              | 29.5 ms  | 0.0 ms   |
    |   largest principal, all links                                    | 260.5 ms | 28.7 ms  |

The recovery and a load case are within the target; the fatigue evaluation
(the factors at every node, the preload's stress recomputed per excitation)
is not yet, on this loaded machine.

Run from the repository's root::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_stress.py [--repeats 21]
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from flexbodies.stress import link_regions, max_principal, state_stress, von_mises
from workbook.model.reference import reference_case
from workbook.scene.build import reduce_links
from workbook.solve.fatigue import link_fatigue
from workbook.solve.load_cases import link_stress


def _median(function, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=21)
    args = parser.parse_args()
    case = reference_case()
    reduced = reduce_links(case)
    links = [link for link in case.links if link.flexible]
    rng = np.random.default_rng(0)
    mean = {link.name: rng.standard_normal(reduced[link.name].n_modes) for link in links}
    phasors = [{link.name: rng.standard_normal(reduced[link.name].n_modes)
                + 1j * rng.standard_normal(reduced[link.name].n_modes) for link in links} for _ in range(2)]
    rotation = np.eye(3)

    def load_case():
        for link in links:
            link_stress(link, reduced[link.name], mean[link.name], 1e4, rotation, 1.5)

    def fatigue():
        for rotor in phasors:
            for link in links:
                body = reduced[link.name]
                link_fatigue(link, body, mean[link.name], state_stress(body, rotor[link.name]), rotation)

    def recovery():
        for link in links:
            body = reduced[link.name]
            von_mises(state_stress(body, mean[link.name]))
            for rotor in phasors:
                state_stress(body, rotor[link.name])

    fields = {link.name: state_stress(reduced[link.name], mean[link.name]) for link in links}
    parts = {
        "stress fields (S q)": lambda: [state_stress(reduced[link.name], mean[link.name]) for link in links],
        "regions": lambda: [link_regions(reduced[link.name]) for link in links],
        "von Mises": lambda: [von_mises(fields[name]) for name in fields],
        "largest principal": lambda: [max_principal(fields[name]) for name in fields],
    }
    nodes = sum(int(reduced[link.name].master_nodes[0]) for link in links)
    modes = sorted({reduced[link.name].n_modes for link in links})
    print(f"{len(links)} links, {nodes} FE nodes in all, {modes[0]} to {modes[-1]} modes; "
          f"medians of {args.repeats}; load average {open('/proc/loadavg').read().split()[0]}")
    print("| what | median |")
    print("|---|---|")
    rows = [("recovery: the preload's and both rotors' stress fields, all links", recovery),
            ("one load case, all links", load_case), ("both rotors' fatigue, all links", fatigue)]
    rows += [(f"  {name}, all links", function) for name, function in parts.items()]
    for name, function in rows:
        print(f"| {name} | {_median(function, args.repeats) * 1e3:.1f} ms |")


if __name__ == "__main__":
    main()
