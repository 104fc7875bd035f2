#!/usr/bin/python3
# Purpose: writes data/scipy_cases.txt, SciPy's linear_sum_assignment answers to large generated problems.
#
# The cost matrices are not stored: both this script and test_linear_assignment.cpp
# (scipy_case_matrix.hpp) rebuild them bit for bit from a seed with splitmix64, whose integer
# arithmetic and exact conversions (53-bit integer times a power of two) leave no room for the
# two languages to differ. So the data file holds only each case's recipe and SciPy's answer.
#
# Write:  /usr/bin/python3 make_scipy_cases.py          (Debian's python3-scipy)
# Check:  /usr/bin/python3 make_scipy_cases.py --check  (ctest "assignment: SciPy still gives
#         data/scipy_cases.txt": every case's feasibility and total as SciPy solves it today, to
#         1e-9 relative, so a SciPy version that breaks ties differently still passes; exit 77,
#         a ctest skip, when numpy or SciPy is missing)
import math
import os
import sys

SKIP = 77

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
    import numpy as np

    m = np.empty((rows, cols))
    for i in range(rows):
        for j in range(cols):
            cost = float(rng.next() % int_range) if int_range > 0 else rng.uniform() * 1024.0
            forbidden = rng.next() % 1000 < forbid_per_mille
            if hall > 0 and i <= hall and j >= hall:
                forbidden = True
            m[i, j] = math.inf if forbidden else cost
    return m


def solve(name, rows, cols, seed, int_range, forbid, hall):
    """(feasible, total, column_for_row) as SciPy's linear_sum_assignment gives them."""
    from scipy.optimize import linear_sum_assignment

    m = matrix(rows, cols, seed, int_range, forbid, hall)
    try:
        r, c = linear_sum_assignment(m)
    except ValueError:  # SciPy: "cost matrix is infeasible"
        return False, math.inf, []
    column_for_row = [-1] * rows
    for i, j in zip(r, c):
        column_for_row[i] = int(j)
    return True, float(m[r, c].sum()), column_for_row


def data_path():
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "scipy_cases.txt")


def write():
    import scipy

    lines = ["# Written by make_scipy_cases.py with SciPy " + scipy.__version__ + "; do not edit.",
             "# name rows cols seed int_range forbid_per_mille hall feasible total(hex) column_for_row..."]
    for case in CASES:
        feasible, total, column_for_row = solve(*case)
        head = " ".join(map(str, case))
        lines.append(f"{head} 1 {total.hex()} " + " ".join(map(str, column_for_row)) if feasible else f"{head} 0 inf")
        print(f"{case[0]}: " + (f"total {total}" if feasible else "infeasible"))
    with open(data_path(), "w") as f:
        f.write("\n".join(lines) + "\n")
    return 0


def check():
    committed = {}
    with open(data_path()) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            fields = line.split()
            committed[fields[0]] = (fields[7] == "1", float.fromhex(fields[8]) if fields[7] == "1" else math.inf)
    failures = 0
    for case in CASES:
        name = case[0]
        feasible, total, _ = solve(*case)
        if name not in committed:
            print(f"FAIL: {name} is not in {data_path()}: rerun make_scipy_cases.py")
            failures += 1
            continue
        want_feasible, want_total = committed[name]
        ok = feasible == want_feasible and (not feasible or abs(total - want_total) <= 1e-9 * max(1.0, abs(want_total)))
        print(("ok" if ok else "FAIL") + f": {name}: SciPy today {feasible} {total}, committed {want_feasible} {want_total}")
        failures += 0 if ok else 1
    if len(committed) != len(CASES):
        print(f"FAIL: {len(committed)} committed cases, {len(CASES)} in CASES")
        failures += 1
    print(f"{len(CASES)} cases solved by SciPy and compared, {failures} failures")
    return 1 if failures else 0


def main():
    try:
        import numpy  # noqa: F401
        import scipy.optimize  # noqa: F401
    except ImportError as e:
        print(f"skipped: {e} (Debian: apt-get install python3-scipy)")
        return SKIP if "--check" in sys.argv[1:] else 1
    return check() if "--check" in sys.argv[1:] else write()


if __name__ == "__main__":
    sys.exit(main())
