# %% [markdown]
# # A stacking plan for a real bent part
#
# Notebook-style (cells marked `# %%`; runs as a plain script too): read a real sheet-metal part from the
# repository's fixtures (BenDFM's `bendfm_2`, an STL recognised as sheet metal), plan a stack, check it, and show it
# with trimesh if that is installed. Install the package first: `pip install ./crates/python` (and `pip install
# trimesh` for the picture).
#
#     python examples/python/plan_real_part.py [--count 6] [--out out-python]

# %%
import argparse
from pathlib import Path

import numpy as np

import stackplan

ROOT = Path(__file__).resolve().parents[2]
PART_FILE = ROOT / "fixtures" / "realparts" / "bendfm_2.stl"

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--count", type=int, default=6, help="parts to stack (default 6)")
parser.add_argument("--out", type=Path, default=None, help="also write the plan's files here, as `stackplan plan`")
parser.add_argument("--no-show", action="store_true", help="do not open a trimesh window")
args, _ = parser.parse_known_args()

# %% The part: its convex pieces as numpy arrays
part = stackplan.Part.from_file(PART_FILE, units="mm")
lo, hi = part.bounds
print(f"{part.name}: {len(part.pieces)} convex pieces, volume {part.volume:.0f} mm^3, "
      f"{hi[0] - lo[0]:.0f} x {hi[1] - lo[1]:.0f} x {hi[2] - lo[2]:.0f} mm")

# %% The plan (the options of `stackplan plan`, same defaults: w = 0.5, 5 mm clearance, 5-degree steps)
plan = stackplan.plan(part, count=args.count, w=0.5, clearance=5.0)
(x0, y0), (x1, y1) = plan.footprint
print(f"{plan.placed} of {plan.count} parts placed ({plan.stopped or 'complete'}): height {plan.height:.1f} mm, "
      f"footprint {x1 - x0:.1f} x {y1 - y0:.1f} mm, {plan.seconds:.2f} s")

# %% Checked again, part by part, as `stackplan check` does
report = stackplan.check(plan)
print("check:", "all checks pass" if report.ok else "CHECKS FAILED")
if args.out is not None:
    plan.write(args.out)
    print(f"wrote {args.out}: plan.json, stack.svg, stack.png, build.svg, build.png, stack.glb, report.html")

# %% The stack in world coordinates: pose[:3, :3] @ p + pose[:3, 3] for every vertex p of every piece
world = [[(pose[:3, :3] @ piece.T).T + pose[:3, 3] for piece in part.pieces] for pose in plan.poses]
print("lowest and highest vertex:", min(w[:, 2].min() for ws in world for w in ws),
      max(w[:, 2].max() for ws in world for w in ws), "mm")

# %% Shown with trimesh (optional): one mesh per placed piece, from the piece's vertices and triangles
try:
    import trimesh
except ImportError:
    trimesh = None
    print("trimesh is not installed: `pip install trimesh` to see the stack")
if trimesh is not None:
    scene = trimesh.Scene()
    rng = np.random.default_rng(1)
    for k, pieces in enumerate(world):
        colour = np.append(rng.integers(60, 230, 3), 255)
        for j, (piece, triangles) in enumerate(zip(pieces, part.triangles)):
            mesh = trimesh.Trimesh(vertices=piece, faces=triangles, process=False)
            mesh.visual.face_colors = colour
            scene.add_geometry(mesh, node_name=f"part {k + 1} piece {j + 1}")
    if args.no_show:
        print(f"trimesh scene: {len(scene.geometry)} pieces, bounds {scene.bounds.tolist()}")
    else:
        scene.show()
