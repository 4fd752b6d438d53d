# A pit built in code behaves as the closed-form answers say (as tests/test_api.cpp checks the
# C++ API), and settings, report, timings and snapshots round-trip through Python.
import math
import os

import numpy as np
import pytest

import ballpit


def test_a_ball_built_in_code_falls_at_g_times_t():
    # Semi-implicit Euler gains exactly g dt of speed per substep under constant gravity: after
    # 30 steps (0.5 s) v = -9.81 x 0.5 m/s, up to float rounding of 120 additions (1e-4 m/s).
    sim = ballpit.Simulation(ballpit.PitSpec(half_width=1.0))
    ball = sim.add_sphere(ballpit.SphereSpec(position=(0.0, 5.0, 0.0)))
    sim.step(30)
    assert sim.sphere_ids[0] == ball
    assert sim.velocities[0, 1] == pytest.approx(-9.81 * 0.5, abs=1e-4)
    assert sim.time == pytest.approx(0.5, abs=1e-6)


def test_a_kinematic_capsule_strikes_a_ball_with_the_restitution_formula():
    # A ball at rest, no gravity, hit head-on by a capsule at 3 m/s leaves at (1 + e) x 3 m/s
    # (e = 0.5; the impact is far above the restitution threshold). Bound: float rounding of
    # the impulse, as tests/test_api.cpp bounds it.
    sim = ballpit.Simulation(ballpit.PitSpec(half_width=5.0, material=ballpit.MaterialSpec(0.5, 0.0)))
    sim.set_gravity((0.0, 0.0, 0.0))
    sim.add_sphere(ballpit.SphereSpec(position=(0.0, 1.0, 0.0)))
    capsule = ballpit.ColliderSpec(shape="capsule", a=(-0.3, 0.9, 0.0), b=(-0.3, 1.1, 0.0), radius=0.05,
                                   velocity=(3.0, 0.0, 0.0))
    assert sim.add_collider(capsule) == 0
    assert sim.collider_count == 1
    sim.step(12)
    assert sim.velocities[0, 0] == pytest.approx(4.5, abs=1e-3)
    sim.set_collider_velocity(0, (0.0, 0.0, 0.0))
    sim.step(1)
    assert sim.velocities[0, 0] == pytest.approx(4.5, abs=1e-3)


def test_materials_and_settings_round_trip():
    sim = ballpit.Simulation(ballpit.PitSpec(half_width=2.0, wall_height=3.0, closed=True))
    bouncy = sim.add_material(ballpit.MaterialSpec(restitution=0.9, friction=0.1))
    assert bouncy == 1
    sim.add_sphere(ballpit.SphereSpec(position=(0, 1, 0), radius=0.05, mass=0.1, material=bouncy))
    sim.set_gravity((0.0, -1.62, 0.0))
    sim.set_dt(1.0 / 120.0)
    sim.set_substeps(8)
    sim.set_sleeping(True)
    assert sim.gravity == pytest.approx((0.0, -1.62, 0.0))
    assert sim.dt == pytest.approx(1.0 / 120.0)
    assert sim.substeps == 8 and sim.sleeping
    assert sim.radii[0] == np.float32(0.05)


def test_a_velocity_set_from_python_carries_the_ball():
    # No gravity, no contact: the ball moves v dt per step, exactly as integration does it.
    sim = ballpit.Simulation(ballpit.PitSpec(half_width=5.0))
    sim.set_gravity((0.0, 0.0, 0.0))
    sim.add_sphere(ballpit.SphereSpec(position=(0.0, 1.0, 0.0)))
    sim.set_velocities(np.array([[1.0, 0.0, 0.0]], np.float32))
    sim.step(60)  # 1 s
    assert sim.positions[0, 0] == pytest.approx(1.0, abs=1e-4)
    sim.set_positions([[0.0, 2.0, 0.5]])  # a list of rows is taken too
    assert tuple(sim.positions[0]) == (0.0, 2.0, 0.5)


def test_the_report_is_a_dict_of_the_run_reports_figures():
    sim = ballpit.Simulation.from_scene("pour", ["populations.0.count=300"])
    sim.step(20)
    r = sim.report()
    for key in ("spheres", "steps", "time_s", "dt", "max_penetration_r", "mean_penetration_r",
                "overlapping_pairs", "max_wall_penetration_r", "escaped", "kinetic_energy_j",
                "max_speed_mps", "momentum", "state_hash", "state_hash_hex"):
        assert key in r, key
    assert r["spheres"] == 300 and r["steps"] == 20 and r["escaped"] == 0
    assert r["time_s"] == pytest.approx(20 / 60)
    assert r["kinetic_energy_j"] > 0 and len(r["momentum"]) == 3
    assert r["state_hash"] == sim.state_hash and len(r["state_hash_hex"]) == 16
    # Kinetic energy is at least the translational part the velocities give (mass 0.05 kg each).
    v = sim.velocities.astype(np.float64)
    assert r["kinetic_energy_j"] >= 0.5 * 0.05 * float((v * v).sum()) * (1 - 1e-6)


def test_timings_name_each_system_once_per_step():
    sim = ballpit.Simulation.from_scene("pour", ["populations.0.count=300"])
    assert sim.timings() == {}
    sim.step(5)
    t = sim.timings()
    assert "solver" in t and "grid" in t
    for name, row in t.items():
        assert row["steps"] == 5, name
        assert row["median_ms"] >= 0 and row["p95_ms"] >= 0 and math.isfinite(row["mean_ms"])
    assert "narrowphase" in sim.timings_table()
    sim.reset_timings()
    assert sim.timings() == {}


def test_a_saved_state_resumes_to_the_hash_of_a_run_that_never_stopped(tmp_path):
    path = str(tmp_path / "resume.snap")
    straight = ballpit.Simulation.from_scene("pour", ["populations.0.count=300"])
    straight.step(20)
    first_half = ballpit.Simulation.from_scene("pour", ["populations.0.count=300"])
    first_half.step(10)
    first_half.save(path)
    resumed = ballpit.Simulation.from_snapshot(path)
    resumed.step(10)
    assert resumed.state_hash == straight.state_hash
    other = ballpit.Simulation()
    other.load(path)
    other.step(10)
    assert other.state_hash == straight.state_hash


def test_the_version_is_the_projects():
    assert ballpit.__version__ == os.environ.get("BALLPIT_EXPECTED_VERSION", ballpit.__version__)
    assert ballpit.__version__.count(".") == 2
