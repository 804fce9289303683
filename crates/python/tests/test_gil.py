"""Long calls release the GIL: Python code runs while a plan runs, and two threads plan at once."""

import threading
import time

import stackplan

# a plan of a few tenths of a second in a dev build
OPTIONS = dict(count=8, dtheta_deg=10, search_partitions=1)


def timed_plan(part, out, key):
    start = time.perf_counter()
    plan = stackplan.plan(part, **OPTIONS)
    out[key] = (start, time.perf_counter(), plan.to_json(timings=False))


def test_python_runs_while_a_plan_runs():
    part = stackplan.Part.example("channel")
    out = {}
    worker = threading.Thread(target=timed_plan, args=(part, out, "a"))
    worker.start()
    spins = 0
    while worker.is_alive():
        spins += 1
    worker.join()
    start, end, _ = out["a"]
    # the main thread ran Python code all along: with the GIL held by the plan it would have waited for its end
    assert end - start > 0.01
    assert spins > 1000


def test_two_threads_plan_at_once():
    part = stackplan.Part.example("channel")
    alone = stackplan.plan(part, **OPTIONS).to_json(timings=False)
    out = {}
    threads = [threading.Thread(target=timed_plan, args=(part, out, k)) for k in "ab"]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    (a0, a1, a_json), (b0, b1, b_json) = out["a"], out["b"]
    # the two calls overlapped in time: with the GIL held, one would start only after the other ended
    assert a0 < b1 and b0 < a1
    assert a_json == b_json == alone
