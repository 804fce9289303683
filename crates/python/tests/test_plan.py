"""Plans, checks and placements equal the command line's for the same options."""

import json
from pathlib import Path

import pytest

import stackplan
from conftest import untimed

OPTIONS = dict(count=3, dtheta_deg=30, clearance=4)
ARGS = ["--count", "3", "--dtheta-deg", "30", "--clearance", "4"]
PICTURES = ["stack.svg", "stack.png", "build.svg", "build.png", "stack.glb"]


def test_plan_equals_the_cli_plan_file_by_file(cli, tmp_path):
    cli("plan", "example:channel", *ARGS, "--out", tmp_path / "cli")
    plan = stackplan.plan(stackplan.Part.example("channel"), **OPTIONS)
    expected = json.loads((tmp_path / "cli" / "plan.json").read_text())
    assert untimed(json.loads(plan.to_json())) == untimed(expected)
    assert json.loads(plan.to_json(timings=False)) == untimed(expected)
    assert json.loads(plan.to_json())["plan"]["seconds"] == plan.seconds > 0
    plan.write(tmp_path / "py")
    for name in PICTURES:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert json.loads((tmp_path / "py" / "plan.json").read_text()) == json.loads(plan.to_json())
    assert plan.placed == plan.count == 3 and plan.stopped is None and plan.stack_stable


def test_a_part_file_and_its_path_give_the_cli_plan(cli, tmp_path):
    fixture = Path(__file__).resolve().parents[3] / "fixtures" / "parts" / "triangle.json"
    cli("plan", fixture, "--count", "2", "--clearance", "0", "--dtheta-deg", "90", "--w", "0.9", "--out", tmp_path)
    expected = untimed(json.loads((tmp_path / "plan.json").read_text()))
    by_part = stackplan.plan(stackplan.Part.from_file(fixture), count=2, clearance=0, dtheta_deg=90, w=0.9)
    by_path = stackplan.plan(str(fixture), count=2, clearance=0, dtheta_deg=90, w=0.9)
    assert json.loads(by_part.to_json(timings=False)) == expected
    assert by_path.to_json(timings=False) == by_part.to_json(timings=False)


def test_check_equals_the_cli_check(cli, tmp_path):
    plan = stackplan.plan(stackplan.Part.example("channel"), **OPTIONS)
    plan.write(tmp_path)
    expected = json.loads(cli("check", tmp_path / "plan.json", "--json").stdout)
    assert expected.pop("stack_file") == str(tmp_path / "plan.json")
    for report in (stackplan.check(plan), stackplan.check(tmp_path / "plan.json")):
        got = report.to_dict()
        assert report.ok and got["ok"]
        got.pop("stack_file")
        assert got == expected
    assert not stackplan.check(plan, clearance=1000).ok


def test_place_equals_the_cli_place(cli, tmp_path):
    plan = stackplan.plan(stackplan.Part.example("channel"), **OPTIONS)
    plan.write(tmp_path)
    expected = json.loads(
        cli("place", "example:channel", "--stack", tmp_path / "plan.json", "--k", "2", "--dtheta-deg", "45", "--json").stdout
    )
    got = stackplan.place(stackplan.Part.example("channel"), plan, k=2, dtheta_deg=45)
    for d in (got, expected):
        d["stats"] = {k: v for k, v in d["stats"].items() if not k.startswith("time")}
    assert got == expected and len(got["placements"]) == 2


def test_contacts_equal_the_cli_contacts(cli):
    # a unit cube on a unit cube, within 0.2 mm and 1 degree, about a second
    expected = json.loads(
        cli(
            "contacts", "example:cube", "example:cube", "--t-min=-0.2,-0.2,0.9,-1,-1,-1", "--t-max=0.2,0.2,1.1,1,1,1",
            "--population", "8", "--generations", "2", "--json",
        ).stdout
    )
    cube = stackplan.Part.example("cube")
    got = stackplan.contacts(
        cube, cube, t_min=(-0.2, -0.2, 0.9, -1, -1, -1), t_max=[0.2, 0.2, 1.1, 1, 1, 1], population=8, generations=2
    )
    assert got == expected
    # feasible states include ones of three or more principal contacts held at once
    feasible = [state for state in got["states"] if state["feasible"]]
    assert feasible and any(state["level"] >= 3 for state in feasible)
