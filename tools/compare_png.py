#!/usr/bin/env python3
"""Compares two images of the same size written by examples/pathtracer (or any 8-bit RGBA PNG without interlacing):
the mean absolute difference per channel (0-255), and the share of pixels whose largest channel difference is above
8 and above 32. Two renders of the same scene and options that agree up to sampling noise differ about as much as
two renders on one driver with different seeds (--seed), or less.

Usage: tools/compare_png.py a.png b.png
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from check_pathtracer import read_png  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    wa, ha, a = read_png(sys.argv[1])
    wb, hb, b = read_png(sys.argv[2])
    if (wa, ha) != (wb, hb):
        sys.exit(f"the images differ in size: {wa}x{ha} and {wb}x{hb}")
    pixels = [(p, q) for ra, rb in zip(a, b) for p, q in zip(ra, rb)]
    mean = [sum(abs(p[k] - q[k]) for p, q in pixels) / len(pixels) for k in range(3)]
    largest = [max(abs(p[k] - q[k]) for k in range(3)) for p, q in pixels]
    over8 = sum(d > 8 for d in largest) / len(pixels)
    over32 = sum(d > 32 for d in largest) / len(pixels)
    print(f"{wa}x{ha}: mean absolute difference r {mean[0]:.2f} g {mean[1]:.2f} b {mean[2]:.2f}; "
          f"pixels differing by more than 8: {100 * over8:.2f}%, by more than 32: {100 * over32:.2f}%")


main()
