#!/usr/bin/env python3
"""Clumping statistics of the fluid in a run's VTK frames (issue 20 item 5: figures 1 and 3).

For every frame of RUN_DIR/vtk/particles.pvd (`aortasph run ... --vtk-every N`) and the fluid bodies named by
index (--bodies, positions in the scene's `bodies` list), prints
  close   the share of particles whose nearest neighbour (of those bodies) is closer than dx/2: pairs and
          clumps (0 on an even lattice);
  p1      the 1st percentile of the nearest-neighbour distance, in dx;
  nn_cv   the coefficient of variation of the nearest-neighbour distance (0 on a lattice).

Usage: clumping.py --dx DX --bodies 0 [1 ...] LABEL=RUN_DIR [LABEL=RUN_DIR ...]
"""
import argparse
import sys

import numpy as np
from scipy.spatial import cKDTree

from jet_noise import frames, read_vtp


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--dx', type=float, required=True)
    ap.add_argument('--bodies', type=int, nargs='+', required=True)
    ap.add_argument('runs', nargs='+', help='LABEL=RUN_DIR')
    args = ap.parse_args()
    print(f'{"run":<16} {"t [s]":>7} {"n":>7} {"close":>7} {"p1 [dx]":>8} {"nn_cv":>6}')
    for spec in args.runs:
        if '=' not in spec:
            sys.exit(f'{spec}: expected LABEL=RUN_DIR')
        label, run_dir = spec.split('=', 1)
        for t, path in frames(run_dir):
            a = read_vtp(path)
            keep = np.isin(a['body'].astype(int), args.bodies)
            x = a['Points'][keep]
            if len(x) < 2:
                continue
            d, _ = cKDTree(x).query(x, k=2)
            nn = d[:, 1]
            print(f'{label:<16} {t:7.3f} {len(x):7d} {100 * np.mean(nn < 0.5 * args.dx):6.1f}% '
                  f'{np.percentile(nn, 1) / args.dx:8.2f} {nn.std() / nn.mean():6.3f}')


if __name__ == '__main__':
    main()
