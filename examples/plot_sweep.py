"""
A frequency sweep of the transmissibility
=========================================

A rotating force of 1000 N at the engine's centre of gravity, stepped through
40 log-spaced frequencies from 5 to 300 Hz
(:func:`~workbook.model.reference.reference_sweep`), on the reference mount
with its flexible links. :func:`~workbook.solve.sweep.run_sweep` linearises
the scene once and solves every frequency in the frequency domain; the answer
holds T per direction of the pylon force and the mounted modes in the band.
"""

import workbook as wb

sweep = wb.reference_sweep(points=40)
answer = wb.run_sweep(wb.reference_case(), sweep)

# %%
# The mounted modes in the band: the engine's six rigid-body modes on its
# links, and any link mode below 300 Hz.

print(answer.modes.to_pandas()[["kind", "frequency Hz", "damping ratio %", "engine share %"]].round(2))

# %%
# T of the pylon force per direction, every fifth frequency:

print(answer.to_pandas().iloc[::5].round(5))

# %%
# The curves, log-log, with the modes marked (mounted modes dashed, link modes
# dotted):

fig = answer.plot()
