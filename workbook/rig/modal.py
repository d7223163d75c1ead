"""Modal correlation: the case's mounted modes against test modes.

**Test modes** come from a UFF file (pyuff): dataset 55 (data at nodes) of
analysis type 2 (normal modes: frequency, viscous damping ratio, real
shapes) or 3 (complex modes: ``f = |lambda| / 2 pi``,
``zeta = -Re(lambda) / |lambda|``, complex shapes), 3 translations per node
(data characteristic 2) or 3 translations and 3 rotations (6); and
dataset 15, the nodes' coordinates, read in m (the file's length unit must
be m: UFF 164 is not read). Every node of a shape must have coordinates.
:func:`write_uff_modes` writes such a file. Or the test modes are
identified from a record's H1 (:mod:`workbook.rig.frf`) by peak picking
(:func:`identify_peaks`): frequencies and half-power damping ratios,
without shapes, since a record holds forces at the transducers, not
motions at points.

**Simulated shapes at the test points.** A mounted mode is a rigid-body
mode of the engine on its mount (:mod:`workbook.solve.modes`); its shape is
the engine node's motion at the centre of gravity c, translation ``t`` (m)
and small rotations ``theta`` about x, y, z (rad). At a test point p on the
engine it is ``u(p) = t + theta x (p - c)``, and the rotation ``theta``
where the test measured rotations. The test points must be on the engine
(its mount fittings, the engine-side hinge positions, its centre of gravity).

**MAC and pairing.** ``MAC_ij = |a_i^H b_j|^2 / ((a_i^H a_i)(b_j^H b_j))``
(unweighted, over the test DOFs: 1 for proportional shapes, 0 for
orthogonal ones). Each test mode is paired with the simulated mode of the
largest MAC, greedily from the largest MAC down, each simulated mode used
once; without test shapes, by the nearest frequency. The frequency error is
``(sim - test) / test x 100 %``, as in the rig comparison.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from workbook.errors import RecordError
from workbook.model.case import DIRECTIONS

__all__ = ["MeasuredModes", "ModePairing", "mac", "read_uff_modes", "write_uff_modes", "shapes_at_points", "case_modes",
           "pair_modes", "identify_peaks", "plot_mac", "NORMAL_MODES", "COMPLEX_MODES"]

#: UFF 55 analysis types read: normal modes, complex eigenvalue modes.
NORMAL_MODES, COMPLEX_MODES = 2, 3
_TRANSLATIONS, _WITH_ROTATIONS = 2, 3     # UFF 55 data characteristic: 3 DOF, 6 DOF per node
_DOF_NAMES = (*DIRECTIONS, "rx", "ry", "rz")


@dataclass
class MeasuredModes:
    """Modes of a test.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (m,)
        Hz.
    damping_ratios : ndarray, shape (m,)
        Viscous damping ratio (NaN: not known).
    shapes : ndarray, shape (m, k), or None
        Shape of each mode at the test DOFs (m and rad, any common scale);
        None: frequencies only.
    dofs : list of (int, int)
        Node and DOF (0-2: x, y, z translation; 3-5: rotation about x, y, z) of each shape column.
    points : dict of int to ndarray, shape (3,)
        Node coordinates, m.
    source : str
        Where they came from.
    """

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    shapes: np.ndarray | None = None
    dofs: list = field(default_factory=list)
    points: dict = field(default_factory=dict)
    source: str = ""

    def dof_labels(self) -> list[str]:
        """``"node 3 y"`` per shape column."""
        return [f"node {node} {_DOF_NAMES[dof]}" for node, dof in self.dofs]


def mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion of every row of *a* against every row of *b*.

    Parameters
    ----------
    a : ndarray, shape (m, k) or (k,)
    b : ndarray, shape (n, k) or (k,)
        Real or complex shapes over the same k DOFs.

    Returns
    -------
    ndarray, shape (m, n)
        0 to 1.
    """
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    cross = np.abs(np.conj(a) @ b.T) ** 2
    return cross / np.outer(np.sum(np.abs(a) ** 2, axis=1), np.sum(np.abs(b) ** 2, axis=1))


def shapes_at_points(engine_shapes: np.ndarray, center: np.ndarray, points: dict, dofs: list) -> np.ndarray:
    """Rigid-engine mode shapes at the test DOFs: ``u(p) = t + theta x (p - c)``, theta at rotations.

    Parameters
    ----------
    engine_shapes : ndarray, shape (n, 6)
        Engine motion per mode at its centre of gravity: x, y, z (m), rotations about x, y, z (rad).
    center : ndarray, shape (3,)
        The engine's centre of gravity, m.
    points : dict of int to ndarray, shape (3,)
        Node coordinates, m.
    dofs : list of (int, int)
        Node and DOF (0-5) of each column.

    Returns
    -------
    ndarray, shape (n, len(dofs))
    """
    engine_shapes = np.atleast_2d(engine_shapes)
    columns = []
    for node, dof in dofs:
        if dof >= 3:
            columns.append(engine_shapes[:, dof])
            continue
        arm = np.asarray(points[node], dtype=float) - np.asarray(center, dtype=float)
        motion = engine_shapes[:, :3] + np.cross(engine_shapes[:, 3:], arm)
        columns.append(motion[:, dof])
    return np.column_stack(columns)


def read_uff_modes(path: str | Path) -> MeasuredModes:
    """Test modes of a UFF file: datasets 55 (shapes) and 15 (node coordinates, m); module docstring.

    Raises
    ------
    RecordError
        Not a UFF file, no dataset 55 of analysis type 2 or 3, modes over
        different nodes, or a node without coordinates, naming the dataset.
    """
    from workbook.rig.uff import read_uff_sets

    path = Path(path)
    sets = read_uff_sets(path, (15, 55))
    points = {int(n): np.array([x, y, z], dtype=float) for _, d in sets if d["type"] == 15
              for n, x, y, z in zip(d["node_nums"], d["x"], d["y"], d["z"], strict=True)}
    modal = [(i, d) for i, d in sets if d["type"] == 55 and int(d.get("analysis_type", 0)) in (NORMAL_MODES, COMPLEX_MODES)]
    if not modal:
        raise RecordError(path, "no dataset 55 of analysis type 2 (normal modes) or 3 (complex modes)")
    frequencies, damping, shapes = [], [], []
    dofs: list[tuple[int, int]] = []
    for index, dataset in modal:
        label = f"dataset {index + 1} (mode {dataset.get('mode_n')})"
        nodes = [int(n) for n in np.atleast_1d(dataset["node_nums"])]
        count = 6 if int(dataset["data_ch"]) == _WITH_ROTATIONS else 3
        here = [(node, dof) for node in nodes for dof in range(count)]
        if dofs and here != dofs:
            raise RecordError(path, f"{label}: other nodes or DOFs than the first mode's")
        dofs = here
        missing = [node for node in nodes if node not in points]
        if missing:
            raise RecordError(path, f"{label}: node {missing[0]} has no coordinates (dataset 15)")
        values = np.column_stack([np.atleast_1d(dataset[f"r{k + 1}"]) for k in range(count)])
        shapes.append(values.reshape(-1))
        if int(dataset["analysis_type"]) == COMPLEX_MODES:
            eigenvalue = complex(dataset["eig"])
            frequencies.append(abs(eigenvalue) / (2 * np.pi))
            damping.append(-eigenvalue.real / abs(eigenvalue))
        else:
            frequencies.append(float(dataset["freq"]))
            damping.append(float(dataset.get("modal_damp_vis", np.nan)))
    stacked = np.array(shapes)
    return MeasuredModes(np.array(frequencies), np.array(damping), stacked if np.iscomplexobj(stacked) else stacked.real,
                     dofs, {node: points[node] for node, _ in dofs}, str(path))


def write_uff_modes(path: str | Path, modes: MeasuredModes) -> Path:
    """Write *modes* as UFF datasets 15 (node coordinates, m) and 55 (normal modes, displacement).

    Every node must have 3 translations, or 3 translations and 3 rotations,
    in the order x, y, z (rx, ry, rz); real shapes.

    Returns
    -------
    Path
    """
    import pyuff

    assert modes.shapes is not None
    nodes = list(dict.fromkeys(node for node, _ in modes.dofs))
    count = len(modes.dofs) // len(nodes)
    coordinates = np.array([modes.points[node] for node in nodes])
    datasets = [pyuff.prepare_15(node_nums=np.array(nodes), def_cs=[0] * len(nodes), disp_cs=[0] * len(nodes),
                                 color=[1] * len(nodes), x=coordinates[:, 0], y=coordinates[:, 1], z=coordinates[:, 2])]
    for number, (frequency, zeta, shape) in enumerate(zip(modes.frequencies_hz, modes.damping_ratios, modes.shapes,
                                                         strict=True), start=1):
        values = np.real(shape).reshape(len(nodes), count)
        rows = {f"r{k + 1}": values[:, k] if k < count else np.zeros(len(nodes)) for k in range(6)}
        datasets.append(pyuff.prepare_55(
            id1=f"mode {number}", id2=modes.source or "NONE", model_type=1, analysis_type=NORMAL_MODES,
            data_ch=_WITH_ROTATIONS if count == 6 else _TRANSLATIONS, spec_data_type=8, data_type=2,
            n_data_per_node=count, load_case=1, mode_n=number, freq=float(frequency), modal_m=1.0,
            modal_damp_vis=0.0 if np.isnan(zeta) else float(zeta), modal_damp_his=0.0, node_nums=np.array(nodes),
            **rows))
    pyuff.UFF(str(path)).write_sets(datasets, mode="overwrite")
    return Path(path)


def case_modes(case, upper_hz: float) -> list:
    """The mounted modes of *case* (engine rigid-body modes on its mount) up to *upper_hz*.

    Parameters
    ----------
    case : Case
    upper_hz : float
        Highest frequency of interest (the links are reduced for it), Hz.

    Returns
    -------
    list of Mode
        Ascending (:func:`workbook.solve.modes.mounted_modes`).
    """
    from workbook.model.case import HarmonicForce
    from workbook.solve.modes import mounted_modes
    from workbook.solve.pipeline import prepare

    probe = HarmonicForce("modal probe", point=case.engine.center_of_mass, direction=(1.0, 0.0, 0.0),
                          amplitude=1.0, frequency_hz=float(upper_hz))
    prepared = prepare(case, probe)
    with prepared.scene:
        pass
    return [mode for mode in mounted_modes(prepared.modes) if mode.frequency_hz <= upper_hz]


@dataclass
class ModePairing:
    """Test modes paired with simulated ones.

    Attributes
    ----------
    test : MeasuredModes
    simulated_hz : ndarray, shape (n,)
        Simulated frequencies, Hz.
    mac : ndarray, shape (m, n) or None
        MAC of test mode i against simulated mode j (None without test shapes).
    pairs : list of (int, int)
        (test index, simulated index), by test mode.
    """

    test: MeasuredModes
    simulated_hz: np.ndarray
    mac: np.ndarray | None
    pairs: list

    def to_pandas(self):
        """The frequency error table: one row per paired test mode.

        Returns
        -------
        pandas.DataFrame
            Index: test mode (1-based); columns ``f test Hz``, ``sim mode``,
            ``f sim Hz``, ``error %`` ((sim - test) / test x 100), ``MAC``
            (NaN without shapes), ``zeta test %``.
        """
        import pandas as pd

        from workbook.answers.isolation import relative_error

        rows = []
        for i, j in self.pairs:
            rows.append((i + 1, self.test.frequencies_hz[i], j + 1, self.simulated_hz[j],
                         float(relative_error(np.array(self.simulated_hz[j]), np.array(self.test.frequencies_hz[i]))),
                         np.nan if self.mac is None else self.mac[i, j], 100 * self.test.damping_ratios[i]))
        frame = pd.DataFrame(rows, columns=["test mode", "f test Hz", "sim mode", "f sim Hz", "error %", "MAC",
                                            "zeta test %"])
        return frame.set_index("test mode")


def pair_modes(test: MeasuredModes, simulated_hz: np.ndarray, simulated_shapes: np.ndarray | None = None) -> ModePairing:
    """Pair test modes with simulated ones: by largest MAC, or by nearest frequency without shapes.

    Parameters
    ----------
    test : MeasuredModes
    simulated_hz : ndarray, shape (n,)
        Hz.
    simulated_shapes : ndarray, shape (n, k), optional
        Simulated shapes at the test DOFs (:func:`shapes_at_points`).

    Returns
    -------
    ModePairing
    """
    simulated_hz = np.asarray(simulated_hz, dtype=float)
    if test.shapes is not None and simulated_shapes is not None:
        matrix = mac(test.shapes, simulated_shapes)
        score = matrix.copy()
    else:
        matrix = None
        score = -np.abs(np.log(simulated_hz[None, :] / test.frequencies_hz[:, None]))
    pairs = []
    free = np.ones_like(score, dtype=bool)
    for _ in range(min(score.shape)):
        masked = np.where(free, score, -np.inf)
        i, j = np.unravel_index(int(np.argmax(masked)), score.shape)
        pairs.append((int(i), int(j)))
        free[i, :] = False
        free[:, j] = False
    return ModePairing(test, simulated_hz, matrix, sorted(pairs))


def identify_peaks(frf, low_hz: float, high_hz: float, *, min_coherence: float = 0.8,
                   prominence: float = 2.0) -> MeasuredModes:
    """Test-mode frequencies and damping by peak picking on the H1 of a record (module docstring).

    The peaks of ``S(f) = sum_d |H1_d(f)|`` over the directions excited, in
    ``[low_hz, high_hz]``, at least *prominence* times the smaller of their
    neighbouring minima and with a mean coherence of at least
    *min_coherence*; each peak's frequency is refined by a parabola through
    log S at its three bins, its damping ratio is the half-power bandwidth
    ``zeta = (f2 - f1) / (2 f)`` of S (NaN when the band ends first).

    Parameters
    ----------
    frf : RecordFRF
    low_hz, high_hz : float
        Hz.
    min_coherence : float
    prominence : float

    Returns
    -------
    MeasuredModes
        Without shapes.
    """
    from scipy.signal import find_peaks

    excited = ~np.isnan(frf.h1).all(axis=0)
    summed = np.nansum(np.abs(frf.h1[:, excited]), axis=1)
    coherence = frf.coherence[:, excited].mean(axis=1)
    inside = np.flatnonzero(frf.band(low_hz, high_hz))
    peaks, _ = find_peaks(np.log(np.maximum(summed[inside], 1e-300)), prominence=np.log(prominence))
    frequencies, damping = [], []
    step = frf.frequencies_hz[1] - frf.frequencies_hz[0]
    for peak in inside[peaks]:
        if coherence[peak] < min_coherence or peak == 0 or peak + 1 >= len(summed):
            continue
        left, centre, right = np.log(summed[peak - 1:peak + 2])
        offset = 0.5 * (left - right) / (left - 2 * centre + right)
        frequency = frf.frequencies_hz[peak] + offset * step
        half = summed[peak] / np.sqrt(2)
        below = np.flatnonzero(summed[:peak] < half)
        above = np.flatnonzero(summed[peak:] < half)
        if len(below) and len(above):
            f1 = np.interp(half, summed[below[-1]:below[-1] + 2], frf.frequencies_hz[below[-1]:below[-1] + 2])
            a = peak + above[0]
            f2 = np.interp(half, summed[a - 1:a + 1][::-1], frf.frequencies_hz[a - 1:a + 1][::-1])
            damping.append((f2 - f1) / (2 * frequency))
        else:
            damping.append(np.nan)
        frequencies.append(frequency)
    return MeasuredModes(np.array(frequencies), np.array(damping), None, [], {},
                     f"{frf.path or 'rig record'}: peaks of the H1")


def plot_mac(pairing: ModePairing):
    """The MAC matrix (test modes against simulated ones), paired cells outlined, frequencies on the axes.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    assert pairing.mac is not None
    figure = Figure(figsize=(1.2 + 0.7 * pairing.mac.shape[1], 1.4 + 0.6 * pairing.mac.shape[0]),
                    layout="constrained")
    axes = figure.add_subplot()
    image = axes.imshow(pairing.mac, vmin=0, vmax=1, cmap="Greys")
    for (i, j), value in np.ndenumerate(pairing.mac):
        axes.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize="small",
                  color="white" if value > 0.5 else "black")
    for i, j in pairing.pairs:
        axes.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, edgecolor="tab:red", lw=2))
    axes.set_xticks(range(len(pairing.simulated_hz)),
                    [f"{k + 1}\n{f:.2f}" for k, f in enumerate(pairing.simulated_hz)], fontsize="small")
    axes.set_yticks(range(len(pairing.test.frequencies_hz)),
                    [f"{k + 1}: {f:.2f}" for k, f in enumerate(pairing.test.frequencies_hz)], fontsize="small")
    axes.set(xlabel="simulated mode, Hz", ylabel="test mode, Hz", title="MAC (pairs outlined)")
    figure.colorbar(image, ax=axes, shrink=0.8)
    return figure
