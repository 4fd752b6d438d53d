# step() runs without the GIL: another Python thread makes progress while it runs, and a call
# on the same Simulation from that thread is refused instead of racing the step.
import threading
import time

import pytest

import ballpit


def test_another_thread_runs_while_ten_steps_run():
    # 20,000 balls on one thread: each step takes milliseconds, ten of them tens.
    sim = ballpit.Simulation.from_scene("pour", ["populations.0.count=20000"], threads=1)
    sim.step(1)
    ticks = []
    started, stop = threading.Event(), threading.Event()

    def count():
        started.set()
        n = 0
        while not stop.is_set():
            n += 1
            if n % 100 == 0:  # a tick per hundred rounds: memory stays small however long steps take
                ticks.append(time.perf_counter())

    worker = threading.Thread(target=count)
    worker.start()
    started.wait()
    t0 = time.perf_counter()
    sim.step(10)
    t1 = time.perf_counter()
    stop.set()
    worker.join()
    during = [t for t in ticks if t0 < t < t1]
    # Holding the GIL through the steps would leave the counter still for all of them (at most
    # a tick or two at the edges). Released, it ticks through them: require ticks spread over
    # most of the steps' time (gaps are GIL handovers, 5 ms each at most, and the engine's own
    # share of the two cores).
    assert sim.step_count == 11
    assert len(during) > 100, f"{len(during)} ticks in {1000 * (t1 - t0):.1f} ms of stepping"
    assert during[-1] - during[0] > 0.5 * (t1 - t0)


def test_a_call_from_another_thread_during_a_step_is_refused():
    sim = ballpit.Simulation.from_scene("pour", ["populations.0.count=20000"], threads=1)
    errors, results = [], []
    stepping = threading.Thread(target=lambda: sim.step(20))
    stepping.start()
    deadline = time.perf_counter() + 30.0
    while stepping.is_alive() and time.perf_counter() < deadline:
        try:
            results.append(sim.sphere_count)
        except RuntimeError as e:
            errors.append(str(e))
            break
        time.sleep(0.001)
    stepping.join()
    assert errors, "no call was refused while the other thread stepped"
    assert "stepping in another thread" in errors[0]
    assert sim.step_count == 20  # the step finished undisturbed
    assert sim.sphere_count == 20000
