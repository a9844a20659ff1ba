#!/usr/bin/env python3
"""Particle counts in the core of scenes/tube_shift_packing.json runs (docs/validation.md, stop 44).

For each run directory (written with --vtk): at each VTK frame, the blood particles between y = 10 and 34 mm
and those of them within 8 mm of the axis. Shifting that the density does not see packs the core; the
unshifted run is the reference.
Usage: scripts/shift_packing.py RUN_DIR [RUN_DIR...]
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from jet_noise import frames, read_vtp  # noqa: E402


def counts(run_dir):
    out = []
    for t, path in frames(run_dir):
        v = read_vtp(path)
        x = v['Points'].reshape(-1, 3)
        blood = v['body'] == 0
        band = blood & (x[:, 1] > 0.010) & (x[:, 1] < 0.034)
        core = band & (np.hypot(x[:, 0], x[:, 2]) < 0.008)
        out.append((t, int(band.sum()), int(core.sum())))
    return out


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for d in sys.argv[1:]:
        if not os.path.isdir(d):
            sys.exit(f'{d}: not a run directory')
        print(f'{d}:')
        for t, band, core in counts(d):
            print(f'  t = {t * 1e3:5.0f} ms  y 10-34 mm: {band:5d}  within 8 mm of the axis: {core:4d}')


if __name__ == '__main__':
    main()
