"""One scene shared by several Python threads gives the answers it gives alone, and checks release the GIL."""
import threading
import time

import numpy as np

from conftest import random_states


def run_threads(count, work):
    results = [None] * count
    errors = []

    def body(i):
        try:
            results[i] = work(i)
        except BaseException as e:  # reported below: a thread's failure must fail the test
            errors.append(e)

    threads = [threading.Thread(target=body, args=(i,)) for i in range(count)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    return results


def test_threads_sharing_a_scene_get_the_single_thread_answers(arm6, panda_box):
    _, panda = panda_box
    scenes = [arm6, panda]
    states = [random_states(s, 3000, seed=40 + k) for k, s in enumerate(scenes)]
    ends = [random_states(s, 3000, seed=50 + k) for k, s in enumerate(scenes)]
    alone = [(s.check(q, report=True), s.check_motions(q[:150], e[:150])) for s, q, e in zip(scenes, states, ends)]

    def work(i):
        k = i % 2  # threads alternate between the two scenes, each scene shared by three threads
        answers = []
        for _ in range(3):
            answers.append((scenes[k].check(states[k], report=True), scenes[k].check_motions(states[k][:150], ends[k][:150])))
        return k, answers

    for k, answers in run_threads(6, work):
        (free, pairs), (mfree, last) = alone[k]
        for (f, p), (mf, lv) in answers:
            np.testing.assert_array_equal(f, free)
            assert p == pairs
            np.testing.assert_array_equal(mf, mfree)
            np.testing.assert_array_equal(lv, last)
    assert 0 < alone[0][0][0].sum() < 3000 and 0 < alone[1][0][0].sum() < 3000


def test_a_check_releases_the_gil(panda_box):
    """While one thread checks a long batch, this thread keeps running Python: no gap as long as the check."""
    _, scene = panda_box
    # A batch long enough to tell (about 0.2 s) however fast the checks are on this build and machine.
    probe = random_states(scene, 2000, seed=60)
    started = time.perf_counter()
    scene.check(probe)
    per_state = max(time.perf_counter() - started, 1e-6) / len(probe)
    states = random_states(scene, int(min(400000, max(20000, 0.2 / per_state))), seed=60)
    span = {}

    def check():
        span["start"] = time.perf_counter()
        scene.check(states)
        span["end"] = time.perf_counter()

    worker = threading.Thread(target=check)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
    worker.join()
    inside = [t for t in ticks if span["start"] <= t <= span["end"]]
    duration = span["end"] - span["start"]
    assert duration > 0.05, "the batch is too short to tell"
    # Holding the GIL for the whole check would stop this loop for its whole duration.
    gaps = np.diff([span["start"], *inside, span["end"]])
    assert len(inside) > 100 and gaps.max() < 0.5 * duration, (len(inside), gaps.max(), duration)
