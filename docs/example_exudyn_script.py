"""For Exudyn users: build the reference mount, extend it, run it yourself.

`workbook.scene.build.build_scene` returns the Exudyn system (`scene.mbs`) with
the item numbers of every body, marker, hinge connector and force sensor.
This script adds its own items - a sensor on the engine's centre of gravity
and a 2 kN lateral gust on the engine - solves the preload with the package's
checks, integrates the HP rotor case with its own Exudyn settings and reads
the hinge-force sensors. Run::

    python docs/example_exudyn_script.py
"""
import exudyn as exu
import numpy as np
from exudyn.itemInterface import LoadForceVector, MarkerBodyPosition, SensorNode

from workbook.answers.amplitude import harmonic_amplitude, period_window
from workbook.model.reference import HP_ROTOR, reference_case
from workbook.scene.build import build_scene
from workbook.solve.preload import solve_preload

case = reference_case()
scene = build_scene(case, HP_ROTOR)        # flexible links, hinges, sensors, loads, HP excitation
mbs = scene.mbs
print("engine node", scene.engine.node, "body", scene.engine.body)
print("link front-left: body", scene.links["front-left"].body, "eye markers",
      scene.links["front-left"].marker_a, scene.links["front-left"].marker_b)
print("hinge front-up-left: connector", scene.hinges["front-up-left"].connector,
      "sensor", scene.hinges["front-up-left"].sensor)

# --- your own items -------------------------------------------------------
cg_sensor = mbs.AddSensor(SensorNode(nodeNumber=scene.engine.node, storeInternal=True, writeToFile=False,
                                     outputVariableType=exu.OutputVariableType.Displacement))
gust_point = mbs.AddMarker(MarkerBodyPosition(bodyNumber=scene.engine.body, localPosition=[0.0, 0.0, 0.0]))
mbs.AddLoad(LoadForceVector(markerNumber=gust_point, loadVector=[0.0, 2000.0, 0.0]))
mbs.Assemble()

# --- preload: mechanism check, static solve (excitation paused), equilibrium check
preload = solve_preload(scene)
print("static pylon force with the gust:", np.round(preload.pylon_force, 1), "N")

# --- dynamics with your own settings ---------------------------------------
frequency = HP_ROTOR.frequency
steps_per_period, periods = 40, 400
settings = exu.SimulationSettings()
settings.solution.file.write = False
settings.solution.sensors.writePeriod = 1 / (frequency * steps_per_period)
settings.timeIntegration.numberOfSteps = steps_per_period * periods
settings.timeIntegration.endTime = periods / frequency
settings.timeIntegration.verboseMode = 0
settings.timeIntegration.newton.useModifiedNewton = True
settings.timeIntegration.newton.absoluteTolerance = 1e-6 * scene.load_scale
mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.GeneralizedAlpha)

# --- read the sensors ------------------------------------------------------
data = mbs.GetSensorStoredData(scene.hinges["front-up-left"].sensor)
time, force = data[:, 0], data[:, 1:]
window = period_window(time, frequency, 20)
amplitude = np.abs(harmonic_amplitude(time[window], force[window], frequency))
print("front-up-left force amplitude at", frequency, "Hz:", np.round(amplitude, 2), "N")
cg = mbs.GetSensorStoredData(cg_sensor)[:, 1:]
print("engine CG vibration amplitude:",
      np.round(1e6 * np.abs(harmonic_amplitude(time[window], cg[window], frequency)), 3), "micrometre")
