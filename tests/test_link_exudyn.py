"""The reduced test link inside Exudyn: static pull, linearised frequencies, plain-script export."""
import exudyn as exu
import numpy as np
import pytest
import scipy.linalg as sla
from test_reduction import TEST_LINK

from flexbodies import STEEL, LinkModel, add_link_to_exudyn, export_exudyn_file, reduce_link
from flexbodies.eigen import factorize, free_dofs
from flexbodies.link import build_fe_model
from flexbodies.reduction import couple

eii = exu.itemInterface

#: An arbitrary, skew placement: nothing may depend on the link being axis-aligned.
END_A = np.array([0.1, 0.2, 0.3])
DIRECTION = np.array([1.0, 1.0, 0.5]) / np.linalg.norm([1.0, 1.0, 0.5])


@pytest.fixture(scope="module")
def link_12_modes(cache_dir):
    return reduce_link(LinkModel(geometry=TEST_LINK, material=STEEL), 12, cache_dir=cache_dir)


@pytest.fixture(scope="module")
def link_static(cache_dir):
    return reduce_link(LinkModel(geometry=TEST_LINK, material=STEEL), "static", cache_dir=cache_dir)


def _pinned_axial_stiffness():
    """Full FE: eye A pinned, eye B held sideways, spin held; axial stiffness in N/m."""
    fe, _ = build_fe_model(LinkModel(geometry=TEST_LINK, material=STEEL))
    c = couple(fe, "RBE2")
    a, b = c.coupling.master_dofs
    keep = free_dofs(c.coupling.n_q, [a[0], a[1], a[2], a[3], b[1], b[2]])
    load = np.zeros(len(keep))
    position = int(np.searchsorted(keep, b[0]))
    load[position] = 1.0
    return 1.0 / factorize(c.stiffness[keep][:, keep]).solve(load)[position]


def _static_settings():
    ss = exu.SimulationSettings()
    ss.solution.file.write = False
    ss.staticSolver.newton.absoluteTolerance = 1e-6
    return ss


@pytest.mark.slow
@pytest.mark.parametrize("fixture", ["link_static", "link_12_modes"])
def test_static_pull_in_exudyn_matches_fe_stiffness(request, fixture):
    link = request.getfixturevalue(fixture)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    end_b = END_A + link.length * DIRECTION
    item = add_link_to_exudyn(mbs, link, END_A, end_b, name="test-link")
    ground = mbs.AddObject(eii.ObjectGround())
    at_a = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=ground, localPosition=list(END_A)))
    mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(markerNumbers=[at_a, item.marker_a], stiffness=[1e10] * 3))
    sideways = np.linalg.svd(DIRECTION[None, :])[2][1:]  # two unit vectors across the link
    for e in sideways:
        anchor = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=ground, localPosition=list(end_b + e)))
        mbs.AddObject(eii.ObjectConnectorSpringDamper(markerNumbers=[anchor, item.marker_b], stiffness=1e10, referenceLength=1.0))
    force = 1e5
    mbs.AddLoad(eii.LoadForceVector(markerNumber=item.marker_b, loadVector=list(force * DIRECTION)))
    sensors = [
        mbs.AddSensor(eii.SensorMarker(markerNumber=m, outputVariableType=exu.OutputVariableType.Position, storeInternal=True))
        for m in (item.marker_a, item.marker_b)
    ]
    mbs.Assemble()
    assert mbs.SolveStatic(_static_settings())
    stretch = (mbs.GetSensorValues(sensors[1]) - mbs.GetSensorValues(sensors[0])) @ DIRECTION - link.length
    assert force / stretch == pytest.approx(_pinned_axial_stiffness(), rel=0.005)


def test_linearised_frequencies_in_exudyn_equal_craig_bampton(link_12_modes):
    link = link_12_modes
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    item = add_link_to_exudyn(mbs, link, END_A, END_A + link.length * DIRECTION, spin_frequency_hz=1.0)
    mbs.Assemble()
    M, K = mbs.ComputeLinearizedSystem(_static_settings(), projectIntoConstraintNullspace=True)[:2]
    freqs = np.sqrt(np.abs(sla.eigh(K, M, eigvals_only=True))) / (2 * np.pi)
    assert np.sum(freqs < 1e-2) == 5, "five free rigid-body motions"
    assert freqs[5] == pytest.approx(1.0, rel=1e-3), "the spin restraint adds one mode at its frequency"
    expected = link.frequencies["reduced_hz"]
    assert freqs[6:] == pytest.approx(expected, rel=0.005)
    assert item.dof == 6 + link.n_modes == 6 + 6 + 12



@pytest.mark.parametrize("ratio", [0.0, 0.03])
def test_a_modal_damping_ratio_damps_every_elastic_mode_by_that_ratio(link_12_modes, ratio):
    """The free link (spin restraint at 1 Hz): every elastic mode of its
    linearisation has the damping ratio asked for, at its undamped frequency."""
    link = link_12_modes
    mbs = exu.SystemContainer().AddSystem()
    add_link_to_exudyn(mbs, link, END_A, END_A + link.length * DIRECTION, spin_frequency_hz=1.0,
                       modal_damping_ratio=ratio)
    mbs.Assemble()
    M, K, D = mbs.ComputeLinearizedSystem(_static_settings(), projectIntoConstraintNullspace=True)[:3]
    n = M.shape[0]
    state = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])
    roots = np.linalg.eigvals(state)
    elastic = roots[(np.abs(roots) > 2 * np.pi * 10.0) & (roots.imag > 0)]
    elastic = elastic[np.argsort(np.abs(elastic))]
    assert np.abs(elastic) / (2 * np.pi) == pytest.approx(link.frequencies["reduced_hz"], rel=0.005)
    np.testing.assert_allclose(-elastic.real / np.abs(elastic), ratio, atol=1e-6)

def _swing_frequencies(link, flexible):
    """Link pinned at eye A, eye B on soft sideways springs: the two swing frequencies, Hz."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    end_b = END_A + link.length * DIRECTION
    item = add_link_to_exudyn(mbs, link, END_A, end_b, flexible=flexible, spin_frequency_hz=0.1)
    ground = mbs.AddObject(eii.ObjectGround())
    at_a = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=ground, localPosition=list(END_A)))
    mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(markerNumbers=[at_a, item.marker_a], stiffness=[1e10] * 3))
    for e in np.linalg.svd(DIRECTION[None, :])[2][1:]:
        anchor = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=ground, localPosition=list(end_b + e)))
        mbs.AddObject(eii.ObjectConnectorSpringDamper(markerNumbers=[anchor, item.marker_b], stiffness=SIDE_SPRING, referenceLength=1.0))
    mbs.Assemble()
    M, K = mbs.ComputeLinearizedSystem(_static_settings(), projectIntoConstraintNullspace=True)[:2]
    freqs = np.sqrt(np.abs(sla.eigh(K, M, eigvals_only=True))) / (2 * np.pi)
    return freqs[(freqs > 1.0) & (freqs < 100.0)]


#: Sideways spring at eye B, N/m: soft enough that the link stays rigid in comparison.
SIDE_SPRING = 1e4


def test_rigid_and_flexible_links_swing_as_their_inertia_says(link_static):
    inertia = link_static.inertia_at_origin  # about eye A, link frame
    expected = np.sort(np.sqrt(SIDE_SPRING * link_static.length**2 / np.array([inertia[2, 2], inertia[1, 1]])) / (2 * np.pi))
    rigid = _swing_frequencies(link_static, flexible=False)
    flexible = _swing_frequencies(link_static, flexible=True)
    assert rigid == pytest.approx(expected, rel=1e-3)
    assert flexible == pytest.approx(rigid, rel=1e-3)


def test_link_end_points_must_match_its_length(link_static):
    SC = exu.SystemContainer()
    with pytest.raises(ValueError, match="apart"):
        add_link_to_exudyn(SC.AddSystem(), link_static, END_A, END_A + 0.31 * DIRECTION)


def test_exported_file_runs_in_a_plain_exudyn_script(link_static, tmp_path):
    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    path = export_exudyn_file(link_static, tmp_path / "link")
    cms = ObjectFFRFreducedOrderInterface()
    cms.LoadFromFile(str(path))
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    cms.AddObjectFFRFreducedOrder(mbs, positionRef=[0, 0, 0])
    mbs.Assemble()
    assert mbs.systemData.ODE2Size() == 7 + link_static.n_modes
    assert cms.totalMass == pytest.approx(link_static.mass)
