#!/usr/bin/env python3
"""Checks generated Modelica packages with rumoca, a real Modelica compiler (rumoca==0.10.2 from PyPI).

Usage:
    check.py ROOT [--aggregate] [--jobs N] [--quiet] [--same-as PACKAGE=REFERENCE]...

ROOT is the folder that holds the generated packages (OpcUaSupport, OpcUa, OpcUaDI, ...), which rumoca
takes as its one library root. Every class file below ROOT (not package.mo or package.order) is checked:

* models, blocks and partial models through `model Check extends <Class>; end Check;`,
* a partial block the same way, except that it may lack equations: Modelica 4.7 does not ask a partial class
  to be balanced, and the read interfaces of OpcUaSupport.Interfaces leave the equation of the value read to
  an implementation (rumoca has no check for partial classes, and refuses even a zero-length array of one).
  Any other error fails; the implementations (OpcUaSupport.Loopback) are checked whole,
* a class with a complete variant (a class `<Pkg>.Complete.X` that extends it and binds the inputs it leaves
  unbound) likewise may lack equations when checked alone; its complete variant is checked whole,
* records through a component `<Class> x;` (so every field needs a default),
* connectors and types through a zero-length array `<Class> x[0];` (the class is still resolved and type
  checked, without leaving an unbound output),
* packages of constants (EnumerationValues) through a parameter bound to each constant.

rumoca compiles a wrapper to a balanced DAE, so a check fails on unresolved names, type errors, invalid
modifications and unbalanced models. What rumoca does not check is checked elsewhere: duplicate enumeration
literals and component names are caught by the Rust unit tests of the generator.

Each class gets a fresh rumoca Session (a Session caches classes across loads). rumoca can crash the whole
Python process on some inputs, so the checks run in worker processes: a worker that dies marks the class it
was checking as failed and a new worker continues with the rest.

With --aggregate, all classes below ROOT are checked in one session through one wrapper model that holds one
component per class; if that fails, the classes are checked one by one to find the culprits. A class with a
complete variant is checked through it there (a component of it would leave its inputs unbound): it passes
when its complete variant does. This is how the
corpus test checks a hundred nodesets in reasonable time.

--same-as PACKAGE=REFERENCE leaves the classes of the top-level package PACKAGE out of the check when
ROOT/PACKAGE is byte for byte REFERENCE/PACKAGE (every file, same names), for a package that is checked in
REFERENCE: the support package OpcUaSupport is written unchanged into every generated tree, and refers to
nothing outside itself, so its 45 classes (30 of them blocks, each checked in a session of its own) would be
checked again in each of the corpus's hundred trees with the same outcome. The classes left out are counted on
a line `left out: N classes of PACKAGE, identical to REFERENCE/PACKAGE`; a package that differs, or is absent
from REFERENCE, is checked as usual.

The last line of the output is always `N passed, N failed`.
"""

import os
import re
import subprocess
import sys
import time

WITHIN = re.compile(r"^\s*within\s+([A-Za-z_][A-Za-z0-9_.]*)?\s*;", re.M)
KIND = re.compile(r"^\s*(?:encapsulated\s+)?(partial\s+)?(model|block|record|connector|type|package|function|class)\s+([A-Za-z_][A-Za-z0-9_]*)\b", re.M)
CONSTANT = re.compile(r"^\s*constant\s+[A-Za-z_][A-Za-z0-9_.]*\s+([A-Za-z_][A-Za-z0-9_]*)\s*(\[[^\]]*\])?\s*=", re.M)


# rumoca 0.10.2 flattens a class that holds an external object (MLS 12.9.7) but refuses to lower it to a DAE:
# it has no value type for an ExternalObject. A class whose only fault is that refusal passes: its names,
# types, modifiers, outer/inner pairs and function calls were checked up to the flat model (the blocks of
# OpcUaSupport.Live and the models that use them). pymoca (check2.py) flattens the same classes.
EXTERNAL_OBJECT_REFUSED = re.compile(
    r"^todae failed: Check__ failed in ToDae: unsupported Flat semantic owner `function value type`: "
    r"`[A-Za-z0-9_.]+` has unsupported type `([A-Za-z_][A-Za-z0-9_]*)`$"
)
EXTENDS_EXTERNAL_OBJECT = re.compile(r"\bclass\s+([A-Za-z_][A-Za-z0-9_]*)\b[^;]*?\s*extends\s+ExternalObject\s*;", re.S)


def external_objects(root):
    """The names of the classes below root that extend ExternalObject."""
    out = set()
    for dirpath, _, filenames in os.walk(root):
        for f in filenames:
            if f.endswith(".mo"):
                with open(os.path.join(dirpath, f), encoding="utf-8") as fh:
                    text = fh.read()
                if "ExternalObject" in text:
                    out.update(m.group(1) for m in EXTENDS_EXTERNAL_OBJECT.finditer(strip_comments(text)))
    return out


def external_object_holders(root, items):
    """The classes of `items` that hold an external object, directly or through a component: rumoca refuses
    them in ToDae (see EXTERNAL_OBJECT_REFUSED), so --aggregate checks them one by one."""
    objects = external_objects(root)
    if not objects:
        return set()
    texts = {}
    for name, *_ in items:
        try:
            with open(os.path.join(root, *name.split(".")) + ".mo", encoding="utf-8") as fh:
                texts[name] = strip_comments(fh.read())
        except OSError:
            pass
    direct = re.compile(r"\b(?:" + "|".join(sorted(objects)) + r")\b")
    holders = {n for n, t in texts.items() if direct.search(t)}
    new = set(holders)
    while new:
        named = re.compile(r"\b(?:" + "|".join(re.escape(n) for n in sorted(new)) + r")\b")
        new = {n for n, t in texts.items() if n not in holders and named.search(t)}
        holders |= new
    return holders


# rumoca's report of a model with fewer equations than unknowns, and nothing else wrong.
UNDERDETERMINED = re.compile(r"^todae failed: Check__ failed in ToDae: unbalanced model: \d+ equations, \d+ unknowns \(balance = -\d+\);[^;]*$")


COMPLETE_EXTENDS = re.compile(r"^\s*extends\s+([A-Za-z_][A-Za-z0-9_.]*)", re.M)


def completed(root, items):
    '''{class: its complete variant} for the classes that a class of a `Complete` package extends.'''
    out = {}
    for name, kind, _, _ in items:
        parts = name.split(".")
        if kind != "model" or "Complete" not in parts[1:-1]:
            continue
        path = os.path.join(root, *parts) + ".mo"
        with open(path, encoding="utf-8") as fh:
            m = COMPLETE_EXTENDS.search(strip_comments(fh.read()))
        if m:
            out[m.group(1)] = name
    return out


def same_files(a, b):
    """Whether folders a and b hold the same files (relative names and bytes), and a holds any."""

    def files(top):
        out = {}
        for dirpath, _, filenames in os.walk(top):
            for f in filenames:
                path = os.path.join(dirpath, f)
                with open(path, "rb") as fh:
                    out[os.path.relpath(path, top)] = fh.read()
        return out

    if not os.path.isdir(a) or not os.path.isdir(b):
        return False
    mine = files(a)
    return bool(mine) and mine == files(b)


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def classes(root):
    """(qualified name, kind, partial, constants) of every class file below root, sorted."""
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames.sort()
        for f in sorted(filenames):
            if not f.endswith(".mo") or f == "package.mo":
                continue
            path = os.path.join(dirpath, f)
            with open(path, encoding="utf-8") as fh:
                text = strip_comments(fh.read())
            w = WITHIN.search(text)
            k = KIND.search(text)
            if not w or not k:
                out.append((os.path.relpath(path, root), "unknown", False, []))
                continue
            within = w.group(1) or ""
            name = (within + "." if within else "") + k.group(3)
            consts = CONSTANT.findall(text) if k.group(2) == "package" else []
            out.append((name, k.group(2), bool(k.group(1)), consts))
    return out


def wrapper(name, kind, partial, consts, ident="Check__"):
    """Source of a model that makes rumoca compile class `name`, or None for a kind that cannot be checked."""
    if kind in ("model", "block"):
        return f"model {ident}\n  extends {name};\nend {ident};\n"
    if kind == "record":
        return f"model {ident}\n  {name} x;\nend {ident};\n"
    if kind in ("connector", "type"):
        return f"model {ident}\n  {name} x[0];\nend {ident};\n"
    if kind == "package" and consts:
        lines = []
        for i, (c, dims) in enumerate(consts):
            lines.append(f"  parameter Integer c{i}{'[:]' if dims else ''} = {name}.{c};")
        return f"model {ident}\n" + "\n".join(lines) + f"\nend {ident};\n"
    return None


def check_one(rm, root, name, kind, partial, consts):
    src = wrapper(name, kind, partial, consts)
    if src is None:
        return False, f"cannot check a {kind} (no wrapper for this kind)"
    try:
        session = rm.Session(roots=[root])
        session.loads(src, model="Check__", filename="Check__.mo")
        return True, ""
    except Exception as e:  # rumoca raises CompileError, ParseError, ... all RumocaError
        msg = " ".join(str(e).split())
        lenient = (kind == "block" and partial is True) or partial == 2
        if lenient and UNDERDETERMINED.search(msg):
            return True, ""
        refused = EXTERNAL_OBJECT_REFUSED.search(msg)
        if refused and refused.group(1) in external_objects(root):
            return True, ""
        return False, msg[:600]


def worker(root, items):
    """Runs in a child process: checks classes read from stdin, prints START/RESULT lines."""
    import rumoca as rm

    for line in sys.stdin:
        name, kind, partial, consts = decode(line.rstrip("\n"))
        print(f"START\t{name}", flush=True)
        ok, msg = check_one(rm, root, name, kind, partial, consts)
        print(f"RESULT\t{name}\t{'OK' if ok else 'FAIL'}\t{msg}", flush=True)


def encode(item):
    name, kind, partial, consts = item
    cs = ";".join(f"{c}{'|' + d if d else ''}" for c, d in consts)
    return f"{name}\t{kind}\t{int(partial)}\t{cs}"


def decode(line):
    name, kind, partial, cs = line.split("\t")
    consts = []
    for c in filter(None, cs.split(";")):
        n, _, d = c.partition("|")
        consts.append((n, d))
    # 1: partial; 2: has a complete variant (see `completed`).
    return name, kind, {"0": False, "1": True}.get(partial, 2), consts


def class_size(root, name):
    """The size of the file of class `name` below root (0 when it has none): a proxy for its cost."""
    try:
        return os.path.getsize(os.path.join(root, *name.split(".")) + ".mo")
    except OSError:
        return 0


def run_checks(root, items, jobs, quiet, script=None):
    """Checks `items` in `jobs` worker processes (`script --worker ROOT`, this file by default); returns
    {name: (ok, message)}.

    The workers take the classes one at a time from one queue, largest file first: a few classes (the
    instance trees of a whole model) cost a hundred times the median, and split in fixed halves they left one
    worker, and one of the machine's two cores, idle for minutes at the end. A worker that dies marks the class
    it was checking as failed and a new worker goes on with the queue."""
    import threading
    from collections import deque

    results = {}
    queue = deque(sorted(items, key=lambda it: (-class_size(root, it[0]), it[0])))
    lock = threading.Lock()

    def start():
        return subprocess.Popen(
            [sys.executable, script or os.path.abspath(__file__), "--worker", root],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            bufsize=1,
        )

    def record(name, ok, message):
        with lock:
            results[name] = (ok, message)
            if not quiet:
                print(f"{'ok  ' if ok else 'FAIL'} {name}" + ("" if ok else f": {message}"), flush=True)

    def drive():
        p = None
        while True:
            with lock:
                item = queue.popleft() if queue else None
            if item is None:
                break
            if p is None:
                p = start()
            try:
                p.stdin.write(encode(item) + "\n")
                p.stdin.flush()
            except OSError:  # the worker ended after its last class: a new one takes this one
                p.wait()
                p = start()
                p.stdin.write(encode(item) + "\n")
                p.stdin.flush()
            done = False
            for line in p.stdout:
                parts = line.rstrip("\n").split("\t")
                if parts[0] == "RESULT" and parts[1] == item[0]:
                    record(parts[1], parts[2] == "OK", parts[3] if len(parts) > 3 else "")
                    done = True
                    break
            if not done:
                rc = p.wait()
                record(item[0], False, f"the checker crashed (exit status {rc}) while compiling this class")
                p = None
        if p is not None:
            p.stdin.close()
            p.wait()

    threads = [threading.Thread(target=drive) for _ in range(max(1, min(jobs, len(items))))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return results


def aggregate_source(items):
    lines = ["model CheckAll__"]
    n = 0
    for name, kind, partial, consts in items:
        n += 1
        if kind in ("model", "block"):
            lines.append(f"  model M{n}\n    extends {name};\n  end M{n};\n  M{n} c{n};")
        elif kind == "record":
            lines.append(f"  {name} c{n};")
        elif kind in ("connector", "type"):
            lines.append(f"  {name} c{n}[0];")
        elif kind == "package" and consts:
            for i, (c, dims) in enumerate(consts):
                lines.append(f"  parameter Integer c{n}_{i}{'[:]' if dims else ''} = {name}.{c};")
    lines.append("end CheckAll__;")
    return "\n".join(lines) + "\n"


def main(argv):
    if len(argv) >= 2 and argv[0] == "--worker":
        worker(argv[1], None)
        return 0
    args = [a for a in argv if not a.startswith("--")]
    aggregate = "--aggregate" in argv
    quiet = "--quiet" in argv
    jobs = 2
    same_as = []
    for i, a in enumerate(argv):
        if a == "--jobs" and i + 1 < len(argv):
            jobs = max(1, int(argv[i + 1]))
            args = [x for x in args if x != argv[i + 1]]
        if a == "--same-as" and i + 1 < len(argv) and "=" in argv[i + 1]:
            package, reference = argv[i + 1].split("=", 1)
            same_as.append((package, os.path.abspath(reference)))
            args = [x for x in args if x != argv[i + 1]]
    if len(args) != 1 or not os.path.isdir(args[0]):
        print(__doc__, file=sys.stderr)
        print("0 passed, 1 failed")
        return 2
    root = os.path.abspath(args[0])
    items = classes(root)
    # Which classes hold an external object is found over every class, the ones left out included: a class
    # holds one through a component of a left-out class (an endpoint of the support package) as well.
    everything = items
    for package, reference in same_as:
        if same_files(os.path.join(root, package), os.path.join(reference, package)):
            left = [it for it in items if it[0] == package or it[0].startswith(package + ".")]
            items = [it for it in items if it not in left]
            print(f"left out: {len(left)} classes of {package}, identical to {os.path.join(reference, package)}")
    unknown = [it for it in items if it[1] == "unknown"]
    items = [it for it in items if it[1] != "unknown"]
    done = completed(root, items)
    items = [(n, k, 2 if n in done else p, c) for n, k, p, c in items]
    total = len(items)
    t0 = time.time()
    failed = {}
    passed = 0
    for path, *_ in unknown:
        failed[path] = "no `within` clause or class header found"
    if aggregate and items:
        import rumoca as rm

        # Blocks are checked one by one: a partial block may lack equations (see check_one), and a block's
        # inputs (the write blocks' `u`) are unbound, both of which unbalance a model holding it as a component.
        # Classes that hold an external object are refused by rumoca's ToDae, which check_one accepts.
        holders = external_object_holders(root, [it for it in everything if it[1] != "unknown"])
        alone = [it for it in items if it[1] == "block" or it[0] in holders]
        items = [it for it in items if it[1] != "block" and it[0] not in holders]
        if alone:
            passed += tally(run_checks(root, alone, jobs, quiet), failed)
        # A class with a complete variant is checked through it.
        through = [it for it in items if it[0] in done]
        items = [it for it in items if it[0] not in done]
        src = aggregate_source(items)
        ok = True
        msg = ""
        # The aggregate runs in a child process too, since rumoca can crash.
        r = subprocess.run(
            [sys.executable, "-c", AGGREGATE_CHILD, root],
            input=src,
            capture_output=True,
            text=True,
        )
        ok = r.returncode == 0 and r.stdout.strip().endswith("OK")
        msg = (r.stdout + r.stderr).strip()[-600:]
        if ok:
            passed += len(items) + len(through)
            if not quiet:
                print(f"ok   {len(items)} classes of {root} in one model, {len(through)} through their complete variants")
        else:
            if not quiet:
                print(f"the aggregate model failed ({' '.join(msg.split())[:300]}); checking class by class")
            passed += tally(run_checks(root, items + through, jobs, quiet), failed)
            if not failed:
                failed["<aggregate model>"] = " ".join(msg.split())
    elif items:
        passed += tally(run_checks(root, items, jobs, quiet), failed)
    return report(f"checked {total} classes below {root} in {time.time() - t0:.1f} s", passed, failed, quiet)


def options(argv, doc):
    """The arguments `ROOT [--only PREFIX]... [--jobs N] [--quiet]` of the checkers: (root, quiet, jobs, only),
    or None after printing `doc` and a failing summary when ROOT is not one folder."""
    quiet, jobs, only, args, i = "--quiet" in argv, 2, [], [], 0
    while i < len(argv):
        a = argv[i]
        if a in ("--jobs", "--only") and i + 1 < len(argv):
            if a == "--jobs":
                jobs = max(1, int(argv[i + 1]))
            else:
                only.append(argv[i + 1])
            i += 1
        elif not a.startswith("--"):
            args.append(a)
        i += 1
    if len(args) != 1 or not os.path.isdir(args[0]):
        print(doc, file=sys.stderr)
        print("0 passed, 1 failed")
        return None
    return os.path.abspath(args[0]), quiet, jobs, only


def pymoca_or_none():
    """The pymoca module, or None after saying how to install it (and a failing summary)."""
    try:
        import pymoca
    except ImportError:
        print("pymoca is missing: run `cargo xtask venv` (it installs tests/requirements.txt)", file=sys.stderr)
        print("0 passed, 1 failed")
        return None
    return pymoca


def tally(results, failed):
    """Adds the failures of `results` ({name: (ok, message)}) to `failed`; returns how many passed."""
    passed = 0
    for name, (good, m) in results.items():
        if good:
            passed += 1
        else:
            failed[name] = m
    return passed


def report(what, passed, failed, quiet):
    """Prints the failures (with --quiet; otherwise they were printed as they came), `what` and the summary
    line every checker ends with, `N passed, N failed`; returns the exit status."""
    if quiet:
        for name, m in sorted(failed.items()):
            print(f"FAIL {name}: {m}")
    print(what)
    print(f"{passed} passed, {len(failed)} failed")
    return 0 if not failed else 1


AGGREGATE_CHILD = r"""
import sys, rumoca as rm
src = sys.stdin.read()
try:
    rm.Session(roots=[sys.argv[1]]).loads(src, model="CheckAll__", filename="CheckAll__.mo")
    print("OK")
except Exception as e:
    print(" ".join(str(e).split())[:2000])
    sys.exit(1)
"""

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
