#!/usr/bin/env python3
"""The source lines of an Nsight Compute source page (ncu --page source --csv --print-source
cuda,sass) with the most warp stall samples, and each file's share.

  ncu-source.py SOURCE.csv [LINES]
"""
import csv
import sys


def main(path, top=40):
    lines, current, header = [], None, None
    for r in csv.reader(open(path, errors="replace")):
        if not r:
            continue
        if r[0] == "File Path":
            current = r[1]
        elif r[0] == "Line No":
            header = r
            column = header.index("Warp Stall Sampling (All Samples)")
        elif header and current and r[0].isdigit():
            try:
                samples = float(r[column].replace(",", "") or 0)
            except ValueError:
                continue
            lines.append((samples, current.rsplit("/", 1)[-1], int(r[0]), r[1].strip()[:90]))
    total = sum(s for s, *_ in lines) or 1.0
    print(f"warp stall samples: {total:.0f} over {len(lines)} source lines")
    files = {}
    for s, f, *_ in lines:
        files[f] = files.get(f, 0.0) + s
    for f, s in sorted(files.items(), key=lambda x: -x[1])[:8]:
        print(f"  {100 * s / total:5.1f}%  {f}")
    for s, f, n, text in sorted(lines, reverse=True)[:top]:
        print(f"  {100 * s / total:5.1f}%  {f}:{n}  {text}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 40)
