# A pour stepped from Python reaches the state `ballpit run` reaches on the same scene and steps:
# the module adds nothing to the engine's arithmetic (tests/test_api.cpp checks the C++ API the
# same way; tests/install_package.sh runs the CLI as here).
import json
import subprocess

import ballpit

SPHERES = 1000
STEPS = 120  # 2 s at the pour's 1/60 s: the balls land and pile, thousands of contacts


def cli_state_hash(cli, *args):
    out = subprocess.run([cli, "run", *args, "--no-progress", "--no-table"],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])["state_hash"]


def test_a_1000_ball_pour_reaches_the_state_hash_of_ballpit_run(cli):
    sim = ballpit.Simulation.from_scene("pour", [f"populations.0.count={SPHERES}"])
    sim.step(STEPS)
    report = sim.report()
    assert report["spheres"] == SPHERES
    assert report["steps"] == STEPS
    assert report["state_hash_hex"] == f"{sim.state_hash:016x}"
    # The built-in pour sized by --spheres, and the pour's scene file sized by --set: one scene.
    assert report["state_hash_hex"] == cli_state_hash(cli, "--scene", "pour", "--spheres", str(SPHERES),
                                                      "--steps", str(STEPS))
    assert report["state_hash_hex"] == cli_state_hash(cli, "--scene", "pour", "--set", f"populations.0.count={SPHERES}",
                                                      "--set", f"steps={STEPS}")


def test_steps_taken_in_pieces_reach_the_state_of_one_call():
    whole = ballpit.Simulation.from_scene("pour", ["populations.0.count=300"])
    whole.step(20)
    pieces = ballpit.Simulation.from_scene("pour", ["populations.0.count=300"])
    for _ in range(4):
        pieces.step(5)
    assert pieces.state_hash == whole.state_hash


def test_the_thread_count_changes_no_bit():
    one = ballpit.Simulation.from_scene("pour", ["populations.0.count=500"], threads=1)
    two = ballpit.Simulation.from_scene("pour", ["populations.0.count=500"], threads=2)
    one.step(30)
    two.step(30)
    assert one.state_hash == two.state_hash
