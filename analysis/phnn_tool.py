"""The phnn binary for the analysis scripts: $PHNN, else build/phnn next to analysis/.

    from phnn_tool import run_csv
    rows = run_csv("reduce", "results/paper.h5", "--format", "csv")   # list of dicts
"""
import csv
import io
import os
import subprocess


def phnn():
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return os.environ.get("PHNN", os.path.join(here, "build", "phnn"))


def run_csv(*args):
    """`phnn ARGS...`'s standard output read as CSV rows (dicts); raises if phnn fails."""
    out = subprocess.run([phnn(), *args], check=True, capture_output=True, text=True).stdout
    return list(csv.DictReader(io.StringIO(out)))
