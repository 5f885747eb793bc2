"""The GIL is released while glint works: Python threads run meanwhile, and calls from several
threads give the single-threaded results."""

import threading
import time

import numpy as np

import glint


def test_other_python_threads_run_during_a_call():
    xyz = np.random.default_rng(8).random((60000, 3), np.float32)
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    time.sleep(0.01)
    before = ticks
    glint.edges.features(xyz, scales=[64, 32])
    during = ticks - before
    done.set()
    counter.join()
    # With the GIL held for the whole call the counter could not tick at all meanwhile.
    assert during > 5


def test_concurrent_calls_match_serial_ones():
    rng = np.random.default_rng(9)
    clouds = [rng.random((4000, 3), np.float32) for _ in range(4)]
    serial = [glint.edges.classify(c)[0] for c in clouds]
    results = [None] * len(clouds)

    def work(i):
        results[i] = glint.edges.classify(clouds[i])[0]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(clouds))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(serial, results):
        np.testing.assert_array_equal(a, b)
