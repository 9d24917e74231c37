"""Ctrl-C during a long call: a greedy search notices it after the current
term and raises KeyboardInterrupt; other threads run Python meanwhile (the GIL
is released)."""
import os
import signal
import threading
import time

import pytest

import brdf_factor as bf


def test_ctrl_c_interrupts_a_greedy_search(grid8):
    opts = dict(texture_size=8, restarts=3, threads=1, seed=2)
    t0 = time.perf_counter()
    bf.search(grid8, terms=1, **opts)
    one_term = time.perf_counter() - t0
    # 12 terms take about 12 x one_term (later terms cost more); SIGINT comes during the first.
    timer = threading.Timer(0.5 * one_term, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        bf.search(grid8, terms=12, **opts)
    elapsed = time.perf_counter() - t0
    timer.join()
    assert elapsed < 4 * one_term + 1.0


def test_gil_is_released_during_a_fit(grid8):
    ticks = []
    stop = threading.Event()

    def ticker():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.005)

    th = threading.Thread(target=ticker)
    th.start()
    t0 = time.perf_counter()
    bf.search(grid8, terms=2, texture_size=8, restarts=2, threads=1)
    t1 = time.perf_counter()
    stop.set()
    th.join()
    # The Python thread kept running while the search ran in C++.
    inside = [t for t in ticks if t0 < t < t1]
    assert t1 - t0 > 0.05 and len(inside) >= 3
