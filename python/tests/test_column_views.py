# positions, velocities, radii and sphere_ids are NumPy arrays over the engine's own columns:
# taken once, they show every step (the reorder keeps each column in its buffer,
# engine/sphere_table.h), nothing is copied per read, they are read-only, and they keep the
# Simulation alive. A call that could move a column is refused while one lives.
import gc

import numpy as np
import pytest

import ballpit

SMALL_POUR = ["populations.0.count=300"]


def data_pointer(a):
    return a.__array_interface__["data"][0]


@pytest.fixture
def sim():
    s = ballpit.Simulation.from_scene("pour", SMALL_POUR)
    s.step(2)  # past the first step, which builds the pipeline
    return s


def test_the_arrays_have_the_columns_shapes_and_types(sim):
    n = sim.sphere_count
    assert n == 300
    assert sim.positions.shape == (n, 3) and sim.positions.dtype == np.float32
    assert sim.velocities.shape == (n, 3) and sim.velocities.dtype == np.float32
    assert sim.radii.shape == (n,) and sim.radii.dtype == np.float32
    assert sim.sphere_ids.shape == (n,) and sim.sphere_ids.dtype == np.uint32
    # Rows are a permutation of the spheres; every radius is the scene's 0.04 m.
    assert sorted(sim.sphere_ids.tolist()) == list(range(n))
    assert np.all(sim.radii == np.float32(0.04))


def test_a_step_changes_an_array_taken_before_it_without_a_new_read(sim):
    positions, velocities, ids = sim.positions, sim.velocities, sim.sphere_ids
    before = positions.copy(), velocities.copy()
    address = data_pointer(positions), data_pointer(velocities), data_pointer(ids)
    sim.step(5)
    # The same memory: the engine's column did not move ...
    assert (data_pointer(positions), data_pointer(velocities), data_pointer(ids)) == address
    assert data_pointer(sim.positions) == address[0]
    assert np.shares_memory(positions, sim.positions)
    # ... and the old arrays hold the new state: falling balls moved and sped up.
    assert not np.array_equal(positions, before[0])
    assert not np.array_equal(velocities, before[1])
    np.testing.assert_array_equal(positions, sim.positions)
    assert sorted(ids.tolist()) == list(range(300))


def test_reading_twice_copies_nothing(sim):
    a, b = sim.positions, sim.positions
    assert a is not b
    assert data_pointer(a) == data_pointer(b)
    assert not a.flags.owndata and not b.flags.owndata


def test_the_arrays_are_read_only(sim):
    positions = sim.positions
    assert not positions.flags.writeable
    with pytest.raises(ValueError):
        positions[0, 0] = 1.0
    with pytest.raises(ValueError):
        positions.setflags(write=True)  # its base exposes no buffer: NumPy refuses
    with pytest.raises(ValueError):
        sim.radii[:] = 1.0


def test_an_array_keeps_its_simulation_alive():
    s = ballpit.Simulation.from_scene("pour", SMALL_POUR)
    positions = s.positions[:, 1]  # a slice of a view
    expected = positions.copy()
    del s
    gc.collect()
    np.testing.assert_array_equal(positions, expected)  # still the engine's memory, still there
    base = positions.base
    while isinstance(base, np.ndarray):
        base = base.base
    assert isinstance(base, ballpit.ColumnLease)
    assert isinstance(base.simulation, ballpit.Simulation)


def test_a_call_that_could_move_a_column_waits_until_no_array_views_it(tmp_path):
    s = ballpit.Simulation()
    s.add_sphere(ballpit.SphereSpec(position=(0, 1, 0)))
    column = s.positions[:, 0]  # a slice counts as a view too
    with pytest.raises(BufferError, match="add_sphere: 1 array"):
        s.add_sphere(ballpit.SphereSpec(position=(0, 2, 0)))
    path = str(tmp_path / "one.snap")
    s.save(path)
    with pytest.raises(BufferError, match="load"):
        s.load(path)
    assert s.sphere_count == 1
    del column
    s.add_sphere(ballpit.SphereSpec(position=(0, 2, 0)))
    assert s.positions.shape == (2, 3)


def test_setters_write_the_columns_in_row_order(sim):
    positions = sim.positions
    moved = positions + np.float32(0.5)
    sim.set_positions(moved)
    np.testing.assert_array_equal(positions, moved)  # the view sees the write
    sim.set_velocities(np.zeros((300, 3)))  # float64 is taken, as float32
    assert not sim.velocities.any()


def test_an_empty_simulation_has_empty_arrays():
    s = ballpit.Simulation()
    assert s.positions.shape == (0, 3)
    assert s.sphere_ids.shape == (0,)
