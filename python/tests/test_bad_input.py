# Bad input raises ValueError or TypeError with the engine's message (the ballpit::Error that
# names the file, field or row at fault), and changes nothing; nothing crashes the interpreter.
import json

import numpy as np
import pytest

import ballpit


@pytest.fixture
def sim():
    s = ballpit.Simulation.from_scene("pour", ["populations.0.count=50"])
    s.step(1)
    return s


def test_a_bad_scene_file_raises_the_engines_message(tmp_path):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"populations": [{"count": 10, "spheerss": 3}]}))
    with pytest.raises(ValueError, match="populations.0.spheerss: unknown key"):
        ballpit.Simulation.from_scene(str(scene))
    with pytest.raises(ValueError, match="populations.0.spheerss: unknown key"):
        ballpit.Simulation.from_scene("pour", ["populations.0.spheerss=3"])
    scene.write_text("{ not json")
    with pytest.raises(ValueError, match="scene.json"):
        ballpit.Simulation.from_scene(str(scene))
    with pytest.raises(ValueError, match="/no/such/scene.json"):
        ballpit.Simulation.from_scene("/no/such/scene.json")


def test_a_bad_snapshot_raises_and_the_state_stays(sim, tmp_path):
    bad = tmp_path / "bad.snap"
    bad.write_bytes(b"not a snapshot at all")
    before = sim.state_hash
    with pytest.raises(ValueError, match="bad.snap"):
        sim.load(str(bad))
    assert sim.state_hash == before
    with pytest.raises(ValueError, match="/no/such/file.snap"):
        ballpit.Simulation.from_snapshot("/no/such/file.snap")
    with pytest.raises(ValueError):
        sim.save("/no/such/folder/x.snap")


def test_positions_of_the_wrong_shape_or_type_raise(sim):
    with pytest.raises(ValueError, match=r"shape \(50, 3\).*got shape \(49, 3\)"):
        sim.set_positions(np.zeros((49, 3), np.float32))
    with pytest.raises(ValueError, match="got shape"):
        sim.set_positions(np.zeros((50, 2), np.float32))
    with pytest.raises(ValueError, match="got shape"):
        sim.set_velocities(np.zeros(150, np.float32))
    with pytest.raises(TypeError, match="dtype int64"):
        sim.set_positions(np.zeros((50, 3), np.int64))
    with pytest.raises(TypeError, match="floating-point"):
        sim.set_velocities([["a", "b", "c"]] * 50)
    with pytest.raises(TypeError):
        sim.set_positions(None)


def test_a_nan_raises_naming_its_row_and_changes_nothing(sim):
    before = sim.positions.copy()
    bad = before.copy()
    bad[17, 1] = np.nan
    row_id = int(sim.sphere_ids[17])
    with pytest.raises(ValueError, match=rf"set_positions: row 17 \(sphere id {row_id}\): position must be finite"):
        sim.set_positions(bad)
    np.testing.assert_array_equal(sim.positions, before)
    fast = np.zeros((50, 3))
    fast[3, 0] = 1e300  # no float32 holds it: infinite, refused
    with pytest.raises(ValueError, match="row 3 .*velocity must be finite"), np.errstate(over="ignore"):
        sim.set_velocities(fast)


def test_bad_values_raise_the_engines_message():
    s = ballpit.Simulation()
    with pytest.raises(ValueError, match="radius must be a finite number > 0"):
        s.add_sphere(ballpit.SphereSpec(radius=-1.0))
    with pytest.raises(ValueError, match="position must be finite"):
        s.add_sphere(ballpit.SphereSpec(position=(0, float("nan"), 0)))
    assert s.sphere_count == 0
    with pytest.raises(ValueError, match=r"restitution must be in \[0, 1\]"):
        s.add_material(ballpit.MaterialSpec(restitution=2.0))
    with pytest.raises(ValueError, match="collider 3 does not exist"):
        s.set_collider_velocity(3, (0, 0, 0))
    with pytest.raises(ValueError, match="dt"):
        s.set_dt(0.0)
    with pytest.raises(ValueError):
        s.set_substeps(0)
    with pytest.raises(ValueError, match="gravity must be finite"):
        s.set_gravity((0, float("inf"), 0))
    with pytest.raises(ValueError, match="steps must be >= 0"):
        s.step(-1)
    with pytest.raises(ValueError, match="pit.half_width"):
        ballpit.Simulation(ballpit.PitSpec(half_width=-1.0))
    with pytest.raises(ValueError, match="shape must be 'sphere' or 'capsule'"):
        ballpit.ColliderSpec(shape="cube")


def test_wrong_types_raise_type_error():
    s = ballpit.Simulation()
    with pytest.raises(TypeError):
        s.add_sphere("a sphere")
    with pytest.raises(TypeError):
        ballpit.SphereSpec(position=(0, 1))  # two coordinates
    with pytest.raises(TypeError):
        s.set_gravity("down")
    with pytest.raises(TypeError):
        s.step("ten")
    with pytest.raises(TypeError):
        ballpit.Simulation.from_scene("pour", "populations.0.count=5")  # a list is wanted
