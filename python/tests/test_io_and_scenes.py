"""Files (XYZ, LAMMPS data, trajectories, SVG, contacts, checkpoints) and the
scenes beyond simple shear: jamming with its certificate, walls, bonds,
pressure control, oscillatory shear, self-propulsion, gravity, soft-core."""

import numpy as np
import pytest

import odhs


def scene(n=32, dim=2, seed=1, phi=0.45):
    s = odhs.System(dim, n)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    s.place_random(phi, seed + 1)
    return s


def test_xyz_and_lammps_round_trips(tmp_path):
    s = scene(dim=3, phi=0.3)
    with odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("auto")) as st:
        st.run_until_strain(0.125)  # a sheared cell
    assert s.strain == pytest.approx(0.125)
    s.set_species(0, "Big")
    p = str(tmp_path / "s.xyz")
    s.write_xyz(p)
    for c in (odhs.read_xyz(p), odhs.parse_xyz(open(p).read()), odhs.System.read_xyz(p, frame=-1)):
        assert np.array_equal(c.positions, s.positions) and np.array_equal(c.radii, s.radii)
        assert c.strain == s.strain and c.species == s.species
    d = str(tmp_path / "s.data")
    odhs.write_lammps_data(s, d)
    c = odhs.read_lammps_data(d)
    assert np.array_equal(c.radii, s.radii) and c.strain == s.strain
    np.testing.assert_allclose(c.positions, s.positions, rtol=0, atol=1e-12 * s.box.max())
    c2 = odhs.parse_lammps_data(open(d).read())
    assert np.array_equal(c2.positions, c.positions)


def test_trajectory_frames_read_back(tmp_path):
    s = scene()
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("auto"))
    path = str(tmp_path / "run.xyz")
    frames = []
    with odhs.Trajectory(path) as tr, odhs.Trajectory(str(tmp_path / "c.dump"), "lammps_local") as tc:
        assert tr.format == odhs.TrajFormat.XYZ
        st.reset()
        for g in (0.0, 0.05, 0.1):
            st.run_until_strain(g) if g else None
            tr.write(s, st)
            tc.write(s, st)
            frames.append(s.positions)
        assert tr.frames == 3
    assert tr.closed
    assert odhs.count_xyz_frames(path) == 3
    for k, x in enumerate(frames):
        assert np.array_equal(odhs.read_xyz(path, frame=k).positions, x)
    assert odhs.traj_format_for("a.lammpstrj") == odhs.TrajFormat.LAMMPS_DUMP
    text = open(str(tmp_path / "c.dump")).read()
    assert text.count("ITEM: ENTRIES") == 3


def test_svg_and_contacts_csv(tmp_path):
    s = scene(phi=0.5)
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("auto"))
    st.run_until_strain(0.2)
    svg = tmp_path / "f.svg"
    st.write_svg(str(svg))
    assert svg.read_text().lstrip().startswith(("<?xml", "<svg"))
    odhs.write_svg(str(tmp_path / "plain.svg"), s)
    csv = str(tmp_path / "c.csv")
    st.write_contacts_csv(csv)
    st.write_contacts(str(tmp_path / "c.txt"))
    data = np.genfromtxt(csv, delimiter=",", names=True)
    c = st.contacts()
    assert np.array_equal(data["i"].astype(np.uintp), c.i) and np.array_equal(data["force"], c.force)


def test_checkpoint_continues_bit_identically(tmp_path):
    solver = odhs.Solver("dense")  # stateless: bit-identical restarts
    s = scene(seed=3)
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), solver)
    st.run_until_strain(0.1)
    ck = str(tmp_path / "run.ckpt")
    st.write_checkpoint(ck)
    st.run_until_strain(0.3)
    for st2 in (odhs.read_checkpoint(ck, solver), odhs.parse_checkpoint(open(ck, "rb").read(), solver)):
        assert st2.strain == pytest.approx(0.1) and st2.driver.shear_rate == 1.0
        st2.run_until_strain(0.3)
        assert np.array_equal(st2.system.positions, s.positions)
        assert st2.counts == st.counts


def test_checkpoint_of_a_force_callback_run(tmp_path):
    s = scene()
    d = odhs.Driver()
    d.set_force_callback(lambda t, sy: np.tile([1.0, 0.0], (sy.n, 1)) * np.where(np.arange(sy.n) % 2, 1, -1)[:, None])
    st = odhs.Stepper(s, d, odhs.Solver("dense"))
    st.run_until_time(0.2)
    ck = str(tmp_path / "f.ckpt")
    st.write_checkpoint(ck)
    st2 = odhs.read_checkpoint(ck, odhs.Solver("dense"))
    with pytest.raises(odhs.StateError):
        st2.step()  # the callback is code: set it again
    st2.driver.set_force_callback(d.force_callback)
    st2.run_until_time(0.4)
    st.run_until_time(0.4)
    assert np.array_equal(st2.system.positions, s.positions)


def test_jamming_certificate():
    s = scene(n=24, seed=2, phi=0.5)
    st = odhs.Stepper(s, odhs.Driver(compression_rate=1.0), odhs.Solver("auto"))
    assert st.run_until_packing_fraction(0.999) == odhs.Status.JAMMED
    c = st.certificate()
    assert c.jammed and c.isostatic and c.min_force > 0 and c.force_balance < 1e-10
    assert c.n_contacts_backbone == c.n_contacts_isostatic
    net = st.network
    assert net.potentially_jammed
    rattlers = net.rattlers()
    assert rattlers.sum() == c.n_rattlers
    f0, res = net.null_vector()
    assert res < 1e-8 and f0.shape == (net.count,)


def test_pressure_oscillation_propulsion_gravity():
    s = scene(n=24, phi=0.5)
    d = odhs.Driver(shear_rate=1.0, pressure=5.0)
    assert d.pressure == 5.0
    st = odhs.Stepper(s, d, odhs.Solver("auto"))
    st.run_until_strain(0.1)
    assert st.feature_work(odhs.Feature.PRESSURE) > 0 and st.kappa != 0
    d.pressure = None
    assert d.pressure is None
    d.set_oscillatory_shear(0.05, 1.0, "triangle")
    assert d.oscillatory_shear.shape == odhs.Oscillation.TRIANGLE
    st.run_until_time(st.time + 0.5)
    d2 = odhs.Driver()
    d2.set_self_propulsion(s.n, 2, 0.5, 1.0, 0.5, 1.5, 7)
    pr = d2.propulsion()
    assert pr.forces.shape == (s.n, 2) and pr.switch_times is None
    st2 = odhs.Stepper(s.clone(), d2, odhs.Solver("auto"))
    st2.run_until_time(0.5)
    assert d2.propulsion().switch_times.shape == (s.n,)
    np.testing.assert_allclose(st2.external_forces(), d2.propulsion().forces)
    d3 = odhs.Driver()
    d3.set_gravity([0.0, -1.0])
    d3.set_gravity_weights(np.ones(s.n))
    st3 = odhs.Stepper(s.clone(), d3, odhs.Solver("auto"))
    st3.reset()
    np.testing.assert_allclose(st3.external_forces()[:, 1], -1.0)


def test_walls_and_bonds():
    s = odhs.System(2, 2)
    s.set_configuration([10.0, 10.0], 0.0, [0.5, 0.5], [[5.0, 2.0], [5.0, 4.0]])
    d = odhs.Driver()
    d.set_gravity([0.0, -1.0])
    st = odhs.Stepper(s, d, odhs.Solver("dense"))
    w = st.add_wall_plane([0.0, 1.0], 1.0)
    assert w == 0 and st.wall_count == 1
    st.add_bond(0, 1)
    assert st.bond_count == 1
    st.run_until_time(20.0)
    # the dimer rests on the wall, which carries its weight
    np.testing.assert_allclose(st.wall_force(w), [0.0, -2.0], atol=1e-9)
    c = st.contacts()
    assert odhs.ContactKind.WALL in c.kind and odhs.ContactKind.PERMANENT in c.kind
    assert np.all(st.wall_displacement(w) == 0)


def test_softcore_runs():
    s = scene(n=32, phi=0.45)
    sc = odhs.Softcore(s, model="RD0", shear_rate=1e-3)
    sc.scale_box(0.74)  # phi 0.82: overlaps (System.scale_box would refuse them)
    assert sc.max_overlap > 0
    it = sc.minimise()
    assert it > 0 and sc.max_force < 1e-8
    sc.run_until_strain(0.01)
    assert sc.strain == pytest.approx(0.01)
    assert sc.stress().shape == (2, 2) and sc.forces().shape == (32, 2)
    assert sc.counts.steps > 0 and sc.energy >= 0
    sc.set_minimiser("fire")
    sc.quasistatic_step(1e-3)
    assert sc.coordination(rattler_free=True) >= 0
