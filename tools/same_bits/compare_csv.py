#!/usr/bin/env python3
"""Compares two CSV files cell by cell as text (the sweep writes every double with 17
significant digits, so equal text is equal bits), skipping the columns whose header matches
a regular expression (the timings). Prints one line: "same  NAME" or what differs first.
Usage: compare_csv.py NAME OLD.csv NEW.csv IGNORED_HEADER_REGEX   (exit 0 same, 1 not)."""
import csv
import re
import sys


def main() -> int:
    name, old_path, new_path, ignored = sys.argv[1:5]
    skip = re.compile(ignored) if ignored else None
    try:
        with open(old_path, newline="") as f:
            old = list(csv.reader(f))
        with open(new_path, newline="") as f:
            new = list(csv.reader(f))
    except OSError as e:
        print(f"DIFFERS {name}: {e}")
        return 1
    if not old or not new or old[0] != new[0]:
        print(f"DIFFERS {name}: headers differ or a file is empty")
        return 1
    header = old[0]
    keep = [i for i, h in enumerate(header) if not (skip and skip.search(h))]
    if len(old) != len(new):
        print(f"DIFFERS {name}: {len(old) - 1} rows against {len(new) - 1}")
        return 1
    for r, (a, b) in enumerate(zip(old[1:], new[1:]), start=1):
        for i in keep:
            x = a[i] if i < len(a) else ""
            y = b[i] if i < len(b) else ""
            if x != y:
                print(f"DIFFERS {name}: row {r}, column {header[i]}: {x} against {y}")
                return 1
    print(f"same    {name} ({len(old) - 1} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
