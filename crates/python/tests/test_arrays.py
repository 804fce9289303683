"""Round trips between numpy arrays and parts, poses and c-space obstacles, against independent arithmetic."""

import itertools
import json

import numpy as np
import pytest

import stackplan


def box(lo, hi):
    return np.array(list(itertools.product(*zip(lo, hi))), dtype=float)


def sorted_rows(a):
    return a[np.lexsort(a.T[::-1])]


def mesh_volume(vertices, triangles):
    """Volume of a closed, outward-oriented triangle mesh by the divergence theorem."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def test_from_arrays_keeps_the_pieces_and_their_volume():
    pieces = [box((0, 0, 0), (10, 20, 2)), box((0, 0, 2), (2, 20, 12))]
    part = stackplan.Part.from_arrays(pieces, name="angle")
    assert part.name == "angle"
    assert len(part.pieces) == 2
    for given, got in zip(pieces, part.pieces):
        assert got.dtype == np.float64 and got.shape == (8, 3)
        np.testing.assert_array_equal(sorted_rows(got), sorted_rows(given))
    assert part.volume == pytest.approx(10 * 20 * 2 + 2 * 20 * 10, rel=1e-12)
    # each piece's triangles close it up: the divergence theorem gives its volume
    for piece, triangles, (lo, hi) in zip(part.pieces, part.triangles, [((0, 0, 0), (10, 20, 2)), ((0, 0, 2), (2, 20, 12))]):
        assert mesh_volume(piece, triangles) == pytest.approx(np.prod(np.subtract(hi, lo)), rel=1e-12)
    lo, hi = part.bounds
    np.testing.assert_array_equal(lo, [0, 0, 0])
    np.testing.assert_array_equal(hi, [10, 20, 12])


def test_interior_points_are_dropped_and_a_part_survives_the_round_trip():
    cube = box((0, 0, 0), (1, 1, 1))
    with_inside = np.vstack([cube, [[0.5, 0.5, 0.5], [0.25, 0.5, 0.75]]])
    part = stackplan.Part.from_arrays([with_inside])
    np.testing.assert_array_equal(sorted_rows(part.pieces[0]), sorted_rows(cube))
    channel = stackplan.Part.example("channel")
    again = stackplan.Part.from_arrays(channel.pieces, name=channel.name)
    # (the vertices in another order: sums may differ in their last bit)
    assert again.volume == pytest.approx(channel.volume, rel=1e-14)
    # the same pieces (the hull numbers their vertices its own way)
    for a, b in zip(again.pieces, channel.pieces):
        np.testing.assert_array_equal(sorted_rows(a), sorted_rows(b))
    np.testing.assert_allclose(again.center_of_gravity, channel.center_of_gravity, rtol=1e-14)


def test_poses_are_the_placements_of_the_plan_file():
    part = stackplan.Part.example("channel")
    plan = stackplan.plan(part, count=3, dtheta_deg=30)
    poses = plan.poses
    assert poses.shape == (3, 4, 4) and poses.dtype == np.float64
    placements = json.loads(plan.to_json())["placements"]
    for pose, placement in zip(poses, placements):
        np.testing.assert_array_equal(pose[:3, :3], placement["rotation"])
        np.testing.assert_array_equal(pose[:3, 3], placement["position"])
        np.testing.assert_array_equal(pose[3], [0, 0, 0, 1])
        np.testing.assert_allclose(pose[:3, :3] @ pose[:3, :3].T, np.eye(3), atol=1e-12)
    # world vertices: every part stands on or above the floor, the top at the plan's height
    world = [(pose[:3, :3] @ piece.T).T + pose[:3, 3] for pose in poses for piece in part.pieces]
    z = np.concatenate([w[:, 2] for w in world])
    assert z.min() >= -1e-9
    assert z.max() == pytest.approx(plan.height, abs=1e-9)


def test_cspace_obstacle_of_two_boxes_is_their_difference_box():
    a = box((0, 0, 0), (1, 2, 3))
    b = box((5, 5, 5), (9, 8, 7))
    vertices, triangles = stackplan.cspace_obstacle(a, b, 0.0)
    assert vertices.shape[1] == 3 and triangles.shape[1] == 3 and triangles.dtype == np.int64
    # translations p with a + p overlapping b: b - a = [5-1, 9] x [5-2, 8] x [5-3, 7]
    np.testing.assert_allclose(vertices.min(axis=0), [4, 3, 2], atol=1e-12)
    np.testing.assert_allclose(vertices.max(axis=0), [9, 8, 7], atol=1e-12)
    assert mesh_volume(vertices, triangles) == pytest.approx(5 * 5 * 5, rel=1e-12)


def test_cspace_obstacle_vertices_are_differences_of_the_pieces_vertices():
    a = np.array([[0, 0, 0], [3, 0, 0], [0, 2, 0], [0, 0, 1]], dtype=float)
    b = box((0, 0, 0), (2, 2, 2))
    theta = 30.0
    t = np.radians(theta)
    rz = np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]])
    vertices, triangles = stackplan.cspace_obstacle(a, b, theta_deg=theta)
    candidates = (b[:, None, :] - (a @ rz.T)[None, :, :]).reshape(-1, 3)
    for v in vertices:
        assert np.min(np.linalg.norm(candidates - v, axis=1)) < 1e-9
    # the obstacle is convex: every candidate lies inside, on the inner side of every face
    normals = np.cross(vertices[triangles[:, 1]] - vertices[triangles[:, 0]], vertices[triangles[:, 2]] - vertices[triangles[:, 0]])
    offsets = np.einsum("ij,ij->i", normals, vertices[triangles[:, 0]])
    assert np.all(candidates @ normals.T <= offsets + 1e-9)
