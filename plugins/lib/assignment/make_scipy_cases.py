#!/usr/bin/python3
# Purpose: writes data/scipy_cases.txt, SciPy's linear_sum_assignment answers to large generated problems.
#
# The cost matrices are not stored: both this script and test_linear_assignment.cpp
# (scipy_case_matrix.hpp) rebuild them bit for bit from a seed with splitmix64, whose integer
# arithmetic and exact conversions (53-bit integer times a power of two) leave no room for the
# two languages to differ. So the data file holds only each case's recipe and SciPy's answer.
#
# Run from this folder with Debian's python3-scipy:  /usr/bin/python3 make_scipy_cases.py
import math
import os
import sys

import numpy as np
from scipy.optimize import linear_sum_assignment

MASK = (1 << 64) - 1


class SplitMix64:
    def __init__(self, seed):
        self.state = seed & MASK

    def next(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        return z ^ (z >> 31)

    def uniform(self):  # [0, 1), exact: a 53-bit integer times 2^-53
        return (self.next() >> 11) * 2.0**-53


# (name, rows, cols, seed, integer range (0: real costs in [0, 1024)), forbidden per mille,
#  hall block k: rows 0..k may only use columns 0..k-1: k + 1 rows on k columns, so with
#  rows <= cols no assignment covers every row (Hall's condition fails))
CASES = [
    ("real_50x80_forbid300", 50, 80, 1, 0, 300, 0),
    ("real_200x200_forbid100", 200, 200, 2, 0, 100, 0),
    ("real_300x150_forbid500", 300, 150, 3, 0, 500, 0),
    ("int1000_200x200_forbid200", 200, 200, 4, 1000, 200, 0),
    ("int20_40x25", 40, 25, 5, 20, 0, 0),
    ("real_150x300_forbid900", 150, 300, 6, 0, 900, 0),
    ("real_250x250", 250, 250, 7, 0, 0, 0),
    ("real_1x200_forbid500", 1, 200, 8, 0, 500, 0),
    ("real_200x1_forbid500", 200, 1, 9, 0, 500, 0),
    ("int100_120x100_forbid50", 120, 100, 10, 100, 50, 0),
    ("real_120x100_hall3", 120, 100, 11, 0, 100, 3),
    ("real_100x100_forbid970", 100, 100, 12, 0, 970, 0),
    ("int50_60x90_forbid600", 60, 90, 13, 50, 600, 0),
    ("real_100x120_hall3", 100, 120, 14, 0, 100, 3),
]


def matrix(rows, cols, seed, int_range, forbid_per_mille, hall):
    """Row-major, one cost draw then one forbid draw per entry (scipy_case_matrix.hpp)."""
    rng = SplitMix64(seed)
    m = np.empty((rows, cols))
    for i in range(rows):
        for j in range(cols):
            cost = float(rng.next() % int_range) if int_range > 0 else rng.uniform() * 1024.0
            forbidden = rng.next() % 1000 < forbid_per_mille
            if hall > 0 and i <= hall and j >= hall:
                forbidden = True
            m[i, j] = math.inf if forbidden else cost
    return m


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    lines = ["# Written by make_scipy_cases.py with SciPy " + __import__("scipy").__version__ + "; do not edit.",
             "# name rows cols seed int_range forbid_per_mille hall feasible total(hex) column_for_row..."]
    for name, rows, cols, seed, int_range, forbid, hall in CASES:
        m = matrix(rows, cols, seed, int_range, forbid, hall)
        head = f"{name} {rows} {cols} {seed} {int_range} {forbid} {hall}"
        try:
            r, c = linear_sum_assignment(m)
        except ValueError as e:  # SciPy: "cost matrix is infeasible"
            lines.append(f"{head} 0 inf")
            print(f"{name}: infeasible ({e})")
            continue
        column_for_row = [-1] * rows
        for i, j in zip(r, c):
            column_for_row[i] = int(j)
        total = float(m[r, c].sum())
        lines.append(f"{head} 1 {total.hex()} " + " ".join(map(str, column_for_row)))
        print(f"{name}: total {total}")
    with open(os.path.join(here, "data", "scipy_cases.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
