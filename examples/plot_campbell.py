"""
A Campbell diagram of the mounted engine
========================================

The reference mount with its two spools as gyroscopic rotors
(``reference_case(rotors=True)``), links rigid to keep the example quick.
:func:`~workbook.solve.campbell.campbell` prepares the scene once, then
solves the modes at 200 speeds of the LP spool (the HP spool turning in
proportion, as on the engine's operating line), follows each mode by its
shape and refines every crossing with a once-per-revolution line on the
eigenproblem itself.
"""

import workbook as wb

case = wb.reference_case(rotors=True).with_rigid_links()
diagram = wb.campbell(case, points=200, operating_rpm=(2400, 3900))

# %%
# The critical speeds: a mode on the 1x line of a spool. The forward-whirl
# modes are the ones an imbalance drives most.

print(diagram.crossings_frame()[["rotor", "speed rpm", "rotor rpm", "frequency Hz", "whirl", "zeta %"]].round(2))

# %%
# What the answer cost and left out: the speeds were solved on the
# non-rotating modes up to four times the top frequency, checked against the
# full model at the top speed.

print(diagram.truncation)
print({stage: round(seconds, 2) for stage, seconds in diagram.timings.items()})

# %%
# The diagram, the LP spool's operating range shaded:

fig = diagram.plot()
