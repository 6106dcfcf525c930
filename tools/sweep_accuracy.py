#!/usr/bin/env python3
"""Force accuracy of a snapthread-sweep CSV against a reference sweep of the same path.

    tools/sweep_accuracy.py TRACE.csv REFERENCE.csv --force-scale S

Per row: true error |F - F_ref|_inf / S (rows matched by step). Prints the max and the
median, the statuses and terminations, mean iterations and median solve_us of the trace;
where the trace has the force_error column (the certified estimate, docs/accuracy.md),
the share of rows it covers (estimate >= true error) and the median estimate / true
error. The reference should be polished to round-off (e.g. the same sweep at
--cutoff 1e-11 --max-iterations 0). Plain Python: no numpy.
"""
import argparse
import collections
import csv
import statistics
import sys


def read(path):
    with open(path, newline="") as f:
        return {int(r["step"]): r for r in csv.DictReader(f)}


def force(row):
    return [float(row[k]) for k in ("f_x", "f_y", "f_z")]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("trace")
    ap.add_argument("reference")
    ap.add_argument("--force-scale", type=float, required=True,
                    help="the model's ForceScale() (thread3d: 20.19 (beta/2) l / (n l)^2)")
    a = ap.parse_args()
    trace, ref = read(a.trace), read(a.reference)
    steps = sorted(set(trace) & set(ref))
    if not steps:
        sys.exit("no common steps")
    errors, covered, ratios = [], 0, []
    has_estimate = "force_error" in trace[steps[0]]
    for k in steps:
        t, r = trace[k], ref[k]
        err = max(abs(x - y) for x, y in zip(force(t), force(r))) / a.force_scale
        errors.append(err)
        if has_estimate:
            est = float(t["force_error"]) / a.force_scale
            covered += est >= err
            if err > 1e-12:
                ratios.append(est / err)
    statuses = collections.Counter(trace[k]["status"] for k in steps)
    terms = collections.Counter(trace[k]["termination"] for k in steps)
    ref_terms = collections.Counter(ref[k]["termination"] for k in steps)
    its = statistics.mean(float(trace[k]["iterations"]) for k in steps)
    us = statistics.median(float(trace[k]["solve_us"]) for k in steps)
    print(f"rows {len(steps)}: force error / scale max {max(errors):.3g} median {statistics.median(errors):.3g}")
    print(f"  statuses {dict(statuses)}; terminations {dict(terms)}; reference terminations {dict(ref_terms)}")
    print(f"  iterations/update {its:.2f}; median solve_us {us:.1f}")
    if has_estimate:
        med = statistics.median(ratios) if ratios else float("nan")
        print(f"  estimate covers {covered}/{len(steps)} rows; median estimate/true {med:.3g}")


if __name__ == "__main__":
    main()
