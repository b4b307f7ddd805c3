"""Shared by the peer scripts: the view voltex exported, the metrics against the truth (through
`voltex compare --json`, so peers and voltex are measured by the same code), the CSV rows that
`voltex pareto --peers` reads, and the machine's threads and load."""

import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VOLTEX = os.environ.get("VOLTEX", os.path.join(ROOT, "target", "release", "voltex"))
COLUMNS = ["renderer", "setting", "samples", "seconds", "threads", "version", "rmse", "rel_rmse", "flip"]


def load_view(path):
    with open(path) as f:
        return json.load(f)


def metrics(image, truth):
    """FLIP, relative RMSE and RMSE of `image` against `truth` (both EXR)."""
    r = subprocess.run([VOLTEX, "compare", image, truth, "--json"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"voltex compare {image} {truth} failed:\n{r.stderr}")
    return json.loads(r.stdout)


def load_average():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def write_csv(path, rows):
    """Rows (dicts with COLUMNS) to `path`, written whole (temporary file, then rename)."""
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, lineterminator="\n")
        w.writeheader()
        for row in rows:
            assert not any("," in str(v) for v in row.values()), row
            w.writerow(row)
    os.replace(tmp, path)


def row(renderer, setting, samples, seconds, threads, version, m):
    return {
        "renderer": renderer,
        "setting": setting,
        "samples": samples,
        "seconds": f"{seconds:.6f}",
        "threads": threads,
        "version": version,
        "rmse": f"{m['rmse']:.6e}",
        "rel_rmse": f"{m['rel_rmse']:.6e}",
        "flip": f"{m['flip']:.6e}",
    }
