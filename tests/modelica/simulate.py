#!/usr/bin/env python3
"""Simulates one Modelica model with rumoca and prints its variables.

Usage:
    simulate.py ROOT MODEL [TIME ...]

ROOT is the library root (the folder holding the packages), MODEL the qualified name of a model whose class
file lies below ROOT. The stop time and output interval come from the model's `experiment(StopTime=...,
Interval=...)` annotation. For every variable the script prints `name value@TIME` for each requested TIME
(nearest output point) and its final value as `name value@end`, one variable per line, then
`simulated MODEL to STOPTIME`.
"""

import os
import re
import sys


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    import rumoca as rm

    root, model = os.path.abspath(argv[0]), argv[1]
    times = [float(t) for t in argv[2:]]
    path = os.path.join(root, *model.split(".")) + ".mo"
    with open(path, encoding="utf-8") as f:
        text = f.read()
    exp = re.search(r"experiment\s*\(([^)]*)\)", text)
    if not exp:
        print(f"{model} has no experiment annotation", file=sys.stderr)
        return 1
    stop = float(re.search(r"StopTime\s*=\s*([0-9.eE+-]+)", exp.group(1)).group(1))
    interval = re.search(r"Interval\s*=\s*([0-9.eE+-]+)", exp.group(1))
    dt = float(interval.group(1)) if interval else stop / 500
    m = rm.Session(roots=[root]).load(path, model=model)
    r = m.simulate(t=(0, stop), dt=dt)
    t = list(r.time)
    for name in r.names:
        values = list(r[name])
        parts = []
        for want in times:
            i = min(range(len(t)), key=lambda k: abs(t[k] - want))
            parts.append(f"{values[i]!r}@{want}")
        parts.append(f"{values[-1]!r}@end")
        print(name, " ".join(parts))
    print(f"simulated {model} to {stop}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
