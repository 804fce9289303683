"""Shared fixtures: the command line under comparison and helpers.

The tests compare the package with the ``stackplan`` program: set ``STACKPLAN_BIN`` to it (``.ci/run`` builds it),
or build it under the repository's ``target/`` (``cargo build -p stackplan-cli``; ``CARGO_TARGET_DIR`` is honoured).
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


def _find_cli():
    given = os.environ.get("STACKPLAN_BIN")
    if given:
        return Path(given)
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("debug", "release"):
        candidate = target / profile / "stackplan"
        if candidate.exists():
            return candidate
    return None


@pytest.fixture(scope="session")
def cli():
    """Runs the program: ``cli(*args, cwd=...)`` returns the completed process."""
    path = _find_cli()
    if path is None or not path.exists():
        pytest.fail("the stackplan program was not found: set STACKPLAN_BIN or run `cargo build -p stackplan-cli`")

    def run(*args, cwd=None, check=True):
        done = subprocess.run([str(path), *map(str, args)], cwd=cwd, capture_output=True, text=True)
        if check and done.returncode not in (0,):
            raise AssertionError(f"stackplan {' '.join(map(str, args))}: exit {done.returncode}\n{done.stderr}")
        return done

    return run


def untimed(document):
    """A plan file's JSON with its three timings 0 (as ``stackplan batch`` and ``Plan.to_json(timings=False)``)."""
    document = json.loads(json.dumps(document))
    document["plan"]["seconds"] = 0.0
    document["plan"]["stats"]["seconds_search"] = 0.0
    document["plan"]["stats"]["seconds_checks"] = 0.0
    return document
