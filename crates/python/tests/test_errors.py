"""Bad input raises StackplanError with the command line's one-line message."""

import numpy as np
import pytest

import stackplan


def cli_error(cli, *args):
    done = cli(*args, check=False)
    assert done.returncode == 2, done.stderr
    line = done.stderr.strip().splitlines()[-1]
    assert line.startswith("error: ")
    return line[len("error: "):]


def test_the_error_is_a_value_error():
    assert issubclass(stackplan.StackplanError, ValueError)


def test_a_missing_file_names_the_file_as_the_cli_does(cli, tmp_path):
    missing = tmp_path / "no-such-part.stl"
    with pytest.raises(stackplan.StackplanError) as raised:
        stackplan.Part.from_file(missing)
    expected = cli_error(cli, "part", "info", missing)
    assert str(raised.value) == expected and "no-such-part.stl" in expected
    assert "\n" not in str(raised.value)


def test_bad_options_give_the_cli_messages(cli, tmp_path):
    part = stackplan.Part.example("channel")
    for kwargs, args in [
        (dict(count=0), ["--count", "0"]),
        (dict(dtheta_deg=0), ["--dtheta-deg", "0"]),
        (dict(floor=(10, 0, 0, 10)), ["--floor=10,0,0,10"]),
        (dict(clearance=float("nan")), ["--clearance", "NaN"]),
    ]:
        with pytest.raises(stackplan.StackplanError) as raised:
            stackplan.plan(part, **kwargs)
        assert str(raised.value) == cli_error(cli, "plan", "example:channel", *args, "--out", tmp_path)


def test_unknown_options_and_bad_arrays_are_named():
    part = stackplan.Part.example("channel")
    with pytest.raises(stackplan.StackplanError, match="unknown key `cout`"):
        stackplan.plan(part, cout=3)
    with pytest.raises(stackplan.StackplanError, match=r"pieces\[0\]: expected an \(n, 3\) array"):
        stackplan.Part.from_arrays([np.zeros((4, 2))])
    with pytest.raises(stackplan.StackplanError, match="degenerate|coplanar|flat"):
        stackplan.Part.from_arrays([[[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]])
    with pytest.raises(stackplan.StackplanError, match="units"):
        stackplan.Part.from_file("x.stl", units="furlong")
    with pytest.raises(stackplan.StackplanError, match="w must lie in"):
        stackplan.plan(part, w=2)


def test_a_plan_that_places_nothing_raises():
    part = stackplan.Part.example("channel")
    with pytest.raises(stackplan.StackplanError, match="no part could be placed|floor|fit"):
        stackplan.plan(part, count=2, floor=(-10, -10, 10, 10))
