"""Per-hinge answers against frequency: the force amplitude and T of a hinge or a hinge group.

``--hinges front`` selects every hinge whose name starts with ``front``; an
exact hinge name selects that hinge; ``pylon`` (when no hinge is named so)
selects the pylon-side force channels, whose complex sum is the pylon force.
T of a hinge is its force amplitude over the excitation amplitude, per
direction, as the pylon's T is.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.errors import InputError
from workbook.model.case import DIRECTIONS

__all__ = ["HingeCurves", "hinge_curves", "select_hinges", "PYLON_GROUP"]

#: The selection of the pylon-side force channels.
PYLON_GROUP = "pylon"


def select_hinges(names, selection: str, pylon=(), option: str = "hinge selection") -> list[str]:
    """The hinges a selection names: the hinge of that name, or those whose name starts with it.

    Parameters
    ----------
    names : sequence of str
        Every force channel, in order.
    selection : str
        A hinge name, a prefix (``front``) or ``pylon``.
    pylon : sequence of str
        The pylon-side channels (what ``pylon`` selects).
    option : str
        What gave the selection (a command-line option), named in the error.

    Raises
    ------
    InputError
        Nothing matches; the message lists the hinges.
    """
    names = list(names)
    if selection in names:
        return [selection]
    if selection == PYLON_GROUP and pylon:
        return [name for name in names if name in set(pylon)]
    chosen = [name for name in names if name.startswith(selection)] if selection else []
    if not chosen:
        raise InputError(f"{option} {selection!r}: expected a hinge name, the start of hinge names or "
                         f"{PYLON_GROUP!r}; hinges: {', '.join(names)}")
    return chosen


@dataclass(frozen=True)
class HingeCurves:
    """Force amplitude and T of chosen hinges at the frequencies of some runs.

    Attributes
    ----------
    selection : str
    runs : tuple of str
    frequencies_hz : ndarray, shape (f,)
    hinges : tuple of str
    amplitudes : ndarray, shape (f, h, 3)
        Force amplitude per hinge and direction, N.
    excitation : ndarray, shape (f,)
        Excitation amplitude, N.
    phasors : ndarray, complex, shape (f, h, 3), or None
        Complex amplitudes (frequency-domain runs), N.
    """

    selection: str
    runs: tuple
    frequencies_hz: np.ndarray
    hinges: tuple
    amplitudes: np.ndarray
    excitation: np.ndarray
    phasors: np.ndarray | None

    def transmissibility(self) -> np.ndarray:
        """T per hinge and direction, shape (f, h, 3)."""
        return self.amplitudes / self.excitation[:, None, None]   # as isolation.transmissibility, per run

    def group_force(self) -> np.ndarray:
        """The complex sum of the selected hinges' forces, shape (f, 3), N (frequency-domain runs only)."""
        if self.phasors is None:
            raise InputError(f"the force of hinges {self.selection!r} together: expected frequency-domain runs (a "
                             f"time-domain run keeps amplitudes, not phases)")
        return self.phasors.sum(axis=1)

    def to_pandas(self):
        """The table: one row per run; columns (hinge, quantity, direction): ``|F| N`` and ``T``.

        Returns
        -------
        pandas.DataFrame
            Indexed by (run, frequency Hz).
        """
        import pandas as pd

        columns = pd.MultiIndex.from_product([self.hinges, ["|F| N", "T"], list(DIRECTIONS)],
                                             names=["hinge", "quantity", "direction"])
        values = np.stack([self.amplitudes, self.transmissibility()], axis=2).reshape(len(self.runs), -1)
        index = pd.MultiIndex.from_arrays([list(self.runs), self.frequencies_hz], names=["run", "frequency Hz"])
        return pd.DataFrame(values, index=index, columns=columns)

    def to_text(self, model: str = "") -> str:
        """The table per hinge as text (*model*: words after the selection in the heading)."""
        table = self.to_pandas()
        parts = [f"hinges {self.selection!r}{model}: force amplitude |F| (N) and T = |F| / |F_exc| per direction"]
        for hinge in self.hinges:
            part = table[hinge]
            part.columns = [f"{quantity} {axis}" for quantity, axis in part.columns]
            parts.append(f"{hinge}:\n{part.to_string(float_format=lambda v: f'{v:10.4g}')}")
        return "\n\n".join(parts)

    def plot(self, compare: HingeCurves | None = None, labels=("", "")):
        """T of each hinge against frequency, one panel per direction (log axes for a range of frequencies).

        Parameters
        ----------
        compare : HingeCurves, optional
            The same hinges of another model, overlaid dashed in the same colours.
        labels : (str, str)
            Appended to the hinge names of this model and of *compare* in the legend.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True, sharex=True)
        order = np.argsort(self.frequencies_hz)
        f = self.frequencies_hz[order]
        T = self.transmissibility()[order]
        spread = len(f) > 1 and f[-1] > 2 * f[0]
        other = None if compare is None else compare.transmissibility()[np.argsort(compare.frequencies_hz)]
        for i, axis in enumerate(DIRECTIONS):
            for h, hinge in enumerate(self.hinges):
                line, = axes[i].plot(f, np.maximum(T[:, h, i], 1e-12), "-" if len(f) > 1 else "o", lw=1.0,
                                     label=f"{hinge} {labels[0]}".strip())
                if other is not None:
                    axes[i].plot(f, np.maximum(other[:, h, i], 1e-12), "--" if len(f) > 1 else "x", lw=1.0,
                                 color=line.get_color(), label=f"{hinge} {labels[1]}".strip())
            if spread:
                axes[i].set_xscale("log")
            axes[i].set_yscale("log")
            axes[i].set_xlabel("frequency Hz")
            axes[i].set_title(f"T {axis}")
        axes[0].set_ylabel("hinge force / excitation")
        axes[0].legend(fontsize="small")
        fig.suptitle(f"hinges {self.selection!r}: transmissibility against frequency")
        return fig


def hinge_curves(result, selection: str, runs=None) -> HingeCurves:
    """The curves of the hinges *selection* names over the runs of a result.

    Parameters
    ----------
    result : MountResult
    selection : str
        See :func:`select_hinges`.
    runs : sequence of ExcitationResult, optional
        Default every run of *result*.

    Returns
    -------
    HingeCurves
    """
    runs = list(result.runs if runs is None else runs)
    first = runs[0]
    hinges = select_hinges(list(first.hinge_amplitudes), selection, first.pylon_hinges)
    amplitudes = np.array([[run.hinge_amplitudes[h] for h in hinges] for run in runs], dtype=float)
    phasors = None
    if all(run.hinge_phasors for run in runs):
        phasors = np.array([[run.hinge_phasors[h] for h in hinges] for run in runs], dtype=complex)
    return HingeCurves(selection, tuple(run.name for run in runs),
                       np.array([run.frequency_hz for run in runs], dtype=float), tuple(hinges), amplitudes,
                       np.array([run.excitation_amplitude for run in runs], dtype=float), phasors)
