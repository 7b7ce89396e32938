"""Bad input on every handle raises the exception of the library's status,
carrying the status, its name and the handle's (or odhs_last_error's, or the
reader's) message."""

import math

import numpy as np
import pytest

import odhs


def scene(n=32, dim=2, seed=1, phi=0.4):
    s = odhs.System(dim, n)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    s.place_random(phi, seed + 1)
    return s


def check(excinfo, cls, status, *words):
    e = excinfo.value
    assert type(e) is cls
    assert isinstance(e, odhs.Error)
    assert e.status == status == cls.status_code
    assert e.status_name == odhs.Status(status).c_name
    assert e.description == odhs.strerror(status)
    for w in words:
        assert w in e.message, (w, e.message)
    assert e.status_name in str(e)


# --- status table ------------------------------------------------------------------


def test_every_error_status_has_its_class():
    for s in odhs.Status:
        if s < 0:
            cls = odhs.error_class(s)
            assert cls is not odhs.Error and cls.status_code == s
            assert odhs.strerror(s) and odhs.status_name(s) == "ODHS_" + s.name
    assert odhs.error_class(-999) is odhs.Error
    assert odhs.status_name(-999) == "ODHS_-999"


def test_python_exception_bases():
    assert issubclass(odhs.InvalidError, ValueError)
    assert issubclass(odhs.RangeError, IndexError)
    assert issubclass(odhs.FileError, OSError)
    assert issubclass(odhs.NoMemoryError, MemoryError)
    assert issubclass(odhs.StateError, RuntimeError)


# --- System ------------------------------------------------------------------------


def test_system_create_errors():
    with pytest.raises(odhs.DimensionError) as e:
        odhs.System(4, 10)
    check(e, odhs.DimensionError, -4)
    assert e.value.message == odhs.last_error() != ""
    with pytest.raises(odhs.EmptyError) as e:
        odhs.System(2, 0)
    check(e, odhs.EmptyError, -9)
    odhs.System(2, 1).close()
    assert odhs.last_error() == ""  # cleared by a successful create


def test_system_setter_errors():
    s = scene()
    r = s.radii
    bad = r.copy()
    bad[3] = -1.0
    with pytest.raises(odhs.InvalidError) as e:
        s.radii = bad
    check(e, odhs.InvalidError, -2)
    bad[3] = math.nan
    with pytest.raises(odhs.NonFiniteError) as e:
        s.radii = bad
    check(e, odhs.NonFiniteError, -6)
    x = s.positions
    x[1] = x[0]
    with pytest.raises(odhs.OverlapError) as e:
        s.positions = x
    check(e, odhs.OverlapError, -7)
    assert "0" in e.value.message and "1" in e.value.message  # names the pair
    assert np.array_equal(s.radii, r)  # nothing changed
    with pytest.raises(odhs.BoxError) as e:
        s.box = [1.0, 1.0]
    check(e, odhs.BoxError, -8)
    with pytest.raises(odhs.InvalidError):
        s.scale_box(-1.0)
    with pytest.raises(odhs.RangeError) as e:
        s.separation(0, 999)
    check(e, odhs.RangeError, -5)
    with pytest.raises(odhs.RangeError):
        s.get_species(999)
    with pytest.raises(odhs.InvalidError):
        s.set_species(0, "has space")
    with pytest.raises(ValueError):  # wrong size: refused before the C call
        s.positions = np.zeros((3, 2))


def test_system_state_errors():
    s = odhs.System(2, 8)
    with pytest.raises(odhs.StateError) as e:
        s.radii
    check(e, odhs.StateError, -12)
    with pytest.raises(odhs.StateError):
        s.positions
    s.set_radii_bidisperse(0.5, 1.4, 0.0, 1)
    with pytest.raises(odhs.TooDenseError) as e:
        s.place_random(0.95, 1)
    check(e, odhs.TooDenseError, -19)


def test_files_errors(tmp_path):
    with pytest.raises(odhs.FileError) as e:
        odhs.read_xyz(str(tmp_path / "missing.xyz"))
    check(e, odhs.FileError, -10, "missing.xyz")
    with pytest.raises(odhs.FormatError) as e:
        odhs.parse_xyz("3\nnot a lattice\nA 0 0 0 1\n")
    check(e, odhs.FormatError, -11)
    assert "line" in e.value.message
    with pytest.raises(odhs.FormatError):
        odhs.parse_lammps_data("nonsense\n\n3 atoms\n")
    s = odhs.System(2, 4)
    with pytest.raises(odhs.StateError):
        s.write_xyz(str(tmp_path / "x.xyz"))
    with pytest.raises(odhs.FileError):
        scene().write_xyz(str(tmp_path / "no" / "such" / "dir.xyz"))
    with pytest.raises(odhs.InvalidError):
        odhs.Trajectory(str(tmp_path / "t.txt"))
    with pytest.raises(odhs.FileError):
        odhs.Trajectory(str(tmp_path / "no" / "t.xyz"))
    with pytest.raises(odhs.RangeError):
        p = str(tmp_path / "one.xyz")
        scene().write_xyz(p)
        odhs.read_xyz(p, frame=5)


# --- Driver ------------------------------------------------------------------------


def test_driver_errors():
    d = odhs.Driver()
    with pytest.raises(odhs.InvalidError) as e:
        d.mobility = 0.0
    check(e, odhs.InvalidError, -2, "")
    assert d.errmsg == e.value.message
    with pytest.raises(odhs.NonFiniteError):
        d.shear_rate = math.inf
    with pytest.raises(odhs.InvalidError):
        d.pressure = -1.0
    with pytest.raises(odhs.InvalidError):
        d.set_oscillatory_shear(0.1, 1.0, shape=7)
    with pytest.raises(ValueError):
        d.set_oscillatory_shear(0.1, 1.0, shape="square")
    with pytest.raises(odhs.DimensionError):
        d.set_forces(np.zeros((4, 5)))
    with pytest.raises(odhs.StateError):
        d.propulsion()
    with pytest.raises(odhs.StateError):
        d.next_switch()
    with pytest.raises(TypeError):
        odhs.Driver(no_such_setting=1)
    with pytest.raises(TypeError):
        d.set_force_callback(42)


# --- Solver ------------------------------------------------------------------------


def test_solver_errors():
    with pytest.raises(odhs.InvalidError) as e:
        odhs.Solver("no-such-solver")
    check(e, odhs.InvalidError, -2, "no-such-solver", "cg", "dense")
    names = [s.name for s in odhs.available_solvers()]
    assert names[0] == "auto" and "cg" in names and "dense" in names
    for info in odhs.available_solvers():
        if info.installed:
            odhs.Solver(info.name).close()
        else:
            with pytest.raises(odhs.NotInstalledError):
                odhs.Solver(info.name)
    s = odhs.Solver("cg")
    with pytest.raises(odhs.InvalidError) as e:
        s.set_param("no_such_parameter", 1.0)
    assert e.value.message == s.errmsg != ""
    with pytest.raises(odhs.InvalidError):
        s.get_stat("no_such_stat")
    with pytest.raises(odhs.InvalidError):
        s.fallback = s  # a cycle
    with pytest.raises(TypeError):
        odhs.Solver(odhs.SolverBackend)  # the class, not an instance
    with pytest.raises(TypeError):
        odhs.Solver(odhs.SolverBackend())  # no solve


# --- Stepper -----------------------------------------------------------------------


def test_stepper_create_error_uses_last_error():
    s = odhs.System(2, 8)  # not ready
    with pytest.raises(odhs.StateError) as e:
        odhs.Stepper(s, odhs.Driver(), odhs.Solver("dense"))
    check(e, odhs.StateError, -12)
    assert e.value.message and e.value.message == odhs.last_error()
    with pytest.raises(TypeError):
        odhs.Stepper(s, None, None)


def test_stepper_errors():
    s = scene()
    st = odhs.Stepper(s, odhs.Driver(), odhs.Solver("dense"))
    with pytest.raises(odhs.StateError) as e:
        st.shear_stress  # no state before reset
    check(e, odhs.StateError, -12)
    with pytest.raises(odhs.InvalidError) as e:
        st.dt = -1.0
    check(e, odhs.InvalidError, -2, "dt")
    with pytest.raises(odhs.InvalidError):
        st.tolerance = 2.0
    with pytest.raises(odhs.InvalidError):
        st.integrator = 9
    with pytest.raises(ValueError):
        st.integrator = "runge-kutta"
    with pytest.raises(odhs.StateError, match="shear rate"):
        st.run_until_strain(0.1)  # no shear rate
    with pytest.raises(odhs.StalledError) as e:
        st.run_events(1)  # an empty driver: no event can ever happen
    check(e, odhs.StalledError, -21)
    with pytest.raises(odhs.RangeError):
        st.wall_force(3)
    with pytest.raises(odhs.RangeError):
        st.add_bond(0, 10**6)
    with pytest.raises(odhs.InvalidError):
        st.feature_work(99)
    # a change behind the stepper's back
    st.reset()
    s.scale_box(1.01)
    with pytest.raises(odhs.StateError):
        st.step()
    st.reset()
    st.step()


def test_run_limits_status():
    s = scene()
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("auto"))
    st.set_run_limits(max_steps=5)
    assert st.run_limits == (5, 1000)
    assert st.run_until_strain(1.0) == odhs.Status.STEP_LIMIT
    assert st.counts.steps == 5
    st.run_limits = (0, 0)
    assert st.run_limits.max_steps == 0


# --- Network, Softcore, checkpoints ------------------------------------------------


def test_network_errors():
    s = scene()
    net = odhs.Network(s)
    with pytest.raises(odhs.InvalidError) as e:
        net.add(2, 2)
    check(e, odhs.InvalidError, -2)
    assert e.value.message == net.errmsg
    with pytest.raises(odhs.RangeError):
        net.add(0, 999)
    with pytest.raises(odhs.InvalidError):
        net.remove(0, 1)
    with pytest.raises(odhs.RangeError):
        net.contact(0)
    with pytest.raises(odhs.StateError):
        net.null_vector()
    net.add(0, 1)
    with pytest.raises(odhs.InvalidError):
        net.add(0, 1)  # already present
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("dense"))
    st.reset()
    with pytest.raises(ValueError, match="read-only"):
        st.network.clear()


def test_softcore_errors():
    with pytest.raises(odhs.StateError) as e:
        odhs.Softcore(odhs.System(2, 8))
    check(e, odhs.StateError, -12)
    sc = odhs.Softcore(scene())
    with pytest.raises(odhs.InvalidError):
        sc.model = 42
    with pytest.raises(odhs.InvalidError):
        sc.set_potential(0.5, 1.0)
    with pytest.raises(odhs.InvalidError):
        sc.run_until_strain(1.0)  # shear rate 0
    with pytest.raises(odhs.StateError):
        sc.relaxation_stress()


def test_checkpoint_errors(tmp_path):
    solver = odhs.Solver("dense")
    with pytest.raises(odhs.FileError):
        odhs.read_checkpoint(str(tmp_path / "none.ckpt"), solver)
    with pytest.raises(odhs.FormatError) as e:
        odhs.parse_checkpoint(b"ODHSCKPT garbage", solver)
    assert e.value.message
    st = odhs.Stepper(scene(), odhs.Driver(), solver)
    with pytest.raises(odhs.StateError):
        st.write_checkpoint(str(tmp_path / "x.ckpt"))  # never reset


def test_closed_objects_refuse():
    s = scene()
    s.close()
    assert s.closed
    with pytest.raises(ValueError, match="closed"):
        s.positions
    s.close()  # twice is harmless
    d = odhs.Driver()
    with d:
        pass
    with pytest.raises(ValueError, match="closed"):
        d.shear_rate = 1.0
    with pytest.raises(ValueError):
        with d:
            pass
