"""Ctrl-C interrupts a long call: KeyboardInterrupt is raised within a fraction of a second."""

import signal
import subprocess
import sys
import time

SCRIPT = """
import sys, time
import stackplan
part = stackplan.Part.example("complex")
print("planning", flush=True)
start = time.perf_counter()
try:
    stackplan.plan(part, count=15, dtheta_deg=1, search_partitions=1)
    print("finished", flush=True)
except KeyboardInterrupt:
    print(f"interrupted after {time.perf_counter() - start:.2f} s", flush=True)
    sys.exit(3)
"""


def test_ctrl_c_interrupts_a_plan():
    process = subprocess.Popen([sys.executable, "-c", SCRIPT], stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "planning"
    time.sleep(0.5)
    sent = time.perf_counter()
    process.send_signal(signal.SIGINT)
    out, _ = process.communicate(timeout=60)
    waited = time.perf_counter() - sent
    # the plan takes seconds; the interrupt ends the call at once (the abandoned plan is dropped with the process)
    assert process.returncode == 3, out
    assert out.startswith("interrupted after"), out
    assert waited < 2.0, waited
