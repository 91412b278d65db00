#!/usr/bin/env python3
"""Simulates one Modelica model with rumoca and prints its variables.

Usage:
    simulate.py [--strings-as-parameters] ROOT MODEL [TIME ...]

ROOT is the library root (the folder holding the packages), MODEL the qualified name of a model whose class
file lies below ROOT. The stop time and output interval come from the model's `experiment(StopTime=...,
Interval=...)` annotation. For every variable the script prints `name value@TIME` for each requested TIME
(nearest output point) and its final value as `name value@end`, one variable per line, then
`simulated MODEL to STOPTIME`.

rumoca 0.10.2 cannot simulate a model with a String variable (tests/modelica/RumocaBehaviour.StringDemo), and
every OPC UA state machine has one (CurrentState). With --strings-as-parameters the script simulates a copy of
ROOT in which each String variable of the generated packages is a parameter: `OpcUaSupport.StringOutput x` and
`OpcUaSupport.StringInput x` become `parameter String x`, a `String x` without a value becomes
`parameter String x = ""`, and the equations `x = ...;` of the latter are left out; the equation `w.u = ...;`
that gives a binding model's String write block `w` its input becomes the binding `u=...` of that parameter. Numbers, Booleans and the
state machines are simulated as generated; the texts are not.
"""

import os
import re
import shutil
import sys
import tempfile


def strings_as_parameters(root):
    """A copy of the library below `root` with String variables as parameters (see the module doc)."""
    copy = os.path.join(tempfile.mkdtemp(prefix="strings-as-parameters-"), "lib")
    shutil.copytree(root, copy)
    for folder, _, files in os.walk(copy):
        for name in files:
            if not name.endswith(".mo"):
                continue
            path = os.path.join(folder, name)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            new = re.sub(r"(?m)^(\s*)OpcUaSupport\.String(?:Output|Input) ", r"\1parameter String ", text)
            unbound = re.findall(r"(?m)^\s*String (\w+)$", new)
            new = re.sub(r"(?m)^(\s*)String (\w+)$", r'\1parameter String \2 = ""', new)
            new = re.sub(r"(?m)^(\s*)String (\w+ = )", r"\1parameter String \2", new)
            for var in unbound:
                new = re.sub(r"(?m)^\s*%s = .*;\n" % re.escape(var), "", new)
            # A binding model's String write block gets its input through an equation; with the input a
            # parameter, the equation becomes its binding.
            for block in re.findall(r"(?m)^\s*WriteString (\w+)\(", new):
                eq = re.search(r"(?m)^\s*%s\.u = (.*);\n" % re.escape(block), new)
                if eq:
                    new = new.replace(eq.group(0), "")
                    new = re.sub(r"(?m)^(\s*WriteString %s\()" % re.escape(block), r"\g<1>u=%s, " % eq.group(1).replace("\\", "\\\\"), new)
            if new != text:
                with open(path, "w", encoding="utf-8") as f:
                    f.write(new)
    return copy


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    import rumoca as rm

    strings = argv[0] == "--strings-as-parameters"
    if strings:
        argv = argv[1:]
    root, model = os.path.abspath(argv[0]), argv[1]
    times = [float(t) for t in argv[2:]]
    if strings:
        root = strings_as_parameters(root)
    try:
        return simulate(rm, root, model, times)
    finally:
        if strings:
            shutil.rmtree(os.path.dirname(root), ignore_errors=True)


def simulate(rm, root, model, times):
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
            # float(): with numpy 2 (pymoca brings it into the venv) the values are numpy scalars, whose
            # repr is `np.float64(...)`.
            parts.append(f"{float(values[i])!r}@{want}")
        parts.append(f"{float(values[-1])!r}@end")
        print(name, " ".join(parts))
    print(f"simulated {model} to {stop}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
