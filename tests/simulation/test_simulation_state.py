"""The state of the time loop extends itself with the elements and connections of a
growth pass (hmatddm.simulation.state), and round-trips through a checkpoint's arrays."""
import numpy as np

import hmatddm as hd
from hmatddm.coupled.contact import OPEN, STICK
from hmatddm.simulation.state import Connection, NewElements, Origin, State, StepStart


def _state():
    mesh = hd.mesh.line([-1.5, 0.0], [1.5, 0.0], 3)  # normals (0, +-1)
    dd = np.array([[0.0, 1.0], [0.0, 2.0], [0.0, 3.0]]) * 1e-3
    return State(mesh, dd, np.array([10.0, 20.0, 30.0]), np.zeros(3), 4.0, 4, 0.5, 1.0, 0.1,
                 origin=np.zeros(3, np.int64), natural_index=-np.ones(3, np.int64), intact=np.ones(4, bool),
                 failed=np.zeros(4, bool), extra_faces=np.zeros((0, 6)))


def _new():
    """A hydraulic element grown from element 2, an activated natural element (natural
    index 1) reached from element 0, and a remotely failed one (natural index 3)."""
    mesh = hd.mesh.concatenate([hd.mesh.line([1.5, 0.0], [2.5, 0.0], 1), hd.mesh.line([0, 1], [1, 2], 1),
                                hd.mesh.line([5, 5], [6, 5], 1)])
    return NewElements(mesh, np.array([2, 0, -1]), np.array([Origin.HYDRAULIC, Origin.ACTIVATED, Origin.FAILED]),
                       np.array([-1, 1, 3]), np.array([np.nan, np.nan, 7.0]))


def test_new_elements_start_from_their_parent_or_open_or_closed():
    state, new = _state(), _new()
    guess = new.first_guess(state.dd, minimum_width=1e-5)
    assert np.array_equal(guess[0], state.dd[2])
    assert np.allclose(guess[1], 1e-5 * new.mesh.normals[1]) and np.linalg.norm(guess[1]) > 0
    assert np.array_equal(guess[2], [0.0, 0.0])
    grown = state.joined(new, guess, creation_time=4.0)
    assert grown.mesh.n_elements == 6 and np.array_equal(grown.dd[3:], guess)
    assert np.array_equal(grown.pressure, [10.0, 20.0, 30.0, 30.0, 10.0, 7.0])
    assert np.array_equal(grown.creation_time, [0, 0, 0, 4, 4, 4])
    assert list(grown.origin) == [0, 0, 0, 0, 1, 2] and list(grown.natural_index) == [-1, -1, -1, -1, 1, 3]
    assert list(grown.intact) == [True, False, True, False]
    assert list(grown.contact_status) == [OPEN] * 5 + [STICK]
    assert np.array_equal(np.isnan(grown.failure_pressure), [True] * 5 + [False]) and grown.failure_pressure[5] == 7.0
    assert grown.slip_direction.shape == (6, 2) and not np.any(grown.slip_direction)
    # the state it grew from is untouched
    assert state.mesh.n_elements == 3 and state.intact.all()


def test_the_start_of_the_step_grows_with_zero_opening_and_the_old_pressure():
    state, new = _state(), _new()
    start = StepStart.of(state)
    assert np.allclose(start.width, np.sum(state.dd * state.mesh.normals, axis=1))
    state.pressure[:] = -1.0  # the iterate moved on; the start keeps p^n
    guess = new.first_guess(state.dd, 1e-5)
    grown = start.joined(new, guess)
    assert np.array_equal(grown.width[3:], [0.0, 0.0, 0.0])
    assert np.array_equal(grown.pressure, [10.0, 20.0, 30.0, 30.0, 10.0, 7.0])
    assert np.array_equal(grown.dd[3:], guess)


def test_connections_number_new_targets_after_the_mesh():
    state = _state()
    to_old = Connection(0, 2, False, 1.0, 0.5, 0.25, 1)
    to_new = Connection(1, 0, True, 1.0, 0.5, 0.25, 0).shifted(2)
    assert to_old.shifted(2) is to_old and to_new.target == 2
    faces = state.connected([to_old, to_new], first_new=3).extra_faces
    assert np.array_equal(faces, [[0, 2, 1.0, 0.5, 0.25, 1], [1, 5, 1.0, 0.5, 0.25, 0]])
    assert state.connected([], 3) is state


def test_copy_is_deep_and_checkpoint_arrays_round_trip():
    state = _state()
    copy = state.copy()
    copy.dd[0, 1] = 99.0
    copy.intact[0] = False
    assert state.dd[0, 1] == 1e-3 and state.intact[0]
    mesh3d = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 1.0, 2, 1)
    for s in (state, State(mesh3d, np.ones((2, 3)), np.ones(2), np.zeros(2), 1.0, 1, 1.0, 0.0, 0.0,
                           origin=np.zeros(2, np.int64), natural_index=-np.ones(2, np.int64),
                           intact=np.zeros(0, bool), failed=np.zeros(0, bool), extra_faces=np.zeros((0, 6)),
                           front_distance=np.array([0.5, np.nan]), front_velocity=np.array([1.0, np.nan]),
                           front_class=np.array([1, 0]))):
        back = State.from_checkpoint(s.arrays(), s.scalars())
        assert type(back.mesh) is type(s.mesh)
        assert np.array_equal(back.mesh.centers, s.mesh.centers)
        for name in ("dd", "pressure", "origin", "intact", "extra_faces", "contact_status", "front_class"):
            a, b = getattr(s, name), getattr(back, name)
            assert (a is None and b is None) or np.array_equal(a, b)
        assert back.scalars() == s.scalars()
