"""Print the criterion medians of the last ``cargo bench`` as a Markdown table
(``python benches/criterion_medians.py``; BENCHMARKS.md records them per version)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

argparse.ArgumentParser(description=__doc__).parse_args()

root = Path(__file__).resolve().parent.parent / "target" / "criterion"
print("| bench | median | 95 % interval |\n|---|---|---|")
for est in sorted(root.glob("**/new/estimates.json")):
    name = str(est.parent.parent.relative_to(root))
    m = json.loads(est.read_text())["median"]
    lo, hi = m["confidence_interval"]["lower_bound"], m["confidence_interval"]["upper_bound"]
    print(f"| {name} | {m['point_estimate'] / 1e3:.3f} us | {lo / 1e3:.3f} - {hi / 1e3:.3f} us |")
