"""Many machines through Dask distributed: a local cluster of 2 worker processes maps ``stackplan.plan`` over 20
jobs; the plans equal ``stackplan batch``'s byte for byte. The same code runs on a real cluster with the scheduler's
address instead of the LocalCluster (docs/python.md)."""

import json

import pytest

distributed = pytest.importorskip("distributed")

import stackplan  # noqa: E402

#: 20 small jobs: four parts, several weights and counts (each a fraction of a second)
JOBS = [
    {"id": f"{part}-w{w}-n{count}", "part": f"example:{part}", "count": count, "w": w, "dtheta_deg": step, **extra}
    for part, step, extra in [
        ("channel", 30, {}),
        ("triangle", 60, {"clearance": 0}),
        ("l-corner", 45, {}),
        ("block", 90, {}),
    ]
    for w, count in [(0.0, 2), (0.25, 3), (0.5, 2), (0.75, 3), (1.0, 2)]
]


def plan_job(job):
    """One job on a worker: the same line as in jobs.jsonl, given to stackplan.plan."""
    options = {k: v for k, v in job.items() if k not in ("id", "part")}
    return job["id"], stackplan.plan(job["part"], **options).to_json(timings=False)


def test_a_local_dask_cluster_plans_what_batch_plans(cli, tmp_path):
    assert len(JOBS) == 20
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            assert len(client.scheduler_info()["workers"]) == 2
            futures = client.map(plan_job, JOBS)
            results = dict(client.gather(futures))
    jobs = tmp_path / "jobs.jsonl"
    jobs.write_text("".join(json.dumps(job) + "\n" for job in JOBS))
    cli("batch", jobs, "--out", tmp_path / "out")
    summary = (tmp_path / "out" / "summary.csv").read_text().splitlines()
    assert len(summary) == 21 and all(",complete," in row for row in summary[1:])
    for job in JOBS:
        assert results[job["id"]] == (tmp_path / "out" / job["id"] / "plan.json").read_text(), job["id"]
