#!/usr/bin/env python3
"""Stack figure sheets of several runs above one another, each row titled, into one PNG (matplotlib).

Usage: figure_stack.py --out OUT.png [--title TITLE] [--width INCHES] "LABEL=path/to/figureN.png" ...

Used for before/after comparisons in docs/validation.md (e.g. figure 5 of the main job without and with
particle shifting: issue 20 item 6). The sheets are shown as they are (no resampling beyond the figure's dpi).
"""
import argparse
import sys

import matplotlib

matplotlib.use('Agg')
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--out', required=True)
    ap.add_argument('--title')
    ap.add_argument('--width', type=float, default=14.0)
    ap.add_argument('--crop-bottom', type=float, default=0.0,
                    help='fraction of each sheet cut off at the bottom (e.g. to drop repeated colour bars), '
                         'except for the last row')
    ap.add_argument('sheets', nargs='+', help='LABEL=PNG')
    args = ap.parse_args()
    images = []
    for spec in args.sheets:
        if '=' not in spec:
            sys.exit(f'{spec}: expected LABEL=PNG')
        label, path = spec.split('=', 1)
        try:
            images.append((label, mpimg.imread(path)))
        except (OSError, ValueError) as e:
            sys.exit(f'{path}: cannot read ({e})')
    cropped = []
    for k, (label, img) in enumerate(images):
        if args.crop_bottom > 0 and k + 1 < len(images):
            img = img[: int(img.shape[0] * (1 - args.crop_bottom))]
        cropped.append((label, img))
    heights = [img.shape[0] / img.shape[1] for _, img in cropped]
    fig, axes = plt.subplots(len(cropped), 1, figsize=(args.width, args.width * sum(heights) * 1.08),
                             gridspec_kw={'height_ratios': heights}, squeeze=False)
    for ax, (label, img) in zip(axes[:, 0], cropped):
        ax.imshow(img)
        ax.set_axis_off()
        ax.set_title(label, loc='left', fontsize=13)
    if args.title:
        fig.suptitle(args.title, fontsize=14)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == '__main__':
    main()
