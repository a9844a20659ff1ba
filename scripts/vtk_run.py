"""What the VTK readers of a run's particles share (scripts/wall_leak.py, scripts/packing.py, scripts/diastole.py, scripts/jet_noise.py): the run's scene,
its bodies by material type, its frames and their times, and the candidate pairs of particles in neighbouring cells.
Needs numpy only."""
import json
import os
import re
import sys

import numpy as np


def run_scene(run_dir):
    """The resolved scene that RUN_DIR/run.json records; exits with the file's error if it cannot be read."""
    try:
        with open(os.path.join(run_dir, "run.json")) as f:
            return json.load(f)["scene"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"{run_dir}/run.json: {e}")


def bodies_of_type(scene, kind):
    """Indices of the scene's bodies (as in the VTK array "body") whose material is of type KIND."""
    mats = scene["materials"]
    return [k for k, b in enumerate(scene["bodies"]) if mats[b["material"]]["type"] == kind]


def frames(run_dir):
    """The particles_*.vtp files of RUN_DIR/vtk in order; exits if there are none."""
    vtk = os.path.join(run_dir, "vtk")
    try:
        found = sorted(f for f in os.listdir(vtk) if f.startswith("particles_") and f.endswith(".vtp"))
    except OSError as e:
        sys.exit(f"{vtk}: {e}")
    if not found:
        sys.exit(f"{vtk}: no particles_*.vtp (run with --vtk)")
    return found


def frame_times(run_dir):
    """(time, path) of each frame that RUN_DIR/vtk/particles.pvd lists, in its order; exits if it is missing."""
    pvd = os.path.join(run_dir, "vtk", "particles.pvd")
    if not os.path.exists(pvd):
        sys.exit(f"{pvd}: not found (run with --vtk or --vtk-every N)")
    with open(pvd) as f:
        text = f.read()
    return [(float(m.group(1)), os.path.join(run_dir, "vtk", m.group(2)))
            for m in re.finditer(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)]


def cell_pairs(xq, xs, side):
    """Candidate pairs within SIDE of each other: yields (rows, j), rows indices into xq and j into xs of equal
    length, covering every pair closer than SIDE (cells of side SIDE, the 27 round each query's)."""
    lo = np.minimum(xq.min(axis=0), xs.min(axis=0)) - side
    dims = np.ceil((np.maximum(xq.max(axis=0), xs.max(axis=0)) + side - lo) / side).astype(np.int64) + 1

    def key(c):
        return (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]

    ks = key(np.floor((xs - lo) / side).astype(np.int64))
    order = np.argsort(ks, kind="stable")
    ks = ks[order]
    cq = np.floor((xq - lo) / side).astype(np.int64)
    for off in np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1])).T.reshape(-1, 3):
        k = key(cq + off)
        begin, end = np.searchsorted(ks, k, "left"), np.searchsorted(ks, k, "right")
        for n in range(int((end - begin).max(initial=0))):
            rows = np.where(begin + n < end)[0]
            yield rows, order[begin[rows] + n]
